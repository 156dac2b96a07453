#!/usr/bin/env bash
# PSNR of `evfs reconstruct` on the quiet windows and the moving windows that must
# not get worse, one row per configuration (benchmarks/results/model_choices.md, "Quiet scenes").
#
#   benchmarks/quiet_scenes.sh [BUILD_DIR] [SCRATCH_DIR] [DATA_DIR] -- LABEL [FLAGS...] [-- LABEL [FLAGS...]]...
#
# The clips' events are simulated once into SCRATCH_DIR (default /tmp/evfs-quiet) with
# `evfs simulate`'s defaults; each configuration is a label and the flags given to every
# reconstruct (e.g. `-- default -- blend --solver=blend -- integrate --solver=integrate`).
set -euo pipefail
build=${1:-build}
scratch=${2:-/tmp/evfs-quiet}
data=${3:-../shared/data}
shift $(( $# < 3 ? $# : 3 ))
cd "$(dirname "$0")/.."
evfs="$build/examples/evfs"
mkdir -p "$scratch"
for clip in adobe240_GOPR9642 nfs_basketball_7; do
  if [ ! -d "$scratch/sim_$clip" ]; then
    "$evfs" simulate --frames="$data/$clip" --out="$scratch/sim_$clip" >/dev/null
  fi
done

# Prints the PSNR of one window: DATA MODE FIRST LAST TRUTH FLAGS...
psnr() {
  local out="$scratch/out_$$"
  "$evfs" reconstruct --data="$1" --mode="$2" --first="$3" --last="$4" --truth="$5" \
    --out="$out" --overwrite "${@:6}" 2>&1 | sed -n 's/.*PSNR \([0-9.]*\) dB.*/\1/p' | head -1
  rm -rf "$out"
}

echo "| configuration | GOPR9642 24,28→26 | GOPR9642 21,25→23 | nfs 8,12→10 | nfs 6,10→8 | slider predict | shapes 18,20→19 | shapes 13→14 |"
echo "|---|---|---|---|---|---|---|---|"
while [ $# -gt 0 ]; do
  [ "$1" = "--" ] && shift
  label=$1; shift
  flags=()
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do flags+=("$1"); shift; done
  row="| $label"
  row+=" | $(psnr "$scratch/sim_adobe240_GOPR9642" interpolate 24 28 26 "${flags[@]}")"
  row+=" | $(psnr "$scratch/sim_adobe240_GOPR9642" interpolate 21 25 23 "${flags[@]}")"
  row+=" | $(psnr "$scratch/sim_nfs_basketball_7" interpolate 8 12 10 "${flags[@]}")"
  row+=" | $(psnr "$scratch/sim_nfs_basketball_7" interpolate 6 10 8 "${flags[@]}")"
  row+=" | $(psnr "$data/slider_depth_70_71" predict 0 1 1 "${flags[@]}")"
  row+=" | $(psnr "$data/shapes_rotation_13_20" interpolate 2 4 3 "${flags[@]}")"
  row+=" | $(psnr "$data/shapes_rotation_13_20" predict 0 1 1 "${flags[@]}") |"
  echo "$row"
done
