// cost(r) = weight * (sqrt(a^2 + |r|^2) - a)
//
// The l1 penalties of the objective (paper Eqs. 3-5, docs/design.md §1) made smooth for Ceres: the
// pseudo-Huber form of weight * |r| with smoothing scale a. It tends to weight * |r| for
// |r| >> a and to weight * |r|^2 / (2 a) near 0.
#ifndef EVFS_COST_FUNCTIONS_WEIGHTED_L1_LOSS_H_
#define EVFS_COST_FUNCTIONS_WEIGHTED_L1_LOSS_H_

#include <ceres/loss_function.h>
#include <glog/logging.h>

#include <cmath>

namespace evfs {

/// Returns a loss whose cost is weight * (sqrt(a^2 + r^2) - a), the pseudo-Huber form of
/// weight*|r| with smoothing scale a (ownership passes to the caller, usually a Problem).
///
/// Why ScaledLoss(SoftLOneLoss(a), weight / a): Ceres' cost of a residual block is
/// 1/2 rho(s) with s = |r|^2, and SoftLOneLoss(a) has
///   rho(s) = 2 a^2 (sqrt(1 + s / a^2) - 1) = 2 a (sqrt(a^2 + s) - a),
/// so 1/2 (weight / a) rho(s) = weight (sqrt(a^2 + |r|^2) - a): weight |r| for |r| >> a and
/// weight |r|^2 / (2 a) near 0. For a residual vector (isotropic TV) this is the smoothed
/// weight * ||r||.
///
/// `weight` and `smoothing_scale` must be > 0 (CHECKed): callers never build zero-weight terms.
inline ceres::LossFunction* CreateWeightedL1Loss(double weight, double smoothing_scale) {
  CHECK_GT(weight, 0.0);
  CHECK_GT(smoothing_scale, 0.0);
  return new ceres::ScaledLoss(new ceres::SoftLOneLoss(smoothing_scale), weight / smoothing_scale,
                               ceres::TAKE_OWNERSHIP);
}

/// sqrt(a^2 + r^2) - a: the cost of CreateWeightedL1Loss(1, a) for a scalar residual r, for
/// evaluators that apply the penalty themselves (the fused objective of the Adam solver).
template <typename T>
T SmoothedAbs(const T& r, double a) {
  using std::sqrt;
  return sqrt(a * a + r * r) - a;
}

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_WEIGHTED_L1_LOSS_H_
