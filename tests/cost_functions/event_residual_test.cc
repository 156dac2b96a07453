#include "evfs/cost_functions/event_residual.h"

#include <ceres/autodiff_cost_function.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "evfs/tests/cost_functions/cost_function_testing.h"

namespace evfs {
namespace {

// Ridders' extrapolation (see test::GradientCheckOptions) leaves an absolute error of ~1e-12,
// and the checker divides it by the entry. Multi-step Jacobian entries of an inner voxel are the
// difference of two steps' slopes and can be as small as ~1e-5, so 1e-6 relative; a wrong
// factor (alpha, g', a sign) is off by orders of magnitude more.
constexpr double kGradientCheckPrecision = 1e-6;
// Closed-form values computed with the same libm calls, summed in a different order.
constexpr double kNominalTolerance = 1e-14;

EventModelParams LinearParams(double alpha) {
  EventModelParams params;
  params.alpha = alpha;
  return params;
}

EventModelParams LogParams(double alpha) {
  EventModelParams params = LinearParams(alpha);
  params.model = EventModel::kLog;
  params.log_offset = 0.1;
  return params;
}

TEST(EventResidual, NominalLinearOneStep) {
  const std::unique_ptr<ceres::CostFunction> cost(EventResidual::Create(1.0, 1, LinearParams(5.0)));
  const test::Evaluation evaluation = test::Evaluate(*cost, {0.2, 0.3});
  ASSERT_TRUE(evaluation.return_value);
  const double predicted = std::tanh(0.5);
  EXPECT_NEAR(evaluation.residuals[0], 1.0 - predicted, kNominalTolerance);
  const double slope = 5.0 * (1.0 - predicted * predicted);
  EXPECT_NEAR(evaluation.jacobians[0][0], slope, kNominalTolerance);
  EXPECT_NEAR(evaluation.jacobians[1][0], -slope, kNominalTolerance);
}

TEST(EventResidual, NominalLogOneStep) {
  const std::unique_ptr<ceres::CostFunction> cost(EventResidual::Create(1.0, 1, LogParams(5.0)));
  const test::Evaluation evaluation = test::Evaluate(*cost, {0.2, 0.3});
  ASSERT_TRUE(evaluation.return_value);
  const double predicted = std::tanh(5.0 * (std::log(0.4) - std::log(0.3)));
  EXPECT_NEAR(evaluation.residuals[0], 1.0 - predicted, kNominalTolerance);
  const double slope = 5.0 * (1.0 - predicted * predicted);
  EXPECT_NEAR(evaluation.jacobians[0][0], slope / 0.3, kNominalTolerance);
  EXPECT_NEAR(evaluation.jacobians[1][0], -slope / 0.4, kNominalTolerance);
}

TEST(EventResidual, NominalMultiStepSumsTheSteps) {
  // Steps 0.2 -> 0.3 -> 0.1 -> 0.5 with alpha = 5: tanh(0.5) + tanh(-1) + tanh(2).
  const std::unique_ptr<ceres::CostFunction> cost(EventResidual::Create(2.0, 3, LinearParams(5.0)));
  const test::Evaluation evaluation = test::Evaluate(*cost, {0.2, 0.3, 0.1, 0.5});
  ASSERT_TRUE(evaluation.return_value);
  EXPECT_NEAR(evaluation.residuals[0], 2.0 - (std::tanh(0.5) + std::tanh(-1.0) + std::tanh(2.0)),
              kNominalTolerance);
  // H_1 enters step 0 as 'after' and step 1 as 'before'.
  const double slope_step0 = 5.0 * (1.0 - std::pow(std::tanh(0.5), 2));
  const double slope_step1 = 5.0 * (1.0 - std::pow(std::tanh(-1.0), 2));
  EXPECT_NEAR(evaluation.jacobians[1][0], -slope_step0 + slope_step1, kNominalTolerance);
}

TEST(EventResidual, NominalCountSaturatesAtTheCountPerStep) {
  // A stacked frame with 3 events over one step: 3 - 3 tanh(alpha (0.3 - 0.2) / 3), slope alpha
  // at zero change as for a single event.
  const std::unique_ptr<ceres::CostFunction> cost(EventResidual::Create(3.0, 1, LinearParams(5.0)));
  const test::Evaluation evaluation = test::Evaluate(*cost, {0.2, 0.3});
  ASSERT_TRUE(evaluation.return_value);
  const double u = std::tanh(0.5 / 3.0);
  EXPECT_NEAR(evaluation.residuals[0], 3.0 - 3.0 * u, kNominalTolerance);
  EXPECT_NEAR(evaluation.jacobians[1][0], -5.0 * (1.0 - u * u), kNominalTolerance);
  // Over two steps, -4 events saturate each step at 2.
  const std::unique_ptr<ceres::CostFunction> two_steps(
      EventResidual::Create(-4.0, 2, LinearParams(5.0)));
  const test::Evaluation stacked = test::Evaluate(*two_steps, {0.5, 0.4, 0.2});
  EXPECT_NEAR(stacked.residuals[0], -4.0 - 2.0 * (std::tanh(-0.5 / 2.0) + std::tanh(-1.0 / 2.0)),
              kNominalTolerance);
  // Counts of at most one per step keep the paper's model.
  EXPECT_DOUBLE_EQ(SaturationForCount(-1.0, 1), 1.0);
  EXPECT_DOUBLE_EQ(SaturationForCount(2.0, 4), 1.0);
  EXPECT_DOUBLE_EQ(SaturationForCount(-6.0, 2), 3.0);
  // A model saturation c raises the floor, never the count per step.
  EXPECT_DOUBLE_EQ(SaturationForCount(1.0, 1, 2.0), 2.0);
  EXPECT_DOUBLE_EQ(SaturationForCount(-6.0, 2, 2.0), 3.0);
  EXPECT_DOUBLE_EQ(SaturationForCount(1.0, 1, 0.0), 1.0);  // not derived: the paper's
}

TEST(EventResidual, ModelSaturationMakesOneEventPredictAboutOneChange) {
  // One event at a step whose change is exactly 1/alpha: the paper's c = 1 predicts tanh(1) =
  // 0.76 of it, c = 2 predicts 2 tanh(1/2) = 0.92.
  EventModelParams params = LinearParams(5.0);
  const std::unique_ptr<ceres::CostFunction> paper(EventResidual::Create(1.0, 1, params));
  EXPECT_NEAR(test::Evaluate(*paper, {0.3, 0.5}).residuals[0], 1.0 - std::tanh(1.0),
              kNominalTolerance);
  params.saturation = 2.0;
  const std::unique_ptr<ceres::CostFunction> saturated(EventResidual::Create(1.0, 1, params));
  const test::Evaluation evaluation = test::Evaluate(*saturated, {0.3, 0.5});
  EXPECT_NEAR(evaluation.residuals[0], 1.0 - 2.0 * std::tanh(0.5), kNominalTolerance);
  // The slope at the step is alpha (1 - u²) with u = tanh(1/2).
  const double u = std::tanh(0.5);
  EXPECT_NEAR(evaluation.jacobians[0][0], 5.0 * (1.0 - u * u), kNominalTolerance);
  params.saturation = 0.5;
  std::string error;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("saturation"), std::string::npos) << error;
}

TEST(EventResidual, DarkeningStepsUseTheOffSlope) {
  EventModelParams params = LinearParams(5.0);
  params.off_alpha_ratio = 2.0;
  const std::unique_ptr<ceres::CostFunction> cost(EventResidual::Create(1.0, 1, params));
  // Brightening by 0.1: tanh(5 · 0.1); darkening by 0.1: tanh(-2 · 5 · 0.1).
  EXPECT_NEAR(test::Evaluate(*cost, {0.3, 0.4}).residuals[0], 1.0 - std::tanh(0.5),
              kNominalTolerance);
  const test::Evaluation darkening = test::Evaluate(*cost, {0.4, 0.3});
  EXPECT_NEAR(darkening.residuals[0], 1.0 - std::tanh(-1.0), kNominalTolerance);
  const double u = std::tanh(-1.0);
  EXPECT_NEAR(darkening.jacobians[0][0], 10.0 * (1.0 - u * u), kNominalTolerance);
  // The analytic form agrees on both sides.
  std::mt19937 rng(11);
  for (int i = 0; i < test::kRandomPoints; ++i) {
    const EventResidualAnalytic analytic(-1.0, params);
    const std::unique_ptr<ceres::CostFunction> autodiff(EventResidual::Create(-1.0, 1, params));
    test::ExpectSameEvaluation(*autodiff, analytic, test::RandomIntensities(&rng, 2, 0.0, 1.0),
                               test::kAnalyticTolerance);
  }
  params.off_alpha_ratio = 0.0;
  std::string error;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("OFF/ON"), std::string::npos) << error;
}

