#!/usr/bin/env python3
"""The slow frames of the whole clips (BENCHMARKS.md, "`evfs video` on whole clips").

Reads the summary.json files that benchmarks/whole_clips.sh leaves in its scratch folder
(SCRATCH/out_CLIP from the default method, SCRATCH/integrate_CLIP from --solver=integrate) and
lists every withheld frame whose blend scores at least --min_blend dB: the frames where the scene
barely moves. Each is held to issue 16's rule, evfs at most 0.1 dB below the better of the blend
and event integration. Prints one row per such frame and a count per clip.

    benchmarks/slow_frames.py [SCRATCH_DIR] [--min_blend=34]
"""
import argparse
import json
import os
import sys

with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "clips.txt")) as listing:
    CLIPS = [line.split()[0] for line in listing if line.strip() and not line.startswith("#")]
TOLERANCE_DB = 0.1


def truth_rows(summary):
    for window in summary["windows"]:
        for row in window.get("truth", []):
            yield window, row


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scratch", nargs="?", default="/tmp/evfs-whole-clips")
    parser.add_argument("--min_blend", type=float, default=34.0)
    args = parser.parse_args()
    print("| clip | frame | window | evfs | blend | integration | evfs − best |")
    print("|---|---|---|---|---|---|---|")
    totals = []
    for clip in CLIPS:
        paths = [os.path.join(args.scratch, kind + "_" + clip, "summary.json")
                 for kind in ("out", "integrate")]
        if not all(os.path.exists(path) for path in paths):
            print(f"{clip}: no summary.json in {args.scratch} (run benchmarks/whole_clips.sh)",
                  file=sys.stderr)
            continue
        with open(paths[0]) as file:
            evfs = json.load(file)
        with open(paths[1]) as file:
            integration = {row["index"]: row["psnr"]
                           for _, row in truth_rows(json.load(file))}
        slow = below = 0
        for window, row in truth_rows(evfs):
            if row["blend_psnr"] < args.min_blend:
                continue
            best = max(row["blend_psnr"], integration[row["index"]])
            margin = row["psnr"] - best
            slow += 1
            below += margin < -TOLERANCE_DB
            frames = window["output_frames"]
            print(f"| {clip} | {row['index']} | {frames[0]}, {frames[-1]} | {row['psnr']:.2f} | "
                  f"{row['blend_psnr']:.2f} | {integration[row['index']]:.2f} | {margin:+.2f} |")
        totals.append((clip, slow, below))
    for clip, slow, below in totals:
        print(f"{clip}: {slow} frames with the blend at {args.min_blend:g} dB or more, "
              f"{below} more than {TOLERANCE_DB} dB below the better of blend and integration")


if __name__ == "__main__":
    main()
