#include "evfs/cost_functions/spatial_tv_residual.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "evfs/tests/cost_functions/cost_function_testing.h"

namespace evfs {
namespace {

// Differences of two doubles in [0, 1].
constexpr double kNominalTolerance = 1e-15;

// center 0.5, right 0.7, below 0.2: dx = 0.2, dy = -0.3.
const std::vector<double> kNeighbourhood = {0.5, 0.7, 0.2};

// Evaluates both forms on kNeighbourhood with offsets (o_x, o_y) and expects the residuals
// dx − o_x + dy − o_y (paper) and (dx − o_x, dy − o_y) (isotropic); the offsets leave the
// Jacobians alone.
void ExpectResiduals(double offset_x, double offset_y, double dx, double dy) {
  const std::unique_ptr<ceres::CostFunction> paper(PaperTvResidual::Create(offset_x, offset_y));
  const test::Evaluation summed = test::Evaluate(*paper, kNeighbourhood);
  ASSERT_TRUE(summed.return_value);
  EXPECT_NEAR(summed.residuals[0], dx + dy, kNominalTolerance);
  EXPECT_EQ(summed.jacobians, (std::vector<std::vector<double>>{{-2.0}, {1.0}, {1.0}}));
  const std::unique_ptr<ceres::CostFunction> isotropic(
      IsotropicTvResidual::Create(offset_x, offset_y));
  const test::Evaluation both = test::Evaluate(*isotropic, kNeighbourhood);
  ASSERT_TRUE(both.return_value);
  ASSERT_EQ(both.residuals.size(), 2u);
  EXPECT_NEAR(both.residuals[0], dx, kNominalTolerance);
  EXPECT_NEAR(both.residuals[1], dy, kNominalTolerance);
  // jacobians[block][residual]: the center pulls both differences, each neighbour one.
  EXPECT_EQ(both.jacobians,
            (std::vector<std::vector<double>>{{-1.0, -1.0}, {1.0, 0.0}, {0.0, 1.0}}));
}

TEST(SpatialTvResiduals, Nominal) { ExpectResiduals(0.0, 0.0, 0.2, -0.3); }

TEST(SpatialTvResiduals, MeasuredFromTheirOffsets) {
  // Offsets (0.05, -0.1): dx − o_x = 0.15, dy − o_y = -0.2.
  ExpectResiduals(0.05, -0.1, 0.15, -0.2);
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
