#!/usr/bin/env bash
# Contact sheets of `evfs video` on the real DAVIS recordings (docs/guide.md):
# shapes_rotation_13_20 (interpolation windows, one prediction tail) and eslnet_cups_blur (its
# six frames observed over their exposures, so deblurred inside the windows).
#
#   benchmarks/contact_sheets.sh [BUILD_DIR] [SCRATCH_DIR] [DATA_DIR] [SHEET_DIR]
#
# Writes SHEET_DIR/contact_RECORDING.jpg (default benchmarks/results) with
# tools/contact_sheet.py (python3-opencv, python3-numpy).
set -euo pipefail
build=${1:-build}
scratch=${2:-/tmp/evfs-contact-sheets}
data=${3:-../shared/data}
sheets=${4:-benchmarks/results}
cd "$(dirname "$0")/.."
mkdir -p "$scratch" "$sheets"
for recording in shapes_rotation_13_20 eslnet_cups_blur; do
  "$build/examples/evfs" video --data="$data/$recording" --out="$scratch/$recording" --overwrite \
    --fps=200 | tail -2
  /usr/bin/python3 tools/contact_sheet.py "$scratch/$recording" "$sheets/contact_$recording.jpg" \
    --frames=12 --columns=4
done
