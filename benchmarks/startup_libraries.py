#!/usr/bin/env python3
"""What loading evfs' shared libraries costs at start-up (BENCHMARKS.md, "Start-up cost").

    benchmarks/startup_libraries.py EVFS [--runs=N]

Prints the median CPU seconds (user + system) of `EVFS --version` over N runs (default 15) and
the cycles its dynamic loader reports (LD_DEBUG=statistics: total, and relocations), then, for
the optional formats' libraries evfs links, the start-up CPU of an empty C program linked
against only that group, beside the same program linked against nothing: an upper bound on
what loading the group on demand (a plug-in, as the MP4 encoder and the image decoder are)
would save at each start.
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

# Each optional group: what it serves, and the linker flags of its libraries.
GROUPS = [
    ("HDF5 (.h5 events)", ["-L/usr/lib/x86_64-linux-gnu/hdf5/serial", "-lhdf5_serial"]),
    ("ROS 1 bags (.bag)", ["/usr/lib/x86_64-linux-gnu/librosbag_storage.so.4d"]),
    ("Open MPI (evfs video under mpirun)", ["-lmpi_cxx", "-lmpi"]),
    ("OpenCV DNN (the denoiser)", ["-lopencv_dnn"]),
]


def cpu_seconds(command, runs, env=None):
    """Median CPU seconds of `command` over `runs` runs."""
    samples = []
    for _ in range(runs):
        child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                 env=env)
        _, status, usage = os.wait4(child.pid, 0)
        if os.waitstatus_to_exitcode(status) != 0:
            sys.exit(f"startup_libraries: {' '.join(command)} failed")
        samples.append(usage.ru_utime + usage.ru_stime)
    return statistics.median(samples)


def loader_cycles(evfs, runs):
    """Median (total, relocation) cycles of the dynamic loader for `evfs --version`."""
    totals, relocations = [], []
    for _ in range(runs):
        env = dict(os.environ, LD_DEBUG="statistics")
        done = subprocess.run([evfs, "--version"], env=env, capture_output=True, text=True)
        total = re.search(r"total startup time in dynamic loader: ([0-9]+) cycles", done.stderr)
        relocation = re.search(r"time needed for relocation: ([0-9]+) cycles", done.stderr)
        if total and relocation:
            totals.append(int(total.group(1)))
            relocations.append(int(relocation.group(1)))
    if not totals:
        return float("nan"), float("nan")
    return statistics.median(totals), statistics.median(relocations)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("evfs")
    parser.add_argument("--runs", type=int, default=15)
    args = parser.parse_args()
    libraries = subprocess.run(["ldd", args.evfs], capture_output=True, text=True).stdout
    total, relocation = loader_cycles(args.evfs, args.runs)
    print(f"`{args.evfs} --version`: {cpu_seconds([args.evfs, '--version'], args.runs):.3f} s "
          f"CPU, {len(libraries.splitlines())} shared libraries; dynamic loader {total / 1e6:.1f} "
          f"M cycles, of which relocation {relocation / 1e6:.1f} M (medians of {args.runs})\n")
    scratch = tempfile.mkdtemp(prefix="evfs-startup-")
    try:
        source = os.path.join(scratch, "main.c")
        with open(source, "w") as out:
            out.write("int main(void) { return 0; }\n")
        empty = os.path.join(scratch, "empty")
        subprocess.run(["gcc", "-O2", source, "-o", empty], check=True)
        base = cpu_seconds([empty], args.runs)
        print("| libraries linked | shared libraries | start-up CPU s | over an empty program |")
        print("| --- | --- | --- | --- |")
        ldd = subprocess.run(["ldd", empty], capture_output=True, text=True)
        count = len(ldd.stdout.splitlines())
        print(f"| none | {count} | {base:.4f} | |")
        for name, flags in GROUPS:
            binary = os.path.join(scratch, "linked")
            subprocess.run(["gcc", "-O2", source, "-o", binary, "-Wl,--no-as-needed"] + flags,
                           check=True)
            count = len(subprocess.run(["ldd", binary], capture_output=True,
                                       text=True).stdout.splitlines())
            seconds = cpu_seconds([binary], args.runs)
            print(f"| {name} | {count} | {seconds:.4f} | +{seconds - base:.4f} |")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main()