TEST(EventResidual, CreateUsesFixedSizeAutoDiffForOneStep) {
  const std::unique_ptr<ceres::CostFunction> one_step(
      EventResidual::Create(1.0, 1, LinearParams(5.0)));
  using OneStepCostFunction = ceres::AutoDiffCostFunction<OneStepEventResidual, 1, 1, 1>;
  EXPECT_NE(dynamic_cast<OneStepCostFunction*>(one_step.get()), nullptr);
  const std::unique_ptr<ceres::CostFunction> stacked(
      EventResidual::Create(3.0, 4, LinearParams(5.0)));
  EXPECT_EQ(stacked->num_residuals(), 1);
  EXPECT_EQ(stacked->parameter_block_sizes(), std::vector<int>(5, 1));
}

TEST(EventResidual, GradientCheck) {
  std::mt19937 rng(3);
  for (const EventModelParams& params : {LinearParams(5.0), LogParams(5.0)}) {
    for (const int num_steps : {1, 2, 4, 6}) {
      SCOPED_TRACE(::testing::Message() << "log model: " << (params.model == EventModel::kLog)
                                        << ", steps: " << num_steps);
      const std::unique_ptr<ceres::CostFunction> cost(
          EventResidual::Create(num_steps == 2 ? -5.0 : 1.0, num_steps, params));
      for (int i = 0; i < test::kRandomPoints; ++i) {
        // Away from 0, where the log model's guard has a kink.
        test::ExpectGradientCheckPasses(*cost,
                                        test::RandomIntensities(&rng, num_steps + 1, 0.05, 1.0),
                                        kGradientCheckPrecision);
      }
    }
  }
}

