#include "evfs/solver/reconstructor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/parallel.h"
#include "evfs/core/time.h"
#include "evfs/solver/step_ramps.h"
#include "evfs/solver/stop_callback.h"

namespace evfs {
namespace {

using Clock = std::chrono::steady_clock;

// Hands each Ceres iteration to an IterationCallback with the whole latent video: Ceres writes
// the segment values (update_state_every_iteration), the layout spreads them over their voxels.
// Parts are solved one after another under one adapter: it reports the whole objective (the
// parts done at their final cost, those to come at their initial one) and counts iterations
// across parts.
class CallbackAdapter : public ceres::IterationCallback {
 public:
  CallbackAdapter(const evfs::IterationCallback& callback, const LatentLayout& layout,
                  Video* latent)
      : callback_(callback), layout_(layout), latent_(latent), start_(Clock::now()) {}

  /// Before each part's solve: the cost of every other part, and whether this is the first.
  void StartPart(double other_parts_cost, bool first) {
    other_parts_cost_ = other_parts_cost;
    first_part_ = first;
    iteration_base_ = iteration_;
  }

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    // Ceres reports each part's starting point as iteration 0; only the first one is new.
    if (summary.iteration == 0 && !first_part_) return ceres::SOLVER_CONTINUE;
    const auto call_start = Clock::now();
    layout_.Expand(latent_);
    iteration_ = iteration_base_ + summary.iteration;
    SolverIteration iteration;
    iteration.iteration = iteration_;
    iteration.cost = other_parts_cost_ + summary.cost;
    iteration.elapsed_s = SecondsSince(start_) - time_in_callback_s_;
    iteration.latent = latent_;
    const bool go_on = callback_(iteration);
    time_in_callback_s_ += SecondsSince(call_start);
    stopped_ = !go_on;
    return go_on ? ceres::SOLVER_CONTINUE : ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }

  double time_in_callback_s() const { return time_in_callback_s_; }
  bool stopped() const { return stopped_; }

 private:
  const evfs::IterationCallback& callback_;
  const LatentLayout& layout_;
  Video* latent_;
  const Clock::time_point start_;
  double time_in_callback_s_ = 0.0;
  double other_parts_cost_ = 0.0;
  bool first_part_ = true;
  int iteration_ = 0;
  int iteration_base_ = 0;
  bool stopped_ = false;
};

// Adds a part's Ceres summary to the whole scene's: costs, steps and stage times add up, the
// evaluation counts are the most any part made; the worst termination wins (with its message),
// otherwise the first (largest) part's message.
void Accumulate(const ceres::Solver::Summary& part, bool first, ceres::Solver::Summary* total) {
  const auto severity = [](ceres::TerminationType type) {
    return type == ceres::FAILURE ? 2 : type == ceres::NO_CONVERGENCE ? 1 : 0;
  };
  if (first) {
    *total = part;
    return;
  }
  if (severity(part.termination_type) > severity(total->termination_type)) {
    total->termination_type = part.termination_type;
    total->message = part.message;
  }
  total->initial_cost += part.initial_cost;
  total->final_cost += part.final_cost;
  total->fixed_cost += part.fixed_cost;
  total->num_successful_steps += part.num_successful_steps;
  total->num_unsuccessful_steps += part.num_unsuccessful_steps;
  total->preprocessor_time_in_seconds += part.preprocessor_time_in_seconds;
  total->minimizer_time_in_seconds += part.minimizer_time_in_seconds;
  total->postprocessor_time_in_seconds += part.postprocessor_time_in_seconds;
  total->total_time_in_seconds += part.total_time_in_seconds;
  total->residual_evaluation_time_in_seconds += part.residual_evaluation_time_in_seconds;
  total->jacobian_evaluation_time_in_seconds += part.jacobian_evaluation_time_in_seconds;
  total->linear_solver_time_in_seconds += part.linear_solver_time_in_seconds;
  // Passes over the residual blocks: the most any part made (its own blocks, each pass).
  total->num_residual_evaluations =
      std::max(total->num_residual_evaluations, part.num_residual_evaluations);
  total->num_jacobian_evaluations =
      std::max(total->num_jacobian_evaluations, part.num_jacobian_evaluations);
  total->num_parameter_blocks += part.num_parameter_blocks;
  total->num_residual_blocks += part.num_residual_blocks;
}

double InitialCost(ceres::Problem* problem) {
  double cost = 0.0;
  problem->Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  return cost;
}

// ReconstructionOptions::quiet_blend_fraction: `largest_change` is that fraction of one event's.
void BlendQuietPixels(const Scene& scene, const EventModelParams& event_model,
                      double largest_change, Video* latent) {
  std::vector<const FrameObservation*> sharp;
  for (const FrameObservation& frame : scene.frames) {
    if (frame.latent_first == frame.latent_last) sharp.push_back(&frame);
  }
  std::sort(sharp.begin(), sharp.end(),
            [](const auto* a, const auto* b) { return a->latent_first < b->latent_first; });
  const int64_t pixels = latent->pixels_per_frame();
  const std::vector<uint8_t> fired = scene.events.FiredPixels();
  const std::vector<int64_t>& times = scene.latent_timestamps_ns();
  for (size_t j = 0; j + 1 < sharp.size(); ++j) {
    const int a = sharp[j]->latent_first, b = sharp[j + 1]->latent_first;
    const double* first = sharp[j]->image.data();
    const double* last = sharp[j + 1]->image.data();
    std::vector<double> weight(b - a + 1, 0.0);  // of `last` at latent frame a + i
    for (int t = a; t <= b && times[b] > times[a]; ++t) {
      weight[t - a] = static_cast<double>(times[t] - times[a]) / (times[b] - times[a]);
    }
    for (int64_t p = 0; p < pixels; ++p) {
      if (fired[p] || std::abs(IntensityTransform(last[p], event_model) -
                               IntensityTransform(first[p], event_model)) >= largest_change) {
        continue;
      }
      for (int t = a; t <= b; ++t) {
        latent->frame_data(t)[p] = (1.0 - weight[t - a]) * first[p] + weight[t - a] * last[p];
      }
    }
  }
}

}  // namespace

