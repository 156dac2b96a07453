#include "evfs/solver/first_order_solvers.h"

#include <ceres/first_order_function.h>
#include <ceres/gradient_problem.h>
#include <ceres/iteration_callback.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/core/time.h"
#include "evfs/solver/stop_callback.h"

namespace evfs {
namespace {

using Clock = std::chrono::steady_clock;

// Solve time and the callback: measures the time since the solve started without the time
// spent in the callback, and skips everything when there is no callback.
class CallbackClock {
 public:
  explicit CallbackClock(const IterationCallback& callback)
      : callback_(callback), start_(Clock::now()) {}

  bool has_callback() const { return static_cast<bool>(callback_); }
  double elapsed_s() const { return SecondsSince(start_) - callback_s_; }

  /// Calls the callback (if any) at iteration `iteration`; false when it asks to stop.
  bool Report(int iteration, double cost, const Video& latent) {
    if (!callback_) return true;
    const Clock::time_point called = Clock::now();
    SolverIteration state;
    state.iteration = iteration;
    state.cost = cost;
    state.elapsed_s = SecondsSince(start_) - callback_s_;
    state.latent = &latent;
    const bool go_on = callback_(state);
    callback_s_ += SecondsSince(called);
    return go_on;
  }

 private:
  const IterationCallback& callback_;
  const Clock::time_point start_;
  double callback_s_ = 0.0;
};

// Checks a solver's options and the latent video, then builds the objective it descends.
template <typename SolverOptions>
std::unique_ptr<FusedObjective> PrepareObjective(const std::string& solver,
                                                 const SolverOptions& options, L1Penalty penalty,
                                                 const Scene& scene,
                                                 const ObjectiveOptions& objective,
                                                 const ActivityMask& mask, const Video& latent) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError(solver + ": " + error);
  if (latent.height() != scene.height || latent.width() != scene.width ||
      latent.num_frames() != scene.num_latent_frames()) {
    throw InvalidArgumentError(solver + ": the latent video does not match the scene's size");
  }
  FusedObjectiveOptions fused_options;
  fused_options.penalty = penalty;
  fused_options.num_threads = options.num_threads;
  return std::make_unique<FusedObjective>(scene, objective, mask, fused_options);
}

// The objective over the active voxels only (GatherActive's layout) for Ceres' line search.
// Ring and inactive voxels stay at their values in `fixed`.
class ActiveVoxelFunction : public ceres::FirstOrderFunction {
 public:
  ActiveVoxelFunction(const FusedObjective& objective, const Video& fixed, int* evaluations)
      : objective_(objective),
        all_active_(objective.num_active_pixels() == objective.pixels_per_frame()),
        evaluations_(evaluations) {
    if (!all_active_) {
      point_ = fixed;
      gradient_ = Video(fixed.height(), fixed.width(), fixed.num_frames());
    }
  }

  bool Evaluate(const double* parameters, double* cost, double* gradient) const override {
    ++*evaluations_;
    // With every pixel active both layouts coincide and nothing is copied.
    if (all_active_) {
      *cost = objective_.Evaluate(parameters, gradient);
    } else {
      objective_.ScatterActive(parameters, point_.data());
      *cost = objective_.Evaluate(point_.data(), gradient == nullptr ? nullptr : gradient_.data());
      if (gradient != nullptr) objective_.GatherActive(gradient_.data(), gradient);
    }
    return std::isfinite(*cost);
  }

  int NumParameters() const override { return static_cast<int>(objective_.num_active_voxels()); }

 private:
  const FusedObjective& objective_;
  const bool all_active_;
  mutable Video point_;
  mutable Video gradient_;
  int* evaluations_;
};

// Hands Ceres' iterations to an evfs IterationCallback, with the current point scattered into the
// caller's latent video (Ceres updates `parameters` before each callback when
// update_state_every_iteration is set).
class LbfgsCallback : public ceres::IterationCallback {
 public:
  LbfgsCallback(const FusedObjective& objective, const std::vector<double>& parameters,
                Video* latent, CallbackClock* clock)
      : objective_(objective), parameters_(parameters), latent_(latent), clock_(clock) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    objective_.ScatterActive(parameters_.data(), latent_->data());
    return clock_->Report(summary.iteration, summary.cost, *latent_)
               ? ceres::SOLVER_CONTINUE
               : ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }

