#!/usr/bin/env bash
# The shared ground-truth clips as evfs sees them with simulated events: for each clip (a data
# folder written by `evfs simulate --frames=../shared/data/CLIP`), frame 2 withheld and
# reconstructed by interpolation from frames 0 and 4 and by prediction from frame 0, by evfs as it
# runs by default, by event integration and against the blend or copy.
#
#   benchmarks/clip_windows.sh BUILD_DIR SCRATCH_DIR SIM_DIR... [-- EXTRA_FLAGS...]
#
# Prints one markdown row per window: PSNR and SSIM, and the share of the truth's pixels within
# the default's predicted one-sigma error (OUT/confidence).
set -euo pipefail
build=$1
scratch=$2
shift 2
sims=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do sims+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
extra=("$@")
cd "$(dirname "$0")/.."
evfs="$build/examples/evfs"
mkdir -p "$scratch"
echo "| clip | window | baseline PSNR | evfs PSNR | integration | baseline SSIM | evfs SSIM | integration | within predicted sigma |"
echo "|---|---|---|---|---|---|---|---|---|"
for sim in "${sims[@]}"; do
  name=$(basename "$sim")
  for case in "interpolate 0 4" "predict 0 2"; do
    read -r mode first last <<< "$case"
    for run in "default:" "integrate:--solver=integrate"; do
      label=${run%%:*}
      flags=${run#*:}
      "$evfs" reconstruct --data="$sim" --mode="$mode" --first="$first" --last="$last" --truth=2 \
        --out="$scratch/$name-$mode-$label" --overwrite $flags "${extra[@]}" > /dev/null
    done
    /usr/bin/python3 - "$name" "$mode $first,$last->2" "$scratch/$name-$mode" <<'PY'
import json, sys
name, window, prefix = sys.argv[1:]
d = json.load(open(prefix + "-default/summary.json"))["truth"]
i = json.load(open(prefix + "-integrate/summary.json"))["truth"]
print("| %s | %s | %.2f | %.2f | %.2f | %.4f | %.4f | %.4f | %.1f %% |" % (
    name, window, d["baseline_psnr"], d["psnr"], i["psnr"], d["baseline_ssim"], d["ssim"],
    i["ssim"], 100 * d["within_predicted_sigma"]))
PY
  done
done
