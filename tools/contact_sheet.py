#!/usr/bin/env python3
"""A contact sheet of an `evfs video` output: a grid of evenly spaced frames, each labelled with
its time and whether it is an observed frame or a reconstructed one.

    /usr/bin/python3 tools/contact_sheet.py VIDEO_OUT SHEET.png|SHEET.jpg [--frames=12] [--columns=4]

VIDEO_OUT is the --out folder of `evfs video` (frames/NNNNNN.png, timestamps.txt,
summary.json). Needs Debian's python3-opencv and python3-numpy.
"""
import argparse
import json
import os
import sys

try:
    import cv2
    import numpy as np
except ImportError as error:
    sys.exit("contact_sheet: %s (apt-get install python3-opencv python3-numpy)" % error)


def observed_times(summary):
    """Times (s) of the sharp frames the windows observed, from summary.json."""
    times = set()
    for window in summary.get("windows", []):
        for frame in window.get("frames", []):
            if not frame.get("blurred", False):
                times.add(round(frame["timestamp_s"], 6))
    return times


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("video_out")
    parser.add_argument("sheet")
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--columns", type=int, default=4)
    args = parser.parse_args()
    if args.frames < 1 or args.columns < 1:
        sys.exit("contact_sheet: --frames and --columns must be >= 1")

    stamps = []
    with open(os.path.join(args.video_out, "timestamps.txt")) as lines:
        for line in lines:
            index, time = line.split()[:2]
            stamps.append((int(index), float(time)))
    if not stamps:
        sys.exit("contact_sheet: %s has no frames" % args.video_out)
    with open(os.path.join(args.video_out, "summary.json")) as text:
        observed = observed_times(json.load(text))

    count = min(args.frames, len(stamps))
    picks = [stamps[round(i * (len(stamps) - 1) / max(count - 1, 1))] for i in range(count)]
    tiles = []
    for index, time in picks:
        path = os.path.join(args.video_out, "frames", "%06d.png" % index)
        image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
        if image is None:
            sys.exit("contact_sheet: cannot read %s" % path)
        scale = 255.0 / 65535.0 if image.dtype == np.uint16 else 1.0
        tile = cv2.cvtColor(np.clip(image * scale, 0, 255).astype(np.uint8), cv2.COLOR_GRAY2BGR)
        kind = "observed frame" if round(time, 6) in observed else "reconstructed"
        label = "t=%.4f s %s" % (time, kind)
        cv2.rectangle(tile, (0, 0), (tile.shape[1], 16), (0, 0, 0), -1)
        cv2.putText(tile, label, (3, 12), cv2.FONT_HERSHEY_SIMPLEX, 0.4,
                    (80, 220, 80) if kind == "observed frame" else (255, 255, 255), 1, cv2.LINE_AA)
        tiles.append(tile)
    while len(tiles) % args.columns:
        tiles.append(np.zeros_like(tiles[0]))
    rows = [np.hstack(tiles[i:i + args.columns]) for i in range(0, len(tiles), args.columns)]
    if not cv2.imwrite(args.sheet, np.vstack(rows), [cv2.IMWRITE_JPEG_QUALITY, 90]):
        sys.exit("contact_sheet: cannot write %s" % args.sheet)
    print("%s: %d frames of %s" % (args.sheet, count, args.video_out))


if __name__ == "__main__":
    main()
