#!/usr/bin/env bash
# `make bench`: the micro-benchmarks, then the real-data reconstructions when the shared data
# is present.   usage: benchmarks/run_all.sh [BUILD_DIR] [DATA_DIR]
set -euo pipefail
build=${1:-build}
data=${2:-../shared/data}
cd "$(dirname "$0")/.."

echo "== event file parsing (io_benchmark)"
"$build/benchmarks/io_benchmark" --benchmark_counters_tabular=true

if [ -d "$data" ]; then
  echo
  echo "== reconstructions on the shared DAVIS snippets (default flags)"
  bash benchmarks/real_data.sh "$build" "$data"
else
  echo "no shared data folder at $data: skipping the real-data runs"
fi
