#!/usr/bin/env bash
# `make bench`: the micro-benchmarks, then the reconstructions on the shared data when it is
# present.   usage: benchmarks/run_all.sh [BUILD_DIR] [DATA_DIR]
set -euo pipefail
build=${1:-build}
data=${2:-../shared/data}
cd "$(dirname "$0")/.."

echo "== event file parsing (io_benchmark)"
"$build/benchmarks/io_benchmark" --benchmark_counters_tabular=true

echo
echo "== cost functors, autodiff against hand-written derivatives; the fused evaluation"
"$build/benchmarks/cost_function_benchmark" --benchmark_counters_tabular=true

echo
echo "== time against the active fraction of a synthetic scene"
"$build/benchmarks/active_fraction_benchmark"

if [ -d "$data" ]; then
  echo
  echo "== reconstructions on the shared data (default options; the simulated clips take long)"
  "$build/benchmarks/reconstruction_benchmark" --data="$data" --csv="$build/reconstruction.csv"
  echo
  echo "== every method on every case, one process per cell (method_benchmark)"
  "$build/benchmarks/method_benchmark" --data="$data" --out="$build/bench"
  echo
  echo "== PSNR against time per case, from method_benchmark's CSV files (plot_methods.py)"
  # Debian's python3-matplotlib is /usr/bin/python3's; another python3 may come first on PATH.
  if /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
    /usr/bin/python3 benchmarks/plot_methods.py "$build/bench"
  else
    echo "no python3-matplotlib (scripts/install-deps.sh installs it): skipping the plots"
  fi
else
  echo "no shared data folder at $data: skipping the real-data runs"
fi
