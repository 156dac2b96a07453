#include "evfs/solver/first_order_solvers.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/scene/event_model_estimation.h"
#include "evfs/solver/problem_builder.h"
#include "evfs/tests/scene/scene_test_scenes.h"

namespace evfs {
namespace {

// Every voxel of a video, as one array.
Eigen::Map<const Eigen::ArrayXd> VoxelValues(const Video& video) {
  return Eigen::Map<const Eigen::ArrayXd>(video.data(),
                                          int64_t{video.num_frames()} * video.pixels_per_frame());
}

// Quality bars on the 48×40 synthetic interpolation scene (frames 0 and 20, truth frame 10):
// about 1 dB below the gain over the blend that each solver reached when they were set (printed
// by the tests: +1.8 dB for Adam on the true ℓ1, +4.8 dB on the smoothed ℓ1, +4.3 dB for L-BFGS),
// so that they catch a solver that stops moving towards the truth, not noise.
constexpr double kMinAdamGainDb = 1.0;
constexpr double kMinAdamSmoothGainDb = 3.5;
constexpr double kMinLbfgsGainDb = 3.0;
// Few enough iterations to keep each test well under a second on two shared cores.
constexpr int kAdamIterations = 300;
constexpr int kLbfgsIterations = 60;
// One thread: these scenes take well under a millisecond per evaluation, less than a time slice
// of a loaded machine, where a descheduled second thread holds up every evaluation.
// fused_objective_test checks that thread counts agree.
constexpr int kThreads = 1;

// AdamOptions or LbfgsOptions with kThreads.
template <typename SolverOptions>
SolverOptions TestOptions() {
  SolverOptions options;
  options.num_threads = kThreads;
  return options;
}

// The interpolation scene with α derived from the data, as Reconstruct does, and its
// initialisation.
struct Problem {
  test::SyntheticRecording recording;
  Scene scene;
  ObjectiveOptions objective;
  Video initial;

  Problem() {
    scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20), recording.events,
                                   BinningOptions());
    objective.event_model.alpha =
        EstimateEventModel(scene, objective.event_model, EventModelEstimationOptions()).alpha;
    initial = InitializeLatentVideo(scene);
  }

  double PsnrAtTruth(const Video& video) const {
    constexpr int kTruth = 10;
    const int index = video.NearestFrame(recording.rendered.timestamp_ns(kTruth));
    return Psnr(video.frame(index), recording.rendered.frame(kTruth));
  }
};

const Problem& SharedProblem() {
  static const Problem problem;
  return problem;
}

