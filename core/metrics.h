// Image quality metrics for intensities in [0, 1].
#ifndef EVFS_CORE_METRICS_H_
#define EVFS_CORE_METRICS_H_

#include "core/video.h"

namespace evfs {

/// Peak signal-to-noise ratio in dB for data range 1: 10 log10(1 / MSE). Identical images give
/// +infinity. Throws InvalidArgumentError when the sizes differ or the images are empty.
double Psnr(const Image& estimate, const Image& reference);

/// Mean structural similarity (Wang, Bovik, Sheikh, Simoncelli, IEEE TIP 2004) with the
/// paper's settings: Gaussian 11×11 window with σ = 1.5, K1 = 0.01, K2 = 0.03, data range 1,
/// averaged over the 'valid' window positions as in the authors' ssim_index.m. Throws
/// InvalidArgumentError when the sizes differ or the images are smaller than the window.
double Ssim(const Image& estimate, const Image& reference);

/// Variance of the 4-neighbour Laplacian over the interior pixels: a sharpness measure
/// (larger is sharper) used to compare deblurred frames with their blurred input.
double LaplacianVariance(const Image& image);

}  // namespace evfs

#endif  // EVFS_CORE_METRICS_H_
