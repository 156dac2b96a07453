#!/usr/bin/env bash
# report.html in Debian's headless Chromium: the video plays its first frames, every plot drew,
# and every resource the page touched is a file inside OUT (no network: the proxy and resolver
# point nowhere as well). Exit 77 (skip) without Chromium or the shared data.
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
out=$work/run
# A short run: frames 0..4 with frame 1 and 3 held out, so the page has its PSNR plot.
"$evfs" video --data="$data" --first=0 --last=4 --frame_step=2 --max_iterations=5 --preview \
  --report --progress=false --out="$out" > "$work/evfs.log" 2>&1 || {
  cat "$work/evfs.log"
  exit 1
}
# The video's codec is H.264 (avc1) where OpenCV's FFmpeg has it; Debian's Chromium plays it.
dom=$(timeout 60 "$browser" --headless --disable-gpu --no-sandbox --user-data-dir="$work/profile" \
  --autoplay-policy=no-user-gesture-required --proxy-server=127.0.0.1:9 \
  --host-resolver-rules="MAP * ~NOTFOUND" --virtual-time-budget=3000 \
  --dump-dom "file://$out/report.html#selfcheck" 2> "$work/chromium.log" || true)
line=$(grep -o 'SELFCHECK {[^<]*}' <<< "$dom" || true)
if [[ -z $line ]]; then
  echo "FAIL: the page's self-check did not report"
  tail -20 "$work/chromium.log"
  exit 1
fi
echo "$line"
python3 - "$out" "${line#SELFCHECK }" <<'PY'
import json, sys
out, report = sys.argv[1], json.loads(sys.argv[2])
errors = []
if report["plots"] != 4: errors.append("expected 4 plots, saw %d" % report["plots"])
if report["empty_plots"] != 0: errors.append("%d plots drew nothing" % report["empty_plots"])
# HAVE_CURRENT_DATA (2) or more, and the clock moved after play(): frames were decoded.
if report["video_ready"] < 2 or report["video_time"] <= 0:
    errors.append("the video did not play: readyState %s, currentTime %s (%s)" % (
        report["video_ready"], report["video_time"], report.get("play_error", "")))
for url in report["resources"]:
    if not (url.startswith("file://" + out + "/") or url.startswith(("data:", "blob:"))):
        errors.append("a request outside OUT: " + url)
if not report["resources"]: errors.append("no resource listed: the check saw nothing")
for e in errors: print("FAIL:", e)
sys.exit(1 if errors else 0)
PY