ObjectiveOptions ResolveObjective(const Scene& scene, const ReconstructionOptions& options,
                                  EventModelEstimate* model, bool* alpha_derived) {
  ObjectiveOptions objective = options.objective;
  EventModelParams& event_model = objective.event_model;
  *alpha_derived = event_model.alpha <= 0.0;
  if (*alpha_derived) {
    *model = EstimateEventModel(scene, event_model, options.estimation);
    event_model.alpha = model->alpha;
    event_model.off_alpha_ratio = model->off_alpha_ratio;
  } else {
    *model = EventModelEstimate();
    model->alpha = event_model.alpha;
    // A given α comes with its OFF ratio (a calibrated model, --event_model=FILE.json).
    model->off_alpha_ratio = event_model.off_alpha_ratio;
    // The change an event stands for when α was derived from it (EstimateEventModel).
    model->change_per_event = options.estimation.alpha_times_change / event_model.alpha;
    model->description = "alpha " + std::to_string(event_model.alpha) + " (given)";
  }
  if (event_model.saturation <= 0.0) {
    event_model.saturation =
        model->estimated_from_frames ? options.estimation.measured_saturation : 1.0;
  }
  model->saturation = event_model.saturation;
  if (event_model.saturation != 1.0) {
    std::ostringstream saturation;
    saturation << ", saturation " << event_model.saturation;
    model->description += saturation.str();
  }
  return objective;
}