TEST(EventResidual, LogGuardKeepsNegativeIntensitiesFinite) {
  for (const int num_steps : {1, 2}) {
    SCOPED_TRACE(num_steps);
    const std::unique_ptr<ceres::CostFunction> cost(
        EventResidual::Create(-1.0, num_steps, LogParams(5.0)));
    std::vector<double> intensities(num_steps + 1, 0.3);
    intensities[0] = -0.5;
    const test::Evaluation evaluation = test::Evaluate(*cost, intensities);
    test::ExpectFinite(evaluation);
    // Below 0 the transform is flat: the clamped voxel gets no gradient.
    EXPECT_EQ(evaluation.jacobians[0][0], 0.0);
  }
  const EventResidualAnalytic analytic(-1.0, LogParams(5.0));
  test::ExpectFinite(test::Evaluate(analytic, {-0.5, 0.3}));
}

TEST(EventResidual, LargeAlphaSaturatesWithFiniteJacobians) {
  const EventModelParams params = LinearParams(1000.0);
  for (const int num_steps : {1, 3}) {
    SCOPED_TRACE(num_steps);
    const std::unique_ptr<ceres::CostFunction> cost(
        EventResidual::Create(num_steps, num_steps, params));
    std::vector<double> rising(num_steps + 1);
    for (int s = 0; s <= num_steps; ++s) rising[s] = 0.2 + 0.2 * s;
    const test::Evaluation saturated = test::Evaluate(*cost, rising);
    test::ExpectFinite(saturated);
    EXPECT_NEAR(saturated.residuals[0], 0.0, kNominalTolerance);
    // At zero change the slope is alpha itself.
    test::ExpectFinite(test::Evaluate(*cost, std::vector<double>(num_steps + 1, 0.5)));
  }
  const EventResidualAnalytic analytic(1.0, params);
  test::ExpectFinite(test::Evaluate(analytic, {0.2, 0.9}));
}

TEST(EventResidualAnalytic, MatchesAutoDiff) {
  std::mt19937 rng(5);
  // Beyond ±1 too: stacked counts saturate at the count.
  std::uniform_real_distribution<double> event_value(-4.0, 4.0);
  for (const EventModelParams& params : {LinearParams(5.0), LogParams(12.0)}) {
    SCOPED_TRACE(params.model == EventModel::kLog ? "log" : "linear");
    for (int i = 0; i < test::kRandomPoints; ++i) {
      const double value = event_value(rng);
      const std::unique_ptr<ceres::CostFunction> autodiff(EventResidual::Create(value, 1, params));
      const EventResidualAnalytic analytic(value, params);
      // Includes negative intensities, where both must apply the log guard the same way.
      test::ExpectSameEvaluation(*autodiff, analytic, test::RandomIntensities(&rng, 2, -0.2, 1.0),
                                 test::kAnalyticTolerance);
    }
  }
}

TEST(EventResidualAnalytic, GradientCheck) {
  std::mt19937 rng(13);
  for (const EventModelParams& params : {LinearParams(5.0), LogParams(5.0)}) {
    const EventResidualAnalytic analytic(0.5, params);
    for (int i = 0; i < test::kRandomPoints; ++i) {
      test::ExpectGradientCheckPasses(analytic, test::RandomIntensities(&rng, 2, 0.05, 1.0),
                                      kGradientCheckPrecision);
    }
  }
}

TEST(EventResidualDeathTest, RejectsInvalidParameters) {
  EXPECT_DEATH(EventResidual::Create(1.0, 0, LinearParams(5.0)), "num_steps");
  EXPECT_DEATH(EventResidual::Create(1.0, 1, LinearParams(0.0)), "alpha");
}

}  // namespace
}  // namespace evfs
