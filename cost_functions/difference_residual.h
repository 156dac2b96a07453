// r = H_after - H_before - o
//
// Temporal TV (paper Eq. 5, |H_{t+1}(p) - H_t(p)|) and each axis of anisotropic spatial TV
// (|H_t(x+1, y) - H_t(x, y) - o|, |H_t(x, y+1) - H_t(x, y) - o|); the l1 penalty is the robust
// loss (weighted_l1_loss.h). The offset o is 0 except for spatial TV measured from the structure
// two frames share (ObjectiveOptions::shared_structure_tv).
#ifndef EVFS_COST_FUNCTIONS_DIFFERENCE_RESIDUAL_H_
#define EVFS_COST_FUNCTIONS_DIFFERENCE_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>

namespace evfs {

/// Difference of two latent voxels, minus `offset`. Parameter blocks: before, after, each of
/// size 1. Residual: 1.
struct DifferenceResidual {
  explicit DifferenceResidual(double offset) : offset(offset) {}

  template <typename T>
  bool operator()(const T* before, const T* after, T* residual) const {
    residual[0] = after[0] - before[0] - T(offset);
    return true;
  }

  static ceres::CostFunction* Create(double offset = 0.0) {
    return new ceres::AutoDiffCostFunction<DifferenceResidual, 1, 1, 1>(
        new DifferenceResidual(offset));
  }

  const double offset;
};

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_DIFFERENCE_RESIDUAL_H_
