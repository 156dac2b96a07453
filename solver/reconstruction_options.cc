#include "solver/reconstruction_options.h"

#include <cmath>

namespace evfs {
namespace {

bool IsNonNegativeFinite(double value) { return std::isfinite(value) && value >= 0.0; }

}  // namespace

bool ObjectiveOptions::IsValid(std::string* error) const {
  if (!IsNonNegativeFinite(frame_weight) || !IsNonNegativeFinite(event_weight) ||
      !IsNonNegativeFinite(spatial_tv_weight) || !IsNonNegativeFinite(temporal_tv_weight)) {
    *error = "term weights must be finite and non-negative";
    return false;
  }
  if (frame_weight == 0.0 && event_weight == 0.0 && spatial_tv_weight == 0.0 &&
      temporal_tv_weight == 0.0) {
    *error = "at least one term weight must be positive";
    return false;
  }
  if (!(std::isfinite(smoothing_scale) && smoothing_scale > 0.0)) {
    *error = "smoothing_scale must be positive";
    return false;
  }
  if (!std::isfinite(event_model.alpha)) {
    *error = "alpha must be finite (<= 0 derives it from the data)";
    return false;
  }
  if (event_model.model == EventModel::kLog &&
      !(std::isfinite(event_model.log_offset) && event_model.log_offset > 0.0)) {
    *error = "log_offset (b of log(x + b)) must be positive";
    return false;
  }
  return true;
}

ceres::Solver::Options DefaultSolverOptions() {
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::CGNR;
  options.preconditioner_type = ceres::JACOBI;
  options.eta = 0.1;
  options.max_num_iterations = 20;
  options.max_linear_solver_iterations = 500;
  options.function_tolerance = 1e-4;
  options.gradient_tolerance = 1e-10;
  options.parameter_tolerance = 1e-6;
  options.num_threads = 2;
  // With bounds, Ceres follows each trust-region step with a projected line search whose
  // gradient evaluations cost as much as the rest of the iteration; on slider_depth it changed
  // no step (identical final cost) and took 45 % of the solve. The step is still projected
  // onto the bounds.
  options.max_num_line_search_step_size_iterations = 0;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  return options;
}

const char* SpatialTvName(SpatialTv form) {
  switch (form) {
    case SpatialTv::kPaper:
      return "paper";
    case SpatialTv::kAnisotropic:
      return "anisotropic";
    case SpatialTv::kIsotropic:
      return "isotropic";
  }
  return "";
}

bool ParseSpatialTv(const std::string& name, SpatialTv* form) {
  for (const SpatialTv candidate :
       {SpatialTv::kPaper, SpatialTv::kAnisotropic, SpatialTv::kIsotropic}) {
    if (name == SpatialTvName(candidate)) {
      *form = candidate;
      return true;
    }
  }
  return false;
}

const char* EventModelName(EventModel model) {
  return model == EventModel::kLog ? "log" : "linear";
}

bool ParseEventModel(const std::string& name, EventModel* model) {
  if (name != "linear" && name != "log") return false;
  *model = name == "log" ? EventModel::kLog : EventModel::kLinear;
  return true;
}

ReconstructionOptions::ReconstructionOptions() : solver(DefaultSolverOptions()) {}

bool ReconstructionOptions::IsValid(std::string* error) const {
  if (!objective.IsValid(error) || !estimation.IsValid(error)) return false;
  if (bound_intensities && solver.minimizer_type == ceres::LINE_SEARCH) {
    *error =
        "Ceres' line-search minimiser cannot keep intensities in [0, 1]: turn the bounds "
        "off or use the trust-region minimiser";
    return false;
  }
  for (const double scale : smoothing_continuation) {
    if (!(scale > 0.0) || !std::isfinite(scale)) {
      *error = "every smoothing_continuation scale must be positive and finite";
      return false;
    }
  }
  if (min_part_pixels < 1) {
    *error = "min_part_pixels must be at least 1";
    return false;
  }
  return solver.IsValid(error);
}

}  // namespace evfs
