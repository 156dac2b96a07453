#!/usr/bin/env bash
# Every real DAVIS window of the shared data that has a ground truth, reconstructed by evfs as
# it runs by default, with the shipped denoiser (--denoise=once), and by event integration,
# beside the blend or copy of the observed frames:
#   slider 70->71 predict; shapes 13->14, 18->19, 19->20 predict; shapes 18,20->19 interpolate;
#   the DAVIS346 street clip (AEDAT 4) 0,2->1 and 1,3->2 interpolate.
#
#   benchmarks/real_windows.sh [BUILD_DIR] [SCRATCH_DIR] [DATA_DIR] [-- EXTRA_FLAGS...]
#
# EXTRA_FLAGS go to every evfs run (e.g. --saturation_level=2 to switch a rule off). Prints one
# markdown row per window: PSNR and SSIM of each, the share of the truth's pixels within the
# default's predicted one-sigma error (OUT/confidence), and how many pixels the frames governed.
set -euo pipefail
build=${1:-build}
scratch=${2:-/tmp/evfs-real-windows}
data=${3:-../shared/data}
shift $(( $# < 3 ? $# : 3 ))
[ "${1:-}" = "--" ] && shift
extra=("$@")
cd "$(dirname "$0")/.."
evfs="$build/examples/evfs"
mkdir -p "$scratch"

mapfile -t windows < <(grep -v "^#" benchmarks/real_windows.txt)
echo "| window | baseline | evfs PSNR | with denoiser | integration | baseline PSNR | evfs SSIM | with denoiser | integration | baseline SSIM | within predicted sigma | saturated px | flickering px |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for entry in "${windows[@]}"; do
  read -r name folder mode first last truth <<< "$entry"
  runs=("default:" "once:--denoise=once" "integrate:--solver=integrate")
  for run in "${runs[@]}"; do
    label=${run%%:*}
    flags=${run#*:}
    "$evfs" reconstruct --data="$data/$folder" --mode="$mode" --first="$first" --last="$last" \
      --truth="$truth" --out="$scratch/$name-$label" --overwrite $flags "${extra[@]}" > /dev/null
  done
  /usr/bin/python3 - "$name" "$scratch/$name" <<'PY'
import json, sys
name, prefix = sys.argv[1:]
s = {k: json.load(open("%s-%s/summary.json" % (prefix, k))) for k in ("default", "once", "integrate")}
t = {k: v["truth"] for k, v in s.items()}
governed = s["default"].get("frames_govern", {})
print("| %s | %s | %.2f | %.2f | %.2f | %.2f | %.4f | %.4f | %.4f | %.4f | %.1f %% | %s | %s |" % (
    name, t["default"]["baseline"], t["default"]["psnr"], t["once"]["psnr"], t["integrate"]["psnr"],
    t["default"]["baseline_psnr"], t["default"]["ssim"], t["once"]["ssim"], t["integrate"]["ssim"],
    t["default"]["baseline_ssim"], 100 * t["default"]["within_predicted_sigma"],
    governed.get("saturated", {}).get("pixels", "-"),
    governed.get("flickering", {}).get("pixels", "-")))
PY
done
