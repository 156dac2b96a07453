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

nlohmann::ordered_json LogOffsetChoiceJson(const LogOffsetChoice& choice) {
  nlohmann::ordered_json frames = nlohmann::ordered_json::array();
  for (const ValidationTriplet& t : choice.triplets) frames.push_back({t.first, t.middle, t.last});
  nlohmann::ordered_json psnr = nlohmann::ordered_json::array();
  for (const double value : choice.psnr) psnr.push_back(Number(value));
  return {{"candidates", choice.candidates},
          {"frames", std::move(frames)},
          {"psnr", std::move(psnr)},
          {"chosen", Number(choice.chosen)},
          {"time_s", Number(choice.seconds)}};
}

}  // namespace evfs
