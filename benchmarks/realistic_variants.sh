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
if [ $# -lt 3 ]; then
  echo "usage: $0 BUILD_DIR DATA_DIR OUT_DIR [CROP_PX] [CLIP...]" >&2
  exit 2
fi
build=$(cd "$1" && pwd)
data=$(cd "$2" && pwd)
out=$3
crop=${4:-160}
shift $(( $# < 4 ? $# : 4 ))
clips=("$@")
[ ${#clips[@]} -gt 0 ] || mapfile -t clips < <(awk '!/^#/ && NF {print $1}' "$(dirname "$0")/clips.txt")
evfs="$build/examples/evfs"
mkdir -p "$out"
out=$(cd "$out" && pwd)
helper="$out/realistic_variants_helper.py"

# PNG reading and writing (8- and 16-bit grey, as evfs writes them), cropping and scoring, with
# the standard library only.
cat > "$helper" <<'PY'
import json, math, os, struct, sys, zlib

def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, width = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert color == 0 and interlace == 0 and depth in (8, 16), path
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    bpp = depth // 8
    stride = width * bpp
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = previous[i]
            c = previous[i - bpp] if i >= bpp else 0
            if kind == 1: line[i] = (line[i] + a) & 255
            elif kind == 2: line[i] = (line[i] + b) & 255
            elif kind == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        previous = line
    full = 255.0 if depth == 8 else 65535.0
    if depth == 8:
        return [[v / full for v in row] for row in rows]
    return [[(row[2 * x] * 256 + row[2 * x + 1]) / full for x in range(width)] for row in rows]

def write_png(path, rows):
    height, width = len(rows), len(rows[0])
    raw = b"".join(b"\x00" + bytes(int(round(v * 255.0)) for v in row) for row in rows)
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))

def crop(source, target, side, num_frames):
    lines = [l.split() for l in open(os.path.join(source, "images.txt")) if l.strip() and not l.startswith("#")]
    os.makedirs(os.path.join(target, "frames"), exist_ok=True)
    with open(os.path.join(target, "images.txt"), "w") as listing:
        for i, (t, path) in enumerate(lines[:num_frames]):
            rows = read_png(os.path.join(source, path))
            if side > 0:
                top, left = max(0, (len(rows) - side) // 2), max(0, (len(rows[0]) - side) // 2)
                rows = [row[left:left + side] for row in rows[top:top + side]]
            name = "frames/frame_%08d.png" % i
            write_png(os.path.join(target, name), rows)
            listing.write("%s %s\n" % (t, name))

def psnr(estimate, reference, keep):
    errors = [(e - r) ** 2 for y, (er, rr) in enumerate(zip(estimate, reference))
              for x, (e, r) in enumerate(zip(er, rr)) if keep(x, y)]
    mse = sum(errors) / len(errors)
    return float("inf") if mse == 0 else 10 * math.log10(1 / mse)

def score(clip, variant, method, reconstruction, clean_frame, led):
    summary = json.load(open(os.path.join(reconstruction, "summary.json")))
    truth = summary["truth"]
    estimate = read_png(os.path.join(reconstruction, "frames", "%06d.png" % truth["latent_index"]))
    clean = read_png(clean_frame)
    whole = psnr(estimate, clean, lambda x, y: True)
    away = "—"
    if led:
        lx, ly, radius = map(float, led.split(","))
        grown = (radius + 4.0) ** 2
        away = "%.2f" % psnr(estimate, clean, lambda x, y: (x - lx) ** 2 + (y - ly) ** 2 > grown)
    print("| %s | %s | %s | %.2f | %.4f | %.2f | %s |"
          % (clip, variant, method, truth["psnr"], truth["ssim"], whole, away))

if __name__ == "__main__":
    if sys.argv[1] == "crop":
        crop(sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]))
    else:
        score(*sys.argv[2:8])
PY

# The variants: name, then the simulate flags. The LED sits a quarter of the way into the frame
# (its centre and radius are set per clip below); the parameters are the literature's (docs/model.md,
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
variants=(clean hot leak flicker_led mains saturation frame_noise exposure20ms all)
methods=("default:" "blend:--solver=blend" "integrate:--solver=integrate")

echo "| clip | variant | method | PSNR (summary.json) | SSIM (summary.json) | PSNR vs clean frame | PSNR away from the LED |"
echo "|---|---|---|---|---|---|---|"
for clip in "${clips[@]}"; do
  frames="$out/frames_$clip"
  [ -f "$frames/images.txt" ] || python3 "$helper" crop "$data/$clip" "$frames" "$crop" 17
  read -r width height < <(python3 -c "
import sys; sys.path.insert(0, '$out'); import realistic_variants_helper as h
rows = h.read_png('$frames/frames/frame_00000000.png'); print(len(rows[0]), len(rows))")
  led_x=$(( width / 4 )); led_y=$(( height / 4 )); led_r=$(( width / 20 > 3 ? width / 20 : 3 ))
  for variant in "${variants[@]}"; do
    sim="$out/sim_${clip}_$variant"
    # shellcheck disable=SC2046  # the flags are words
    "$evfs" simulate --frames="$frames" --out="$sim" --overwrite \
      $(variant_flags "$led_x" "$led_y" "$led_r" "$variant") >/dev/null
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
