// r = sqrt(w) * (H_t(p) - T),  Ceres cost 1/2 r^2 = w/2 * (H_t(p) - T)^2
//
// The quadratic coupling term of plug & play (paper §3.4, Table 4): ADMM's x-update solves the
// objective plus rho/2 ||H - (Z - U)||^2, whose target T = Z - U is what the denoiser last gave
// (minus the scaled dual). It is a plain squared residual (no robust loss), one per parameter
// block. A block standing for m voxels of one value x with targets T_1 … T_m has
// sum_i (x - T_i)^2 = m (x - mean T)^2 + const, so it gets weight m w and target mean T.
#ifndef EVFS_COST_FUNCTIONS_PRIOR_RESIDUAL_H_
#define EVFS_COST_FUNCTIONS_PRIOR_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>
#include <glog/logging.h>

#include <cmath>

namespace evfs {

/// Weighted distance of one latent value to its target. Parameter block: the value, size 1.
/// Residual: 1.
struct PriorResidual {
  PriorResidual(double target, double sqrt_weight) : target(target), sqrt_weight(sqrt_weight) {}

  template <typename T>
  bool operator()(const T* value, T* residual) const {
    residual[0] = sqrt_weight * (value[0] - target);
    return true;
  }

  /// `weight` (w of the header's formula) must be > 0 (CHECKed).
  static ceres::CostFunction* Create(double target, double weight) {
    CHECK_GT(weight, 0.0);
    return new ceres::AutoDiffCostFunction<PriorResidual, 1, 1>(
        new PriorResidual(target, std::sqrt(weight)));
  }

  const double target;
  const double sqrt_weight;
};

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_PRIOR_RESIDUAL_H_
