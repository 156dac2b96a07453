#!/usr/bin/python3
"""How the predicted one-sigma band of `evfs reconstruct --truth=K` holds the truth when it is
scaled: the share of the truth's pixels within k x sigma, for several k.

    /usr/bin/python3 benchmarks/confidence_scales.py [--data=FOLDER] [--scales=0.6,0.8,...]
        OUT_DIR [OUT_DIR ...]

OUT_DIR: a folder written by `evfs reconstruct --truth=K` (summary.json's truth, frames/ and
confidence/ at the truth's latent frame). The truth frame is line K of images.txt in the data
folder summary.json names, or in --data (for a recording evfs reads from a file: `evfs convert
--data=FILE --out=FOLDER` gives the same frames as a folder). An 8-bit truth counts each pixel
with the share of its level's bin inside the band, as evfs' `within_predicted_sigma` does
(scene/confidence.h, ShareWithinSigma); at k = 1 the share is that figure. Prints one markdown
row per folder: the shares, and the k at which the band would hold 68 % (the scale a calibrated
band needs; "> kmax" when even the largest k holds less). With --strict a pixel counts when
|estimate - truth| <= k sigma, whatever the truth's bit depth.
Needs python3-opencv and python3-numpy.
"""

import argparse
import json
import os

import cv2
import numpy as np


def read(path):
    image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if image is None:
        raise SystemExit("cannot read " + path)
    if image.ndim == 3:
        image = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    scale = 65535.0 if image.dtype == np.uint16 else 255.0
    return image.astype(np.float64) / scale, image.dtype == np.uint8


def shares(estimate, sigma, truth, eight_bit, scales, strict=False):
    half = 0.5 / 255.0 if eight_bit and not strict else 0.0
    result = []
    for k in scales:
        band = k * sigma
        if half > 0.0:
            low = np.maximum(estimate - band, truth - half)
            high = np.minimum(estimate + band, truth + half)
            result.append(float(np.mean(np.clip(high - low, 0.0, None) / (2.0 * half))))
        else:
            result.append(float(np.mean(np.abs(estimate - truth) <= band)))
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out_dirs", nargs="+")
    parser.add_argument("--data", default="", help="the recording as a folder (images.txt)")
    parser.add_argument("--scales", default="0.6,0.8,1,1.25,1.5,2")
    parser.add_argument("--strict", action="store_true",
                        help="count |estimate - truth| <= k sigma, an 8-bit truth's bin ignored")
    args = parser.parse_args()
    scales = [float(k) for k in args.scales.split(",")]
    fine = np.linspace(0.1, max(scales), 400)
    print("| window | " + " | ".join("k = %g" % k for k in scales) + " | k for 68 % |")
    print("|---" * (len(scales) + 2) + "|")
    for out in args.out_dirs:
        summary_path = os.path.join(out, "summary.json")
        if not os.path.isfile(summary_path):
            raise SystemExit(out + ": no summary.json (not a folder evfs reconstruct wrote)")
        summary = json.load(open(summary_path))
        truth_info = summary.get("truth")
        if not truth_info:
            raise SystemExit(out + ": summary.json has no truth (run reconstruct with --truth)")
        data = args.data or summary["data"]
        if not os.path.isdir(data):
            raise SystemExit(data + " is not a folder: give the recording as one with --data")
        lines = [line.split() for line in open(os.path.join(data, "images.txt"))
                 if line.strip() and not line.startswith("#")]
        truth, eight_bit = read(os.path.join(data, lines[truth_info["index"]][1]))
        name = "%06d.png" % truth_info["latent_index"]
        estimate, _ = read(os.path.join(out, "frames", name))
        sigma, _ = read(os.path.join(out, "confidence", name))
        row = shares(estimate, sigma, truth, eight_bit, scales, args.strict)
        curve = shares(estimate, sigma, truth, eight_bit, fine, args.strict)
        needed = next((k for k, share in zip(fine, curve) if share >= 0.68), None)
        print("| %s | %s | %s |" % (os.path.basename(os.path.normpath(out)),
                                    " | ".join("%.1f %%" % (100 * s) for s in row),
                                    "%.2f" % needed if needed is not None else "> %g" % max(scales)))


if __name__ == "__main__":
    main()
