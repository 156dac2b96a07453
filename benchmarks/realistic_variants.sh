#!/usr/bin/env bash
# Realistic sensor effects (`evfs simulate`'s hot pixels, leak, light sources and frame effects):
# how each one, alone and all together, moves the reconstruction of the five ground-truth clips.
#
#   benchmarks/realistic_variants.sh BUILD_DIR DATA_DIR OUT_DIR [CROP_PX] [CLIP...]
#
# The camera these variants stand for is a DAVIS-like frame sensor at 30 fps: every 8th frame of
# a 240 fps clip is one of its frames, so a 20 ms exposure fits inside its 33 ms frame period.
# For every clip: its first 17 frames, cropped to the central CROP_PX x CROP_PX pixels (160 by
# default; 0 keeps the whole frame), are simulated once per variant below (events from all 17),
# and camera frame 1 (clip frame 8) is reconstructed from camera frames 0 and 2 (clip frames 0
# and 16: `evfs reconstruct --mode=interpolate --first=0 --last=16 --truth=8`) by evfs as it runs
# by default, by the blend and by event integration. Prints one markdown row per clip, variant
# and method:
#   - PSNR and SSIM of summary.json, scored against frame 8 as the variant wrote it (with its
#     saturation, noise or exposure);
#   - PSNR against the clean frame 8 (the cropped input), and for the light-source variants the
#     same PSNR away from the LED (outside its disc grown by 4 pixels).
# Everything is written under OUT_DIR, which must be a new or scratch folder.
set -euo pipefail
# The arguments (build, data, out, crop, clips, evfs, helper) and variant_flags.
# shellcheck source=benchmarks/realistic_common.sh
source "$(dirname "$0")/realistic_common.sh"
parse_arguments "$0" "$@"

variants=(clean hot leak flicker_led mains saturation frame_noise exposure20ms all)
methods=("default:" "blend:--solver=blend" "integrate:--solver=integrate")

echo "| clip | variant | method | PSNR (summary.json) | SSIM (summary.json) | PSNR vs clean frame | PSNR away from the LED |"
echo "|---|---|---|---|---|---|---|"
for clip in "${clips[@]}"; do
  prepare_clip "$clip"
  for variant in "${variants[@]}"; do
    simulate_variant "$clip" "$variant"
    led=""
    case $variant in flicker_led | all) led="$led_x,$led_y,$led_r" ;; esac
    for entry in "${methods[@]}"; do
      method=${entry%%:*}
      flags=${entry#*:}
      rec="$out/rec_${clip}_${variant}_$method"
      # shellcheck disable=SC2086
      "$evfs" reconstruct --data="$sim" --mode=interpolate --first=0 --last=16 --truth=8 \
        --out="$rec" --overwrite $flags >/dev/null
      python3 "$helper" score "$clip" "$variant" "$method" "$rec" \
        "$frames/frames/frame_00000008.png" "$led"
    done
  done
done
