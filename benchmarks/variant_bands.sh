#!/usr/bin/env bash
# The predicted one-sigma band (OUT/confidence) on the realistic variants, cases it was not
# chosen on: for each of the five ground-truth clips and the variants clean, hot, frame_noise,
# mains and all of benchmarks/realistic_variants.sh (30 fps camera frames from the 240 fps
# clips, cropped), camera frame 1 (clip frame 8) interpolated from camera frames 0 and 2 and
# predicted from camera frame 0 by evfs as it runs by default.
#
#   benchmarks/variant_bands.sh BUILD_DIR DATA_DIR OUT_DIR [CROP_PX] [CLIP...]
#
# Prints one markdown row per clip, variant and window: the share of the truth's pixels within
# the band (a calibrated band holds 68 %) and the PSNR. Everything is written under OUT_DIR,
# which must be a new or scratch folder.
set -euo pipefail
# shellcheck source=benchmarks/realistic_common.sh
source "$(dirname "$0")/realistic_common.sh"
parse_arguments "$0" "$@"

echo "| clip | variant | window | within predicted sigma | PSNR |"
echo "|---|---|---|---|---|"
for clip in "${clips[@]}"; do
  prepare_clip "$clip"
  for variant in clean hot frame_noise mains all; do
    simulate_variant "$clip" "$variant"
    for window in "interpolate 0 16" "predict 0 8"; do
      read -r mode first last <<< "$window"
      rec="$out/rec_${clip}_${variant}_$mode"
      "$evfs" reconstruct --data="$sim" --mode="$mode" --first="$first" --last="$last" \
        --truth=8 --out="$rec" --overwrite >/dev/null
      /usr/bin/python3 - "$clip" "$variant" "$mode" "$rec" <<'PY'
import json, sys
clip, variant, mode, rec = sys.argv[1:]
truth = json.load(open(rec + "/summary.json"))["truth"]
print("| %s | %s | %s | %.1f %% | %.2f |" % (
    clip, variant, mode, 100 * truth["within_predicted_sigma"], truth["psnr"]))
PY
    done
  done
done
