// What one evaluation of the objective costs, from the single residual to the whole video.
//
//  * BM_CostFunction/<functor>/<autodiff|analytic>: CostFunction::Evaluate (residual and
//    Jacobians) of each residual family with Ceres' automatic differentiation against a
//    hand-written derivative of the same residual (cost_functions/*Analytic, or written here).
//  * BM_FusedObjective/threads:N/penalty:P: FusedObjective::Evaluate (cost and gradient) over a
//    240×180×21 latent video, every pixel active (P = 0 smoothed, 1 true ℓ1).
//  * BM_ProblemEvaluate/threads:N: ceres::Problem::Evaluate (cost and gradient) of the problem
//    ProblemBuilder builds for the same scene, one parameter block per voxel.
//  * BM_AdamStep/threads:N: SolveWithAdam per step (evaluation and update).
//
// Rerun with:
//   build/benchmarks/cost_function_benchmark --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <glog/logging.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "evfs/cost_functions/difference_residual.h"
#include "evfs/cost_functions/event_residual.h"
#include "evfs/cost_functions/frame_residual.h"
#include "evfs/cost_functions/spatial_tv_residual.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/scene/event_model.h"
#include "evfs/solver/first_order_solvers.h"
#include "evfs/solver/fused_objective.h"
#include "evfs/solver/problem_builder.h"

namespace evfs {
namespace {

// The event model of the micro-benchmarks: the paper's linear model, α in its range.
EventModelParams BenchmarkEventModel() {
  EventModelParams params;
  params.alpha = 8.0;
  return params;
}

// r = H_after − H_before (DifferenceResidual): ∂r/∂H_before = −1, ∂r/∂H_after = 1.
class DifferenceAnalytic : public ceres::SizedCostFunction<1, 1, 1> {
 public:
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = parameters[1][0] - parameters[0][0];
    if (jacobians == nullptr) return true;
    if (jacobians[0] != nullptr) jacobians[0][0] = -1.0;
    if (jacobians[1] != nullptr) jacobians[1][0] = 1.0;
    return true;
  }
};

// r = (H_right − H_center) + (H_below − H_center) (PaperTvResidual): ∂r/∂H = (−2, 1, 1).
class PaperTvAnalytic : public ceres::SizedCostFunction<1, 1, 1, 1> {
 public:
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = (parameters[1][0] - parameters[0][0]) + (parameters[2][0] - parameters[0][0]);
    if (jacobians == nullptr) return true;
    const double slopes[] = {-2.0, 1.0, 1.0};
    for (int i = 0; i < 3; ++i) {
      if (jacobians[i] != nullptr) jacobians[i][0] = slopes[i];
    }
    return true;
  }
};

// r = (H_right − H_center, H_below − H_center) (IsotropicTvResidual); each block's Jacobian is
// a column of [[−1, 1, 0], [−1, 0, 1]].
class IsotropicTvAnalytic : public ceres::SizedCostFunction<2, 1, 1, 1> {
 public:
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    residuals[0] = parameters[1][0] - parameters[0][0];
    residuals[1] = parameters[2][0] - parameters[0][0];
    if (jacobians == nullptr) return true;
    const double columns[3][2] = {{-1.0, -1.0}, {1.0, 0.0}, {0.0, 1.0}};
    for (int i = 0; i < 3; ++i) {
      if (jacobians[i] == nullptr) continue;
      jacobians[i][0] = columns[i][0];
      jacobians[i][1] = columns[i][1];
    }
    return true;
  }
};

// EventResidual over several steps with hand-written Jacobians: with
// u_s = tanh(α (g(H_{s+1}) − g(H_s)) / c), ∂r/∂H_s gets +α (1 − u_s²) g'(H_s) from step s and
// −α (1 − u_{s−1}²) g'(H_s) from step s − 1.
class MultiStepEventAnalytic : public ceres::CostFunction {
 public:
  MultiStepEventAnalytic(double event_value, int num_steps, const EventModelParams& params)
      : event_value_(event_value),
        num_steps_(num_steps),
        params_(params),
        saturation_(SaturationForCount(event_value, num_steps)) {
    set_num_residuals(1);
    mutable_parameter_block_sizes()->assign(num_steps + 1, 1);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (jacobians != nullptr) {
      for (int s = 0; s <= num_steps_; ++s) {
        if (jacobians[s] != nullptr) jacobians[s][0] = 0.0;
      }
    }
    double predicted_event = 0.0;
    for (int s = 0; s < num_steps_; ++s) {
      const double intensity_before = parameters[s][0], intensity_after = parameters[s + 1][0];
      const double step_event =
          PredictedEvent(intensity_before, intensity_after, params_, saturation_);
      predicted_event += step_event;
      if (jacobians == nullptr) continue;
      const double u = step_event / saturation_;
      const double slope = params_.alpha * (1.0 - u * u);
      if (jacobians[s] != nullptr) {
        jacobians[s][0] += slope * IntensityTransformDerivative(intensity_before, params_);
      }
      if (jacobians[s + 1] != nullptr) {
        jacobians[s + 1][0] -= slope * IntensityTransformDerivative(intensity_after, params_);
      }
    }
    residuals[0] = event_value_ - predicted_event;
    return true;
  }

