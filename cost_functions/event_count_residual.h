// d_k = log(I_k + b) - C_on · N_on,k + C_off · N_off,k,   k = 0 … K-1
// r_k = (d_k - mean_j d_j) / C,   C = (C_on + C_off) / 2
//
// The sensor's Eq. 1 (paper) for one pixel over K frames: N_on,k and N_off,k count its ON and
// OFF events from the first frame to frame k, and its reference level, the log intensity of its
// last event, is where it started plus C_on · N_on,k - C_off · N_off,k. Its log intensity stays
// within (-C_off, C_on) of that level, so d_k is the level it started from plus that distance:
// the same for every k up to a spread of about one threshold. The residual is d_k about its
// mean over the pixel's frames (the unknown starting level taken out), in events.
// Calibration (solver/event_model_calibration.h) fits b, C_on and C_off to it.
#ifndef EVFS_COST_FUNCTIONS_EVENT_COUNT_RESIDUAL_H_
#define EVFS_COST_FUNCTIONS_EVENT_COUNT_RESIDUAL_H_

#include <ceres/dynamic_autodiff_cost_function.h>

#include <cmath>
#include <utility>
#include <vector>

namespace evfs {

/// One pixel over K >= 2 frames. Parameter blocks: log b, C_on, C_off, each of size 1 (b enters
/// as its logarithm: it ranges over decades). With `tied_thresholds` C_off is not read and C_on
/// stands for both. Residuals: K, in events.
struct EventCountResidual {
  EventCountResidual(std::vector<double> intensities, std::vector<double> events_on,
                     std::vector<double> events_off, std::vector<double> last_polarity,
                     bool tied_thresholds)
      : intensities(std::move(intensities)),
        events_on(std::move(events_on)),
        events_off(std::move(events_off)),
        last_polarity(std::move(last_polarity)),
        tied_thresholds(tied_thresholds) {}

  template <typename T>
  bool operator()(T const* const* parameters, T* residuals) const {
    using std::exp;
    using std::log;
    const T offset = exp(parameters[0][0]);
    const T on = parameters[1][0];
    const T off = tied_thresholds ? on : parameters[2][0];
    const int frames = static_cast<int>(intensities.size());
    T mean(0.0);
    for (int k = 0; k < frames; ++k) {
      residuals[k] = log(T(intensities[k]) + offset) - on * events_on[k] + off * events_off[k];
      if (last_polarity[k] > 0.0) residuals[k] -= on * 0.5;
      if (last_polarity[k] < 0.0) residuals[k] += off * 0.5;
      mean += residuals[k];
    }
    mean /= T(frames);
    const T threshold = (on + off) * 0.5;
    for (int k = 0; k < frames; ++k) residuals[k] = (residuals[k] - mean) / threshold;
    return true;
  }

  /// `intensities[k]` the pixel in frame k, `events_on[k]`, `events_off[k]` its events from the
  /// first frame to frame k (both 0 at k = 0), `last_polarity[k]` the sign of its last event
  /// before frame k (0: none).
  static ceres::CostFunction* Create(std::vector<double> intensities, std::vector<double> events_on,
                                     std::vector<double> events_off,
                                     std::vector<double> last_polarity, bool tied_thresholds) {
    const int frames = static_cast<int>(intensities.size());
    auto* cost = new ceres::DynamicAutoDiffCostFunction<EventCountResidual, 4>(
        new EventCountResidual(std::move(intensities), std::move(events_on), std::move(events_off),
                               std::move(last_polarity), tied_thresholds));
    for (int i = 0; i < 3; ++i) cost->AddParameterBlock(1);
    cost->SetNumResiduals(frames);
    return cost;
  }

  const std::vector<double> intensities;
  const std::vector<double> events_on;
  const std::vector<double> events_off;
  const std::vector<double> last_polarity;
  const bool tied_thresholds;
};

}  // namespace evfs

#endif  // EVFS_COST_FUNCTIONS_EVENT_COUNT_RESIDUAL_H_