// One Levenberg–Marquardt solve of `solve_options`' objective from result->video, which it
// updates; adds its times and iterations to result->summary and sets the rest from this solve.
// Returns whether `callback` stopped the solve.
bool BuildAndSolve(const Scene& scene, const ReconstructionOptions& solve_options,
                   const IterationCallback& callback, Reconstruction* result) {
  ReconstructionSummary& summary = result->summary;
  const int threads = std::max(1, solve_options.solver.num_threads);
  const auto build_start = Clock::now();
  const ProblemBuilder builder(scene, solve_options);
  const int64_t max_bytes = solve_options.max_problem_mb > 0
                                ? solve_options.max_problem_mb * (int64_t{1} << 20)
                                : int64_t{-1};
  const ProblemPlan plan = builder.Plan(&result->video, max_bytes);
  summary.build_time_s += SecondsSince(build_start);
  summary.problem = ProblemStatistics();
  summary.problem.parts = 0;
  summary.problem.batches = static_cast<int64_t>(plan.batches().size());
  summary.problem.estimated_bytes = plan.estimated_bytes();
  summary.problem.skipped_pixels = static_cast<int64_t>(scene.height) * scene.width;

  std::unique_ptr<CallbackAdapter> adapter;
  if (callback)
    adapter = std::make_unique<CallbackAdapter>(callback, plan.layout(), &result->video);
  double done_cost = 0.0;  // final cost of the batches solved so far
  int iterations = 0;      // of the unit that took most
  bool first_unit = true;
  bool any_unknowns = false;
  const StopCondition& stop = solve_options.stop;
  StopCallback stop_callback(stop);
  for (const std::vector<ProblemUnit>& batch : plan.batches()) {
    if (adapter && adapter->stopped()) break;
    if (stop.Reached()) break;  // the batches not reached keep their start
    const auto batch_build_start = Clock::now();
    std::vector<std::unique_ptr<BuiltProblem>> parts(batch.size());
    ParallelForEach(static_cast<int>(batch.size()), threads,
                    [&](int i) { parts[i] = builder.BuildUnit(plan, batch[i], &result->video); });
    summary.build_time_s += SecondsSince(batch_build_start);
    for (const auto& part : parts) {
      summary.problem += part->statistics();
      any_unknowns = any_unknowns || part->statistics().variable_parameter_blocks > 0;
    }

    std::vector<ceres::Solver::Summary> part_summaries(parts.size());
    const auto solve_start = Clock::now();
    // Ceres stops when an iteration changes the cost by less than function_tolerance times the
    // cost. A part is held to the same absolute change as its whole batch would be: its
    // tolerance is scaled by the batch's initial cost over its own, so that a small region
    // stops once its progress no longer matters to the objective instead of iterating on its
    // own noise.
    std::vector<double> costs(parts.size(), 0.0);
    if (parts.size() > 1 || (adapter && plan.batches().size() > 1)) {
      ParallelForEach(static_cast<int>(parts.size()), threads,
                      [&](int i) { costs[i] = InitialCost(&parts[i]->problem()); });
    }
    double batch_cost = 0.0;
    for (const double cost : costs) batch_cost += cost;
    const auto part_options = [&](size_t i, int part_threads) {
      ceres::Solver::Options part = solve_options.solver;
      part.num_threads = part_threads;
      if (part.preconditioner_type == ceres::SUBSET) {
        part.residual_blocks_for_subset_preconditioner = parts[i]->temporal_residuals();
      }
      if (stop.active()) {
        part.max_solver_time_in_seconds =
            std::min(part.max_solver_time_in_seconds, stop.SecondsLeft());
        part.callbacks.push_back(&stop_callback);
      }
      if (parts.size() > 1 && costs[i] > 0.0) part.function_tolerance *= batch_cost / costs[i];
      return part;
    };
    double time_in_callback_s = 0.0;
    if (adapter) {
      // One after another, each with every thread, so that the callback sees a whole video.
      // It reports the batches solved so far at their final cost, this one's parts not yet
      // solved at their initial one; batches to come are not built yet and not counted.
      const double callback_time_before = adapter->time_in_callback_s();
      double current_total = done_cost + batch_cost;
      for (size_t i = 0; i < parts.size() && !adapter->stopped(); ++i) {
        adapter->StartPart(current_total - costs[i], first_unit);
        first_unit = false;
        ceres::Solver::Options options_i = part_options(i, threads);
        options_i.callbacks.push_back(adapter.get());
        options_i.update_state_every_iteration = true;
        ceres::Solve(options_i, &parts[i]->problem(), &part_summaries[i]);
        current_total += part_summaries[i].final_cost - costs[i];
        costs[i] = part_summaries[i].final_cost;
      }
      time_in_callback_s = adapter->time_in_callback_s() - callback_time_before;
      // Parts left when the callback stopped the solve stay at their start.
      for (size_t i = 0; i < parts.size(); ++i) {
        if (!part_summaries[i].iterations.empty()) continue;
        part_summaries[i].termination_type = ceres::USER_SUCCESS;
        part_summaries[i].initial_cost = part_summaries[i].final_cost = costs[i];
      }
    } else {
      // Largest first, each worker taking the next part as it becomes free. Each part gets
      // Ceres threads in proportion to its share of the batch's residual blocks: a part that
      // holds nearly all of them (slider_depth: 98 %) would otherwise run on one thread while
      // the other workers, done with the small parts, sit idle.
      const int workers = std::min<int>(threads, static_cast<int>(parts.size()));
      int64_t batch_blocks = 0;
      for (const auto& part : parts) batch_blocks += part->statistics().residual_blocks();
      const auto part_threads = [&](int i) {
        const double share =
            batch_blocks > 0
                ? static_cast<double>(parts[i]->statistics().residual_blocks()) / batch_blocks
                : 0.0;
        return std::clamp(static_cast<int>(std::lround(share * threads)), 1, threads);
      };
      std::vector<char> skipped(parts.size(), 0);
      ParallelForEach(static_cast<int>(parts.size()), workers, [&](int i) {
        if (stop.Reached()) {
          skipped[i] = 1;  // left at its start, below
          return;
        }
        ceres::Solve(part_options(i, part_threads(i)), &parts[i]->problem(), &part_summaries[i]);
      });
      for (size_t i = 0; i < parts.size(); ++i) {
        if (!skipped[i]) continue;
        const double cost = InitialCost(&parts[i]->problem());
        part_summaries[i].termination_type = ceres::USER_SUCCESS;
        part_summaries[i].message = "not solved: stopped early";
        part_summaries[i].initial_cost = part_summaries[i].final_cost = cost;
      }
    }
    summary.solve_time_s += SecondsSince(solve_start) - time_in_callback_s;
    for (size_t i = 0; i < parts.size(); ++i) {
      Accumulate(part_summaries[i], &batch == &plan.batches().front() && i == 0, &summary.ceres);
      for (const ceres::IterationSummary& step : part_summaries[i].iterations) {
        summary.linear_solver_iterations += step.linear_solver_iterations;
      }
      done_cost += part_summaries[i].final_cost;
      iterations = std::max(iterations, static_cast<int>(part_summaries[i].iterations.size()) - 1);
    }
  }
  if (stop.Reached()) summary.stopped_early = stop.Reason();
  if (!summary.stopped_early.empty() && summary.ceres.iterations.empty() &&
      summary.ceres.termination_type != ceres::FAILURE) {
    // Stopped before any part was solved: nothing failed.
    summary.ceres.termination_type = ceres::USER_SUCCESS;
    summary.ceres.message = std::string("stopped early: ") + summary.stopped_early;
  }
  // Bands overlap: a pixel is counted once.
  summary.problem.active_pixels = plan.active_pixels();
  summary.problem.skipped_pixels -= summary.problem.active_pixels;
  if (!any_unknowns) {
    summary.skipped_reason = summary.stopped_early.empty()
                                 ? "no unknowns: no pixel is active"
                                 : "stopped early before the solve: " + summary.stopped_early;
    return adapter && adapter->stopped();
  }
  summary.iterations += iterations;
  if (summary.ceres.termination_type == ceres::FAILURE) {
    throw SolverError("the solver failed: " + summary.ceres.message);
  }
  summary.solved = true;
  summary.initial_cost = summary.ceres.initial_cost;
  summary.final_cost = summary.ceres.final_cost;
  plan.layout().Expand(&result->video);
  summary.ramped_steps =
      RampSteps(scene, plan.layout(), solve_options.step_ramp_px, &result->video);
  return adapter && adapter->stopped();
}

