#include "solver/reconstructor.h"

#include <chrono>

#include "core/error.h"

namespace evfs {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Reconstruction Reconstruct(const Scene& scene, const ReconstructionOptions& options,
                           const Video* initial) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("invalid options: " + error);
  Reconstruction result;
  ReconstructionOptions solve_options = options;
  EventModelParams& event_model = solve_options.objective.event_model;
  if (event_model.alpha <= 0.0) {
    result.summary.model = EstimateEventModel(scene, event_model, options.estimation);
    result.summary.alpha_derived = true;
    event_model.alpha = result.summary.model.alpha;
  } else {
    result.summary.model.alpha = event_model.alpha;
    result.summary.model.description = "alpha " + std::to_string(event_model.alpha) + " (given)";
  }

  if (initial != nullptr) {
    if (initial->num_frames() != scene.num_latent_frames() || initial->height() != scene.height ||
        initial->width() != scene.width) {
      throw InvalidArgumentError("the initial video does not match the scene's latent timeline");
    }
    result.video = *initial;
  } else {
    result.video = InitializeLatentVideo(scene);
  }
  ReconstructionSummary& summary = result.summary;
  if (scene.num_events == 0) {
    summary.skipped_reason = "no events in the window: the initialisation is the answer";
    return result;
  }

  const auto build_start = std::chrono::steady_clock::now();
  const std::unique_ptr<BuiltProblem> built = ProblemBuilder(scene, solve_options).Build(&result.video);
  summary.build_time_s = SecondsSince(build_start);
  summary.problem = built->statistics();

  const auto solve_start = std::chrono::steady_clock::now();
  ceres::Solve(solve_options.solver, &built->problem(), &summary.ceres);
  summary.solve_time_s = SecondsSince(solve_start);
  summary.solved = true;
  summary.initial_cost = summary.ceres.initial_cost;
  summary.final_cost = summary.ceres.final_cost;
  summary.iterations = static_cast<int>(summary.ceres.iterations.size()) - 1;
  built->layout().Expand(&result.video);
  return result;
}

}  // namespace evfs
