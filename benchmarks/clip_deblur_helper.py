#!/usr/bin/env python3
"""The blurred recording and the score of benchmarks/clip_deblurs.sh, with the standard library
only.

  clip_deblur_helper.py blur SIMULATION TARGET NUM_FRAMES
      TARGET: one 8-bit frame, the mean of the simulation's first NUM_FRAMES frames, observed
      over their time span (exposures.txt), with the simulation's events.
  clip_deblur_helper.py score SIMULATION RECONSTRUCTION NUM_FRAMES
      Mean PSNR (dB) of the reconstruction's frames nearest each of those frames' timestamps.
"""
import os, shutil, sys

from realistic_variants_helper import psnr, read_png, write_png

def frame_list(folder, num_frames):
    lines = [l.split() for l in open(os.path.join(folder, "images.txt"))
             if l.strip() and not l.startswith("#")]
    if len(lines) < num_frames:
        sys.exit("%s holds %d frames, fewer than %d" % (folder, len(lines), num_frames))
    return [(t, os.path.join(folder, path)) for t, path in lines[:num_frames]]

def blur(simulation, target, num_frames):
    frames = frame_list(simulation, num_frames)
    images = [read_png(path) for _, path in frames]
    mean = [[sum(image[y][x] for image in images) / len(images) for x in range(len(images[0][0]))]
            for y in range(len(images[0]))]
    os.makedirs(os.path.join(target, "images"), exist_ok=True)
    write_png(os.path.join(target, "images", "blurred.png"), mean)
    first, last = frames[0][0], frames[-1][0]
    with open(os.path.join(target, "images.txt"), "w") as listing:
        listing.write("%.9f images/blurred.png\n" % ((float(first) + float(last)) / 2))
    with open(os.path.join(target, "exposures.txt"), "w") as exposures:
        exposures.write("images/blurred.png %s %s\n" % (first, last))
    shutil.copy(os.path.join(simulation, "events.txt"), os.path.join(target, "events.txt"))

def score(simulation, reconstruction, num_frames):
    times = [float(l.split()[1]) for l in open(os.path.join(reconstruction, "timestamps.txt"))]
    outputs = sorted(os.listdir(os.path.join(reconstruction, "frames")))
    total = 0.0
    for t, path in frame_list(simulation, num_frames):
        nearest = min(range(len(times)), key=lambda k: abs(times[k] - float(t)))
        estimate = read_png(os.path.join(reconstruction, "frames", outputs[nearest]))
        total += psnr(estimate, read_png(path), lambda x, y: True)
    print("%.2f" % (total / num_frames))

if __name__ == "__main__":
    if sys.argv[1] == "blur":
        blur(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    else:
        score(sys.argv[2], sys.argv[3], int(sys.argv[4]))