// Voxels of pixels that are not active must keep their initial values.
void ExpectInactiveVoxelsUnchanged(const ActivityMask& mask, const Video& initial,
                                   const Video& solved) {
  int64_t checked = 0;
  for (int t = 0; t < initial.num_frames(); ++t) {
    for (int64_t p = 0; p < initial.pixels_per_frame(); ++p) {
      if (mask.active(p)) continue;
      ASSERT_EQ(solved.frame_data(t)[p], initial.frame_data(t)[p]) << "t " << t << " p " << p;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0) << "the scene should have pixels far from every event";
}

TEST(AdamOptions, LearningRateFollowsThePapersSchedule) {
  const AdamOptions options;
  EXPECT_DOUBLE_EQ(options.LearningRate(0), 0.002);
  EXPECT_DOUBLE_EQ(options.LearningRate(199), 0.002);
  EXPECT_DOUBLE_EQ(options.LearningRate(200), 0.002 / 5.0);
  EXPECT_DOUBLE_EQ(options.LearningRate(399), 0.002 / 5.0);
  EXPECT_DOUBLE_EQ(options.LearningRate(400), 0.002 / 25.0);
  EXPECT_EQ(options.max_iterations, 1000);
  EXPECT_EQ(options.beta1, 0.9);
  EXPECT_EQ(options.beta2, 0.99);
  EXPECT_EQ(options.penalty, L1Penalty::kTrueL1);
}

TEST(AdamOptions, RejectsInvalidSettings) {
  std::string error;
  EXPECT_TRUE(AdamOptions().IsValid(&error)) << error;
  const auto invalid = [](auto change) {
    AdamOptions options;
    change(&options);
    std::string reason;
    return !options.IsValid(&reason) && !reason.empty();
  };
  EXPECT_TRUE(invalid([](AdamOptions* o) { o->learning_rate = 0.0; }));
  EXPECT_TRUE(invalid([](AdamOptions* o) { o->decay_every = 0; }));
  EXPECT_TRUE(invalid([](AdamOptions* o) { o->decay_factor = 1.5; }));
  EXPECT_TRUE(invalid([](AdamOptions* o) { o->beta2 = 1.0; }));
  EXPECT_TRUE(invalid([](AdamOptions* o) { o->epsilon = 0.0; }));
  EXPECT_TRUE(invalid([](AdamOptions* o) { o->num_threads = 0; }));
  const Problem& problem = SharedProblem();
  const ActivityMask mask(problem.scene.events, 2);
  Video latent = problem.initial;
  AdamOptions options = TestOptions<AdamOptions>();
  options.max_iterations = -1;
  EXPECT_THROW(SolveWithAdam(problem.scene, problem.objective, mask, options, &latent),
               InvalidArgumentError);
  LbfgsOptions lbfgs = TestOptions<LbfgsOptions>();
  lbfgs.solver.line_search_direction_type = ceres::BFGS;
  EXPECT_FALSE(lbfgs.IsValid(&error));
  EXPECT_THROW(SolveWithLbfgs(problem.scene, problem.objective, mask, lbfgs, &latent),
               InvalidArgumentError);
}

class AdamTest : public ::testing::TestWithParam<L1Penalty> {};

TEST_P(AdamTest, LowersTheCostAndBeatsTheBlend) {
  const Problem& problem = SharedProblem();
  const ActivityMask mask(problem.scene.events, 2);
  AdamOptions options = TestOptions<AdamOptions>();
  options.penalty = GetParam();
  options.max_iterations = kAdamIterations;
  Video latent = problem.initial;
  const FirstOrderSummary summary =
      SolveWithAdam(problem.scene, problem.objective, mask, options, &latent);
  EXPECT_EQ(summary.solver, GetParam() == L1Penalty::kTrueL1 ? "adam" : "adam_smooth");
  EXPECT_EQ(summary.iterations, kAdamIterations);
  EXPECT_EQ(summary.evaluations, kAdamIterations + 1);
  EXPECT_EQ(summary.active_voxels, mask.num_active() * problem.scene.num_latent_frames());
  EXPECT_LT(summary.final_cost, summary.initial_cost);
  // The reported cost is the objective at the returned video.
  FusedObjectiveOptions fused_options;
  fused_options.penalty = GetParam();
  const double final_cost = FusedObjective(problem.scene, problem.objective, mask, fused_options)
                                .Evaluate(latent, nullptr);
  EXPECT_DOUBLE_EQ(summary.final_cost, final_cost);

  const double blend = problem.PsnrAtTruth(problem.initial);
  const double solved = problem.PsnrAtTruth(latent);
  std::printf("%s, %d iterations: blend %.2f dB, solved %.2f dB, cost %.4g -> %.4g, %.3f s\n",
              summary.solver.c_str(), summary.iterations, blend, solved, summary.initial_cost,
              summary.final_cost, summary.solve_time_s);
  EXPECT_GE(solved,
            blend + (GetParam() == L1Penalty::kTrueL1 ? kMinAdamGainDb : kMinAdamSmoothGainDb));
  ExpectInactiveVoxelsUnchanged(mask, problem.initial, latent);
}

INSTANTIATE_TEST_SUITE_P(BothPenalties, AdamTest,
                         ::testing::Values(L1Penalty::kTrueL1, L1Penalty::kSmoothed),
                         [](const ::testing::TestParamInfo<L1Penalty>& info) {
                           return std::string(L1PenaltyName(info.param));
                         });

TEST(Adam, ClipsToTheUnitIntervalWhenBounded) {
  // A learning rate 150× the paper's throws voxels out of [0, 1] within a few steps unless they
  // are clipped.
  const Problem& problem = SharedProblem();
  const ActivityMask mask(problem.scene.events, 2);
  const auto range = [](const Video& video) {
    const int64_t size = video.num_frames() * video.pixels_per_frame();
    const auto [low, high] = std::minmax_element(video.data(), video.data() + size);
    return std::make_pair(*low, *high);
  };
  AdamOptions options = TestOptions<AdamOptions>();
  options.learning_rate = 0.3;
  options.max_iterations = 10;
  options.bound_intensities = false;
  Video unbounded = problem.initial;
  SolveWithAdam(problem.scene, problem.objective, mask, options, &unbounded);
  const auto [unbounded_low, unbounded_high] = range(unbounded);
  EXPECT_TRUE(unbounded_low < 0.0 || unbounded_high > 1.0);
  options.bound_intensities = true;
  Video bounded = problem.initial;
  SolveWithAdam(problem.scene, problem.objective, mask, options, &bounded);
  const auto [low, high] = range(bounded);
  EXPECT_GE(low, 0.0);
  EXPECT_LE(high, 1.0);
}

TEST(Adam, CallbackSeesEveryIterationAndCanStop) {
  const Problem& problem = SharedProblem();
  const ActivityMask mask(problem.scene.events, 2);
  AdamOptions options = TestOptions<AdamOptions>();
  options.max_iterations = 10;
  std::vector<SolverIteration> seen;
  std::vector<double> psnr;
  Video latent = problem.initial;
  const FirstOrderSummary summary = SolveWithAdam(
      problem.scene, problem.objective, mask, options, &latent, [&](const SolverIteration& state) {
        seen.push_back(state);
        psnr.push_back(problem.PsnrAtTruth(*state.latent));
        return true;
      });
  ASSERT_EQ(seen.size(), 11u);
  for (int i = 0; i <= 10; ++i) {
    EXPECT_EQ(seen[i].iteration, i);
    if (i > 0) {
      EXPECT_GE(seen[i].elapsed_s, seen[i - 1].elapsed_s);
    }
  }
  EXPECT_EQ(seen.front().cost, summary.initial_cost);
  EXPECT_EQ(seen.back().cost, summary.final_cost);
  EXPECT_EQ(psnr.front(), problem.PsnrAtTruth(problem.initial));
  EXPECT_EQ(psnr.back(), problem.PsnrAtTruth(latent));

  int calls = 0;
  latent = problem.initial;
  const FirstOrderSummary stopped = SolveWithAdam(problem.scene, problem.objective, mask, options,
                                                  &latent, [&](const SolverIteration& state) {
                                                    ++calls;
                                                    return state.iteration < 3;
                                                  });
  EXPECT_EQ(calls, 4);
  EXPECT_EQ(stopped.iterations, 3);
  EXPECT_NE(stopped.termination.find("callback"), std::string::npos) << stopped.termination;
}

// A StopCondition ends either solver at its first iteration once reached, with a valid iterate
// (a time budget of 0 here; an interrupt raises a flag the same way), and says why.
TEST(FirstOrderSolvers, StopConditionEndsTheSolveWithItsCurrentIterate) {
  const Problem& problem = SharedProblem();
  const ActivityMask mask(problem.scene.events, 2);
  AdamOptions adam = TestOptions<AdamOptions>();
  adam.max_iterations = 1000000;
  Video latent = problem.initial;
  const FirstOrderSummary adam_summary = SolveWithAdam(problem.scene, problem.objective, mask, adam,
                                                       &latent, nullptr, StopCondition::After(0.0));
  EXPECT_LE(adam_summary.iterations, 1);
  EXPECT_FALSE(adam_summary.stopped_early.empty());
  EXPECT_NE(adam_summary.termination.find("stopped early"), std::string::npos)
      << adam_summary.termination;
  EXPECT_TRUE(VoxelValues(latent).allFinite());
  EXPECT_GE(VoxelValues(latent).minCoeff(), 0.0);
  EXPECT_LE(VoxelValues(latent).maxCoeff(), 1.0);

  std::atomic<bool> interrupt(true);
  LbfgsOptions lbfgs = TestOptions<LbfgsOptions>();
  lbfgs.solver.max_num_iterations = 100000;
  latent = problem.initial;
  const FirstOrderSummary lbfgs_summary =
      SolveWithLbfgs(problem.scene, problem.objective, mask, lbfgs, &latent, nullptr,
                     StopCondition().WhenRaised(&interrupt));
  EXPECT_LE(lbfgs_summary.iterations, 1);
  EXPECT_EQ(lbfgs_summary.stopped_early, "interrupted");
  EXPECT_TRUE(VoxelValues(latent).allFinite());
}

TEST(Lbfgs, LowersTheCostAndBeatsTheBlend) {
  const Problem& problem = SharedProblem();
  const ActivityMask mask(problem.scene.events, 2);
  LbfgsOptions options = TestOptions<LbfgsOptions>();
  options.solver.max_num_iterations = kLbfgsIterations;
  Video latent = problem.initial;
  int callbacks = 0;
  double last_cost = 0.0;
  const FirstOrderSummary summary = SolveWithLbfgs(problem.scene, problem.objective, mask, options,
                                                   &latent, [&](const SolverIteration& state) {
                                                     EXPECT_EQ(state.iteration, callbacks);
                                                     ++callbacks;
                                                     last_cost = state.cost;
                                                     return true;
                                                   });
  EXPECT_EQ(summary.solver, "lbfgs");
  EXPECT_GT(summary.iterations, 0);
  EXPECT_LE(summary.iterations, kLbfgsIterations);
  EXPECT_EQ(callbacks, summary.iterations + 1);
  EXPECT_LT(summary.final_cost, summary.initial_cost);
  EXPECT_DOUBLE_EQ(last_cost, summary.final_cost);
  const double final_cost =
      FusedObjective(problem.scene, problem.objective, mask).Evaluate(latent, nullptr);
  EXPECT_NEAR(final_cost, summary.final_cost, 1e-12 * summary.final_cost);

  const double blend = problem.PsnrAtTruth(problem.initial);
  const double solved = problem.PsnrAtTruth(latent);
  std::printf(
      "lbfgs, %d iterations, %d evaluations: blend %.2f dB, solved %.2f dB, cost %.4g -> "
      "%.4g, %.3f s (%s)\n",
      summary.iterations, summary.evaluations, blend, solved, summary.initial_cost,
      summary.final_cost, summary.solve_time_s, summary.termination.c_str());
  EXPECT_GE(solved, blend + kMinLbfgsGainDb);
  ExpectInactiveVoxelsUnchanged(mask, problem.initial, latent);
}

TEST(FirstOrderSolvers, SceneWithoutActivePixelsIsLeftAlone) {
  const Problem& problem = SharedProblem();
  Scene quiet = problem.scene;
  for (int k = 0; k < quiet.events.num_frames(); ++k) {
    std::fill(quiet.events.frame_data(k),
              quiet.events.frame_data(k) + quiet.events.pixels_per_frame(), 0.0f);
  }
  const ActivityMask mask(quiet.events, 2);
  ASSERT_EQ(mask.num_active(), 0);
  Video latent = problem.initial;
  const FirstOrderSummary adam =
      SolveWithAdam(quiet, problem.objective, mask, TestOptions<AdamOptions>(), &latent);
  EXPECT_EQ(adam.iterations, 0);
  const FirstOrderSummary lbfgs =
      SolveWithLbfgs(quiet, problem.objective, mask, TestOptions<LbfgsOptions>(), &latent);
  EXPECT_EQ(lbfgs.iterations, 0);
  EXPECT_EQ(lbfgs.final_cost, 0.0);
  const int64_t size = latent.num_frames() * latent.pixels_per_frame();
  EXPECT_TRUE(std::equal(latent.data(), latent.data() + size, problem.initial.data()));
}

}  // namespace
}  // namespace evfs
