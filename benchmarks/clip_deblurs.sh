#!/usr/bin/env bash
# The simulated clips of benchmarks/clips.txt deblurred as a user would with evfs: the central
# SIDE x SIDE pixels of each clip's first 8 frames, events from `evfs simulate` at its defaults
# (log(I + 0.001), thresholds 0.2), one 8-bit frame that is the mean of the 8 frames, observed over
# their span (exposures.txt). Each reconstruction is scored against the 8 sharp frames (mean PSNR
# of the output frames nearest their timestamps). Methods:
#   default       evfs reconstruct --mode=deblur as it runs by default;
#   calibrated    the same with --event_model=MODEL.json from `evfs calibrate` on the clip's
#                 8 sharp frames (the sensor's model, measured where it can be);
#   edi           --solver=edi with the simulator's threshold, --contrast_threshold=0.2;
#   edi_search    --solver=edi choosing its threshold by its sharpness criterion, as a user who
#                 does not know the threshold would run it.
#
#   benchmarks/clip_deblurs.sh EVFS [SCRATCH_DIR] [DATA_DIR] [SIDE] [-- EXTRA_FLAGS...]
#
# EXTRA_FLAGS go to the default and calibrated runs. Prints one markdown row per clip, and the
# calibrated model (b, C_on, C_off).
set -euo pipefail
evfs=$1
scratch=${2:-/tmp/evfs-clip-deblurs}
data=${3:-../shared/data}
side=${4:-160}
shift $(( $# < 4 ? $# : 4 ))
[ "${1:-}" = "--" ] && shift
extra=("$@")
cd "$(dirname "$0")/.."
helper="python3 benchmarks/clip_deblur_helper.py"
frames=8
mkdir -p "$scratch"
echo "| clip | default | calibrated | edi (threshold 0.2) | edi (searched threshold) | calibrated b, C_on, C_off |"
echo "|---|---|---|---|---|---|"
for clip in $(grep -v "^#" benchmarks/clips.txt | cut -d' ' -f1); do
  dir="$scratch/$clip"
  if [ ! -f "$dir/blurred/events.txt" ]; then
    rm -rf "$dir" && mkdir -p "$dir"
    python3 benchmarks/realistic_variants_helper.py crop "$data/$clip" "$dir/crop" "$side" "$frames"
    "$evfs" simulate --frames="$dir/crop" --out="$dir/sim" --progress_interval_s=0 > /dev/null
    $helper blur "$dir/sim" "$dir/blurred" "$frames"
  fi
  "$evfs" calibrate --data="$dir/sim" --out="$dir/model.json" --overwrite \
      --progress_interval_s=0 > "$dir/calibrate.log"
  row="| $clip |"
  for run in "default:" "calibrated:--event_model=$dir/model.json" \
             "edi:--solver=edi --contrast_threshold=0.2" "edi_search:--solver=edi"; do
    label=${run%%:*}
    read -r -a flags <<< "${run#*:}"
    case $label in edi*) ;; *) flags+=("${extra[@]}") ;; esac
    out="$dir/out_$label"
    "$evfs" reconstruct --data="$dir/blurred" --mode=deblur --first=0 --last=0 --fps=960 \
        --out="$out" --overwrite --progress_interval_s=0 "${flags[@]}" > "$dir/$label.log"
    row="$row $($helper score "$dir/sim" "$out" "$frames") |"
  done
  model=$(python3 -c "import json, sys; m = json.load(open(sys.argv[1])); print('%.4f, %.3f, %.3f' % tuple(m[k]['value'] for k in ('log_offset', 'threshold_on', 'threshold_off')))" "$dir/model.json")
  echo "$row $model |"
done
