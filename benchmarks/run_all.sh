#!/usr/bin/env bash
# `make bench`: the micro-benchmarks, then the reconstructions on the shared data when it is
# present.   usage: benchmarks/run_all.sh [BUILD_DIR] [DATA_DIR]
set -euo pipefail
build=${1:-build}
data=${2:-../shared/data}
cd "$(dirname "$0")/.."

echo "== event file parsing (io_benchmark)"
"$build/benchmarks/io_benchmark" --benchmark_counters_tabular=true

if [ -d "$data" ]; then
  echo
  echo "== reconstructions on the shared data (default options; the simulated clips take long)"
  "$build/benchmarks/reconstruction_benchmark" --data="$data" --csv="$build/reconstruction.csv"
else
  echo "no shared data folder at $data: skipping the real-data runs"
fi
