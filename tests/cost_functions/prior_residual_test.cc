#include "evfs/cost_functions/prior_residual.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "evfs/tests/cost_functions/cost_function_testing.h"

namespace evfs {
namespace {

// One subtraction and one product of doubles of order 1.
constexpr double kNominalTolerance = 1e-15;

TEST(PriorResidual, Nominal) {
  // w = 4: r = 2 (x - T), Ceres' cost 1/2 r^2 = 2 (x - T)^2 = w/2 (x - T)^2.
  const std::unique_ptr<ceres::CostFunction> cost(PriorResidual::Create(0.25, 4.0));
  const test::Evaluation evaluation = test::Evaluate(*cost, {0.75});
  ASSERT_TRUE(evaluation.return_value);
  EXPECT_NEAR(evaluation.residuals[0], 1.0, kNominalTolerance);
  EXPECT_NEAR(evaluation.jacobians[0][0], 2.0, kNominalTolerance);
  const test::Evaluation at_target = test::Evaluate(*cost, {0.25});
  EXPECT_EQ(at_target.residuals[0], 0.0);
}

TEST(PriorResidual, GradientCheck) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> target(0.0, 1.0), weight(0.01, 100.0);
  for (int i = 0; i < test::kRandomPoints; ++i) {
    const std::unique_ptr<ceres::CostFunction> cost(
        PriorResidual::Create(target(rng), weight(rng)));
    test::ExpectGradientCheckPasses(*cost, test::RandomIntensities(&rng, 1, 0.0, 1.0),
                                    test::kLinearGradientCheckPrecision);
  }
}

}  // namespace
}  // namespace evfs
