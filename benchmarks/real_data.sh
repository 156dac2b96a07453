#!/usr/bin/env bash
# Runs `evfs reconstruct` with the default flags on the shared DAVIS snippets and prints one line
# per run: PSNR/SSIM against the held-out frame, the baseline's, and the wall time.
#   usage: benchmarks/real_data.sh [BUILD_DIR] [DATA_DIR]
set -euo pipefail
build=${1:-build}
data=${2:-../shared/data}
evfs="$build/examples/evfs"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
[ -x "$evfs" ] || { echo "no $evfs: run 'make build' first" >&2; exit 1; }
[ -d "$data" ] || { echo "no data folder $data" >&2; exit 1; }

run() {
  local name=$1; shift
  local start end
  start=$(date +%s%N)
  "$evfs" reconstruct --out="$out/$name" "$@" > "$out/$name.log" 2>&1 || {
    echo "$name: FAILED"; cat "$out/$name.log"; return 1; }
  end=$(date +%s%N)
  local ms=$(( (end - start) / 1000000 ))
  printf '%-24s %s  wall %d.%03d s\n' "$name" \
    "$(grep '^truth:' "$out/$name.log" || grep '^solve:' "$out/$name.log")" $((ms / 1000)) $((ms % 1000))
}

run slider_predict_70_71 --data="$data/slider_depth_70_71" --mode=predict --first=0 --last=1 --truth=1
run shapes_interpolate_19 --data="$data/shapes_rotation_13_20" --mode=interpolate --first=2 --last=4 --truth=3