 private:
  const double event_value_;
  const int num_steps_;
  const EventModelParams params_;
  const double saturation_;
};

// Random points of each cost function's parameter blocks (intensities in [0, 1]), cycled
// through so that the evaluation cannot be folded into a constant.
constexpr int kNumPoints = 64;

// Parameters, residuals and Jacobians of one evaluation of a cost function with scalar blocks.
struct EvaluationBuffers {
  std::vector<std::vector<double>> points;  // kNumPoints × blocks
  std::vector<const double*> parameters;
  std::vector<double> residuals;
  std::vector<double> jacobian_values;
  std::vector<double*> jacobians;

  explicit EvaluationBuffers(const ceres::CostFunction& cost) {
    const int blocks = static_cast<int>(cost.parameter_block_sizes().size());
    std::mt19937 random(5);
    std::uniform_real_distribution<double> intensity(0.0, 1.0);
    points.assign(kNumPoints, std::vector<double>(blocks));
    for (auto& point : points) {
      for (double& value : point) value = intensity(random);
    }
    parameters.resize(blocks);
    residuals.resize(cost.num_residuals());
    jacobian_values.resize(static_cast<size_t>(blocks) * cost.num_residuals());
    for (int i = 0; i < blocks; ++i) {
      jacobians.push_back(jacobian_values.data() + static_cast<size_t>(i) * cost.num_residuals());
    }
  }

  void Evaluate(const ceres::CostFunction& cost, int point) {
    for (size_t i = 0; i < parameters.size(); ++i) parameters[i] = &points[point][i];
    CHECK(cost.Evaluate(parameters.data(), residuals.data(), jacobians.data()));
  }
};

// A residual family with its autodiff cost function and the hand-written one.
struct CostFunctionPair {
  std::string name;
  std::shared_ptr<ceres::CostFunction> autodiff;
  std::shared_ptr<ceres::CostFunction> analytic;
};

std::vector<CostFunctionPair> CostFunctionPairs() {
  const EventModelParams model = BenchmarkEventModel();
  constexpr int kSteps = 3;  // a stacked event frame spanning three latent steps
  return {
      {"frame", std::shared_ptr<ceres::CostFunction>(FrameResidual::Create(0.4, 1)),
       std::make_shared<FrameResidualAnalytic>(0.4)},
      {"event_one_step", std::shared_ptr<ceres::CostFunction>(EventResidual::Create(1.0, 1, model)),
       std::make_shared<EventResidualAnalytic>(1.0, model)},
      {"event_three_steps",
       std::shared_ptr<ceres::CostFunction>(EventResidual::Create(5.0, kSteps, model)),
       std::make_shared<MultiStepEventAnalytic>(5.0, kSteps, model)},
      // Anisotropic spatial TV and temporal TV are both this difference.
      {"difference_anisotropic_tv_temporal_tv",
       std::shared_ptr<ceres::CostFunction>(DifferenceResidual::Create()),
       std::make_shared<DifferenceAnalytic>()},
      {"paper_tv", std::shared_ptr<ceres::CostFunction>(PaperTvResidual::Create()),
       std::make_shared<PaperTvAnalytic>()},
      {"isotropic_tv", std::shared_ptr<ceres::CostFunction>(IsotropicTvResidual::Create()),
       std::make_shared<IsotropicTvAnalytic>()},
  };
}

// The hand-written derivative must be the autodiff one, or the comparison means nothing.
void CheckSameDerivatives(const CostFunctionPair& pair) {
  // Both evaluate the same expressions in double; autodiff's tanh derivative is 1 − tanh².
  constexpr double kTolerance = 1e-12;
  EvaluationBuffers autodiff(*pair.autodiff), analytic(*pair.analytic);
  for (int point = 0; point < kNumPoints; ++point) {
    autodiff.Evaluate(*pair.autodiff, point);
    analytic.Evaluate(*pair.analytic, point);
    for (size_t i = 0; i < autodiff.residuals.size(); ++i) {
      CHECK_LE(std::abs(autodiff.residuals[i] - analytic.residuals[i]), kTolerance) << pair.name;
    }
    for (size_t i = 0; i < autodiff.jacobian_values.size(); ++i) {
      CHECK_LE(std::abs(autodiff.jacobian_values[i] - analytic.jacobian_values[i]), kTolerance)
          << pair.name;
    }
  }
}

void BM_CostFunction(benchmark::State& state, std::shared_ptr<ceres::CostFunction> cost) {
  EvaluationBuffers buffers(*cost);
  int point = 0;
  for (auto _ : state) {
    buffers.Evaluate(*cost, point);
    benchmark::DoNotOptimize(buffers.residuals.data());
    benchmark::DoNotOptimize(buffers.jacobian_values.data());
    benchmark::ClobberMemory();
    point = (point + 1) % kNumPoints;
  }
}

// The prototype's full-size case (../shared/notes/solver-measurements.md): 240×180, 20
// collision steps (21 latent frames), sharp frames at both ends, every pixel active, the
// paper's TV. Values are random: an evaluation's cost does not depend on them.
constexpr int kWidth = 240;
constexpr int kHeight = 180;
constexpr int kNumLatent = 21;

