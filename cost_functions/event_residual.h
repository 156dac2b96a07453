// r = E_k(p) - sum_{s=a}^{b-1} c tanh(alpha * (g(H_{s+1}(p)) - g(H_s(p))) / c)
//     (paper Eq. 2 with g linear; Eq. 1 with g = log(x + b); c = 1 in the paper)
//
// One residual per event-frame pixel. Collision binning (paper §3.3, Binning 1) gives event
// frames spanning one latent step (b = a + 1) and values in {-1, 0, 1}, and c = 1; stacked
// binning (Binning 2) spans one or more steps and holds signed counts, modelled as the sum of
// the steps, each saturating at c = max(1, |E| / steps) (PredictedEvent).
#ifndef EVFS_COST_FUNCTIONS_EVENT_RESIDUAL_H_
#define EVFS_COST_FUNCTIONS_EVENT_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>
#include <glog/logging.h>

#include "evfs/cost_functions/scalar_parameter_blocks.h"
#include "evfs/scene/event_model.h"

namespace evfs {

/// Residual of one event-frame pixel against the event model summed over its latent steps.
/// Parameter blocks: H_a(p) .. H_b(p) (num_steps + 1 of them), each of size 1. Residual: 1.
struct EventResidual {
  /// `event_value` is E_k(p); `num_steps` is b - a (at least 1).
  EventResidual(double event_value, int num_steps, const EventModelParams& params)
      : event_value(event_value),
        num_steps(num_steps),
        params(params),
        saturation(SaturationForCount(event_value, num_steps, params.saturation)) {
    CHECK_GE(num_steps, 1);
    CheckEventModelParams(params);
  }

  template <typename T>
  bool operator()(T const* const* intensities, T* residual) const {
    T predicted_event(0.0);
    for (int s = 0; s < num_steps; ++s) {
      predicted_event +=
          PredictedEvent(intensities[s][0], intensities[s + 1][0], params, saturation);
    }
    residual[0] = T(event_value) - predicted_event;
    return true;
  }

  /// A fixed-size AutoDiffCostFunction<OneStepEventResidual, 1, 1, 1> when `num_steps` is 1
  /// (collision binning, by far the most common), else a DynamicAutoDiffCostFunction with
  /// num_steps + 1 parameter blocks of size 1.
  static ceres::CostFunction* Create(double event_value, int num_steps,
                                     const EventModelParams& params);

  const double event_value;
  const int num_steps;
  const EventModelParams params;
  const double saturation;  // c, from the count per step
};

/// EventResidual for one latent step with a fixed parameter layout (H_a, H_{a+1}), so that Ceres
/// can use its fixed-size autodiff.
struct OneStepEventResidual {
  OneStepEventResidual(double event_value, const EventModelParams& params)
      : event_value(event_value),
        params(params),
        saturation(SaturationForCount(event_value, 1, params.saturation)) {
    CheckEventModelParams(params);
  }

  template <typename T>
  bool operator()(const T* intensity_before, const T* intensity_after, T* residual) const {
    residual[0] = T(event_value) -
                  PredictedEvent(intensity_before[0], intensity_after[0], params, saturation);
    return true;
  }

  const double event_value;
  const EventModelParams params;
  const double saturation;  // c, from the count
};

inline ceres::CostFunction* EventResidual::Create(double event_value, int num_steps,
                                                  const EventModelParams& params) {
  CHECK_GE(num_steps, 1);
  if (num_steps == 1) {
    return new ceres::AutoDiffCostFunction<OneStepEventResidual, 1, 1, 1>(
        new OneStepEventResidual(event_value, params));
  }
  return CreateDynamicAutoDiffOverScalarBlocks(new EventResidual(event_value, num_steps, params),
                                               num_steps + 1, /*num_residuals=*/1);
}

/// OneStepEventResidual with its Jacobians written by hand, for the micro-benchmarks that
/// compare autodiff against analytic derivatives. With u = tanh(alpha (g(H_1) - g(H_0)) / c):
///   dr/dH_0 =  alpha (1 - u^2) g'(H_0),   dr/dH_1 = -alpha (1 - u^2) g'(H_1).
class EventResidualAnalytic : public ceres::SizedCostFunction<1, 1, 1> {
 public:
  EventResidualAnalytic(double event_value, const EventModelParams& params)
      : event_value_(event_value),
        params_(params),
        saturation_(SaturationForCount(event_value, 1, params.saturation)) {
    CheckEventModelParams(params);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double intensity_before = parameters[0][0];
    const double intensity_after = parameters[1][0];
    const double change = IntensityTransform(intensity_after, params_) -
                          IntensityTransform(intensity_before, params_);
    const double predicted_event = PredictedEventForChange(change, params_, saturation_);
    residuals[0] = event_value_ - predicted_event;
    if (jacobians == nullptr) return true;
    const double u = predicted_event / saturation_;
    const double slope = params_.AlphaFor(change) * (1.0 - u * u);
    if (jacobians[0] != nullptr) {
      jacobians[0][0] = slope * IntensityTransformDerivative(intensity_before, params_);
    }
    if (jacobians[1] != nullptr) {
      jacobians[1][0] = -slope * IntensityTransformDerivative(intensity_after, params_);
    }
    return true;
  }

 private:
  const double event_value_;
  const EventModelParams params_;
  const double saturation_;
};

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_EVENT_RESIDUAL_H_
