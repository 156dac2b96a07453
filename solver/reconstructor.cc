#include "solver/reconstructor.h"

#include <algorithm>
#include <chrono>
#include <memory>

#include "core/error.h"
#include "core/time.h"

namespace evfs {
namespace {

using Clock = std::chrono::steady_clock;

// Hands each Ceres iteration to an IterationCallback with the whole latent video: Ceres writes
// the segment values (update_state_every_iteration), the layout spreads them over their voxels.
class CallbackAdapter : public ceres::IterationCallback {
 public:
  CallbackAdapter(const evfs::IterationCallback& callback, const LatentLayout& layout,
                  Video* latent)
      : callback_(callback), layout_(layout), latent_(latent), start_(Clock::now()) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    const auto call_start = Clock::now();
    layout_.Expand(latent_);
    SolverIteration iteration;
    iteration.iteration = summary.iteration;
    iteration.cost = summary.cost;
    iteration.elapsed_s = SecondsSince(start_) - time_in_callback_s_;
    iteration.latent = latent_;
    const bool go_on = callback_(iteration);
    time_in_callback_s_ += SecondsSince(call_start);
    return go_on ? ceres::SOLVER_CONTINUE : ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }

  double time_in_callback_s() const { return time_in_callback_s_; }

 private:
  const evfs::IterationCallback& callback_;
  const LatentLayout& layout_;
  Video* latent_;
  const Clock::time_point start_;
  double time_in_callback_s_ = 0.0;
};

}  // namespace

ObjectiveOptions ResolveObjective(const Scene& scene, const ReconstructionOptions& options,
                                  EventModelEstimate* model, bool* alpha_derived) {
  ObjectiveOptions objective = options.objective;
  EventModelParams& event_model = objective.event_model;
  *alpha_derived = event_model.alpha <= 0.0;
  if (*alpha_derived) {
    *model = EstimateEventModel(scene, event_model, options.estimation);
    event_model.alpha = model->alpha;
  } else {
    *model = EventModelEstimate();
    model->alpha = event_model.alpha;
    model->description = "alpha " + std::to_string(event_model.alpha) + " (given)";
  }
  return objective;
}

Reconstruction Reconstruct(const Scene& scene, const ReconstructionOptions& options,
                           const Video* initial, const IterationCallback& callback) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("invalid options: " + error);
  Reconstruction result;
  ReconstructionOptions solve_options = options;
  solve_options.objective =
      ResolveObjective(scene, options, &result.summary.model, &result.summary.alpha_derived);

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

  const auto build_start = Clock::now();
  const std::unique_ptr<BuiltProblem> built = ProblemBuilder(scene, solve_options).Build(&result.video);
  summary.build_time_s = SecondsSince(build_start);
  summary.problem = built->statistics();
  if (summary.problem.variable_parameter_blocks == 0) {
    summary.skipped_reason = "no unknowns: no pixel is active";
    return result;
  }

  std::unique_ptr<CallbackAdapter> adapter;
  if (callback) {
    adapter = std::make_unique<CallbackAdapter>(callback, built->layout(), &result.video);
    solve_options.solver.callbacks.push_back(adapter.get());
    solve_options.solver.update_state_every_iteration = true;
  }
  const auto solve_start = Clock::now();
  ceres::Solve(solve_options.solver, &built->problem(), &summary.ceres);
  summary.solve_time_s =
      SecondsSince(solve_start) - (adapter ? adapter->time_in_callback_s() : 0.0);
  if (summary.ceres.termination_type == ceres::FAILURE) {
    throw InvalidArgumentError("the solve failed: " + summary.ceres.message);
  }
  summary.solved = true;
  summary.initial_cost = summary.ceres.initial_cost;
  summary.final_cost = summary.ceres.final_cost;
  summary.iterations = std::max(0, static_cast<int>(summary.ceres.iterations.size()) - 1);
  built->layout().Expand(&result.video);
  return result;
}

}  // namespace evfs
