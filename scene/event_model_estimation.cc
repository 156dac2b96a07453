#include "evfs/scene/event_model_estimation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "evfs/core/option_checker.h"

namespace evfs {
namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Net signed event count per pixel over the latent steps [first, last).
std::vector<double> NetEventCount(const Scene& scene, int first, int last) {
  std::vector<double> net(static_cast<size_t>(scene.height) * scene.width, 0.0);
  for (int k = 0; k < scene.events.num_frames(); ++k) {
    const EventFrameSpan& span = scene.events.span(k);
    if (span.latent_first < first || span.latent_last > last) continue;
    const float* values = scene.events.frame_data(k);
    for (size_t p = 0; p < net.size(); ++p) net[p] += values[p];
  }
  return net;
}

}  // namespace

bool EventModelEstimationOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.Check(alpha_times_change > 0.0 && assumed_contrast_threshold > 0.0 &&
                  assumed_linear_change > 0.0 && min_pixels >= 1,
              "event model estimation options must be positive");
  return check.Passed(error);
}

EventModelEstimate EstimateEventModel(const Scene& scene, const EventModelParams& model,
                                      const EventModelEstimationOptions& options) {
  EventModelEstimate estimate;

  // The first and last sharp frames, if they are distinct, bracket the events between them:
  // the change of g per net event there is what one event stands for, measured directly. Without
  // two sharp frames, the first and last blurred ones stand at the middle of their exposures: a
  // frame averaged over its exposure is close to the scene at its middle, and the median over
  // the pixels reads through what the averaging smooths at moving edges.
  struct Anchor {
    const FrameObservation* frame = nullptr;
    int latent = 0;
  };
  const auto bracket = [&scene](bool sharp_only, Anchor* first, Anchor* last) {
    for (const FrameObservation& frame : scene.frames) {
      const bool sharp = frame.latent_first == frame.latent_last;
      if (sharp_only && !sharp) continue;
      const int latent = (frame.latent_first + frame.latent_last) / 2;
      if (!first->frame || latent < first->latent) *first = {&frame, latent};
      if (!last->frame || latent > last->latent) *last = {&frame, latent};
    }
    return first->frame && last->frame && first->latent < last->latent;
  };
  Anchor first, last;
  bool blurred_frames = false;
  if (!bracket(true, &first, &last)) {
    first = last = Anchor();
    blurred_frames = bracket(false, &first, &last);
  }
  int pixels_used = 0;
  double change = 0.0;
  double change_off = 0.0;  // measured per polarity: Δg of an OFF event (change: of an ON one)
  if (first.frame && last.frame && first.latent < last.latent) {
    const std::vector<double> net = NetEventCount(scene, first.latent, last.latent);
    std::vector<double> per_on_event, per_off_event;
    for (size_t p = 0; p < net.size(); ++p) {
      if (net[p] == 0.0) continue;
      const double frame_change = IntensityTransform(last.frame->image.data()[p], model) -
                                  IntensityTransform(first.frame->image.data()[p], model);
      if (frame_change * net[p] <= 0.0) continue;  // frames and events disagree: noise, occlusion
      (net[p] > 0.0 ? per_on_event : per_off_event).push_back(frame_change / net[p]);
    }
    pixels_used = static_cast<int>(per_on_event.size() + per_off_event.size());
    if (pixels_used >= options.min_pixels) {
      estimate.estimated_from_frames = true;
      if (options.per_polarity && static_cast<int>(per_on_event.size()) >= options.min_pixels &&
          static_cast<int>(per_off_event.size()) >= options.min_pixels) {
        change = Median(per_on_event);
        change_off = Median(per_off_event);
      } else {
        std::vector<double> per_event = std::move(per_on_event);
        per_event.insert(per_event.end(), per_off_event.begin(), per_off_event.end());
        change = Median(std::move(per_event));
      }
    }
  }

  if (!estimate.estimated_from_frames) {
    change = model.model == EventModel::kLog ? options.assumed_contrast_threshold
                                             : options.assumed_linear_change;
  }
  estimate.change_per_event = change;
  estimate.alpha = options.alpha_times_change / change;

  char line[256];
  if (change_off > 0.0) {
    estimate.off_alpha_ratio = change / change_off;
    std::snprintf(line, sizeof(line),
                  "change per event ON %.4f, OFF %.4f (measured between the %sframes at %d "
                  "pixels), alpha %.2f, OFF %.2f",
                  change, change_off, blurred_frames ? "blurred " : "", pixels_used, estimate.alpha,
                  estimate.alpha * estimate.off_alpha_ratio);
  } else if (estimate.estimated_from_frames) {
    std::snprintf(line, sizeof(line),
                  "change per event %.4f (measured between the %sframes at %d pixels), "
                  "alpha %.2f",
                  estimate.change_per_event, blurred_frames ? "blurred " : "", pixels_used,
                  estimate.alpha);
  } else {
    std::snprintf(line, sizeof(line),
                  "change per event %.4f (assumed: no two sharp frames to measure it), "
                  "alpha %.2f",
                  estimate.change_per_event, estimate.alpha);
  }
  estimate.description = line;
  return estimate;
}

}  // namespace evfs
