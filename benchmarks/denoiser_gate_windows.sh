#!/usr/bin/env bash
# The residual denoiser on every real window with a ground truth (the windows of
# benchmarks/real_windows.sh), with and without the confidence gate (--denoise_gate), beside the
# reconstruction alone (--denoise=none): PSNR and SSIM against the truth frame, and for each run
# its difference to none. What decides `--denoise=auto` (models/README.md, "Acceptance on real
# windows"): every window within 0.05 dB of none and an SSIM not below none's.
#
#   benchmarks/denoiser_gate_windows.sh BUILD_DIR SCRATCH_DIR DATA_DIR WEIGHTS [LABEL:FLAGS...]
#
# A run's cell ends in "ok" when it meets that acceptance on the window (compared at full
# precision, not at the digits printed). Each LABEL:FLAGS is one run (flags separated by commas); by default the network as it is
# (once), gated with the automatic tau (gated) and gated with tau 0.04 and 0.16.
set -euo pipefail
if [ $# -lt 4 ]; then
  echo "usage: $0 BUILD_DIR SCRATCH_DIR DATA_DIR WEIGHTS [LABEL:FLAGS...]" >&2
  exit 2
fi
build=$1
scratch=$2
data=$3
weights=$4
shift 4
runs=("$@")
[ ${#runs[@]} -gt 0 ] || runs=("once:--denoise=once" "gated:--denoise=once,--denoise_gate"
  "tau0.04:--denoise=once,--denoise_gate,--denoise_gate_tau=0.04"
  "tau0.16:--denoise=once,--denoise_gate,--denoise_gate_tau=0.16")
evfs="$build/examples/evfs"
mkdir -p "$scratch"

mapfile -t windows < <(grep -v '^#' "$(dirname "$0")/real_windows.txt")
labels="none"
for run in "${runs[@]}"; do labels="$labels ${run%%:*}"; done
header="| window | none PSNR / SSIM |"
rule="|---|---|"
for run in "${runs[@]}"; do
  header="$header ${run%%:*} PSNR / SSIM (ΔdB, ΔSSIM) |"
  rule="$rule---|"
done
echo "$header"
echo "$rule"
for entry in "${windows[@]}"; do
  read -r name folder mode first last truth <<< "$entry"
  for run in "none:--denoise=none" "${runs[@]}"; do
    label=${run%%:*}
    IFS=, read -r -a flags <<< "${run#*:}"
    "$evfs" reconstruct --data="$data/$folder" --mode="$mode" --first="$first" --last="$last" \
      --truth="$truth" --denoiser="$weights" --out="$scratch/$name-$label" --overwrite \
      "${flags[@]}" > /dev/null 2>&1
  done
  /usr/bin/python3 - "$name" "$scratch/$name" $labels <<'PY'
import json, sys
name, prefix, labels = sys.argv[1], sys.argv[2], sys.argv[3:]
t = {k: json.load(open("%s-%s/summary.json" % (prefix, k)))["truth"] for k in labels}
none = t["none"]
cells = ["%.2f / %.4f" % (none["psnr"], none["ssim"])]
for k in labels[1:]:
    meets = t[k]["psnr"] >= none["psnr"] - 0.05 and t[k]["ssim"] >= none["ssim"]
    cells.append("%.2f / %.4f (%+.2f, %+.4f)%s" % (t[k]["psnr"], t[k]["ssim"],
                 t[k]["psnr"] - none["psnr"], t[k]["ssim"] - none["ssim"], " ok" if meets else ""))
print("| %s | %s |" % (name, " | ".join(cells)))
PY
done
