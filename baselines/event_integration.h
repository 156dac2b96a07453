// Direct event integration: a sharp frame plus the contrast threshold times the signed event
// count since it,
//   g(H_t) = g(F_j) + c · (N_t − N_j),   g(I) = log(I + b) or I,
// the event generation model of P. Lichtsteiner, C. Posch, T. Delbruck, "A 128×128 120 dB 15 µs
// latency asynchronous temporal contrast vision sensor", IEEE JSSC 2008 (an event fires when
// the log intensity has changed by the contrast threshold) summed over time, as in the paper's
// Eq. 1. Forward from the sharp frame before t, backward from the one after, and between two
// sharp frames both, weighted linearly in time: w = (τ_t − τ_j) / (τ_m − τ_j) for the later
// frame m. Time weighting matches or beats a plain mean of the two directions
// (benchmarks/results/model_choices.md, "The baselines' settings"), and it makes the estimate
// continuous at the sharp frames.
//
// Event timing comes from the scene's event frames: N_t is the signed count of the frames that
// end at or before latent frame t. A collision-binned frame spans one latent step (at most one
// event per pixel), so its events count from the end of their step; a stacked frame spanning
// several steps is assumed to spread its count evenly over them.
#ifndef EVFS_BASELINES_EVENT_INTEGRATION_H_
#define EVFS_BASELINES_EVENT_INTEGRATION_H_

#include <vector>

#include "evfs/baselines/baseline_options.h"
#include "evfs/core/video.h"
#include "evfs/scene/scene.h"

namespace evfs {

/// N_t(p): the signed event count from latent frame 0 to latent frame t (N_0 = 0), on the
/// scene's latent timeline.
Video CumulativeEventCount(const Scene& scene);

/// Indices into scene.frames of the sharp frame observations (latent_first == latent_last),
/// ordered by latent index, one per latent index (the first listed wins).
std::vector<int> SharpFrameIndices(const Scene& scene);

/// Gaussian blur of `image` in place with σ = sigma_px (cv::GaussianBlur, reflected border);
/// nothing when sigma_px is 0.
void GaussianBlurImage(double sigma_px, Image* image);

/// g(I) applied to every pixel (ToIntegrationDomain).
Image ImageToDomain(const Image& image, IntegrationDomain domain, double log_offset);
/// Intensities from g values (FromIntegrationDomain), clipped to [0, 1] when `clamp`.
Image ImageFromDomain(const Image& values, IntegrationDomain domain, double log_offset, bool clamp);

/// The integrated video on the scene's latent timeline, with options.domain, log_offset,
/// direction, blur_sigma_px and clamp_to_unit_range and the threshold `contrast_threshold`
/// (> 0). Throws InvalidArgumentError when the scene has no sharp frame or the threshold is not
/// positive.
Video IntegrateEvents(const Scene& scene, const BaselineOptions& options,
                      double contrast_threshold);

}  // namespace evfs

#endif  // EVFS_BASELINES_EVENT_INTEGRATION_H_
