// Values summary.json records the same way for `reconstruct` and for each window of `video`: a
// number (null when not finite, which JSON cannot hold) and what Ceres reports about a solve.
#ifndef EVFS_APP_SUMMARY_JSON_H_
#define EVFS_APP_SUMMARY_JSON_H_

#include <ceres/solver.h>

#include <nlohmann/json.hpp>

#include "evfs/app/log_offset_search.h"

namespace evfs {

/// `value`, or null when it is not finite.
nlohmann::ordered_json Number(double value);

/// {"time_s": {preprocessor, residual_evaluation, jacobian_evaluation, linear_solver,
/// minimizer}, "residual_evaluations", "jacobian_evaluations"}: where the solve's time went and
/// its passes over the residual blocks, Ceres' own accounting (Reconstructor sums the times over
/// a solve's parts and keeps the most passes any part made). Their count times one pass's cost
/// is the floor the solve cannot go below without fewer passes.
nlohmann::ordered_json CeresWorkJson(const ceres::Solver::Summary& summary);

/// What a log offset search tried and chose (app/log_offset_search.h), and its time.
nlohmann::ordered_json LogOffsetChoiceJson(const LogOffsetChoice& choice);

}  // namespace evfs

#endif  // EVFS_APP_SUMMARY_JSON_H_