 private:
  const FusedObjective& objective_;
  const std::vector<double>& parameters_;
  Video* latent_;
  CallbackClock* clock_;
};

}  // namespace

bool AdamOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.Require(max_iterations >= 0, "max_iterations", ">= 0")
      .Require(std::isfinite(learning_rate) && learning_rate > 0.0, "learning_rate", "positive")
      .Require(decay_every >= 1, "decay_every", "at least 1")
      .Require(decay_factor > 0.0 && decay_factor <= 1.0, "decay_factor", "in (0, 1]")
      .Require(beta1 >= 0.0 && beta1 < 1.0 && beta2 >= 0.0 && beta2 < 1.0, "beta1 and beta2",
               "in [0, 1)")
      .Require(std::isfinite(epsilon) && epsilon > 0.0, "epsilon", "positive")
      .Require(num_threads >= 1, "num_threads", "at least 1");
  return check.Passed(error);
}

double AdamOptions::LearningRate(int iteration) const {
  return learning_rate * std::pow(decay_factor, iteration / decay_every);
}

ceres::GradientProblemSolver::Options DefaultLbfgsSolverOptions() {
  ceres::GradientProblemSolver::Options options;
  options.line_search_direction_type = ceres::LBFGS;
  options.max_lbfgs_rank = 20;
  options.max_num_iterations = 500;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  return options;
}

LbfgsOptions::LbfgsOptions() : solver(DefaultLbfgsSolverOptions()) {}

bool LbfgsOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.Require(num_threads >= 1, "num_threads", "at least 1")
      .Check(solver.line_search_direction_type != ceres::BFGS,
             "dense BFGS needs n² memory for n unknowns: use LBFGS")
      .Valid(solver);
  return check.Passed(error);
}

FirstOrderSummary SolveWithAdam(const Scene& scene, const ObjectiveOptions& objective_options,
                                const ActivityMask& mask, const AdamOptions& options, Video* latent,
                                const IterationCallback& callback, const StopCondition& stop) {
  const Clock::time_point setup_start = Clock::now();
  const std::unique_ptr<FusedObjective> fused =
      PrepareObjective("adam", options, options.penalty, scene, objective_options, mask, *latent);
  const FusedObjective& objective = *fused;

  FirstOrderSummary summary;
  summary.setup_time_s = SecondsSince(setup_start);
  summary.solver = options.penalty == L1Penalty::kTrueL1 ? "adam" : "adam_smooth";
  summary.active_voxels = objective.num_active_voxels();
  CallbackClock clock(callback);
  const int64_t num_active = objective.num_active_pixels();
  // Moment estimates per active voxel, in GatherActive's layout.
  std::vector<double> first_moment(summary.active_voxels, 0.0);
  std::vector<double> second_moment(summary.active_voxels, 0.0);
  // Two iterates, read from one and written to the other: the callback sees the point whose
  // cost it is given, and the fused step never reads a voxel it has already moved.
  Video other = *latent;
  Video* current = latent;
  Video* next = &other;
  double step_size = 0.0, second_correction_root = 1.0;
  const double beta1 = options.beta1, beta2 = options.beta2, epsilon = options.epsilon;
  const bool bounded = options.bound_intensities;
  constexpr double kUnbounded = std::numeric_limits<double>::infinity();
  const FusedObjective::StepFunction step =
      [&](int t, const PixelRun& run, const double* __restrict g, const double* __restrict x,
          double* __restrict x_next) {
        const int64_t length = run.end - run.begin;
        double* __restrict m = first_moment.data() + t * num_active + run.offset;
        double* __restrict v = second_moment.data() + t * num_active + run.offset;
        // Locals, so that the stores below need not reload them.
        const double rate = step_size, correction_root = second_correction_root;
        const double low = bounded ? 0.0 : -kUnbounded, high = bounded ? 1.0 : kUnbounded;
        for (int64_t i = 0; i < length; ++i) {
          m[i] = beta1 * m[i] + (1.0 - beta1) * g[i];
          v[i] = beta2 * v[i] + (1.0 - beta2) * g[i] * g[i];
          const double value = x[i] - rate * m[i] / (std::sqrt(v[i]) / correction_root + epsilon);
          x_next[i] = std::min(std::max(value, low), high);
        }
      };
  for (int iteration = 0;; ++iteration) {
    const bool last = iteration == options.max_iterations || summary.active_voxels == 0;
    double cost = 0.0;
    if (last) {
      cost = objective.Evaluate(current->data(), nullptr);
    } else {
      const int adam_step = iteration + 1;
      step_size = options.LearningRate(iteration) / (1.0 - std::pow(beta1, adam_step));
      second_correction_root = std::sqrt(1.0 - std::pow(beta2, adam_step));
      cost = objective.EvaluateAndStep(current->data(), next->data(), step);
    }
    ++summary.evaluations;
    if (iteration == 0) summary.initial_cost = cost;
    summary.final_cost = cost;
    summary.iterations = iteration;
    if (!std::isfinite(cost)) {
      summary.termination = "the cost is not finite at iteration " + std::to_string(iteration);
      break;
    }
    if (!clock.Report(iteration, cost, *current)) {
      summary.termination = "stopped by the callback at iteration " + std::to_string(iteration);
      break;
    }
    if (summary.active_voxels == 0) {
      summary.termination = "no active pixels: nothing to solve";
      break;
    }
    if (!last && stop.Reached()) {
      summary.termination = std::string("stopped early (") + stop.Reason() + ") after " +
                            std::to_string(iteration) + " of " +
                            std::to_string(options.max_iterations) + " iterations";
      summary.stopped_early = stop.Reason();
      break;
    }
    if (last) {
      summary.termination = "reached " + std::to_string(iteration) + " iterations";
      // The schedule returns its last iterate, as the paper does; say so when that is worse.
      if (cost > summary.initial_cost) summary.termination += ", with a higher cost than the start";
      break;
    }
    std::swap(current, next);
  }
  if (current != latent) *latent = *current;
  summary.solve_time_s = clock.elapsed_s();
  return summary;
}

