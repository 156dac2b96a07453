#include "evfs/solver/reconstruction_options.h"

#include <cmath>

#include "evfs/core/option_checker.h"

namespace evfs {
namespace {

bool IsNonNegativeFinite(double value) { return std::isfinite(value) && value >= 0.0; }

// The SUBSET preconditioner's residual blocks are each problem's temporal chains
// (BuiltProblem::temporal_residuals), known only once it is built: the other options are
// checked with one stand-in block.
ceres::Solver::Options SolverOptionsToCheck(const ceres::Solver::Options& solver) {
  ceres::Solver::Options checked = solver;
  if (checked.preconditioner_type == ceres::SUBSET) {
    static int stand_in;
    checked.residual_blocks_for_subset_preconditioner.insert(
        reinterpret_cast<ceres::ResidualBlockId>(&stand_in));
  }
  return checked;
}

}  // namespace

bool ObjectiveOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check
      .Check(IsNonNegativeFinite(frame_weight) && IsNonNegativeFinite(event_weight) &&
                 IsNonNegativeFinite(spatial_tv_weight) && IsNonNegativeFinite(temporal_tv_weight),
             "term weights must be finite and non-negative")
      .Check(frame_weight != 0.0 || event_weight != 0.0 || spatial_tv_weight != 0.0 ||
                 temporal_tv_weight != 0.0,
             "at least one term weight must be positive")
      .Check(std::isfinite(smoothing_scale) && smoothing_scale > 0.0,
             "smoothing_scale must be positive")
      .Check(std::isfinite(event_model.alpha) && event_model.alpha <= kMaxAlpha,
             "--alpha must be at most 1e6 (<= 0 derives it from the data)")
      .Check(event_model.saturation == 0.0 ||
                 (std::isfinite(event_model.saturation) && event_model.saturation >= 1.0),
             "event_saturation (c of c tanh(alpha dg / c)) must be >= 1 (0 derives it)")
      .Check(event_model.model != EventModel::kLog ||
                 (std::isfinite(event_model.log_offset) && event_model.log_offset > 0.0),
             "log_offset (b of log(x + b)) must be positive")
      .NonNegative("log_temporal_tv_reversals", log_temporal_tv_reversals)
      .Check(IsNonNegativeFinite(prior_weight), "prior_weight must be finite and non-negative")
      .Check(prior_weight == 0.0 || prior_target != nullptr,
             "a positive prior_weight needs a prior_target");
  return check.Passed(error);
}

ceres::Solver::Options DefaultSolverOptions() {
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::CGNR;
  options.preconditioner_type = ceres::JACOBI;
  options.eta = 0.1;
  // The withheld frames stop improving long before the cost stops falling: at most 10
  // iterations scored as well as 20 on the real windows and the simulated clips, in half the
  // time where the cap is reached (BENCHMARKS.md, "Where the time goes").
  options.max_num_iterations = 10;
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

const char* SpatialTvName(SpatialTv form) { return NameOf(kSpatialTvNames, form); }

bool ParseSpatialTv(const std::string& name, SpatialTv* form) {
  return FindName(kSpatialTvNames, name, form);
}

const char* EventModelName(EventModel model) { return NameOf(kEventModelNames, model); }

bool ParseEventModel(const std::string& name, EventModel* model) {
  return FindName(kEventModelNames, name, model);
}

ReconstructionOptions::ReconstructionOptions() : solver(DefaultSolverOptions()) {}

bool ReconstructionOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.Valid(objective)
      .Valid(estimation)
      .Check(!(bound_intensities && solver.minimizer_type == ceres::LINE_SEARCH),
             "Ceres' line-search minimiser cannot keep intensities in [0, 1]: turn the bounds "
             "off or use the trust-region minimiser");
  for (const double scale : smoothing_continuation) {
    check.Check(scale > 0.0 && std::isfinite(scale),
                "every smoothing_continuation scale must be positive and finite");
  }
  check.Check(min_part_pixels >= 1, "min_part_pixels must be at least 1")
      .Check(ring_tolerance >= 0.0 && ring_tolerance <= 1.0, "ring_tolerance must be in [0, 1]")
      .Check(quiet_blend_fraction >= 0.0 && quiet_blend_fraction <= kMaxQuietBlendFraction,
             "quiet_blend_fraction must be in [0, 100]")
      .Check(step_ramp_px >= 0.0 && step_ramp_px <= kMaxStepRampPx,
             "step_ramp_px must be in [0, 1e6]")
      .Check(max_problem_mb <= kMaxProblemMb,
             "max_problem_mb must be at most " + std::to_string(kMaxProblemMb) + " (1 TiB)")
      .Check(solver.num_threads >= 1, "--threads must be 1 or more")
      .Valid(SolverOptionsToCheck(solver));
  return check.Passed(error);
}

}  // namespace evfs
