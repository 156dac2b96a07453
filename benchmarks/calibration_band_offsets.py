#!/usr/bin/python3
"""Where a pixel's log intensity sits in its band at the frames, on a recording `evfs simulate`
wrote: the premise of `evfs calibrate`'s fit measured against the simulator's truth.

    /usr/bin/python3 benchmarks/calibration_band_offsets.py SIM --log_eps=B
        --threshold_pos=P --threshold_neg=N [--first=I]

SIM: a folder written by `evfs simulate --frames=... --log_eps=B --threshold_pos=P
--threshold_neg=N --out=SIM` (images.txt, frames, events.txt). The simulator moves g = log(I + B)
linearly in time between two frames and fires when g crosses its reference, so the reference
after an event is g interpolated at the event's time. At each frame from I on, at each pixel that
is neither dark (< 2/255) nor saturated (>= 0.99) and has fired before the frame, this prints
delta = g(frame) - reference, split by the polarity of the pixel's last event, in units of that
polarity's threshold. `evfs calibrate` takes delta as +1/2 after an ON event and -1/2 after an
OFF one (solver/event_model_calibration.h; docs/model.md, "Calibrating the event model").
Needs python3-opencv and python3-numpy.
"""

import argparse
import os

import cv2
import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sim")
    parser.add_argument("--log_eps", type=float, required=True)
    parser.add_argument("--threshold_pos", type=float, required=True)
    parser.add_argument("--threshold_neg", type=float, required=True)
    parser.add_argument("--first", type=int, default=0)
    args = parser.parse_args()

    times, frames = [], []
    with open(os.path.join(args.sim, "images.txt")) as listing:
        for line in listing:
            if not line.strip() or line.startswith("#"):
                continue
            time, name = line.split()[:2]
            image = cv2.imread(os.path.join(args.sim, name), cv2.IMREAD_UNCHANGED)
            if image is None:
                raise SystemExit("cannot read " + name)
            scale = 255.0 if image.dtype == np.uint8 else 65535.0
            times.append(float(time))
            frames.append(image.astype(np.float64) / scale)
    times = np.array(times)
    frames = np.array(frames)
    count, height, width = frames.shape
    g = np.log(frames.reshape(count, -1) + args.log_eps)

    events = np.loadtxt(os.path.join(args.sim, "events.txt"), ndmin=2)
    pixel = events[:, 2].astype(int) * width + events[:, 1].astype(int)
    polarity = np.where(events[:, 3] > 0, 1, -1)
    interval = np.clip(np.searchsorted(times, events[:, 0], side="right") - 1, 0, count - 2)
    fraction = (events[:, 0] - times[interval]) / (times[interval + 1] - times[interval])
    reference = (1 - fraction) * g[interval, pixel] + fraction * g[interval + 1, pixel]

    offsets = {1: [], -1: []}
    for k in range(max(args.first, 1), count):
        before = np.flatnonzero(events[:, 0] < times[k])  # time-ordered: the last one wins
        last_reference = np.full(height * width, np.nan)
        last_polarity = np.zeros(height * width)
        last_reference[pixel[before]] = reference[before]
        last_polarity[pixel[before]] = polarity[before]
        intensity = frames[k].ravel()
        usable = (intensity >= 2.0 / 255.0) & (intensity < 0.99)
        for sign, threshold in ((1, args.threshold_pos), (-1, args.threshold_neg)):
            chosen = usable & (last_polarity == sign)
            offsets[sign].append((g[k] - last_reference)[chosen] / threshold)

    print("| after | frame-pixels | mean delta / C | quartiles | calibrate assumes |")
    print("| --- | --- | --- | --- | --- |")
    for sign, name, assumed in ((1, "ON", "+0.5"), (-1, "OFF", "-0.5")):
        values = np.concatenate(offsets[sign]) if offsets[sign] else np.zeros(0)
        if values.size == 0:
            print("| %s | 0 | | | %s |" % (name, assumed))
            continue
        quartiles = np.percentile(values, [25, 50, 75])
        print("| %s | %d | %+.2f | %+.2f / %+.2f / %+.2f | %s |" %
              (name, values.size, values.mean(), quartiles[0], quartiles[1], quartiles[2],
               assumed))


if __name__ == "__main__":
    main()