struct FullScene {
  Scene scene;
  ObjectiveOptions objective;
  Video latent;

  FullScene() {
    std::mt19937 random(9);
    std::uniform_real_distribution<double> intensity(0.0, 1.0);
    std::uniform_int_distribution<int> event_value(-1, 1);
    scene.height = kHeight;
    scene.width = kWidth;
    scene.events = EventFrames(kHeight, kWidth);
    std::vector<int64_t> latent_ns;
    for (int t = 0; t < kNumLatent; ++t) latent_ns.push_back(1000000 * t);
    scene.events.set_latent_timestamps_ns(latent_ns);
    for (int k = 0; k + 1 < kNumLatent; ++k) {
      scene.events.AddFrame({k, k + 1, latent_ns[k], latent_ns[k + 1], 0});
      float* values = scene.events.frame_data(k);
      for (int64_t p = 0; p < scene.events.pixels_per_frame(); ++p) {
        values[p] = static_cast<float>(event_value(random));
        scene.num_events += values[p] != 0.0f;
      }
    }
    for (const int t : {0, kNumLatent - 1}) {
      FrameObservation frame;
      frame.image = Image(kHeight, kWidth);
      for (int64_t p = 0; p < frame.image.size(); ++p) frame.image.data()[p] = intensity(random);
      frame.latent_first = frame.latent_last = t;
      scene.frames.push_back(frame);
    }
    objective.event_model.alpha = 8.0;
    objective.spatial_tv = SpatialTv::kPaper;
    latent = InitializeLatentVideo(scene);
  }
};

const FullScene& SharedFullScene() {
  static const FullScene full;
  return full;
}

void SetVoxelRate(benchmark::State& state, int64_t voxels) {
  state.counters["voxels_per_s"] = benchmark::Counter(
      static_cast<double>(voxels), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_FusedObjective(benchmark::State& state) {
  const FullScene& full = SharedFullScene();
  const ActivityMask mask(full.scene.events, -1);
  FusedObjectiveOptions options;
  options.num_threads = static_cast<int>(state.range(0));
  options.penalty = state.range(1) == 0 ? L1Penalty::kSmoothed : L1Penalty::kTrueL1;
  const FusedObjective objective(full.scene, full.objective, mask, options);
  std::vector<double> gradient(objective.num_voxels());
  for (auto _ : state) {
    benchmark::DoNotOptimize(objective.Evaluate(full.latent.data(), gradient.data()));
    benchmark::ClobberMemory();
  }
  SetVoxelRate(state, objective.num_voxels());
}
BENCHMARK(BM_FusedObjective)
    ->ArgNames({"threads", "penalty"})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_ProblemEvaluate(benchmark::State& state) {
  const FullScene& full = SharedFullScene();
  ReconstructionOptions options;
  options.objective = full.objective;
  options.activity_radius_px = -1;
  options.merge_quiet_steps = false;  // the per-voxel problem the fused pass evaluates
  Video latent = full.latent;
  const std::unique_ptr<BuiltProblem> built = ProblemBuilder(full.scene, options).Build(&latent);
  ceres::Problem::EvaluateOptions evaluate_options;
  evaluate_options.num_threads = static_cast<int>(state.range(0));
  std::vector<double> gradient;
  for (auto _ : state) {
    double cost = 0.0;
    CHECK(built->problem().Evaluate(evaluate_options, &cost, nullptr, &gradient, nullptr));
    benchmark::DoNotOptimize(cost);
  }
  state.counters["residual_blocks"] = static_cast<double>(built->statistics().residual_blocks());
  SetVoxelRate(state, latent.num_frames() * latent.pixels_per_frame());
}
BENCHMARK(BM_ProblemEvaluate)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

void BM_AdamStep(benchmark::State& state) {
  constexpr int kSteps = 20;
  const FullScene& full = SharedFullScene();
  const ActivityMask mask(full.scene.events, -1);
  AdamOptions options;
  options.max_iterations = kSteps;
  options.num_threads = static_cast<int>(state.range(0));
  Video latent = full.latent;
  double solve_s = 0.0;
  for (auto _ : state) {
    latent = full.latent;
    solve_s += SolveWithAdam(full.scene, full.objective, mask, options, &latent).solve_time_s;
  }
  // Per step, from the solver's own clock: the objective's set-up is not a step; the cost at
  // the last point (one evaluation without gradient per kSteps steps) is.
  state.counters["ms_per_step"] =
      benchmark::Counter(1e3 * solve_s / kSteps, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_AdamStep)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  for (const evfs::CostFunctionPair& pair : evfs::CostFunctionPairs()) {
    evfs::CheckSameDerivatives(pair);
    benchmark::RegisterBenchmark(("BM_CostFunction/" + pair.name + "/autodiff").c_str(),
                                 evfs::BM_CostFunction, pair.autodiff);
    benchmark::RegisterBenchmark(("BM_CostFunction/" + pair.name + "/analytic").c_str(),
                                 evfs::BM_CostFunction, pair.analytic);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
