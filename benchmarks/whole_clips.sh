#!/usr/bin/env bash
# Whole clips, "skip 3" (docs/guide.md, BENCHMARKS.md "`evfs video` on whole clips"): events
# simulated with `evfs simulate`'s defaults, every 4th frame observed, every withheld frame
# scored, by `evfs video` as it runs by default (the model-based reconstruction alone), with the
# shipped residual denoiser (`--denoise=once`) and with event integration.
#
#   benchmarks/whole_clips.sh [BUILD_DIR] [SCRATCH_DIR] [DATA_DIR] [CLIP...]
#
# Prints one row per clip: PSNR mean (worst) and SSIM mean of evfs, of evfs with the denoiser, of
# the blend and of event integration (`--solver=integrate`) over the withheld frames, and the
# wall times of evfs without and with the denoiser.
set -euo pipefail
build=${1:-build}
scratch=${2:-/tmp/evfs-whole-clips}
data=${3:-../shared/data}
shift $(( $# < 3 ? $# : 3 ))
clips=("$@")
[ ${#clips[@]} -gt 0 ] || mapfile -t clips < <(awk '!/^#/ && NF {print $1}' "$(dirname "$0")/clips.txt")
cd "$(dirname "$0")/.."
evfs="$build/examples/evfs"
mkdir -p "$scratch"

# Prints the table row of CLIP WALL_S from its evfs and its integration summary.json.
row() {
  /usr/bin/python3 - "$@" <<'PY'
import json, sys
clip, wall, wall_denoised, evfs, denoised, integration = sys.argv[1:]
e = json.load(open(evfs))["truth"]
d = json.load(open(denoised))["truth"]
i = json.load(open(integration))["truth"]
print("| %s | %d | %.2f (%.2f) | %.2f (%.2f) | %.2f | %.2f | %.4f | %.4f | %.4f | %.4f | %.0f s, %.0f s |"
      % (clip, e["frames"], e["mean_psnr"], e["worst_psnr"], d["mean_psnr"], d["worst_psnr"],
         e["blend_mean_psnr"], i["mean_psnr"], e["mean_ssim"], d["mean_ssim"],
         e["blend_mean_ssim"], i["mean_ssim"], float(wall), float(wall_denoised)))
PY
}

echo "| clip | withheld frames | evfs PSNR mean (worst) | with denoiser | blend | integration | evfs SSIM | with denoiser | blend SSIM | integration SSIM | evfs wall, with denoiser |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"

# Runs evfs video on SIM into OUT with the flags after them; prints its wall time in seconds.
timed_video() {
  local sim=$1 out=$2
  shift 2
  local start
  start=$(date +%s.%N)
  "$evfs" video --data="$sim" --out="$out" --overwrite --frame_step=4 --fps=240 "$@" >/dev/null 2>&1
  awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }'
}
for clip in "${clips[@]}"; do
  sim="$scratch/sim_$clip"
  [ -d "$sim" ] || "$evfs" simulate --frames="$data/$clip" --out="$sim" >/dev/null
  wall=$(timed_video "$sim" "$scratch/out_$clip")
  wall_denoised=$(timed_video "$sim" "$scratch/denoised_$clip" --denoise=once)
  timed_video "$sim" "$scratch/integrate_$clip" --solver=integrate >/dev/null
  row "$clip" "$wall" "$wall_denoised" "$scratch/out_$clip/summary.json" \
    "$scratch/denoised_$clip/summary.json" "$scratch/integrate_$clip/summary.json"
done
