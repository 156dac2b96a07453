// Building a DynamicAutoDiffCostFunction over scalar parameter blocks: every latent voxel H_t(p)
// is its own parameter block of size 1, and a residual spanning several latent frames takes one
// block per frame.
#ifndef EVFS_COST_FUNCTIONS_SCALAR_PARAMETER_BLOCKS_H_
#define EVFS_COST_FUNCTIONS_SCALAR_PARAMETER_BLOCKS_H_

#include <ceres/cost_function.h>
#include <ceres/dynamic_autodiff_cost_function.h>
#include <glog/logging.h>

namespace evfs {

/// Derivatives evaluated per pass of the dynamic autodiff cost functions. With blocks of size 1
/// a residual over n blocks takes ceil(n / stride) passes; Ceres' default of 4 covers the usual
/// spans (a few latent steps) in one or two passes.
constexpr int kScalarBlocksAutoDiffStride = 4;

/// Wraps `functor` (ownership taken) in a DynamicAutoDiffCostFunction with
/// `num_parameter_blocks` parameter blocks of size 1 and `num_residuals` residuals. `Functor`
/// must provide `template <typename T> bool operator()(T const* const*, T*) const`.
template <typename Functor>
ceres::CostFunction* CreateDynamicAutoDiffOverScalarBlocks(Functor* functor,
                                                           int num_parameter_blocks,
                                                           int num_residuals) {
  CHECK_GE(num_parameter_blocks, 1);
  CHECK_GE(num_residuals, 1);
  auto* cost_function =
      new ceres::DynamicAutoDiffCostFunction<Functor, kScalarBlocksAutoDiffStride>(functor);
  for (int i = 0; i < num_parameter_blocks; ++i) cost_function->AddParameterBlock(1);
  cost_function->SetNumResiduals(num_residuals);
  return cost_function;
}

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_SCALAR_PARAMETER_BLOCKS_H_
