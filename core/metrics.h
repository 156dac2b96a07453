// Image quality metrics for intensities in [0, 1].
#ifndef EVFS_CORE_METRICS_H_
#define EVFS_CORE_METRICS_H_

#include "evfs/core/video.h"

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

/// How wide the edges of `image` are where `edges_from` has its strongest edges (EdgeWidth).
struct EdgeWidthScore {
  double mean_px = 0.0;  // NaN when no edge qualifies
  int edges = 0;
};

/// Sharpness as the mean 10–90 % rise width, in pixels, of `image` across the strongest edges of
/// `edges_from` (smaller is sharper). Unlike LaplacianVariance, isolated noisy pixels barely move
/// it, so it tells edges softened from speckle removed. The edges are the local maxima of the
/// gradient magnitude of `edges_from` smoothed by a Gaussian of σ 2 px, in its top 3 %, at least
/// 8 px from the border. Across each, along the smoothed gradient, `image` is sampled (bilinear)
/// every 0.1 px over ±6 px; its mean level over the first and last pixel of that profile are 0 %
/// and 100 %, and an edge whose two levels differ by less than 0.03 in `image` is left out. The
/// width runs from the first sample at 10 % to the first at 90 % of the profile's running maximum.
/// A step blurred by a Gaussian of σ s measures 2.56 s for a wide blur and a little more for a
/// narrow one, whose pixels the bilinear profile joins by straight lines (2.9 px at σ 1). Pass
/// the same `edges_from` to compare videos at the same edges. Throws InvalidArgumentError when the
/// sizes differ or the images are smaller than 18x18.
EdgeWidthScore EdgeWidth(const Image& image, const Image& edges_from);

}  // namespace evfs

#endif  // EVFS_CORE_METRICS_H_
