#!/usr/bin/env bash
# Flickering light (a 100 Hz mains lamp over the whole frame, and every realistic effect at
# once): for each of the five ground-truth clips, camera frame 1 (clip frame 8) predicted from
# camera frame 0 and interpolated from camera frames 0 and 2, with the temporal TV of flickering
# pixels measured in g (the default, --log_temporal_tv_reversals=3) and on H everywhere
# (--log_temporal_tv_reversals=0), beside the copy or blend. The variants are those of
# benchmarks/realistic_variants.sh (30 fps camera frames from the 240 fps clips, cropped).
#
#   benchmarks/flicker_windows.sh BUILD_DIR DATA_DIR OUT_DIR [CROP_PX] [CLIP...]
#
# Prints one markdown row per clip, variant and window: PSNR / SSIM of each, and how many pixels
# had their temporal TV measured in g. Everything is written under OUT_DIR, which must be a new
# or scratch folder.
set -euo pipefail
# shellcheck source=benchmarks/realistic_common.sh
source "$(dirname "$0")/realistic_common.sh"
parse_arguments "$0" "$@"

echo "| clip | variant | window | in g (default) | on H | copy / blend | pixels in g |"
echo "|---|---|---|---|---|---|---|"
for clip in "${clips[@]}"; do
  prepare_clip "$clip"
  for variant in mains all; do
    simulate_variant "$clip" "$variant"
    for window in "predict 0 8" "interpolate 0 16"; do
      read -r mode first last <<< "$window"
      for reversals in 3 0; do
        "$evfs" reconstruct --data="$sim" --mode="$mode" --first="$first" --last="$last" \
          --truth=8 --log_temporal_tv_reversals="$reversals" \
          --out="$out/rec_${clip}_${variant}_${mode}_$reversals" --overwrite >/dev/null
      done
      /usr/bin/python3 - "$clip" "$variant" "$mode" "$out/rec_${clip}_${variant}_${mode}" <<'PY'
import json, sys
clip, variant, mode, prefix = sys.argv[1:]
g = json.load(open(prefix + "_3/summary.json"))
h = json.load(open(prefix + "_0/summary.json"))
tg, th = g["truth"], h["truth"]
print("| %s | %s | %s | %.2f / %.4f | %.2f / %.4f | %.2f / %.4f | %d |" % (
    clip, variant, mode, tg["psnr"], tg["ssim"], th["psnr"], th["ssim"], tg["baseline_psnr"],
    tg["baseline_ssim"], g["problem"]["log_temporal_tv_pixels"]))
PY
    done
  done
done
