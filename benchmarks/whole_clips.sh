#!/usr/bin/env bash
# Whole clips, "skip 3" (issue 18; README "`evfs video`", BENCHMARKS.md "Whole clips"): events
# simulated with `evfs simulate`'s defaults, every 4th frame observed, every withheld frame
# scored, by `evfs video` with the default method and with event integration.
#
#   benchmarks/whole_clips.sh [BUILD_DIR] [SCRATCH_DIR] [DATA_DIR] [CLIP...]
#
# Prints one row per clip: PSNR mean (worst) and SSIM mean of evfs, of the blend and of event
# integration (`--solver=integrate`) over the withheld frames, and the wall time of evfs.
set -euo pipefail
build=${1:-build}
scratch=${2:-/tmp/evfs-whole-clips}
data=${3:-../shared/data}
shift $(( $# < 3 ? $# : 3 ))
clips=("$@")
[ ${#clips[@]} -gt 0 ] || clips=(nfs_basketball_7 adobe240_GOPR9642 adobe240_GOPR9637b
                                 adobe240_IMG_0004b adobe240_IMG_0036)
cd "$(dirname "$0")/.."
evfs="$build/examples/evfs"
mkdir -p "$scratch"

# Prints "mean (worst) | blend mean | SSIM mean | blend SSIM" from a video's summary.json.
scores() {
  /usr/bin/python3 - "$1" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["truth"]
print("%.2f (%.2f) | %.2f | %.4f | %.4f | %d" % (t["mean_psnr"], t["worst_psnr"],
      t["blend_mean_psnr"], t["mean_ssim"], t["blend_mean_ssim"], t["frames"]))
PY
}

echo "| clip | withheld frames | evfs PSNR mean (worst) | blend | integration | evfs SSIM | blend SSIM | integration SSIM | evfs wall |"
echo "|---|---|---|---|---|---|---|---|---|"
for clip in "${clips[@]}"; do
  sim="$scratch/sim_$clip"
  [ -d "$sim" ] || "$evfs" simulate --frames="$data/$clip" --out="$sim" >/dev/null
  start=$(date +%s.%N)
  "$evfs" video --data="$sim" --out="$scratch/out_$clip" --overwrite --frame_step=4 --fps=240 \
    >/dev/null 2>&1
  wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
  "$evfs" video --data="$sim" --out="$scratch/integrate_$clip" --overwrite --frame_step=4 \
    --fps=240 --solver=integrate >/dev/null 2>&1
  IFS='|' read -r evfs_psnr blend evfs_ssim blend_ssim frames <<<"$(scores "$scratch/out_$clip/summary.json")"
  IFS='|' read -r integration _ integration_ssim _ _ <<<"$(scores "$scratch/integrate_$clip/summary.json")"
  integration=${integration%% (*}
  printf "| %s | %s | %s | %s | %s | %s | %s | %s | %.0f s |\n" "$clip" "${frames// /}" \
    "${evfs_psnr% }" "${blend// /}" "${integration// /}" "${evfs_ssim// /}" "${blend_ssim// /}" \
    "${integration_ssim// /}" "$wall"
done
