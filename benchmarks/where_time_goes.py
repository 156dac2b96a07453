#!/usr/bin/env python3
"""Where the time of one evfs window goes, and how two builds compare (BENCHMARKS.md, "Where the
time goes").

    benchmarks/where_time_goes.py EVFS [EVFS_BEFORE] [--runs=N] [--data=DIR] [--flags="..."]
        [--cases=stages|speed|scaling] [--scratch=DIR]
        [--video_benchmark=BUILD/benchmarks/video_benchmark]

Runs each case N times (default 5), alternating the two binaries when two are given, and prints
one markdown table per binary of the medians of:
  * the whole process: wall and CPU seconds (user + system, of the process and its children);
  * start-up: `evfs --version`, CPU seconds;
  * the stages summary.json times (read, bin, build, solve, write) and, inside the solve, what
    Ceres reports (preprocessor, residual and Jacobian evaluation, linear solver);
  * Ceres iterations, conjugate-gradient steps (reconstruct) and the PSNR of the withheld frame
    or frames;
and, with two binaries, the ratios after / before of the pairs' CPU and wall seconds, peak
resident memory and, for video, windows per second. --flags go to every job of EVFS
(--flags_before to EVFS_BEFORE's); with one binary, EVFS with them is compared with EVFS without
them (e.g. --flags=--preconditioner=SUBSET).

--cases=speed measures the whole-recording speed targets instead: slider, `evfs video --fps=500`
on shapes and on the video benchmark's 20 s synthetic recording (written once into --scratch by
`video_benchmark --recordings_only`), both again with --frame_step=2 for the withheld frames'
PSNR and SSIM, and one DAVIS346-sized window (346 x 260 pixels of the shared adobe240_GOPR9642
clip's first 3 frames, events from `evfs simulate` of EVFS, also kept in --scratch),
interpolating frame 1 from 0 and 2. --cases=scaling runs `evfs video --fps=500` on shapes and
the 20 s recording at --jobs=1 and 2, and under mpirun with 2 and 3 ranks (one and two workers
beside rank 0, one job each).

The floor of a solve is its evaluations: every Levenberg-Marquardt iteration evaluates the
residuals and the Jacobian at least once, so "evaluation" (Ceres' residual + Jacobian time) is
what the solve cannot go below without fewer iterations or cheaper terms ("passes": Ceres'
residual and Jacobian evaluations, each one pass over every residual block; "s per pass" their
mean time). "floor share" is that evaluation over all the time Ceres reports (preprocessor +
evaluation + linear solver; summed over the independent parts, which run in parallel, so these
may add to more than "solve"), and "wall / floor" the whole process's wall time over it (for
video, over the windows' evaluation divided by the jobs that ran them): how far the job is from
its floor.
"""
import argparse
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time


def slider_case(data):
    """The slider 70->71 prediction, a job of every case set."""
    return ("slider 70->71 predict",
            ["reconstruct", f"--data={data}/slider_depth_70_71", "--mode=predict", "--first=0",
             "--last=1", "--truth=1"], "reconstruct")


def cases(data):
    """(name, evfs arguments, kind) of each measured job of --cases=stages."""
    return [
        slider_case(data),
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


def speed_inputs(data, scratch, evfs, video_benchmark):
    """Writes the inputs of --cases=speed and scaling once; returns (20 s recording, DAVIS346)."""
    recording = os.path.join(scratch, "rec_20s")
    if not os.path.isdir(recording):
        if not video_benchmark:
            sys.exit("where_time_goes: --cases=speed needs --video_benchmark (or SCRATCH/rec_20s)")
        subprocess.run([video_benchmark, f"--work_dir={scratch}", "--recordings_only",
                        f"--evfs={evfs}"], check=True, stdout=subprocess.DEVNULL)
    davis346 = os.path.join(scratch, "davis346_GOPR9642")
    if not os.path.isfile(os.path.join(davis346, "events.txt")):
        helper = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                              "realistic_variants_helper.py")
        crop = os.path.join(scratch, "davis346_crop")
        subprocess.run([sys.executable, helper, "crop", f"{data}/adobe240_GOPR9642", crop,
                        "346x260", "3"], check=True)
        subprocess.run([evfs, "simulate", f"--frames={crop}", f"--out={davis346}",
                        "--progress_interval_s=0", "--overwrite"], check=True,
                       stdout=subprocess.DEVNULL)
    return recording, davis346


