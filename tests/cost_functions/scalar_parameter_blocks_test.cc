#include "evfs/cost_functions/scalar_parameter_blocks.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "evfs/tests/cost_functions/cost_function_testing.h"

namespace evfs {
namespace {

// Sum of a few doubles.
constexpr double kNominalTolerance = 1e-15;

// r = (sum of the blocks, first block): two residuals over any number of scalar blocks.
struct SumAndFirst {
  explicit SumAndFirst(int num_blocks) : num_blocks(num_blocks) {}

  template <typename T>
  bool operator()(T const* const* blocks, T* residual) const {
    residual[0] = T(0.0);
    for (int i = 0; i < num_blocks; ++i) residual[0] += blocks[i][0];
    residual[1] = blocks[0][0];
    return true;
  }

  const int num_blocks;
};

TEST(ScalarParameterBlocks, NominalLayoutAndDerivatives) {
  // More blocks than the stride, so that autodiff takes several passes.
  constexpr int kNumBlocks = 2 * kScalarBlocksAutoDiffStride + 1;
  const std::unique_ptr<ceres::CostFunction> cost(
      CreateDynamicAutoDiffOverScalarBlocks(new SumAndFirst(kNumBlocks), kNumBlocks, 2));
  EXPECT_EQ(cost->num_residuals(), 2);
  EXPECT_EQ(cost->parameter_block_sizes(), std::vector<int>(kNumBlocks, 1));

  std::vector<double> blocks(kNumBlocks);
  for (int i = 0; i < kNumBlocks; ++i) blocks[i] = 0.1 * i;
  const test::Evaluation evaluation = test::Evaluate(*cost, blocks);
  ASSERT_TRUE(evaluation.return_value);
  EXPECT_NEAR(evaluation.residuals[0], 0.1 * kNumBlocks * (kNumBlocks - 1) / 2, kNominalTolerance);
  EXPECT_EQ(evaluation.residuals[1], 0.0);
  for (int i = 0; i < kNumBlocks; ++i) {
    EXPECT_EQ(evaluation.jacobians[i], (std::vector<double>{1.0, i == 0 ? 1.0 : 0.0}));
  }
}

}  // namespace
}  // namespace evfs
