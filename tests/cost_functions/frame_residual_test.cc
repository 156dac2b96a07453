#include "evfs/cost_functions/frame_residual.h"

#include <ceres/autodiff_cost_function.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "evfs/tests/cost_functions/cost_function_testing.h"

namespace evfs {
namespace {

// Sums of a few doubles in [0, 1].
constexpr double kNominalTolerance = 1e-15;

TEST(FrameResidual, NominalSharpFrame) {
  const std::unique_ptr<ceres::CostFunction> cost(FrameResidual::Create(0.7, 1));
  const test::Evaluation evaluation = test::Evaluate(*cost, {0.25});
  ASSERT_TRUE(evaluation.return_value);
  EXPECT_NEAR(evaluation.residuals[0], 0.45, kNominalTolerance);
  EXPECT_EQ(evaluation.jacobians[0][0], -1.0);
}

TEST(FrameResidual, NominalBlurredFrameIsMeanOverExposure) {
  // 0.6 - (0.2 + 0.4 + 0.9) / 3 = 0.6 - 0.5.
  const std::unique_ptr<ceres::CostFunction> cost(FrameResidual::Create(0.6, 3));
  const test::Evaluation evaluation = test::Evaluate(*cost, {0.2, 0.4, 0.9});
  ASSERT_TRUE(evaluation.return_value);
  EXPECT_NEAR(evaluation.residuals[0], 0.1, kNominalTolerance);
  for (const std::vector<double>& jacobian : evaluation.jacobians) {
    EXPECT_NEAR(jacobian[0], -1.0 / 3.0, kNominalTolerance);
  }
}

TEST(FrameResidual, CreateUsesFixedSizeAutoDiffForSharpFrames) {
  const std::unique_ptr<ceres::CostFunction> sharp(FrameResidual::Create(0.5, 1));
  using SharpCostFunction = ceres::AutoDiffCostFunction<SharpFrameResidual, 1, 1>;
  EXPECT_NE(dynamic_cast<SharpCostFunction*>(sharp.get()), nullptr);
  const std::unique_ptr<ceres::CostFunction> blurred(FrameResidual::Create(0.5, 7));
  EXPECT_EQ(blurred->num_residuals(), 1);
  EXPECT_EQ(blurred->parameter_block_sizes(), std::vector<int>(7, 1));
}

TEST(FrameResidual, GradientCheck) {
  std::mt19937 rng(7);
  for (const int num_latent_frames : {1, 2, 5, 9}) {
    SCOPED_TRACE(num_latent_frames);
    const std::unique_ptr<ceres::CostFunction> cost(FrameResidual::Create(0.4, num_latent_frames));
    for (int i = 0; i < test::kRandomPoints; ++i) {
      test::ExpectGradientCheckPasses(*cost,
                                      test::RandomIntensities(&rng, num_latent_frames, 0.0, 1.0),
                                      test::kLinearGradientCheckPrecision);
    }
  }
}

TEST(FrameResidualAnalytic, MatchesAutoDiff) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> observed(0.0, 1.0);
  for (int i = 0; i < test::kRandomPoints; ++i) {
    const double observed_intensity = observed(rng);
    const std::unique_ptr<ceres::CostFunction> autodiff(
        FrameResidual::Create(observed_intensity, 1));
    const FrameResidualAnalytic analytic(observed_intensity);
    test::ExpectSameEvaluation(*autodiff, analytic, test::RandomIntensities(&rng, 1, 0.0, 1.0),
                               test::kAnalyticTolerance);
  }
}

TEST(FrameResidualDeathTest, RejectsEmptyExposure) {
  EXPECT_DEATH(FrameResidual::Create(0.5, 0), "run_lengths");
}

}  // namespace
}  // namespace evfs
