// The Complementary Filter of C. Scheerlinck, N. Barnes, R. Mahony, "Continuous-time intensity
// estimation using event cameras", ACCV 2018. Per pixel, the log-intensity estimate L̂ follows
//   dL̂/dt = E(t) − α (L̂ − L_F(t)),   E(t) = Σ_i c σ_i δ(t − t_i)
// where L_F is the log of the latest frame and α the crossover (cutoff) frequency in rad/s:
// events carry the high frequencies, frames the low ones. Between events the estimate decays
// exponentially towards L_F: L̂(t) = L_F + e^{−α (t − t_i)} (L̂(t_i) − L_F); each event adds c σ_i.
//
// As in the paper the filter is causal: a frame becomes L_F from its latent frame on (a blurred
// frame from the centre of its exposure), and the estimate starts at the first frame. Logs are
// of I + b (BaselineOptions::log_offset). Event timing: the events of a latent step are applied
// together at one time, the midpoint of their first and last timestamps for a collision frame
// (at most one event per pixel), the middle of the step for a stacked frame, which is assumed
// to spread its count evenly over its steps.
#ifndef EVFS_BASELINES_COMPLEMENTARY_FILTER_H_
#define EVFS_BASELINES_COMPLEMENTARY_FILTER_H_

#include "evfs/baselines/baseline_options.h"
#include "evfs/core/video.h"
#include "evfs/scene/scene.h"

namespace evfs {

/// The filter's estimate at every latent frame of the scene, with options.cutoff_rad_per_s,
/// log_offset and clamp_to_unit_range and the log contrast threshold `contrast_threshold` (> 0).
/// Throws InvalidArgumentError when the scene has no frame observation or the threshold is not
/// positive.
Video ComplementaryFilter(const Scene& scene, const BaselineOptions& options,
                          double contrast_threshold);

}  // namespace evfs

#endif  // EVFS_BASELINES_COMPLEMENTARY_FILTER_H_
