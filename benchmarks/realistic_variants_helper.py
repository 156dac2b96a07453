#!/usr/bin/env python3
"""PNG reading and writing (8- and 16-bit grey, as evfs writes them), cropping, camera
recordings and scoring for benchmarks/realistic_variants.sh and realistic_video.sh, with the
standard library only.

  realistic_variants_helper.py crop SOURCE TARGET SIDE NUM_FRAMES
  realistic_variants_helper.py camera SIMULATION TARGET STEP [SHARP_FRAMES]
  realistic_variants_helper.py score CLIP VARIANT METHOD RECONSTRUCTION CLEAN_FRAME LED
  realistic_variants_helper.py saturation CLIP CLEAN_REC SATURATED_REC GAIN
"""
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
    """The central SIDE x SIDE pixels (SIDE 'WxH': W x H; 0: the whole frame) of the first frames."""
    width, height = (int(v) for v in side.split("x")) if "x" in side else (int(side), int(side))
    lines = [l.split() for l in open(os.path.join(source, "images.txt")) if l.strip() and not l.startswith("#")]
    os.makedirs(os.path.join(target, "frames"), exist_ok=True)
    with open(os.path.join(target, "images.txt"), "w") as listing:
        for i, (t, path) in enumerate(lines[:num_frames]):
            rows = read_png(os.path.join(source, path))
            if width > 0:
                top, left = max(0, (len(rows) - height) // 2), max(0, (len(rows[0]) - width) // 2)
                rows = [row[left:left + width] for row in rows[top:top + height]]
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

def truth_and_estimate(reconstruction):
    """The frame a reconstruction was scored against, its estimate there, its summary.json, and
    a reader of its recording's frames by images.txt line."""
    summary = json.load(open(os.path.join(reconstruction, "summary.json")))
    truth = summary["truth"]
    data = summary["data"]
    lines = [l.split() for l in open(os.path.join(data, "images.txt")) if l.strip() and not l.startswith("#")]
    frame = lambda index: read_png(os.path.join(data, lines[index][1]))
    estimate = read_png(os.path.join(reconstruction, "frames", "%06d.png" % truth["latent_index"]))
    return frame(truth["index"]), estimate, summary, frame

def saturation(clip, clean_rec, saturated_rec, gain):
    """The clean clip against its variant with frame gain GAIN, away from where the variant
    saturates: pixels of the variant's truth or of the frames the window observed at or above
    0.99 (of 1), grown by 4 pixels, are left out. The variant's errors are divided by the gain
    (its frames are GAIN times brighter, so the same relative error is GAIN times larger)."""
    gain = float(gain)
    clean_truth, clean_estimate, _, _ = truth_and_estimate(clean_rec)
    truth, estimate, summary, frame = truth_and_estimate(saturated_rec)
    observed = [frame(int(summary["options"][k])) for k in ("first", "last")]
    height, width = len(truth), len(truth[0])
    saturated = [[any(img[y][x] >= 0.99 for img in [truth] + observed) for x in range(width)]
                 for y in range(height)]
    grow = 4
    near = [[False] * width for _ in range(height)]
    for y in range(height):
        for x in range(width):
            if saturated[y][x]:
                for yy in range(max(0, y - grow), min(height, y + grow + 1)):
                    for xx in range(max(0, x - grow), min(width, x + grow + 1)):
                        near[yy][xx] = True
    keep = lambda x, y: not near[y][x]
    share = sum(row.count(True) for row in near) / float(width * height)
    away_clean = psnr(clean_estimate, clean_truth, keep)
    away_saturated = psnr(estimate, truth, keep) + 20 * math.log10(gain)
    print("| %s | %.1f %% | %.2f | %.2f | %+.2f |" % (clip, 100 * share, away_clean, away_saturated,
                                                    away_saturated - away_clean))

def camera(simulation, target, step, sharp_frames=None):
    """The recording a slower frame camera makes of SIMULATION: every STEP-th frame (and its
    exposure), all of the events. With SHARP_FRAMES (the folder of the frames the simulation was
    made from), every other camera frame, the ones `evfs video --frame_step=2` withholds and
    scores, is the sharp frame at its timestamp instead, without an exposure: the frame a user
    wants the video to show there."""
    os.makedirs(target, exist_ok=True)
    lines = [l.split() for l in open(os.path.join(simulation, "images.txt")) if l.strip() and not l.startswith("#")]
    kept = lines[::step]
    withheld = set()
    if sharp_frames:
        link = os.path.join(target, "sharp")
        if not os.path.lexists(link):
            os.symlink(os.path.abspath(sharp_frames), link)
        for i in range(1, len(kept), 2):
            withheld.add(kept[i][1])
            kept[i] = [kept[i][0], "sharp/" + os.path.basename(kept[i][1])]
    open(os.path.join(target, "images.txt"), "w").writelines("%s %s\n" % (t, p) for t, p in kept)
    paths = {p for _, p in kept}
    exposures = os.path.join(simulation, "exposures.txt")
    if os.path.exists(exposures):
        open(os.path.join(target, "exposures.txt"), "w").writelines(
            l for l in open(exposures) if l.split() and l.split()[0] in paths)
    for name in ("frames", "events.txt"):
        link = os.path.join(target, name)
        if not os.path.lexists(link):
            os.symlink(os.path.join(os.path.abspath(simulation), name), link)

if __name__ == "__main__":
    if sys.argv[1] == "crop":
        crop(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]))
    elif sys.argv[1] == "camera":
        camera(sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5] if len(sys.argv) > 5 else None)
    elif sys.argv[1] == "saturation":
        saturation(*sys.argv[2:6])
    else:
        score(*sys.argv[2:8])
