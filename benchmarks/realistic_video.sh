#!/usr/bin/env bash
# `evfs video --frame_step=2` on realistic variants with 20 ms exposures: is a whole recording of a
# 30 fps frame camera with blurred frames at least as good as the blend of its frames, and as good
# as its windows reconstructed one by one?
#
#   benchmarks/realistic_video.sh BUILD_DIR DATA_DIR OUT_DIR [CROP_PX] [CLIP...]
#
# For every clip: all of its frames, cropped to the central CROP_PX x CROP_PX pixels (160 by
# default), are simulated with 20 ms exposures ("exposure20ms") and with every effect on ("all",
# benchmarks/realistic_common.sh). Every 8th frame and its exposure is one frame of the
# 30 fps camera (realistic_variants_helper.py camera); the events are all kept. `evfs video
# --frame_step=2` withholds every other camera frame and scores it against the sharp frame at its
# timestamp (the same variant simulated without the exposure: what a user wants the video to show,
# not the blurred frame the camera recorded there). Each withheld frame K is also reconstructed alone (`evfs reconstruct
# --mode=interpolate --first=K-1 --last=K+1 --truth=K`), with the frames at their timestamps
# (`--frame_time=instant`, reconstruct's default) and as the mean over their exposures
# (`--frame_time=middle`, which reads exposures.txt; `--exposure_s=0.000001` gives the withheld
# sharp frame, which has no exposure, an instant one), with the b of g = log(I + b) the video used
# (`--log_offset`: one by one, a window would choose b on the camera frames the video withholds,
# docs/model.md "Choosing b by the recording's own frames"). Prints one markdown row per clip and
# variant: mean PSNR / SSIM over the withheld frames of the video, of the blend, of the windows
# one by one both ways, and the video's exposure verdicts (summary.json `exposures`).
# Everything is written under OUT_DIR, which must be a new or scratch folder.
set -euo pipefail
# The arguments (build, data, out, crop, clips, evfs, helper) and variant_flags.
# shellcheck source=benchmarks/realistic_common.sh
source "$(dirname "$0")/realistic_common.sh"
parse_arguments "$0" "$@"

echo "| clip | variant | withheld | video PSNR / SSIM | blend | one by one, instant | one by one, over the exposure | exposures found blurred |"
echo "|---|---|---|---|---|---|---|---|"
for clip in "${clips[@]}"; do
  prepare_clip "$clip" "$(grep -cv '^#' "$data/$clip/images.txt")"
  for variant in exposure20ms all; do
    simulate_variant "$clip" "$variant"
    flags=$(variant_flags "$led_x" "$led_y" "$led_r" "$variant")
    sharp="$out/sharp_${clip}_$variant"
    # shellcheck disable=SC2086  # the flags are words
    "$evfs" simulate --frames="$frames" --out="$sharp" --overwrite ${flags/--exposure_s=0.02/} \
      >/dev/null
    cam="$out/camera_${clip}_$variant"
    python3 "$helper" camera "$sim" "$cam" 8 "$sharp/frames"
    "$evfs" video --data="$cam" --frame_step=2 --out="$out/video_${clip}_$variant" --overwrite \
      --progress_interval_s=0 >/dev/null 2>&1
    cameras=$(grep -cv '^#' "$cam/images.txt")
    b=$(/usr/bin/python3 - "$out/video_${clip}_$variant/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
choice = s.get("log_offset_search")
settings = dict(item.split("=", 1) for item in s["settings"].split())
print(choice["chosen"] if choice else settings["log_offset"])
PY
)
    instant=() exposure=()
    for (( k = 1; k + 1 < cameras; k += 2 )); do
      for timing in instant middle; do
        single="$out/single_${clip}_${variant}_${k}_$timing"
        "$evfs" reconstruct --data="$cam" --mode=interpolate --first=$((k - 1)) --last=$((k + 1)) \
          --truth=$k --frame_time=$timing --exposure_s=0.000001 --log_offset="$b" \
          --out="$single" --overwrite --progress_interval_s=0 >/dev/null 2>&1
      done
      instant+=("$out/single_${clip}_${variant}_${k}_instant/summary.json")
      exposure+=("$out/single_${clip}_${variant}_${k}_middle/summary.json")
    done
    /usr/bin/python3 - "$clip" "$variant" "$out/video_${clip}_$variant/summary.json" \
      "${instant[*]}" "${exposure[*]}" <<'PY'
import json, sys
clip, variant, video, instant, exposure = sys.argv[1:6]
s = json.load(open(video))
t = s["truth"]
def mean(paths):
    one = [json.load(open(p))["truth"] for p in paths.split()]
    return "%.2f / %.4f" % (sum(o["psnr"] for o in one) / len(one), sum(o["ssim"] for o in one) / len(one))
blurred = sum(1 for e in s.get("exposures", []) if e.get("blurred"))
print("| %s | %s | %d | %.2f / %.4f | %.2f / %.4f | %s | %s | %d of %d |" % (
    clip, variant, t["frames"], t["mean_psnr"], t["mean_ssim"], t["blend_mean_psnr"],
    t["blend_mean_ssim"], mean(instant), mean(exposure), blurred, len(s.get("exposures", []))))
PY
  done
done
