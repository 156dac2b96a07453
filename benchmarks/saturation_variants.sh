#!/usr/bin/env bash
# Saturated frames away from where they saturate: each ground-truth clip against its "saturation"
# variant (`evfs simulate --frame_gain=1.5`, realistic_common.sh), camera frame 1 (clip frame 8)
# interpolated from camera frames 0 and 2 (clip frames 0 and 16) by evfs as it runs by default,
# as in realistic_variants.sh. Prints one markdown row per clip: the share of pixels left out
# (saturated in the variant's truth or in either observed frame, grown by 4 pixels), PSNR there
# for the clean clip and for the variant (its errors divided by the gain), and the difference.
#
#   benchmarks/saturation_variants.sh BUILD_DIR DATA_DIR OUT_DIR [CROP_PX] [CLIP...]
#
# Everything is written under OUT_DIR, which must be a new or scratch folder.
set -euo pipefail
# shellcheck source=benchmarks/realistic_common.sh
source "$(dirname "$0")/realistic_common.sh"
parse_arguments "$0" "$@"

gain=$(variant_flags 0 0 0 saturation | sed -n 's/.*--frame_gain=\([0-9.]*\).*/\1/p')
echo "| clip | pixels left out | clean PSNR away | saturated PSNR away (/ gain $gain) | difference dB |"
echo "|---|---|---|---|---|"
for clip in "${clips[@]}"; do
  prepare_clip "$clip"
  for variant in clean saturation; do
    simulate_variant "$clip" "$variant"
    "$evfs" reconstruct --data="$sim" --mode=interpolate --first=0 --last=16 --truth=8 \
      --out="$out/rec_${clip}_$variant" --overwrite >/dev/null
  done
  python3 "$helper" saturation "$clip" "$out/rec_${clip}_clean" "$out/rec_${clip}_saturation" "$gain"
done
