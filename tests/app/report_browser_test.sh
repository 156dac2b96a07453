#!/usr/bin/env bash
# report.html in Debian's headless Chromium, of `evfs video` and of `evfs reconstruct`: the video
# plays its first frames, every plot drew, every picture loaded, and every resource the page
# touched is a file inside OUT (no network: the proxy and resolver point nowhere as well).
# Exit 77 (skip) without Chromium or the shared data.
# Usage: report_browser_test.sh EVFS DATA_DIR
set -euo pipefail
evfs=$1
data=${2:-}/shapes_rotation_13_20
browser=$(command -v chromium || command -v chromium-browser || true)
if [[ -z $browser ]]; then
  echo "SKIP: no chromium (scripts/install-deps.sh --with-browser installs it)"
  exit 77
fi
if [[ ! -d $data ]]; then
  echo "SKIP: shared data $data absent"
  exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Opens OUT/report.html with its self-check and holds the report to: PLOTS plots, all drawn, at
# least IMAGES pictures, all loaded, the video playing when VIDEO is 1, nothing outside OUT.
# Chromium decodes the video in real time while the page's clock is virtual, so on a loaded
# machine the video may not have started when the page gives up waiting: that alone is tried
# again, up to three times, each time with a longer wait (the page reports as soon as the video
# plays); every other check fails at once.
# Usage: check_page OUT PLOTS IMAGES VIDEO
check_page() {
  local out=$1 plots=$2 images=$3 video=$4 dom line attempt status budget_ms
  for attempt in 1 2 3; do
    budget_ms=$((3000 * attempt * attempt))
    dom=$(timeout 90 "$browser" --headless --disable-gpu --no-sandbox \
      --user-data-dir="$work/profile" --autoplay-policy=no-user-gesture-required \
      --proxy-server=127.0.0.1:9 --host-resolver-rules="MAP * ~NOTFOUND" \
      --virtual-time-budget=$budget_ms \
      --dump-dom "file://$out/report.html#selfcheck:$((budget_ms - 1000))" \
      2> "$work/chromium.log" || true)
    line=$(grep -o 'SELFCHECK {[^<]*}' <<< "$dom" || true)
    if [[ -z $line ]]; then
      echo "FAIL: the self-check of $out/report.html did not report"
      tail -20 "$work/chromium.log"
      return 1
    fi
    echo "$line"
    status=0
    check_report "$out" "${line#SELFCHECK }" "$plots" "$images" "$video" || status=$?
    if [[ $status -ne 3 || $attempt -eq 3 ]]; then return "$status"; fi
    echo "the video had not started yet (attempt $attempt of 3): again"
  done
}

# Exit 0: the report passes; 3: it fails only because the video had not started; 1: otherwise.
check_report() {
  python3 - "$@" <<'PY'
import json, sys
out, report = sys.argv[1], json.loads(sys.argv[2])
plots, images, video = int(sys.argv[3]), int(sys.argv[4]), sys.argv[5] == "1"
errors = []
if report["plots"] != plots: errors.append("expected %d plots, saw %d" % (plots, report["plots"]))
if report["empty_plots"] != 0: errors.append("%d plots drew nothing" % report["empty_plots"])
if report["images"] < images:
    errors.append("expected %d pictures or more, saw %d" % (images, report["images"]))
if report["broken_images"] != 0: errors.append("%d pictures did not load" % report["broken_images"])
for url in report["resources"]:
    if not (url.startswith("file://" + out + "/") or url.startswith(("data:", "blob:"))):
        errors.append("a request outside OUT: " + url)
if not report["resources"]: errors.append("no resource listed: the check saw nothing")
# HAVE_CURRENT_DATA (2) or more, and the clock moved after play(): frames were decoded.
not_playing = video and (report["video_ready"] < 2 or report["video_time"] <= 0)
if not_playing:
    errors.append("the video did not play: readyState %s, currentTime %s (%s)" % (
        report["video_ready"], report["video_time"], report.get("play_error", "")))
for e in errors: print("FAIL:", e)
sys.exit(0 if not errors else 3 if not_playing and len(errors) == 1 else 1)
PY
}

# A short video run: frames 0..4 with frame 1 and 3 held out, so the page has its PSNR plot.
out=$work/run
"$evfs" video --data="$data" --first=0 --last=4 --frame_step=2 --max_iterations=5 --preview \
  --report --progress=false --out="$out" > "$work/evfs.log" 2>&1 || {
  cat "$work/evfs.log"
  exit 1
}
# The video's codec is H.264 (avc1) where OpenCV's FFmpeg has it; Debian's Chromium plays it.
check_page "$out" 4 0 1

# One reconstruct window scored against frame 1, with the cost per iteration (--checkpoints):
# two plots; eight frames, the truth, the estimate, the blend and the confidence maps.
out=$work/reconstruct
"$evfs" reconstruct --data="$data" --mode=interpolate --first=0 --last=2 --truth=1 \
  --max_iterations=5 --checkpoints --report --progress=false --out="$out" > "$work/evfs.log" 2>&1 || {
  cat "$work/evfs.log"
  exit 1
}
check_page "$out" 2 11 0
