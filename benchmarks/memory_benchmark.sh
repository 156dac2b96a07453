#!/usr/bin/env bash
# Peak memory (max RSS, /usr/bin/time -v) and wall time of `evfs info` and `evfs reconstruct` on
# the hot-pixel and 2 M-event recordings that benchmarks/memory_cases writes (the
# figures are in BENCHMARKS.md, "Memory bounded before allocation").
#
#   benchmarks/memory_benchmark.sh [BUILD_DIR] [SCRATCH_DIR] [EVFS_BINARY] [-- EXTRA_FLAGS...]
#
# SCRATCH_DIR (default /tmp/evfs-memory) receives the recordings (made once, then reused) and
# the reconstructions; EVFS_BINARY (default BUILD_DIR/examples/evfs) may be an older build to
# compare with. EXTRA_FLAGS go to every reconstruct (e.g. --max_iterations=1).
set -euo pipefail
build=${1:-build}
scratch=${2:-/tmp/evfs-memory}
evfs=${3:-$build/examples/evfs}
shift $(( $# < 3 ? $# : 3 ))
if [ "${1:-}" = "--" ]; then shift; fi
extra=("$@")
cd "$(dirname "$0")/.."

if [ ! -d "$scratch/hot_pixel" ] || [ ! -d "$scratch/busy_640x480" ]; then
  "$build/benchmarks/memory_cases" --out="$scratch"
fi

# Runs evfs under /usr/bin/time -v; prints "max RSS MB | wall s | exit status".
measure() {
  local log
  log=$(mktemp)
  /usr/bin/time -v "$evfs" "$@" >/dev/null 2>"$log" || true
  local rss_kb wall status
  rss_kb=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$log")
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$log")
  status=$(sed -n 's/.*Exit status: //p' "$log")
  rm -f "$log"
  printf '%d MB | %s | %s' $(( rss_kb / 1024 )) "$wall" "$status"
}

echo "| case | command | peak memory | wall | exit |"
echo "|---|---|---|---|---|"
for case in hot_pixel busy_640x480; do
  data="$scratch/$case"
  echo "| $case | info --first=0 --last=1 | $(measure info --data="$data" --first=0 --last=1) |"
  out="$scratch/out_${case}_$$"
  echo "| $case | reconstruct --mode=predict ${extra[*]:-} | $(measure reconstruct \
    --data="$data" --mode=predict --first=0 --last=1 --truth=1 --out="$out" "${extra[@]}") |"
done
