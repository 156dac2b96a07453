// Scene → latent video: builds the problem, initialises, solves with Ceres and reports.
#ifndef EVFS_SOLVER_RECONSTRUCTOR_H_
#define EVFS_SOLVER_RECONSTRUCTOR_H_

#include <ceres/ceres.h>

#include <string>

#include "evfs/core/video.h"
#include "evfs/scene/event_model_estimation.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/iteration_callback.h"
#include "evfs/solver/problem_builder.h"
#include "evfs/solver/reconstruction_options.h"

namespace evfs {

/// What a reconstruction did: Ceres' own summary plus evfs' counts and timings.
struct ReconstructionSummary {
  /// Ceres' summary; with several independent parts, their costs, steps and stage times
  /// summed (stage times are then thread time, not wall time) and the worst termination.
  ceres::Solver::Summary ceres;
  ProblemStatistics problem;
  EventModelEstimate model;  // the α used, and how it was derived when it was
  bool alpha_derived = false;
  bool solved = false;         // false when the scene needed no solve
  std::string skipped_reason;  // why not, when solved is false
  /// Why options.stop ended the solve before its own end (StopCondition::Reason); the parts and
  /// bands not reached keep their start. Empty otherwise.
  std::string stopped_early;
  double build_time_s = 0.0;
  double solve_time_s = 0.0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;  // of the part that took most
  /// Linear solver (CG) iterations of every part and step together.
  int64_t linear_solver_iterations = 0;
  /// Steps spread over a ramp (ReconstructionOptions::step_ramp_px).
  int64_t ramped_steps = 0;
};

struct Reconstruction {
  Video video;  // H_0 … H_K with their latent timestamps
  ReconstructionSummary summary;
};

/// Reconstructs the latent video of `scene`, starting from `initial` (the scene's latent
/// timeline; e.g. a classical estimate from baselines/) or, when null, from
/// InitializeLatentVideo(scene). Throws InvalidArgumentError for invalid options or an initial
/// video of another shape, SolverError when Ceres ends with FAILURE. α <= 0 in the options is
/// derived from the scene first. A scene without events is answered with its initialisation,
/// without a solve. `callback`, when given, sees every Ceres iteration with the current latent
/// video.
Reconstruction Reconstruct(const Scene& scene, const ReconstructionOptions& options,
                           const Video* initial = nullptr,
                           const IterationCallback& callback = nullptr);
/// The same, starting from `initial`, which the reconstruction takes over (no second copy of
/// the latent video is held while it solves).
Reconstruction Reconstruct(const Scene& scene, const ReconstructionOptions& options, Video initial,
                           const IterationCallback& callback = nullptr);

/// options.objective with α derived from `scene` (EstimateEventModel) when it is <= 0; `model`
/// says what was used and how, `alpha_derived` whether it was derived.
ObjectiveOptions ResolveObjective(const Scene& scene, const ReconstructionOptions& options,
                                  EventModelEstimate* model, bool* alpha_derived);

}  // namespace evfs

#endif  // EVFS_SOLVER_RECONSTRUCTOR_H_
