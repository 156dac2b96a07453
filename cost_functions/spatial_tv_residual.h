// Spatial total variation of a latent frame H_t at pixel p = (x, y), with forward differences
// dx H = H(x+1, y) - H(x, y) and dy H = H(x, y+1) - H(x, y):
//   paper:       r = dx H + dy H                      -> |dx H + dy H|        (paper Eq. 4)
//   isotropic:   r = (dx H, dy H)                     -> sqrt(dx H^2 + dy H^2)
//   anisotropic: two DifferenceResidual blocks         -> |dx H| + |dy H|
// The l1 penalty itself is the robust loss (weighted_l1_loss.h): applied to the squared norm
// |r|^2 of the isotropic residual it gives smoothed isotropic TV. Each difference may be measured
// from an offset (o_x, o_y), the structure two frames share (ObjectiveOptions::
// shared_structure_tv): dx H - o_x, dy H - o_y; the offsets are 0 otherwise.
#ifndef EVFS_COST_FUNCTIONS_SPATIAL_TV_RESIDUAL_H_
#define EVFS_COST_FUNCTIONS_SPATIAL_TV_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>

namespace evfs {

/// Which spatial TV the objective uses.
enum class SpatialTv {
  kPaper,        ///< |dx H + dy H|   (paper Eq. 4)
  kAnisotropic,  ///< |dx H| + |dy H|   (two DifferenceResidual blocks)
  kIsotropic,    ///< sqrt(dx H^2 + dy H^2)   (IsotropicTvResidual)
};

/// The paper's spatial TV term. Parameter blocks: H_t(x, y), H_t(x+1, y), H_t(x, y+1), each of
/// size 1. Residual: 1.
struct PaperTvResidual {
  PaperTvResidual(double offset_x, double offset_y) : offset(offset_x + offset_y) {}

  template <typename T>
  bool operator()(const T* center, const T* right, const T* below, T* residual) const {
    residual[0] = (right[0] - center[0]) + (below[0] - center[0]) - T(offset);
    return true;
  }

  static ceres::CostFunction* Create(double offset_x = 0.0, double offset_y = 0.0) {
    return new ceres::AutoDiffCostFunction<PaperTvResidual, 1, 1, 1, 1>(
        new PaperTvResidual(offset_x, offset_y));
  }

  const double offset;  // o_x + o_y
};

/// The forward-difference gradient for isotropic TV. Parameter blocks: H_t(x, y), H_t(x+1, y),
/// H_t(x, y+1), each of size 1. Residuals: 2 (dx H, dy H).
struct IsotropicTvResidual {
  IsotropicTvResidual(double offset_x, double offset_y) : offset_x(offset_x), offset_y(offset_y) {}

  template <typename T>
  bool operator()(const T* center, const T* right, const T* below, T* residual) const {
    residual[0] = right[0] - center[0] - T(offset_x);
    residual[1] = below[0] - center[0] - T(offset_y);
    return true;
  }

  static ceres::CostFunction* Create(double offset_x = 0.0, double offset_y = 0.0) {
    return new ceres::AutoDiffCostFunction<IsotropicTvResidual, 2, 1, 1, 1>(
        new IsotropicTvResidual(offset_x, offset_y));
  }

  const double offset_x, offset_y;
};

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_SPATIAL_TV_RESIDUAL_H_
