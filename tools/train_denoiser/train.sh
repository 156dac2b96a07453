#!/usr/bin/env bash
# `make train-denoiser`: makes the training pairs with evfs's own simulator and DMR, trains the
# residual denoiser and exports it to models/evfs_denoiser.onnx (model card: models/README.md).
#
#   tools/train_denoiser/train.sh BUILD_DIR [WORK_DIR]
#
# WORK_DIR (default BUILD_DIR/denoiser_training) receives the pairs and the logs. SAMPLES and
# STEPS override the sample count and the optimiser steps (the shipped weights use the defaults).
# REALISTIC (default 0) is the share of samples recorded with a real sensor's effects
# (make_denoiser_pairs --realistic). ONNX, LOG and REFERENCE_DIR say where the network, its log
# and the C++ test's reference pair go (default: models/ and tests/denoiser/data, the shipped
# files); a candidate goes elsewhere until it meets models/README.md's acceptance.
# Sources: synthetic scenes, photographs from opencv-doc and python3-skimage, the videos of
# opencv-doc, and the three training clips of ../shared/data when it exists. The validation
# recordings (adobe240_IMG_0004b, adobe240_IMG_0036, slider_depth_70_71, shapes_rotation_13_20,
# eslnet_cups_blur) are never read.
set -euo pipefail

build_dir=${1:?usage: train.sh BUILD_DIR [WORK_DIR]}
work_dir=${2:-$build_dir/denoiser_training}
repo=$(cd "$(dirname "$0")/../.." && pwd)
samples=${SAMPLES:-400}
steps=${STEPS:-12000}
seed=${SEED:-17}
realistic=${REALISTIC:-0}
onnx=${ONNX:-$repo/models/evfs_denoiser.onnx}
log=${LOG:-$repo/models/training_log.md}
reference_dir=${REFERENCE_DIR:-$repo/tests/denoiser/data}

opencv_data=/usr/share/doc/opencv-doc/examples/data
skimage_data=/usr/lib/python3/dist-packages/skimage/data
photos=()
for name in baboon.jpg fruits.jpg building.jpg butterfly.jpg home.jpg messi5.jpg \
    starry_night.jpg stuff.jpg orange.jpg apple.jpg aero1.jpg HappyFish.jpg smarties.png \
    squirrel_cls.jpg rubberwhale1.png graf1.png leuvenA.jpg board.jpg blox.jpg \
    box_in_scene.png basketball1.png lena.jpg; do
  [ -f "$opencv_data/$name" ] && photos+=("$opencv_data/$name")
done
for name in astronaut.png camera.png coffee.png chelsea.png brick.png grass.png gravel.png \
    moon.png rocket.jpg coins.png motorcycle_left.png hubble_deep_field.jpg retina.jpg page.png; do
  [ -f "$skimage_data/$name" ] && photos+=("$skimage_data/$name")
done
videos=()
for name in vtest.avi tree.avi Megamind.avi; do
  [ -f "$opencv_data/$name" ] && videos+=("$opencv_data/$name")
done
clips=()
data_dir=${EVFS_DATA_DIR:-$repo/../shared/data}
for name in $(awk '!/^#/ && $2 == "training" {print $1}' "$repo/benchmarks/clips.txt"); do
  [ -f "$data_dir/$name/images.txt" ] && clips+=("$data_dir/$name")
done
join() { local IFS=,; echo "$*"; }
echo "train-denoiser: ${#photos[@]} photographs, ${#videos[@]} videos, ${#clips[@]} clips"

mkdir -p "$work_dir"
start=$(date +%s)
nice "$build_dir/tools/make_denoiser_pairs" --out="$work_dir/pairs" --overwrite \
  --samples="$samples" --seed="$seed" --threads=1 --realistic="$realistic" --photos="$(join "${photos[@]}")" \
  --videos="$(join "${videos[@]}")" --clips="$(join "${clips[@]}")" > "$work_dir/pairs.log"
tail -1 "$work_dir/pairs.log"
pairs_s=$(( $(date +%s) - start ))
echo "train-denoiser: pairs made in $pairs_s s"

nice /usr/bin/python3 "$repo/tools/train_denoiser/train.py" --pairs="$work_dir/pairs" \
  --onnx="$onnx" --log="$log" --reference_dir="$reference_dir" --steps="$steps" --seed="$seed" --threads=2 \
  | tee "$work_dir/train.log"
echo "train-denoiser: pairs $pairs_s s, all $(( $(date +%s) - start )) s" \
  | tee -a "$log"
