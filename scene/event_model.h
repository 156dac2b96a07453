// The differentiable event model, one latent step at a time:
//   B(H_s, H_{s+1}) = tanh(alpha * (g(H_{s+1}) - g(H_s)))
// with g(x) = x (the paper's model, its Eq. 2) or g(x) = log(x + b) (the sensor's log-intensity
// contrast of its Eq. 1, where an event fires when log(I_t + b) - log(I_0 + b) passes a
// threshold).
#ifndef EVFS_SCENE_EVENT_MODEL_H_
#define EVFS_SCENE_EVENT_MODEL_H_

#include <glog/logging.h>

#include <cmath>
#include <string>

#include "evfs/core/enum_names.h"
#include "evfs/core/option_checker.h"

namespace evfs {

/// Which intensity transform g the event model compares between latent frames.
enum class EventModel {
  kLinear,  ///< g(x) = x   (paper Eq. 2)
  kLog,     ///< g(x) = log(x + b)   (paper Eq. 1)
};

/// Names used by flags and summaries.
inline constexpr EnumName<EventModel> kEventModelNames[] = {
    {EventModel::kLinear, "linear", "g(x) = x, paper Eq. 2"},
    {EventModel::kLog, "log", "g(x) = log(x + b), paper Eq. 1"},
};

/// Parameters of the event model.
struct EventModelParams {
  EventModel model = EventModel::kLinear;  ///< the intensity transform g
  double alpha = 5.0;                      ///< slope of the tanh activation (paper Eq. 2), > 0
  double log_offset = 0.1;                 ///< b in log(x + b) (paper Eq. 1), > 0; kLog only
  /// c of the predicted event c·tanh(α·Δg / c) for a step that holds at most one event, >= 1.
  /// 1 is the paper's curve: it reaches 0.76 at α·Δg = 1, so an event pulls its step past the
  /// change 1/α it stands for. A larger c keeps the curve nearly linear over one event's
  /// change (c = 2: 0.92 at α·Δg = 1), so that one event predicts about 1/α. 0: derived with α
  /// (ResolveObjective), and 1 where nothing derives it.
  double saturation = 1.0;
  /// α of a darkening step over α of a brightening one, > 0. A DAVIS pixel's OFF threshold is
  /// lower than its ON threshold (on the shared recordings one OFF event stands for 0.65–0.75
  /// of the change one ON event does), so an OFF event predicts a smaller change: darkening
  /// steps use the slope alpha · off_alpha_ratio. 1: one slope (the paper's model).
  double off_alpha_ratio = 1.0;

  /// α of the step from g_before to g_after: alpha, times off_alpha_ratio when it darkens.
  template <typename T>
  double AlphaFor(const T& g_change) const {
    return g_change < T(0.0) ? alpha * off_alpha_ratio : alpha;
  }

  /// True when alpha > 0 and, for kLog, log_offset > 0; otherwise false with the reason in
  /// `*error` (when not null).
  bool IsValid(std::string* error) const {
    OptionChecker check;
    if (!(alpha > 0.0)) {
      check.Check(false, "event model alpha must be > 0, got " + std::to_string(alpha));
    }
    if (model == EventModel::kLog && !(log_offset > 0.0)) {
      check.Check(false, "log event model offset b must be > 0, got " + std::to_string(log_offset));
    }
    if (!(off_alpha_ratio > 0.0 && std::isfinite(off_alpha_ratio))) {
      check.Check(false, "event model OFF/ON alpha ratio must be > 0, got " +
                             std::to_string(off_alpha_ratio));
    }
    if (saturation != 0.0 && !(saturation >= 1.0 && std::isfinite(saturation))) {
      check.Check(
          false, "event model saturation c must be >= 1 (or 0), got " + std::to_string(saturation));
    }
    return check.Passed(error);
  }
};

/// CHECKs `params.IsValid`: the residuals are built from options that were validated already,
/// so invalid parameters there are a programmer error.
inline void CheckEventModelParams(const EventModelParams& params) {
  std::string error;
  CHECK(params.IsValid(&error)) << error;
}

/// g(x): x for EventModel::kLinear, log(max(x, 0) + b) for EventModel::kLog.
///
/// The clamp at 0 is a guard for the optimiser stepping below 0 when intensities are not
/// bounded to [0, 1]: log(x + b) would be NaN for x < -b and poison the whole solve. Below 0 the
/// transform is flat (zero derivative), so such a step is neither rewarded nor fatal. At exactly
/// 0 the derivative is the right-hand one, 1/b: a bounded solve holds black pixels at 0 (a black
/// first frame is copied to every latent frame), and a derivative of 0 there would leave the
/// event term no gradient to brighten them with.
template <typename T>
T IntensityTransform(const T& intensity, const EventModelParams& params) {
  if (params.model == EventModel::kLinear) return intensity;
  using std::log;
  const T clamped_intensity = intensity >= T(0.0) ? intensity : T(0.0);
  return log(clamped_intensity + params.log_offset);
}

/// dg/dx, matching IntensityTransform (0 below the clamp, 1/b at 0), for hand-written Jacobians.
inline double IntensityTransformDerivative(double intensity, const EventModelParams& params) {
  if (params.model == EventModel::kLinear) return 1.0;
  return intensity >= 0.0 ? 1.0 / (intensity + params.log_offset) : 0.0;
}

/// PredictedEvent of a step whose change of g is `change`: c tanh(AlphaFor(change) change / c).
template <typename T>
T PredictedEventForChange(const T& change, const EventModelParams& params, double saturation) {
  using std::tanh;
  return saturation * tanh(params.AlphaFor(change) * change / saturation);
}

/// Predicted event value of one latent step: c tanh(alpha (g(after) - g(before)) / c), with
/// params.AlphaFor the change (the OFF slope for a darkening step).
///
/// c = 1 is the paper's model (Eq. 2): a collision-binned step holds at most one event. A step
/// of a stacked event frame (Binning 2) holds a signed count, which tanh cannot reach; the
/// paper sums several sub-steps instead, at the price of more latent frames. With c = the
/// count per step the curve keeps the paper's slope alpha at 0 and saturates at the count, so
/// one latent step can explain it (SaturationForCount).
template <typename T>
T PredictedEvent(const T& intensity_before, const T& intensity_after,
                 const EventModelParams& params, double saturation = 1.0) {
  return PredictedEventForChange(
      IntensityTransform(intensity_after, params) - IntensityTransform(intensity_before, params),
      params, saturation);
}

/// c of PredictedEvent for an event frame holding `event_value` over `num_steps` steps: the
/// count per step, and at least `min_saturation` (EventModelParams::saturation) and 1 (the
/// paper's model for collision frames and zero counts).
inline double SaturationForCount(double event_value, int num_steps, double min_saturation = 1.0) {
  const double per_step = (event_value < 0.0 ? -event_value : event_value) / num_steps;
  const double floor = min_saturation > 1.0 ? min_saturation : 1.0;
  return per_step > floor ? per_step : floor;
}

}  // namespace evfs

#endif  // EVFS_SCENE_EVENT_MODEL_H_
