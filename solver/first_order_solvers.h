// Reference solvers on the objective of docs/design.md §1, driven by the fused evaluation of
// solver/fused_objective.h (docs/design.md §3: "so that every speed-up we claim for Ceres is
// real"):
//
//  * Adam (Kingma & Ba 2015), the paper's optimiser and schedule: learning rate 0.002 divided by
//    5 every 200 iterations, β = (0.9, 0.99), 1000 iterations, H clipped to [0, 1] after every
//    step. Per active voxel x with gradient g at step k = 1, 2, …:
//      m ← β1 m + (1 − β1) g,   v ← β2 v + (1 − β2) g²,
//      x ← x − lr_k / (1 − β1^k) · m / (sqrt(v) / sqrt(1 − β2^k) + ε)       (PyTorch's form)
//    on the paper's true ℓ1 ("adam") or the smoothed ℓ1 that Ceres minimises ("adam_smooth").
//  * L-BFGS through ceres::GradientProblemSolver on the smoothed objective ("lbfgs").
//
// Both solve for the active voxels only; ring and inactive pixels keep the values they have in
// the latent video passed in. The caller initialises it (InitializeLatentVideo) and derives α
// (EstimateEventModel), as Reconstruct does.
#ifndef EVFS_SOLVER_FIRST_ORDER_SOLVERS_H_
#define EVFS_SOLVER_FIRST_ORDER_SOLVERS_H_

#include <ceres/gradient_problem_solver.h>

#include <cstdint>
#include <string>

#include "evfs/core/stop_condition.h"
#include "evfs/core/video.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/fused_objective.h"
#include "evfs/solver/iteration_callback.h"
#include "evfs/solver/reconstruction_options.h"

namespace evfs {

/// The paper's Adam settings (its released code: torch.optim.Adam with StepLR).
struct AdamOptions {
  /// Steps taken.
  int max_iterations = 1000;
  /// Learning rate of the first `decay_every` steps.
  double learning_rate = 0.002;
  /// Steps between two learning-rate decays.
  int decay_every = 200;
  /// Factor applied to the learning rate at each decay (0.2: divided by 5).
  double decay_factor = 0.2;
  /// Decay rate of the first-moment estimate.
  double beta1 = 0.9;
  /// Decay rate of the second-moment estimate.
  double beta2 = 0.99;
  /// ε added to the root of the second moment.
  double epsilon = 1e-8;
  /// Clip every active voxel to [0, 1] after each step (the paper clips H).
  bool bound_intensities = true;
  /// kTrueL1: the paper's objective ("adam"); kSmoothed: the Ceres problem's ("adam_smooth").
  L1Penalty penalty = L1Penalty::kTrueL1;
  /// Threads of the objective evaluation and of the update.
  int num_threads = 2;

  bool IsValid(std::string* error) const;
  /// The learning rate of step `iteration` (0-based): learning_rate ·
  /// decay_factor^⌊iteration / decay_every⌋.
  double LearningRate(int iteration) const;
};

/// L-BFGS on the smoothed objective. Ceres' line-search minimiser has no bounds, so the solve is
/// unbounded: intensities may leave [0, 1] (the log model is flat below 0, see event_model.h),
/// and the result is the unconstrained minimiser; clip it for display if needed.
struct LbfgsOptions {
  /// Ceres' settings; the defaults are DefaultLbfgsSolverOptions(). Any line search direction but
  /// dense BFGS (n² memory) is accepted.
  ceres::GradientProblemSolver::Options solver;
  /// Threads of the objective evaluation.
  int num_threads = 2;

  LbfgsOptions();
  bool IsValid(std::string* error) const;
};

/// L-BFGS (rank 20), Wolfe line search, at most 500 iterations, silent. At a few hundred
/// thousand unknowns Ceres' own bookkeeping dominates an iteration: on slider_depth (4.1e5
/// unknowns) a profile put 45 % of the time in libceres, 37 % in the kernel (page faults) and
/// 6 % in the objective.
ceres::GradientProblemSolver::Options DefaultLbfgsSolverOptions();

/// What a first-order solve did.
struct FirstOrderSummary {
  /// "adam", "adam_smooth" or "lbfgs".
  std::string solver;
  /// Steps taken (Adam) or Ceres iterations (L-BFGS).
  int iterations = 0;
  /// Objective evaluations (cost and gradient).
  int evaluations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  /// Building the fused objective (precomputing its runs, masks and bands).
  double setup_time_s = 0.0;
  /// The iterations, without the set-up and the time spent in the callback.
  double solve_time_s = 0.0;
  /// Why the solve stopped, in words.
  std::string termination;
  /// Why a StopCondition ended it before its own end (StopCondition::Reason); empty otherwise.
  std::string stopped_early;
  /// Unknowns: active pixels × latent frames.
  int64_t active_voxels = 0;
};

/// Minimises the objective over the active voxels of `latent` (initialised by the caller,
/// scene-sized) with Adam. `callback`, when given, sees every iterate (all voxels, ring and
/// inactive ones at their fixed values) with its cost; without it nothing is spent on it. The
/// solve ends at the first iteration where `stop` is reached, with the iterate it has. Throws
/// InvalidArgumentError for invalid options, an α that is not > 0, or a latent video or mask of
/// another size.
FirstOrderSummary SolveWithAdam(const Scene& scene, const ObjectiveOptions& objective,
                                const ActivityMask& mask, const AdamOptions& options, Video* latent,
                                const IterationCallback& callback = nullptr,
                                const StopCondition& stop = StopCondition());

/// The same with Ceres' L-BFGS on the smoothed objective (unbounded, see LbfgsOptions).
FirstOrderSummary SolveWithLbfgs(const Scene& scene, const ObjectiveOptions& objective,
                                 const ActivityMask& mask, const LbfgsOptions& options,
                                 Video* latent, const IterationCallback& callback = nullptr,
                                 const StopCondition& stop = StopCondition());

}  // namespace evfs

#endif  // EVFS_SOLVER_FIRST_ORDER_SOLVERS_H_
