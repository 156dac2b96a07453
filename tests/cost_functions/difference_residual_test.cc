#include "evfs/cost_functions/difference_residual.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "evfs/tests/cost_functions/cost_function_testing.h"

namespace evfs {
namespace {

// A difference of two doubles in [0, 1].
constexpr double kNominalTolerance = 1e-15;

TEST(DifferenceResidual, Nominal) {
  const std::unique_ptr<ceres::CostFunction> cost(DifferenceResidual::Create());
  const test::Evaluation evaluation = test::Evaluate(*cost, {0.25, 0.75});
  ASSERT_TRUE(evaluation.return_value);
  EXPECT_NEAR(evaluation.residuals[0], 0.5, kNominalTolerance);
  EXPECT_EQ(evaluation.jacobians[0][0], -1.0);
  EXPECT_EQ(evaluation.jacobians[1][0], 1.0);
}

TEST(DifferenceResidual, MeasuredFromItsOffset) {
  const std::unique_ptr<ceres::CostFunction> cost(DifferenceResidual::Create(0.125));
  const test::Evaluation evaluation = test::Evaluate(*cost, {0.25, 0.75});
  ASSERT_TRUE(evaluation.return_value);
  EXPECT_NEAR(evaluation.residuals[0], 0.5 - 0.125, kNominalTolerance);
  EXPECT_EQ(evaluation.jacobians[0][0], -1.0);
  EXPECT_EQ(evaluation.jacobians[1][0], 1.0);
}

TEST(DifferenceResidual, GradientCheck) {
  std::mt19937 rng(19);
  const std::unique_ptr<ceres::CostFunction> cost(DifferenceResidual::Create());
  for (int i = 0; i < test::kRandomPoints; ++i) {
    test::ExpectGradientCheckPasses(*cost, test::RandomIntensities(&rng, 2, 0.0, 1.0),
                                    test::kLinearGradientCheckPrecision);
  }
}

}  // namespace
}  // namespace evfs
