// Plug & play (paper §3.4, Table 4): ADMM between the model-based reconstruction (DMR, the
// Ceres problem) and the residual denoiser D, in its scaled form:
//
//   X ← argmin_X L(X) + ρ/2 ‖X − (Z − U)‖²   (Ceres, the objective's quadratic prior)
//   Z ← D(X + U)
//   U ← U + X − Z
//
// starting from the solve's result X₀ with U = 0, so that the first Z is the one-time denoised
// reconstruction. ρ grows each iteration (a common schedule for plug & play ADMM: the iterates
// settle as the coupling tightens). Each x-update starts from the previous X (warm start). Only
// the voxels the solver solved for take part: the others keep their values, which D leaves
// unchanged (DenoiseRegion), so U stays 0 there.
#ifndef EVFS_PLUG_AND_PLAY_PLUG_AND_PLAY_H_
#define EVFS_PLUG_AND_PLAY_PLUG_AND_PLAY_H_

#include <string>
#include <vector>

#include "evfs/core/video.h"
#include "evfs/denoiser/denoiser.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/reconstruction_options.h"

namespace evfs {

struct PlugAndPlayOptions {
  /// ADMM iterations (x-update, denoising, dual update) after the first denoising.
  int iterations = 3;
  /// ρ of the first x-update: the objective's prior_weight, a weight per voxel normalised like
  /// the other terms (solver/objective_terms.h).
  double initial_rho = 1000.0;
  /// ρ is multiplied by this after each iteration (≥ 1).
  double rho_growth = 3.0;
  /// Levenberg–Marquardt iterations of each warm-started x-update.
  int solver_iterations = 10;

  bool IsValid(std::string* error) const;
};

/// What plug & play did, for summary.json.
struct PlugAndPlayRecord {
  int iterations = 0;                  // ADMM iterations run
  std::vector<double> rho;             // ρ of each x-update
  std::vector<int> solver_iterations;  // LM iterations of each x-update
  double solve_time_s = 0.0;           // the x-updates (build and solve)
  double denoise_time_s = 0.0;         // every application of the denoiser, the first included
};

/// Runs plug & play from `solved`, the Ceres solve's latent video of `scene` (X₀), with the
/// objective and Ceres settings of `options` (α resolved: > 0). Returns the last Z. `region`
/// is the solved pixels (SolvedRegion); `stats` (may be null) sums the denoiser's work. Throws
/// InvalidArgumentError for invalid options.
Video PlugAndPlay(const Scene& scene, const ReconstructionOptions& options,
                  const Denoiser& denoiser, const DenoiseRegion& region, const Video& solved,
                  const PlugAndPlayOptions& pnp, PlugAndPlayRecord* record,
                  DenoiseStats* stats = nullptr);

}  // namespace evfs

#endif  // EVFS_PLUG_AND_PLAY_PLUG_AND_PLAY_H_
