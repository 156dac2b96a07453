#include "evfs/baselines/complementary_filter.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "evfs/baselines/event_integration.h"
#include "evfs/core/error.h"
#include "evfs/core/time.h"

namespace evfs {
namespace {

// Moves `state` towards `target` as dt of the filter's decay: L̂ = L_F + e^{−α dt} (L̂ − L_F).
// dt = 0 leaves it unchanged, also for α = +infinity (where e^{−α·0} would be NaN).
void Decay(const Image& target, double cutoff_rad_per_s, int64_t dt_ns, Image* state) {
  if (dt_ns <= 0) return;
  const double keep = std::exp(-cutoff_rad_per_s * NanosecondsToSeconds(dt_ns));
  *state = target + keep * (*state - target);
}

}  // namespace

Video ComplementaryFilter(const Scene& scene, const BaselineOptions& options,
                          double contrast_threshold) {
  CheckContrastThreshold(contrast_threshold, "the complementary filter");
  if (scene.frames.empty()) {
    throw InvalidArgumentError("the complementary filter needs a frame observation");
  }
  const IntegrationDomain log = IntegrationDomain::kLog;
  // Frames in order of the latent frame they arrive at (the centre of the exposure, doubled to
  // stay an integer).
  std::vector<const FrameObservation*> frames;
  for (const FrameObservation& frame : scene.frames) frames.push_back(&frame);
  const auto arrival2 = [](const FrameObservation* f) { return f->latent_first + f->latent_last; };
  std::stable_sort(frames.begin(), frames.end(),
                   [&](const auto* a, const auto* b) { return arrival2(a) < arrival2(b); });
  std::vector<Image> log_frames;
  for (const FrameObservation* frame : frames) {
    log_frames.push_back(ImageToDomain(frame->image, log, options.log_offset));
  }

  // The event frame covering each latent step (spans tile the timeline), -1 for none.
  const std::vector<int64_t>& latent_ns = scene.latent_timestamps_ns();
  const int num_latent = static_cast<int>(latent_ns.size());
  std::vector<int> step_frame(std::max(num_latent - 1, 0), -1);
  for (int k = 0; k < scene.events.num_frames(); ++k) {
    const EventFrameSpan& span = scene.events.span(k);
    for (int s = span.latent_first; s < span.latent_last; ++s) step_frame[s] = k;
  }

  Video latent(scene.height, scene.width, num_latent);
  int current = 0;  // the latest frame that has arrived (the first one before any has)
  Image state = log_frames[0];
  const auto emit = [&](int t) {
    latent.set_timestamp_ns(t, latent_ns[t]);
    latent.frame(t) = ImageFromDomain(state, log, options.log_offset, options.clamp_to_unit_range);
  };
  emit(0);
  for (int s = 0; s + 1 < num_latent; ++s) {
    while (current + 1 < static_cast<int>(frames.size()) &&
           arrival2(frames[current + 1]) <= 2 * s) {
      ++current;
    }
    const Image& target = log_frames[current];
    const int k = step_frame[s];
    if (k < 0) {
      Decay(target, options.cutoff_rad_per_s, latent_ns[s + 1] - latent_ns[s], &state);
    } else {
      const EventFrameSpan& span = scene.events.span(k);
      const int steps = span.latent_last - span.latent_first;
      int64_t event_ns = latent_ns[s] + (latent_ns[s + 1] - latent_ns[s]) / 2;
      if (steps == 1 && span.num_events > 0) {
        event_ns = std::clamp(span.t_first_ns + (span.t_last_ns - span.t_first_ns) / 2,
                              latent_ns[s], latent_ns[s + 1]);
      }
      Decay(target, options.cutoff_rad_per_s, event_ns - latent_ns[s], &state);
      const Eigen::Map<const Eigen::ArrayXf> values(scene.events.frame_data(k), state.size());
      Eigen::Map<Eigen::ArrayXd>(state.data(), state.size()) +=
          (contrast_threshold / steps) * values.cast<double>();
      Decay(target, options.cutoff_rad_per_s, latent_ns[s + 1] - event_ns, &state);
    }
    emit(s + 1);
  }
  return latent;
}

}  // namespace evfs
