#include "evfs/cost_functions/event_count_residual.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "evfs/tests/cost_functions/cost_function_testing.h"

namespace evfs {
namespace {

// A few logarithms and products of numbers near 1: double rounding only.
constexpr double kNominalTolerance = 1e-12;
// log(I + e^x) and the division by the mean threshold curve the residual, smoothly and at scales
// far above the checker's step: central differences agree to about 1e-8, checked to 1e-6.
constexpr double kGradientCheckPrecision = 1e-6;

// One pixel over two frames: 0.2 then 0.5, two ON events between them, the last one ON.
std::unique_ptr<ceres::CostFunction> TwoFramePixel(bool tied) {
  return std::unique_ptr<ceres::CostFunction>(
      EventCountResidual::Create({0.2, 0.5}, {0.0, 2.0}, {0.0, 0.0}, {0.0, 1.0}, tied));
}

TEST(EventCountResidual, Nominal) {
  const std::unique_ptr<ceres::CostFunction> cost = TwoFramePixel(/*tied=*/false);
  const double b = 0.1, on = 0.3, off = 0.2;
  const test::Evaluation evaluation = test::Evaluate(*cost, {std::log(b), on, off});
  ASSERT_TRUE(evaluation.return_value);
  // d_0 = log(0.3); d_1 = log(0.6) - 2 C_on - C_on / 2 (the last event was ON).
  const double d0 = std::log(0.2 + b);
  const double d1 = std::log(0.5 + b) - 2.0 * on - 0.5 * on;
  const double mean = 0.5 * (d0 + d1);
  const double threshold = 0.5 * (on + off);
  ASSERT_EQ(evaluation.residuals.size(), 2u);
  EXPECT_NEAR(evaluation.residuals[0], (d0 - mean) / threshold, kNominalTolerance);
  EXPECT_NEAR(evaluation.residuals[1], (d1 - mean) / threshold, kNominalTolerance);
  EXPECT_NEAR(evaluation.residuals[0] + evaluation.residuals[1], 0.0, kNominalTolerance);
}

TEST(EventCountResidual, TiedThresholdsReadOnlyTheOnThreshold) {
  const std::unique_ptr<ceres::CostFunction> tied = TwoFramePixel(/*tied=*/true);
  const test::Evaluation a = test::Evaluate(*tied, {std::log(0.1), 0.3, 0.2});
  const test::Evaluation b = test::Evaluate(*tied, {std::log(0.1), 0.3, 0.9});
  ASSERT_TRUE(a.return_value && b.return_value);
  EXPECT_EQ(a.residuals, b.residuals);
  EXPECT_EQ(a.jacobians[2][0], 0.0);
}

TEST(EventCountResidual, GradientCheck) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> log_offset(std::log(1e-3), std::log(2.0));
  std::uniform_real_distribution<double> threshold(0.1, 0.5);
  const std::unique_ptr<ceres::CostFunction> cost(EventCountResidual::Create(
      {0.05, 0.3, 0.6, 0.4}, {0.0, 3.0, 5.0, 5.0}, {0.0, 0.0, 0.0, 2.0}, {-1.0, 1.0, 1.0, -1.0},
      /*tied_thresholds=*/false));
  for (int i = 0; i < test::kRandomPoints; ++i) {
    test::ExpectGradientCheckPasses(*cost, {log_offset(rng), threshold(rng), threshold(rng)},
                                    kGradientCheckPrecision);
  }
}

}  // namespace
}  // namespace evfs
