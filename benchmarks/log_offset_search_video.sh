#!/usr/bin/env bash
# What choosing b on the recording's own frames (--log_offset_search, docs/model.md "Choosing b
# by the recording's own frames") does to `evfs video --frame_step=2` on the realistic variants
# recorded by a 30 fps camera with sharp frames.
#
#   benchmarks/log_offset_search_video.sh BUILD_DIR DATA_DIR OUT_DIR [CROP_PX] [CLIP...]
#
# For every clip: all of its frames, cropped to CROP_PX x CROP_PX (160 by default), simulated
# with each variant of benchmarks/realistic_common.sh named in VARIANTS (default: clean
# frame_noise mains all); every 8th frame is one camera frame (realistic_variants_helper.py
# camera), the events are all kept. `evfs video --frame_step=2` withholds every other camera
# frame and scores it against the recorded one, once with the search switched off
# (--log_offset_search=) and once by default. Prints one row per clip and variant: the
# withheld frames, PSNR / SSIM of both, the blend's, the b chosen and both runs' wall time.
# Everything is written under OUT_DIR, which must be a new or scratch folder.
set -euo pipefail
# shellcheck source=benchmarks/realistic_common.sh
source "$(dirname "$0")/realistic_common.sh"
parse_arguments "$0" "$@"

read -r -a variants <<< "${VARIANTS:-clean frame_noise mains all}"
echo "| clip | variant | withheld | b = 0.5 | chosen | blend | b | wall s, b = 0.5 / chosen |"
echo "|---|---|---|---|---|---|---|---|"
for clip in "${clips[@]}"; do
  prepare_clip "$clip" "$(grep -cv '^#' "$data/$clip/images.txt")"
  for variant in "${variants[@]}"; do
    simulate_variant "$clip" "$variant"
    cam="$out/camera_${clip}_$variant"
    python3 "$helper" camera "$sim" "$cam" 8
    for run in fixed search; do
      flags=()
      [ "$run" = fixed ] && flags=(--log_offset_search=)
      "$evfs" video --data="$cam" --frame_step=2 --out="$out/video_${clip}_${variant}_$run" \
        --overwrite --progress_interval_s=0 "${flags[@]}" >/dev/null 2>&1
    done
    /usr/bin/python3 - "$clip" "$variant" "$out/video_${clip}_${variant}_fixed/summary.json" \
      "$out/video_${clip}_${variant}_search/summary.json" <<'PY'
import json, sys
clip, variant, fixed, search = sys.argv[1:5]
a, b = json.load(open(fixed)), json.load(open(search))
ta, tb = a["truth"], b["truth"]
chosen = b.get("log_offset_search", {}).get("chosen", "-")
print("| %s | %s | %d | %.2f / %.4f | %.2f / %.4f | %.2f / %.4f | %s | %.1f / %.1f |" % (
    clip, variant, ta["frames"], ta["mean_psnr"], ta["mean_ssim"], tb["mean_psnr"],
    tb["mean_ssim"], ta["blend_mean_psnr"], ta["blend_mean_ssim"], chosen,
    a["run"]["total_wall_s"], b["run"]["total_wall_s"]))
PY
  done
done
