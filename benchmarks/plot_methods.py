#!/usr/bin/python3
"""PSNR against time, one figure per case, from method_benchmark's CSV files.

usage: benchmarks/plot_methods.py FOLDER [--out OUT_FOLDER]

Reads FOLDER/methods.csv and FOLDER/methods_checkpoints.csv and writes
OUT_FOLDER/psnr_time_<case>.png (OUT_FOLDER defaults to FOLDER; ':' in a case id becomes '_'),
the names methods.md links. Each successful cell is a marker at its final PSNR and time; where
the case has a truth, an iterative method's checkpoints draw its curve up to that marker. A case
is plotted when a cell has a finite PSNR, as method_benchmark decides when it links the plot.
Needs Debian's python3-matplotlib (scripts/install-deps.sh).
"""

import argparse
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")  # no display: write files only
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

# The score method_benchmark gives a case without a sharp truth (Case::Score); its checkpoints
# carry no PSNR, so only the markers are drawn.
NO_TRUTH_SCORE = "mean of latent frames vs input"
# A log axis has no zero: times below this (a baseline can take microseconds) are drawn at it.
MIN_TIME_S = 1e-3


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def label(row):
    method = row["method"]
    return method if row["config"] == "default" else f"{method} ({row['config']})"


def plot_case(case, rows, curves, path):
    """Writes the figure of one case; returns False, writing nothing, without a finite PSNR."""
    cells = [r for r in rows if r["status"] == "ok" and math.isfinite(float(r["psnr_db"]))]
    if not cells:
        return False
    first = rows[0]
    has_truth = first["score"] != NO_TRUTH_SCORE
    fig, ax = plt.subplots(figsize=(10, 6), layout="constrained")
    colours = plt.get_cmap("tab10").colors
    for i, row in enumerate(cells):
        colour = colours[i % len(colours)]
        line_style = ("-", "--", ":")[i // len(colours) % 3]  # past ten cells, colours repeat
        time_s = max(float(row["time_s"]), MIN_TIME_S)
        psnr = float(row["psnr_db"])
        points = curves.get((case, row["method"], row["config"]), []) if has_truth else []
        points = [(max(t, MIN_TIME_S), p) for t, p in points if math.isfinite(p)]
        if points:
            ax.plot([t for t, _ in points], [p for _, p in points], color=colour,
                    linestyle=line_style, linewidth=1.3)
        ax.plot([time_s], [psnr], "o", color=colour, markeredgecolor="black", markersize=7,
                label=f"{label(row)}: {psnr:.2f} dB, {float(row['time_s']):.2f} s")
    ax.set_xscale("log")
    ax.xaxis.set_major_formatter(FuncFormatter(lambda t, _: f"{t:g}"))
    ax.set_xlabel("time (s, log scale): build + solve, without reading the data and scoring")
    ax.set_ylabel(f"PSNR (dB), {first['score']}")
    ax.set_title(f"PSNR against time: {first['data']}, {first['mode']} (case {case})")
    ax.grid(True, which="major", color="0.85")
    ax.grid(True, which="minor", axis="x", color="0.94")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small",
              title="method: final PSNR, time", title_fontsize="small")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return True


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="method_benchmark's --out: methods.csv and "
                        "methods_checkpoints.csv")
    parser.add_argument("--out", help="where the PNG files go (default: the folder)")
    args = parser.parse_args()
    out = args.out or args.folder

    rows_by_case = defaultdict(list)
    for row in read_csv(os.path.join(args.folder, "methods.csv")):
        rows_by_case[row["case"]].append(row)
    curves = defaultdict(list)
    for row in read_csv(os.path.join(args.folder, "methods_checkpoints.csv")):
        key = (row["case"], row["method"], row["config"])
        curves[key].append((float(row["time_s"]), float(row["psnr_db"])))

    os.makedirs(out, exist_ok=True)
    written = 0
    for case, rows in rows_by_case.items():
        path = os.path.join(out, "psnr_time_" + case.replace(":", "_") + ".png")
        written += plot_case(case, rows, curves, path)
    print(f"plot_methods: wrote {written} plots to {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
