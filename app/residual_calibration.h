// How much of the residual denoiser's correction a recording supports. The network was trained
// on simulated reconstructions; on a recording unlike them (a real DAVIS sensor's noise and
// edges) it also "corrects" what the recording observed. Where the recording observes the scene,
// the answer is known: a frame is the mean of the latent frames over its exposure. The residual
// scale s in [0, 1] is the one under which the denoised video explains those observations best
// (least squares), and the correction is applied scaled by s everywhere:
//
//   after_t = before_t - s R_t,   R_t = before_t - denoised_t,
//   s = clamp(sum_k <r_k, d_k> / sum_k <r_k, r_k>, 0, 1),
//   r_k = mean of R over frame k's exposure,  d_k = mean of before over it - frame k.
//
// A correction that moves the observed frames towards what the recording saw keeps its full
// size; one unrelated to them (or moving away) is scaled down to nothing. Measured on the
// validation cases in BENCHMARKS.md ("Residual denoiser").
#ifndef EVFS_APP_RESIDUAL_CALIBRATION_H_
#define EVFS_APP_RESIDUAL_CALIBRATION_H_

#include "core/video.h"
#include "scene/scene.h"

namespace evfs {

struct ResidualCalibration {
  double scale = 1.0;      // s
  double agreement = 0.0;  // sum_k <r_k, d_k>
  double energy = 0.0;     // sum_k <r_k, r_k>; 0: the correction leaves every observation as it
                           // was, nothing contradicts it, s = 1
  int observations = 0;    // frames of the scene used
};

/// The scale of the correction `before` → `denoised` that `scene`'s frames support. Both videos
/// are on the scene's latent timeline (InvalidArgumentError otherwise).
ResidualCalibration CalibrateResidual(const Scene& scene, const Video& before,
                                      const Video& denoised);

/// `denoised` ← before − scale (before − denoised). A pixel the denoiser left as it was keeps its
/// value bit for bit.
void ScaleResidual(double scale, const Video& before, Video* denoised);

}  // namespace evfs

#endif  // EVFS_APP_RESIDUAL_CALIBRATION_H_