def speed_cases(data, recording, davis346):
    """(name, evfs arguments, kind) of each job of --cases=speed."""
    shapes = f"{data}/shapes_rotation_13_20"
    video = ["video", "--progress_interval_s=0"]
    return [
        slider_case(data),
        ("shapes video --fps=500", video + [f"--data={shapes}", "--fps=500"], "video"),
        ("shapes video --frame_step=2", video + [f"--data={shapes}", "--frame_step=2"], "video"),
        ("20 s recording video --fps=500", video + [f"--data={recording}", "--fps=500"], "video"),
        ("20 s recording video --frame_step=2", video + [f"--data={recording}", "--frame_step=2"],
         "video"),
        ("DAVIS346 simulated 0,2->1 interpolate",
         ["reconstruct", f"--data={davis346}", "--mode=interpolate", "--first=0", "--last=2",
          "--truth=1"], "reconstruct"),
    ]


def scaling_cases(data, recording):
    """(name, evfs arguments, kind, launcher) of --cases=scaling: `evfs video --fps=500` at
    --jobs=1 and 2, and under mpirun with one and two worker ranks (one job each)."""
    mpirun = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np"]
    jobs = []
    recordings = (("shapes", f"{data}/shapes_rotation_13_20"), ("20 s recording", recording))
    for name, folder in recordings:
        video = ["video", f"--data={folder}", "--fps=500", "--progress_interval_s=0"]
        jobs += [(f"{name} --jobs=1", video + ["--jobs=1"], "video", []),
                 (f"{name} --jobs=2", video + ["--jobs=2"], "video", []),
                 (f"{name} mpirun -np 2 --jobs=1", video + ["--jobs=1"], "video", mpirun + ["2"]),
                 (f"{name} mpirun -np 3 --jobs=1", video + ["--jobs=1"], "video", mpirun + ["3"])]
    return jobs


def run(command):
    """Runs `command`; returns (wall s, CPU s, peak resident MB of the child, its output)."""
    start = time.monotonic()
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    output = child.stdout.read()
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.monotonic() - start
    child.returncode = os.waitstatus_to_exitcode(status)
    cpu = usage.ru_utime + usage.ru_stime
    if child.returncode != 0:
        sys.exit(f"where_time_goes: {' '.join(command)} failed:\n{output}")
    return wall, cpu, usage.ru_maxrss / 1024.0, output


def stage_times(out, kind):
    """Stage and Ceres times, iterations and passes, summed over windows for video."""
    summary = json.load(open(os.path.join(out, "summary.json")))
    records = summary["windows"] if kind == "video" else [summary]
    figures = {}

    def add(name, value):
        figures[name] = figures.get(name, 0) + value

    for record in records:
        for stage, seconds in record["time_s"].items():
            if stage != "total":
                add(stage, seconds)
        add("iterations", record.get("iterations", 0))
        # Ceres' accounting: summary.json's "solver" (reconstruct), each window's "ceres" (video).
        ceres = record.get("ceres") if kind == "video" else record.get("solver")
        if not ceres or "time_s" not in ceres:
            continue
        times = ceres["time_s"]
        add("preprocessor", times["preprocessor"])
        add("evaluation", times["residual_evaluation"] + times["jacobian_evaluation"])
        add("linear solver", times["linear_solver"])
        add("CG steps", ceres.get("linear_solver_iterations", record.get("linear_solver_iterations",
                                                                        float("nan"))))
        # Passes over the residual blocks (residual-only and residual + Jacobian evaluations).
        add("passes", ceres.get("residual_evaluations", float("nan")) +
            ceres.get("jacobian_evaluations", float("nan")))
    if figures.get("passes", 0) > 0:
        figures["s per pass"] = figures["evaluation"] / figures["passes"]
    # The windows of a video run `jobs` at a time: its floor is their evaluation over the jobs.
    figures["floor"] = figures.get("evaluation", 0) / summary.get("run", {}).get("jobs", 1)
    return figures