FirstOrderSummary SolveWithLbfgs(const Scene& scene, const ObjectiveOptions& objective_options,
                                 const ActivityMask& mask, const LbfgsOptions& options,
                                 Video* latent, const IterationCallback& callback,
                                 const StopCondition& stop) {
  const Clock::time_point setup_start = Clock::now();
  const std::unique_ptr<FusedObjective> fused = PrepareObjective(
      "lbfgs", options, L1Penalty::kSmoothed, scene, objective_options, mask, *latent);
  const FusedObjective& objective = *fused;

  FirstOrderSummary summary;
  summary.setup_time_s = SecondsSince(setup_start);
  summary.solver = "lbfgs";
  summary.active_voxels = objective.num_active_voxels();
  CallbackClock clock(callback);
  if (summary.active_voxels == 0) {
    summary.initial_cost = summary.final_cost = objective.Evaluate(latent->data(), nullptr);
    summary.evaluations = 1;
    clock.Report(0, summary.initial_cost, *latent);
    summary.termination = "no active pixels: nothing to solve";
    summary.solve_time_s = clock.elapsed_s();
    return summary;
  }

  std::vector<double> parameters(summary.active_voxels);
  objective.GatherActive(latent->data(), parameters.data());
  ceres::GradientProblem problem(new ActiveVoxelFunction(objective, *latent, &summary.evaluations));
  ceres::GradientProblemSolver::Options solver_options = options.solver;
  LbfgsCallback iteration_callback(objective, parameters, latent, &clock);
  if (clock.has_callback()) {
    solver_options.update_state_every_iteration = true;
    solver_options.callbacks.push_back(&iteration_callback);
  }
  StopCallback stop_callback(stop);
  if (stop.active()) {
    solver_options.max_solver_time_in_seconds =
        std::min(solver_options.max_solver_time_in_seconds, stop.SecondsLeft());
    solver_options.callbacks.push_back(&stop_callback);
  }
  ceres::GradientProblemSolver::Summary ceres_summary;
  ceres::Solve(solver_options, problem, parameters.data(), &ceres_summary);
  objective.ScatterActive(parameters.data(), latent->data());

  summary.iterations = std::max(0, static_cast<int>(ceres_summary.iterations.size()) - 1);
  summary.initial_cost = ceres_summary.initial_cost;
  summary.final_cost = ceres_summary.final_cost;
  summary.termination = ceres::TerminationTypeToString(ceres_summary.termination_type) +
                        std::string(": ") + ceres_summary.message;
  if (stop.Reached()) {
    summary.stopped_early = stop.Reason();
    summary.termination = std::string("stopped early (") + stop.Reason() + ") after " +
                          std::to_string(summary.iterations) + " iterations";
  }
  summary.solve_time_s = clock.elapsed_s();
  return summary;
}

}  // namespace evfs
