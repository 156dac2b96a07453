// What every iterative solver of evfs reports after each iteration, so that one observer can
// print progress or record checkpoints (cost, PSNR against wall time) whichever solver runs.
#ifndef EVFS_SOLVER_ITERATION_CALLBACK_H_
#define EVFS_SOLVER_ITERATION_CALLBACK_H_

#include <functional>

#include "evfs/core/video.h"

namespace evfs {

struct SolverIteration {
  /// 0 for the initial point, then the number of iterations taken.
  int iteration = 0;
  /// The objective at the current iterate (the solver's own penalty).
  double cost = 0.0;
  /// Solve time up to this point, not counting the time spent in the callback.
  double elapsed_s = 0.0;
  /// The current iterate, every voxel; valid during the call only.
  const Video* latent = nullptr;
};

/// Called after every iteration (and for the initial point). Returning false stops the solve.
/// Its own time is excluded from the solve time.
using IterationCallback = std::function<bool(const SolverIteration&)>;

}  // namespace evfs

#endif  // EVFS_SOLVER_ITERATION_CALLBACK_H_
