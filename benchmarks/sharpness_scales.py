#!/usr/bin/python3
"""Sharpness of reconstructed videos at more than one scale, to tell noise removed from edges
softened (issue 17: what the residual denoiser does to eslnet_cups_blur).

    /usr/bin/python3 benchmarks/sharpness_scales.py [--image=BLURRED.png] [--speckle_reference]
        OUT_DIR [OUT_DIR ...]

OUT_DIR: a folder written by `evfs reconstruct` (its frames/*.png). For each folder, and for
--image, prints the mean over frames of
  * the variance of the 4-neighbour Laplacian (x1e3), as benchmarks/benchmark_cases.cc scores
    sharpness: pixel noise counts as much as edges;
  * the same after a 2x2 area downsampling: pixel-sized speckle averages out, edges stay;
  * the mean squared Sobel gradient after a Gaussian blur of sigma 1 (Tenengrad, x1e3).
--speckle_reference adds a row: the first folder's frames with only their isolated pixels
replaced (a pixel more than 3 robust standard deviations -- 1.4826 x the median absolute
deviation of the frame from its 3x3 median -- away from its 3x3 median takes that median), what
removing the speckle alone, and nothing else, does to each measure.
Needs python3-opencv and python3-numpy.
"""

import argparse
import glob
import os
import sys

import cv2
import numpy as np


def read(path):
    image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if image is None:
        sys.exit(f"sharpness_scales.py: cannot read {path}")
    if image.ndim == 3:
        image = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    scale = 65535.0 if image.dtype == np.uint16 else 255.0
    return image.astype(np.float64) / scale


def laplacian_variance(image):
    return float(cv2.Laplacian(image, cv2.CV_64F, ksize=1)[1:-1, 1:-1].var())


def without_speckle(frame):
    """`frame` with its isolated pixels replaced by their 3x3 median (see --speckle_reference)."""
    median = cv2.medianBlur(frame.astype(np.float32), 3).astype(np.float64)
    deviation = frame - median
    robust_sigma = 1.4826 * np.median(np.abs(deviation))
    out = frame.copy()
    isolated = np.abs(deviation) > 3.0 * robust_sigma
    out[isolated] = median[isolated]
    return out, float(isolated.mean())


def measures(frames):
    full = np.mean([laplacian_variance(f) for f in frames])
    half = np.mean([laplacian_variance(cv2.resize(f, None, fx=0.5, fy=0.5,
                                                  interpolation=cv2.INTER_AREA))
                    for f in frames])
    tenengrad = []
    for f in frames:
        smooth = cv2.GaussianBlur(f, (0, 0), 1.0)
        gx = cv2.Sobel(smooth, cv2.CV_64F, 1, 0)
        gy = cv2.Sobel(smooth, cv2.CV_64F, 0, 1)
        tenengrad.append(np.mean(gx ** 2 + gy ** 2))
    return 1e3 * full, 1e3 * half, 1e3 * float(np.mean(tenengrad))


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--image", default="", help="a single image to score as well")
    parser.add_argument("--speckle_reference", action="store_true",
                        help="add the first folder with its isolated pixels replaced")
    parser.add_argument("folders", nargs="+", help="evfs reconstruct output folders")
    args = parser.parse_args(argv)
    print("| video | frames | Laplacian variance x1e3 | at half size x1e3 | "
          "Tenengrad (sigma 1) x1e3 |")
    print("| --- | --- | --- | --- | --- |")
    rows = [(args.image, [read(args.image)])] if args.image else []
    for folder in args.folders:
        files = sorted(glob.glob(os.path.join(folder, "frames", "*.png")))
        if not files:
            sys.exit(f"sharpness_scales.py: no frames/*.png in {folder}")
        rows.append((folder, [read(f) for f in files]))
    if args.speckle_reference:
        first = rows[1 if args.image else 0]
        cleaned = [without_speckle(frame) for frame in first[1]]
        share = 100.0 * np.mean([fraction for _, fraction in cleaned])
        rows.append((f"{first[0]}, isolated pixels replaced ({share:.1f} % of the pixels)",
                     [frame for frame, _ in cleaned]))
    for name, frames in rows:
        full, half, tenengrad = measures(frames)
        print(f"| {name} | {len(frames)} | {full:.2f} | {half:.2f} | {tenengrad:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