def printed(output, pattern):
    """The number `pattern` (one group) finds in the command's output, or NaN."""
    match = re.search(pattern, output)
    return float(match.group(1)) if match else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("evfs")
    parser.add_argument("evfs_before", nargs="?")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--flags", default="", help="extra evfs flags of EVFS's runs")
    parser.add_argument("--flags_before", default="", help="extra evfs flags of EVFS_BEFORE's runs")
    parser.add_argument("--data", default=os.path.join(os.path.dirname(__file__),
                                                       "../../shared/data"))
    parser.add_argument("--cases", choices=["stages", "speed", "scaling"], default="stages")
    parser.add_argument("--scratch", help="kept inputs of --cases=speed (default: a temporary one)")
    parser.add_argument("--video_benchmark", help="the video_benchmark binary (--cases=speed)")
    args = parser.parse_args()
    flags = args.flags.split()
    # (label, binary, extra flags) of each variant; the first is "after".
    variants = [(" ".join([args.evfs] + flags), args.evfs, flags)]
    if args.evfs_before:
        before_flags = args.flags_before.split()
        variants.append((" ".join([args.evfs_before] + before_flags), args.evfs_before,
                         before_flags))
    elif flags:
        variants.append((args.evfs, args.evfs, []))
    binaries = [label for label, _, _ in variants]
    scratch = tempfile.mkdtemp(prefix="evfs-time-")
    if args.cases in ("speed", "scaling"):
        inputs = os.path.abspath(args.scratch or scratch)
        os.makedirs(inputs, exist_ok=True)
        recording, davis346 = speed_inputs(args.data, inputs, args.evfs, args.video_benchmark)
        jobs = (speed_cases(args.data, recording, davis346) if args.cases == "speed"
                else scaling_cases(args.data, recording))
    else:
        jobs = cases(args.data)
    jobs = [job if len(job) == 4 else job + ([],) for job in jobs]
    results = {b: {} for b in binaries}  # binary -> case -> list of figure dicts
    try:
        for _ in range(args.runs):
            for label, binary, _ in variants:
                _, cpu, peak, _ = run([binary, "--version"])
                results[label].setdefault("start-up", []).append({"cpu": cpu, "peak MB": peak})
            for name, arguments, kind, launcher in jobs:
                for label, binary, extra in variants:
                    out = os.path.join(scratch, "out")
                    wall, cpu, peak, output = run(launcher + [binary] + arguments + extra +
                                              [f"--out={out}"])
                    figures = stage_times(out, kind)
                    figures.update({"wall": wall, "cpu": cpu, "peak MB": peak,
                                    "psnr": printed(output, r"PSNR (?:mean )?([0-9.]+) dB"),
                                    "ssim": printed(output, r"SSIM (?:mean )?([0-9.]+)"),
                                    "windows_per_s": printed(output, r"([0-9.]+) windows/s")})
                    if figures["floor"] > 0:
                        figures["wall / floor"] = wall / figures["floor"]
                    results[label].setdefault(name, []).append(figures)
                    shutil.rmtree(out)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)

    columns = ["wall", "cpu", "peak MB", "windows_per_s", "read", "bin", "build", "solve",
               "preprocessor", "evaluation", "linear solver", "write", "iterations", "passes",
               "s per pass", "CG steps", "wall / floor", "psnr", "ssim"]
    for binary in binaries:
        print(f"\n{binary} (medians of {args.runs}; seconds, PSNR dB)\n")
        print("| job | " + " | ".join(columns) + " | floor share |")
        print("|" + " --- |" * (len(columns) + 2))
        for name, runs in results[binary].items():
            cells = []
            for column in columns:
                values = [r[column] for r in runs if column in r and r[column] == r[column]]
                form = {"psnr": ".2f", "ssim": ".4f"}.get(column, ".3g")
                cells.append(f"{statistics.median(values):{form}}" if values else "")
            floor = [r["evaluation"] / (r["evaluation"] + r["linear solver"] + r["preprocessor"])
                     for r in runs if "evaluation" in r]
            share = f"{statistics.median(floor):.0%}" if floor else ""
            print(f"| {name} | " + " | ".join(cells) + f" | {share} |")
    if len(binaries) == 2:
        print(f"\nafter / before, median of the {args.runs} pairs\n")
        ratio_columns = ("cpu", "wall", "peak MB", "windows_per_s")
        print("| job | CPU s | wall s | peak MB | windows/s |\n| --- | --- | --- | --- | --- |")
        for name in results[binaries[0]]:
            pairs = list(zip(results[binaries[0]][name], results[binaries[1]][name]))
            cells = []
            for figure in ratio_columns:
                ratios = [a[figure] / b[figure] for a, b in pairs
                          if not math.isnan(a.get(figure, math.nan)) and b.get(figure, 0) > 0]
                cells.append(f"x{statistics.median(ratios):.2f}" if ratios else "")
            print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
