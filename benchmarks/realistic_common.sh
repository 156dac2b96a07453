# Sourced by benchmarks/realistic_variants.sh, realistic_video.sh, variant_bands.sh, flicker_windows.sh
# and saturation_variants.sh.
#
#   parse_arguments SCRIPT BUILD_DIR DATA_DIR OUT_DIR [CROP_PX] [CLIP...]
#   prepare_clip CLIP [FRAMES]
#   variant_flags LED_X LED_Y LED_RADIUS VARIANT
#   simulate_variant CLIP VARIANT

# Sets build, data, out (created), crop, clips (clips.txt's when none given), evfs and helper.
parse_arguments() {
  local script=$1
  shift
  if [ $# -lt 3 ]; then
    echo "usage: $script BUILD_DIR DATA_DIR OUT_DIR [CROP_PX] [CLIP...]" >&2
    exit 2
  fi
  local here
  here=$(cd "$(dirname "$script")" && pwd)
  build=$(cd "$1" && pwd)
  data=$(cd "$2" && pwd)
  out=$3
  crop=${4:-160}
  shift $(( $# < 4 ? $# : 4 ))
  clips=("$@")
  [ ${#clips[@]} -gt 0 ] || mapfile -t clips < <(awk '!/^#/ && NF {print $1}' "$here/clips.txt")
  evfs="$build/examples/evfs"
  mkdir -p "$out"
  out=$(cd "$out" && pwd)
  helper="$here/realistic_variants_helper.py"
}

# Crops the first FRAMES (17 by default) frames of CLIP to crop x crop pixels into
# $out/frames_CLIP, once, and sets frames (that folder) and the LED's place in it: a quarter of
# the way into the frame (led_x, led_y), radius a twentieth of its width and at least 3 (led_r).
prepare_clip() {
  frames="$out/frames_$1"
  [ -f "$frames/images.txt" ] || python3 "$helper" crop "$data/$1" "$frames" "$crop" "${2:-17}"
  local width height
  read -r width height < <(python3 -c "
import sys; sys.path.insert(0, '$(dirname "$helper")'); import realistic_variants_helper as h
rows = h.read_png('$frames/frames/frame_00000000.png'); print(len(rows[0]), len(rows))")
  led_x=$((width / 4))
  led_y=$((height / 4))
  led_r=$((width / 20 > 3 ? width / 20 : 3))
}

# The variants: name, then the simulate flags. The LED sits a quarter of the way into the frame
# (its centre and radius: the first three arguments, set per clip by the caller); the parameters are the literature's (docs/model.md,
# "Simulator defaults").
variant_flags() {
  local led="--flicker_led_hz=1000 --flicker_led_xy_px=$1,$2 --flicker_led_radius_px=$3"
  local mains="--mains_hz=100 --mains_depth=0.3"
  local hot="--hot_pixel_fraction=0.002 --hot_pixel_rate_hz=100"
  local leak="--leak_rate_hz=0.1"
  local saturation="--frame_gain=1.5"
  local frame_noise="--read_noise_dn=2 --fpn_offset_dn=1 --fpn_gain_sigma=0.01"
  local exposure="--exposure_s=0.02"
  case $4 in
    clean) echo "" ;;
    hot) echo "$hot" ;;
    leak) echo "$leak" ;;
    flicker_led) echo "$led" ;;
    mains) echo "$mains" ;;
    saturation) echo "$saturation" ;;
    frame_noise) echo "$frame_noise" ;;
    exposure20ms) echo "$exposure" ;;
    all) echo "$hot $leak $led $mains $saturation $frame_noise $exposure" ;;
  esac
}

# Simulates VARIANT of CLIP (after prepare_clip CLIP) into $out/sim_CLIP_VARIANT and sets sim to it.
simulate_variant() {
  sim="$out/sim_$1_$2"
  # shellcheck disable=SC2046  # the flags are words
  "$evfs" simulate --frames="$frames" --out="$sim" --overwrite \
    $(variant_flags "$led_x" "$led_y" "$led_r" "$2") >/dev/null
}
