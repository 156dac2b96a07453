#include "evfs/plug_and_play/plug_and_play.h"

#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <memory>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/solver/reconstructor.h"

namespace evfs {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Applies the denoiser and adds its work to `stats` and `record`.
Video Denoise(const Denoiser& denoiser, const Video& video, const DenoiseRegion& region,
              DenoiseStats* stats, PlugAndPlayRecord* record) {
  DenoiseStats once;
  Video denoised = denoiser.Apply(video, region, &once);
  record->denoise_time_s += once.time_s;
  if (stats != nullptr) {
    stats->frames = once.frames;
    stats->tiles += once.tiles;
    stats->pixels_changed += once.pixels_changed;
    stats->network_pixels += once.network_pixels;
    stats->time_s += once.time_s;
  }
  return denoised;
}

// A view of every value of `video`, frames one after another.
Eigen::Map<Eigen::ArrayXd> Values(Video* video) {
  return Eigen::Map<Eigen::ArrayXd>(video->data(), video->num_frames() * video->pixels_per_frame());
}

}  // namespace

bool PlugAndPlayOptions::IsValid(std::string* error) const {
  return OptionChecker()
      .InRange("pnp iterations", iterations, 1, 100)
      .Check(std::isfinite(initial_rho) && initial_rho > 0.0, "pnp initial_rho must be positive")
      .Check(std::isfinite(rho_growth) && rho_growth >= 1.0, "pnp rho_growth must be >= 1")
      .InRange("pnp solver_iterations", solver_iterations, 1, 10000)
      .Passed(error);
}

Video PlugAndPlay(const Scene& scene, const ReconstructionOptions& options,
                  const Denoiser& denoiser, const DenoiseRegion& region, const Video& solved,
                  const PlugAndPlayOptions& pnp, PlugAndPlayRecord* record, DenoiseStats* stats) {
  std::string error;
  if (!pnp.IsValid(&error)) throw InvalidArgumentError("plug & play: " + error);
  if (!(options.objective.event_model.alpha > 0.0)) {
    throw InvalidArgumentError("plug & play: alpha must be resolved (> 0) before the x-updates");
  }
  *record = PlugAndPlayRecord();
  Video x = solved;
  Video z = Denoise(denoiser, x, region, stats, record);
  Video u = x;
  Values(&u).setZero();

  ReconstructionOptions x_update = options;
  x_update.solver.max_num_iterations = pnp.solver_iterations;
  x_update.smoothing_continuation.clear();  // a warm start needs no continuation
  double rho = pnp.initial_rho;
  for (int k = 0; k < pnp.iterations; ++k) {
    if (options.stop.Reached()) break;  // z, the last denoised iterate, is the answer
    auto target = std::make_shared<Video>(z);
    Values(target.get()) -= Values(&u);
    x_update.objective.prior_weight = rho;
    x_update.objective.prior_target = target;
    const auto solve_start = Clock::now();
    Reconstruction reconstruction = Reconstruct(scene, x_update, &x);
    record->solve_time_s += SecondsSince(solve_start);
    record->rho.push_back(rho);
    record->solver_iterations.push_back(reconstruction.summary.iterations);
    x = std::move(reconstruction.video);

    Video x_plus_u = x;
    Values(&x_plus_u) += Values(&u);
    z = Denoise(denoiser, x_plus_u, region, stats, record);
    Values(&u) += Values(&x) - Values(&z);
    ++record->iterations;
    rho *= pnp.rho_growth;
  }
  return z;
}

}  // namespace evfs
