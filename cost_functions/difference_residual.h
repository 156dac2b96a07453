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

#include "evfs/scene/event_model.h"

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

/// scale · (g(H_after) − g(H_before)), g the event model's IntensityTransform: temporal TV
/// measured in the domain the events count in. With the log model a brightening step and the
/// darkening step that undoes it then cost alike, where |ΔH| charges the brighter one
/// (H + b)/(H' + b) times more; a pixel whose events alternate many times (a flickering light)
/// would otherwise drift dark, by a little every cycle (ObjectiveOptions::
/// log_temporal_tv_reversals). `scale` = 1/g' at mid-grey (0.5 + b for the log model) makes a
/// small step at H = 0.5 cost what DifferenceResidual charges. Parameter blocks: before, after,
/// each of size 1. Residual: 1.
struct TransformedDifferenceResidual {
  TransformedDifferenceResidual(const EventModelParams& params, double scale)
      : params(params), scale(scale) {}

  template <typename T>
  bool operator()(const T* before, const T* after, T* residual) const {
    residual[0] =
        T(scale) * (IntensityTransform(after[0], params) - IntensityTransform(before[0], params));
    return true;
  }

  /// The scale that makes a small step at mid-grey cost what |ΔH| charges.
  static double MidGreyScale(const EventModelParams& params) {
    return params.model == EventModel::kLog ? 0.5 + params.log_offset : 1.0;
  }

  static ceres::CostFunction* Create(const EventModelParams& params) {
    return new ceres::AutoDiffCostFunction<TransformedDifferenceResidual, 1, 1, 1>(
        new TransformedDifferenceResidual(params, MidGreyScale(params)));
  }

  const EventModelParams params;
  const double scale;
};

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_DIFFERENCE_RESIDUAL_H_
