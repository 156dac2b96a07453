#include "cost_functions/spatial_tv_residual.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "tests/cost_functions/cost_function_testing.h"

namespace evfs {
namespace {

// Differences of two doubles in [0, 1].
constexpr double kNominalTolerance = 1e-15;

// center 0.5, right 0.7, below 0.2: dx = 0.2, dy = -0.3.
const std::vector<double> kNeighbourhood = {0.5, 0.7, 0.2};

TEST(PaperTvResidual, Nominal) {
  const std::unique_ptr<ceres::CostFunction> cost(PaperTvResidual::Create());
  const test::Evaluation evaluation = test::Evaluate(*cost, kNeighbourhood);
  ASSERT_TRUE(evaluation.return_value);
  EXPECT_NEAR(evaluation.residuals[0], 0.2 + -0.3, kNominalTolerance);
  EXPECT_EQ(evaluation.jacobians, (std::vector<std::vector<double>>{{-2.0}, {1.0}, {1.0}}));
}

TEST(IsotropicTvResidual, Nominal) {
  const std::unique_ptr<ceres::CostFunction> cost(IsotropicTvResidual::Create());
  const test::Evaluation evaluation = test::Evaluate(*cost, kNeighbourhood);
  ASSERT_TRUE(evaluation.return_value);
  ASSERT_EQ(evaluation.residuals.size(), 2u);
  EXPECT_NEAR(evaluation.residuals[0], 0.2, kNominalTolerance);
  EXPECT_NEAR(evaluation.residuals[1], -0.3, kNominalTolerance);
  // jacobians[block][residual]: the center pulls both differences, each neighbour one.
  EXPECT_EQ(evaluation.jacobians,
            (std::vector<std::vector<double>>{{-1.0, -1.0}, {1.0, 0.0}, {0.0, 1.0}}));
}

TEST(SpatialTvResiduals, GradientCheck) {
  std::mt19937 rng(17);
  const std::unique_ptr<ceres::CostFunction> paper(PaperTvResidual::Create());
  const std::unique_ptr<ceres::CostFunction> isotropic(IsotropicTvResidual::Create());
  for (int i = 0; i < test::kRandomPoints; ++i) {
    const std::vector<double> neighbourhood = test::RandomIntensities(&rng, 3, 0.0, 1.0);
    test::ExpectGradientCheckPasses(*paper, neighbourhood, test::kLinearGradientCheckPrecision);
    test::ExpectGradientCheckPasses(*isotropic, neighbourhood, test::kLinearGradientCheckPrecision);
  }
}

}  // namespace
}  // namespace evfs
