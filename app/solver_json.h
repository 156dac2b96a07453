// What Ceres reports about one solve, as summary.json records it for `reconstruct` and for each
// window of `video`: where its time went and how many passes over the residual blocks it made.
#ifndef EVFS_APP_SOLVER_JSON_H_
#define EVFS_APP_SOLVER_JSON_H_

#include <ceres/solver.h>

#include <nlohmann/json.hpp>

namespace evfs {

/// {"time_s": {preprocessor, residual_evaluation, jacobian_evaluation, linear_solver,
/// minimizer}, "residual_evaluations", "jacobian_evaluations"}, Ceres' own accounting, summed
/// over a solve's parts. The evaluations are the solve's passes over its residual blocks: their
/// count times one pass's cost is the floor the solve cannot go below without fewer passes.
nlohmann::ordered_json CeresWorkJson(const ceres::Solver::Summary& summary);

}  // namespace evfs

#endif  // EVFS_APP_SOLVER_JSON_H_
