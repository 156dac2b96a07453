#!/usr/bin/env python3
"""How long the Python module takes from SIGINT to KeyboardInterrupt, per call and solver.

Each case starts a call, sends this process SIGINT after `--delay_s` (mid-solve) and measures
the time until KeyboardInterrupt reaches Python; a video case also checks that no output and
no staging folder is left. Prints a table (min / median / max over --repeats) and writes CSV.

  PYTHONPATH=build/python python3 benchmarks/python_interrupt_latency.py \\
      --data=../shared/data --repeats=5 --csv=/tmp/interrupt_latency.csv
"""
import argparse
import csv
import os
import signal
import statistics
import sys
import tempfile
import threading
import time

import evfs


def interrupted_after(delay_s, call):
    """Runs call(); SIGINT after delay_s. Returns seconds from the signal to KeyboardInterrupt,
    or None when the call ended first."""
    sent = []

    def fire():
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)
    timer = threading.Timer(delay_s, fire)
    timer.start()
    try:
        call()
    except KeyboardInterrupt:
        return time.perf_counter() - sent[0]
    finally:
        timer.cancel()
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", default=os.environ.get("EVFS_DATA_DIR", "../shared/data"))
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--delay_s", type=float, default=3.0)
    parser.add_argument("--csv", default="")
    args = parser.parse_args()

    cups = evfs.read(os.path.join(args.data, "eslnet_cups_blur"))

    def deblur(options):
        return lambda: evfs.reconstruct(cups["frames"], cups["frame_times"], cups["events"],
                                        mode="deblur", exposures=cups["exposures"],
                                        options=options)

    work = tempfile.mkdtemp(prefix="evfs-interrupt-")
    video_runs = [0]

    def video():
        video_runs[0] += 1
        out = os.path.join(work, f"video{video_runs[0]}")
        try:
            evfs.video(os.path.join(args.data, "shapes_rotation_13_20"), out)
        finally:
            left = [n for n in os.listdir(work) if n.startswith(f"video{video_runs[0]}") or
                    (f"video{video_runs[0]}." in n and "evfs-tmp" in n)]
            assert not left, f"left behind: {left}"

    cases = [("reconstruct cups deblur, adam", deblur({"solver": "adam"})),
             ("reconstruct cups deblur, ceres_lm (default)", deblur(None)),
             ("video shapes_rotation_13_20 (default)", video)]
    rows = []
    for name, call in cases:
        latencies = [interrupted_after(args.delay_s, call) for _ in range(args.repeats)]
        measured = [x for x in latencies if x is not None]
        if not measured:
            print(f"{name}: ended before {args.delay_s} s every time", flush=True)
            continue
        row = {"case": name, "delay_s": args.delay_s, "runs": len(measured),
               "min_s": min(measured), "median_s": statistics.median(measured),
               "max_s": max(measured)}
        rows.append(row)
        print(f"{name:45s} runs {row['runs']}  min {row['min_s']:.3f} s  median "
              f"{row['median_s']:.3f} s  max {row['max_s']:.3f} s", flush=True)
    if args.csv:
        with open(args.csv, "w", newline="") as out:
            writer = csv.DictWriter(out, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
