// r = H_after - H_before
//
// Temporal TV (paper Eq. 5, |H_{t+1}(p) - H_t(p)|) and each axis of anisotropic spatial TV
// (|H_t(x+1, y) - H_t(x, y)|, |H_t(x, y+1) - H_t(x, y)|); the l1 penalty is the robust loss
// (weighted_l1_loss.h).
#ifndef EVFS_COST_FUNCTIONS_DIFFERENCE_RESIDUAL_H_
#define EVFS_COST_FUNCTIONS_DIFFERENCE_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>

namespace evfs {

/// Difference of two latent voxels. Parameter blocks: before, after, each of size 1. Residual: 1.
struct DifferenceResidual {
  template <typename T>
  bool operator()(const T* before, const T* after, T* residual) const {
    residual[0] = after[0] - before[0];
    return true;
  }

  static ceres::CostFunction* Create() {
    return new ceres::AutoDiffCostFunction<DifferenceResidual, 1, 1, 1>(new DifferenceResidual);
  }
};

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_DIFFERENCE_RESIDUAL_H_
