#!/usr/bin/env python3
"""Where the time of one evfs window goes, and how two builds compare (BENCHMARKS.md, "Where the
time goes").

    benchmarks/where_time_goes.py EVFS [EVFS_BEFORE] [--runs=N] [--data=DIR] [--flags="..."]

Runs each case N times (default 5), alternating the two binaries when two are given, and prints
one markdown table per binary of the medians of:
  * the whole process: wall and CPU seconds (user + system, of the process and its children);
  * start-up: `evfs --version`, CPU seconds;
  * the stages summary.json times (read, bin, build, solve, write) and, inside the solve, what
    Ceres reports (preprocessor, residual and Jacobian evaluation, linear solver);
  * Ceres iterations, conjugate-gradient steps (reconstruct) and the PSNR of the withheld frame
    or frames;
and, with two binaries, the ratios after / before of the pairs' CPU and wall seconds. --flags
go to every job of EVFS; with one binary, EVFS with them is compared with EVFS without them
(e.g. --flags=--preconditioner=SUBSET).

The floor of a solve is its evaluations: every Levenberg-Marquardt iteration evaluates the
residuals and the Jacobian at least once, so "evaluation" (Ceres' residual + Jacobian time) is
what the solve cannot go below without fewer iterations or cheaper terms. "floor share" is that
evaluation over all the time Ceres reports (preprocessor + evaluation + linear solver; summed
over the independent parts, which run in parallel, so these may add to more than "solve").
"""
import argparse
import json
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time


def cases(data):
    """(name, evfs arguments, kind) of each measured job."""
    return [
        ("slider 70->71 predict",
         ["reconstruct", f"--data={data}/slider_depth_70_71", "--mode=predict", "--first=0",
          "--last=1", "--truth=1"], "reconstruct"),
        ("shapes 18,20->19 interpolate",
         ["reconstruct", f"--data={data}/shapes_rotation_13_20", "--mode=interpolate",
          "--first=2", "--last=4", "--truth=3"], "reconstruct"),
        ("DAVIS346 street 0,2->1 interpolate",
         ["reconstruct", f"--data={data}/aedat4_davis346_street/sample.aedat4",
          "--mode=interpolate", "--first=0", "--last=2", "--truth=1"], "reconstruct"),
        ("shapes video --frame_step=2",
         ["video", f"--data={data}/shapes_rotation_13_20", "--frame_step=2",
          "--progress_interval_s=0"], "video"),
    ]


def run(command):
    """Runs `command`; returns (wall s, CPU s of the child, its stdout + stderr)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if done.returncode != 0:
        sys.exit(f"where_time_goes: {' '.join(command)} failed:\n{done.stdout}")
    return wall, cpu, done.stdout


def stage_times(out, kind):
    """Stage and Ceres times, iterations, summed over windows for video."""
    summary = json.load(open(os.path.join(out, "summary.json")))
    records = summary["windows"] if kind == "video" else [summary]
    figures = {}
    for record in records:
        for stage, seconds in record["time_s"].items():
            if stage != "total":
                figures[stage] = figures.get(stage, 0.0) + seconds
        figures["iterations"] = figures.get("iterations", 0) + record.get("iterations", 0)
    if kind == "reconstruct":
        ceres = summary["solver"]["time_s"]
        figures["preprocessor"] = ceres["preprocessor"]
        figures["evaluation"] = ceres["residual_evaluation"] + ceres["jacobian_evaluation"]
        figures["linear solver"] = ceres["linear_solver"]
        figures["CG steps"] = summary["solver"].get("linear_solver_iterations", float("nan"))
    return figures


def psnr(output):
    """The PSNR the command printed for its withheld frame(s)."""
    match = re.search(r"PSNR (?:mean )?([0-9.]+) dB", output)
    return float(match.group(1)) if match else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("evfs")
    parser.add_argument("evfs_before", nargs="?")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--flags", default="", help="extra evfs flags of EVFS's runs")
    parser.add_argument("--data", default=os.path.join(os.path.dirname(__file__),
                                                       "../../shared/data"))
    args = parser.parse_args()
    flags = args.flags.split()
    # (label, binary, extra flags) of each variant; the first is "after".
    variants = [(" ".join([args.evfs] + flags), args.evfs, flags)]
    if args.evfs_before:
        variants.append((args.evfs_before, args.evfs_before, []))
    elif flags:
        variants.append((args.evfs, args.evfs, []))
    binaries = [label for label, _, _ in variants]
    scratch = tempfile.mkdtemp(prefix="evfs-time-")
    results = {b: {} for b in binaries}  # binary -> case -> list of figure dicts
    try:
        for _ in range(args.runs):
            for label, binary, _ in variants:
                _, cpu, _ = run([binary, "--version"])
                results[label].setdefault("start-up", []).append({"cpu": cpu})
            for name, arguments, kind in cases(args.data):
                for label, binary, extra in variants:
                    out = os.path.join(scratch, "out")
                    wall, cpu, output = run([binary] + arguments + extra + [f"--out={out}"])
                    figures = stage_times(out, kind)
                    figures.update(wall=wall, cpu=cpu, psnr=psnr(output))
                    results[label].setdefault(name, []).append(figures)
                    shutil.rmtree(out)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)

    columns = ["wall", "cpu", "read", "bin", "build", "solve", "preprocessor", "evaluation",
               "linear solver", "write", "iterations", "CG steps", "psnr"]
    for binary in binaries:
        print(f"\n{binary} (medians of {args.runs}; seconds, PSNR dB)\n")
        print("| job | " + " | ".join(columns) + " | floor share |")
        print("|" + " --- |" * (len(columns) + 2))
        for name, runs in results[binary].items():
            cells = []
            for column in columns:
                values = [r[column] for r in runs if column in r and r[column] == r[column]]
                form = ".2f" if column == "psnr" else ".3g"
                cells.append(f"{statistics.median(values):{form}}" if values else "")
            floor = [r["evaluation"] / (r["evaluation"] + r["linear solver"] + r["preprocessor"])
                     for r in runs if "evaluation" in r]
            share = f"{statistics.median(floor):.0%}" if floor else ""
            print(f"| {name} | " + " | ".join(cells) + f" | {share} |")
    if len(binaries) == 2:
        print(f"\nafter / before, median of the {args.runs} pairs\n")
        print("| job | CPU s | wall s |\n| --- | --- | --- |")
        for name in results[binaries[0]]:
            pairs = list(zip(results[binaries[0]][name], results[binaries[1]][name]))
            cells = []
            for figure in ("cpu", "wall"):
                ratios = [a[figure] / b[figure] for a, b in pairs if figure in a and figure in b]
                cells.append(f"x{statistics.median(ratios):.2f}" if ratios else "")
            print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
