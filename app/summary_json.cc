#include "evfs/app/summary_json.h"

#include <cmath>

namespace evfs {

nlohmann::ordered_json Number(double value) {
  return std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json(nullptr);
}

nlohmann::ordered_json CeresWorkJson(const ceres::Solver::Summary& summary) {
  nlohmann::ordered_json json;
  json["time_s"] = {
      {"preprocessor", Number(summary.preprocessor_time_in_seconds)},
      {"residual_evaluation", Number(summary.residual_evaluation_time_in_seconds)},
      {"jacobian_evaluation", Number(summary.jacobian_evaluation_time_in_seconds)},
      {"linear_solver", Number(summary.linear_solver_time_in_seconds)},
      {"minimizer", Number(summary.minimizer_time_in_seconds)},
  };
  json["residual_evaluations"] = summary.num_residual_evaluations;
  json["jacobian_evaluations"] = summary.num_jacobian_evaluations;
  return json;
}

}  // namespace evfs
