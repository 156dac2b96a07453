#!/usr/bin/env bash
# The simulated clips of benchmarks/clips.txt, each interpolated from frames 0 and 4 with
# frame 2 withheld, as `evfs` runs from the command line: events from `evfs simulate` at its
# defaults (made once into SCRATCH_DIR and reused), then `evfs reconstruct --mode=interpolate
# --first=0 --last=4 --truth=2`. One markdown row per clip: PSNR dB, Ceres iterations and the
# process's CPU seconds (user + system), so that two builds or two settings compare.
#
#   benchmarks/clip_interpolations.sh EVFS [SCRATCH_DIR] [DATA_DIR] [-- EXTRA_FLAGS...]
#
# EXTRA_FLAGS go to every reconstruct (e.g. --max_iterations=20).
set -euo pipefail
evfs=$1
scratch=${2:-/tmp/evfs-clip-interpolations}
data=${3:-../shared/data}
shift $(( $# < 3 ? $# : 3 ))
[ "${1:-}" = "--" ] && shift
extra=("$@")
cd "$(dirname "$0")/.."
mkdir -p "$scratch"
echo "| clip | PSNR dB | iterations | CPU s |"
echo "|---|---|---|---|"
grep -v '^#' benchmarks/clips.txt | while read -r clip _; do
  simulated="$scratch/$clip"
  [ -f "$simulated/events.txt" ] || "$evfs" simulate --frames="$data/$clip" --out="$simulated" >/dev/null
  out=$(mktemp -d)
  /usr/bin/time -o "$out/time" -f "%U %S" "$evfs" reconstruct --data="$simulated" \
    --mode=interpolate --first=0 --last=4 --truth=2 --out="$out/o" "${extra[@]}" >"$out/log" 2>&1
  psnr=$(grep -o 'PSNR [0-9.]*' "$out/log" | head -1 | cut -d' ' -f2)
  iterations=$(grep -o '[0-9]* iterations' "$out/log" | head -1 | cut -d' ' -f1)
  cpu=$(awk '{printf "%.1f", $1 + $2}' "$out/time")
  echo "| $clip | $psnr | $iterations | $cpu |"
  rm -rf "$out"
done
