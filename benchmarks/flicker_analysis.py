#!/usr/bin/python3
"""What a clip's global brightness flicker costs the "skip 3" protocol (BENCHMARKS.md, "`evfs
video` on whole clips", nfs_basketball_7).

    benchmarks/flicker_analysis.py SIM_DIR VIDEO_OUT_DIR [--frame_step=4]

SIM_DIR is a recording made by `evfs simulate` (frames/, images.txt, events.txt); VIDEO_OUT_DIR
the output of `evfs video --data=SIM_DIR --frame_step=N --fps=240` on it (frames on the clip's
own timestamps). Prints, per withheld frame: the frame's mean brightness over the mean of the two
observed frames around it, the share of pixels without an event in its window, the PSNR of evfs
and of the blend, and of an oracle that multiplies the blend at the pixels without events by the
truth's own brightness ratio there: the most any method could gain from knowing the flicker.
"""
import argparse
import os

import cv2
import numpy as np


def read_frames(folder):
    """(timestamps, frames in [0, 1]) of a folder with an images.txt."""
    times, frames = [], []
    with open(os.path.join(folder, "images.txt")) as listing:
        for line in listing:
            fields = line.split()
            if len(fields) < 2:
                continue
            image = cv2.imread(os.path.join(folder, fields[1]), cv2.IMREAD_UNCHANGED)
            times.append(float(fields[0]))
            frames.append(image.astype(np.float64) / (65535.0 if image.dtype == np.uint16 else 255.0))
    return np.array(times), frames


def psnr(estimate, truth):
    return 10.0 * np.log10(1.0 / np.mean((np.clip(estimate, 0.0, 1.0) - truth) ** 2))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sim_dir")
    parser.add_argument("video_dir")
    parser.add_argument("--frame_step", type=int, default=4)
    args = parser.parse_args()

    times, truth = read_frames(args.sim_dir)
    events = np.loadtxt(os.path.join(args.sim_dir, "events.txt"), ndmin=2)
    out_times = np.loadtxt(os.path.join(args.video_dir, "timestamps.txt"), ndmin=2)[:, 1]
    out_names = sorted(os.listdir(os.path.join(args.video_dir, "frames")))
    height, width = truth[0].shape
    t0 = times[0]

    print("frame | brightness / observed | pixels without events | evfs dB | blend dB | oracle dB")
    print("---|---|---|---|---|---")
    rows = []
    step = args.frame_step
    for first in range(0, len(truth) - step, step):
        last = first + step
        window = events[(events[:, 0] >= times[first]) & (events[:, 0] < times[last])]
        fired = np.zeros((height, width), bool)
        fired[window[:, 2].astype(int), window[:, 1].astype(int)] = True
        quiet = ~fired
        for index in range(first + 1, last):
            a = (times[index] - times[first]) / (times[last] - times[first])
            blend = (1.0 - a) * truth[first] + a * truth[last]
            # The output frame at this frame's time (the video's timestamps start at 0).
            output = int(np.argmin(np.abs(out_times - (times[index] - t0))))
            image = cv2.imread(os.path.join(args.video_dir, "frames", out_names[output]),
                               cv2.IMREAD_UNCHANGED).astype(np.float64) / 65535.0
            oracle = image.copy()
            gain = truth[index][quiet].mean() / blend[quiet].mean()
            oracle[quiet] = blend[quiet] * gain
            brightness = truth[index].mean() / (0.5 * (truth[first].mean() + truth[last].mean()))
            row = (psnr(image, truth[index]), psnr(blend, truth[index]),
                   psnr(oracle, truth[index]))
            rows.append(row)
            print("%d | %.3f | %.2f | %.2f | %.2f | %.2f" % (index, brightness, quiet.mean(), *row))
    means = np.mean(np.array(rows), axis=0)
    print("mean | | | %.2f | %.2f | %.2f" % tuple(means))


if __name__ == "__main__":
    main()
