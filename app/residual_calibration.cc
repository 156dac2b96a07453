#include "app/residual_calibration.h"

#include <algorithm>

#include "core/error.h"

namespace evfs {

ResidualCalibration CalibrateResidual(const Scene& scene, const Video& before,
                                      const Video& denoised) {
  if (before.num_frames() != scene.num_latent_frames() ||
      denoised.num_frames() != before.num_frames() || before.height() != scene.height ||
      before.width() != scene.width || denoised.height() != before.height() ||
      denoised.width() != before.width()) {
    throw InvalidArgumentError("the videos to calibrate are not on the scene's latent timeline");
  }
  ResidualCalibration calibration;
  for (const FrameObservation& frame : scene.frames) {
    const int length = frame.latent_last - frame.latent_first + 1;
    Image residual = Image::Zero(scene.height, scene.width);
    Image misfit = -frame.image;
    for (int t = frame.latent_first; t <= frame.latent_last; ++t) {
      residual += (before.frame(t) - denoised.frame(t)) / length;
      misfit += before.frame(t) / length;
    }
    calibration.agreement += (residual * misfit).sum();
    calibration.energy += residual.square().sum();
    ++calibration.observations;
  }
  if (calibration.energy > 0.0) {
    calibration.scale = std::clamp(calibration.agreement / calibration.energy, 0.0, 1.0);
  }
  return calibration;
}

void ScaleResidual(double scale, const Video& before, Video* denoised) {
  if (scale == 1.0) return;
  // Where the denoiser changed nothing, before − scale · 0 is before, bit for bit.
  for (int t = 0; t < before.num_frames(); ++t) {
    denoised->frame(t) = before.frame(t) - scale * (before.frame(t) - denoised->frame(t));
  }
}

}  // namespace evfs
