// Keeps the residual denoiser's correction consistent with what the recording observed. The
// network was trained on simulated reconstructions; on a recording it also "corrects" what the
// sensor saw. Where the recording observes the scene the answer is known: a frame is the mean of
// the latent frames over its exposure, and the solve already matches it. So the correction
// R_t = before_t − denoised_t is projected onto the corrections that leave every observed
// frame's exposure mean as it was (least squares: the nearest such correction):
//
//   after_t = before_t − (R_t − r_k)   for every latent frame t in frame k's exposure,
//   r_k = mean of R over frame k's exposure.
//
// What the network changes between the frames (the interpolated and predicted frames) and
// within an exposure (a deblurred frame's motion and noise) it keeps; what would change an
// observed frame (its brightness, a sharp frame itself) it gives back. The reconstruction then
// explains the frames exactly as well as the solve left them. Measured on the validation cases
// in BENCHMARKS.md ("Residual denoiser").
#ifndef EVFS_DENOISER_FRAME_CONSISTENCY_H_
#define EVFS_DENOISER_FRAME_CONSISTENCY_H_

#include <cstdint>
#include <vector>

#include "evfs/core/video.h"
#include "evfs/scene/scene.h"

namespace evfs {

struct FrameConsistency {
  int observations = 0;            // frames of the scene the correction was projected for
  double correction_energy = 0.0;  // sum_t |R_t|^2 of the network's correction
  double removed_energy = 0.0;     // the part of it the frames observed, taken out
  /// The fraction of the correction's energy the projection took out (0 when there was none).
  double RemovedFraction() const {
    return correction_energy > 0.0 ? removed_energy / correction_energy : 0.0;
  }
};

/// Projects the correction `before` → `*denoised` as above, in place. Both videos are on the
/// scene's latent timeline (InvalidArgumentError otherwise). A pixel the denoiser left as it was
/// keeps its value bit for bit. Where exposures share latent frames the projections are repeated
/// until every exposure mean is kept (to 1e-12).
FrameConsistency KeepFramesConsistent(const Scene& scene, const Video& before, Video* denoised);

/// The latent frames a denoiser has to run on so that the frames flagged in `read` (one flag per
/// latent frame of `scene`) come out of KeepFramesConsistent as they would with every frame
/// denoised: the flagged ones, every latent frame of an exposure that holds one of them (its
/// mean needs them all), and not the latent frame of a sharp frame that no other exposure
/// holds (its whole correction is taken out). A job that writes only some latent frames (a
/// video resampled to --fps) denoises these instead of all. Throws InvalidArgumentError when
/// `read` is not one flag per latent frame.
std::vector<uint8_t> FramesToDenoise(const Scene& scene, std::vector<uint8_t> read);

}  // namespace evfs

#endif  // EVFS_DENOISER_FRAME_CONSISTENCY_H_