Reconstruction Reconstruct(const Scene& scene, const ReconstructionOptions& options,
                           const Video* initial, const IterationCallback& callback) {
  return Reconstruct(scene, options, initial != nullptr ? *initial : InitializeLatentVideo(scene),
                     callback);
}

Reconstruction Reconstruct(const Scene& scene, const ReconstructionOptions& options, Video initial,
                           const IterationCallback& callback) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("invalid options: " + error);
  Reconstruction result;
  ReconstructionOptions solve_options = options;
  solve_options.objective =
      ResolveObjective(scene, options, &result.summary.model, &result.summary.alpha_derived);

  if (initial.num_frames() != scene.num_latent_frames() || initial.height() != scene.height ||
      initial.width() != scene.width) {
    throw InvalidArgumentError("the initial video does not match the scene's latent timeline");
  }
  result.video = std::move(initial);
  ReconstructionSummary& summary = result.summary;
  if (scene.num_events == 0) {
    summary.skipped_reason = "no events in the window: the initialisation is the answer";
    return result;
  }

  // Continuation: each smoothing scale's solution starts the next, the objective's own last.
  std::vector<double> scales = options.smoothing_continuation;
  scales.push_back(solve_options.objective.smoothing_scale);
  for (size_t i = 0; i < scales.size(); ++i) {
    ReconstructionOptions stage = solve_options;
    stage.objective.smoothing_scale = scales[i];
    // Steps are ramped once, on the answer; with a prior (plug & play's x-update) the solve's
    // answer is the minimiser it asked for.
    if (i + 1 < scales.size() || options.objective.prior_weight != 0.0) stage.step_ramp_px = 0.0;
    const bool stopped = BuildAndSolve(scene, stage, callback, &result);
    // A callback or a stop condition that ends the solve ends it whole: no later scale is built.
    if (stopped || !summary.solved || !summary.stopped_early.empty()) break;
  }
  // With a prior (plug & play's x-update) the solve's answer is the minimiser it asked for.
  if (options.quiet_blend_fraction > 0.0 && options.objective.prior_weight == 0.0 &&
      summary.solved) {
    BlendQuietPixels(scene, solve_options.objective.event_model,
                     options.quiet_blend_fraction * summary.model.change_per_event, &result.video);
  }
  return result;
}

}  // namespace evfs
