#include "evfs/solver/step_ramps.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace evfs {
namespace {

// The event frames' times at each pixel, one list per sign, ascending (a CSR layout: pixel p's
// times are times[begin[p] .. begin[p + 1])).
struct FiringTimes {
  std::vector<int64_t> begin;
  std::vector<double> times;

  // Time from t to the nearest entry of pixel p, or +inf when p has none.
  double Nearest(int64_t p, double t) const {
    const auto first = times.begin() + begin[p];
    const auto last = times.begin() + begin[p + 1];
    const auto it = std::lower_bound(first, last, t);
    double nearest = std::numeric_limits<double>::infinity();
    if (it != last) nearest = *it - t;
    if (it != first) nearest = std::min(nearest, t - *(it - 1));
    return nearest;
  }
};

// The times of the event frames whose value at a pixel has sign `sign`.
FiringTimes TimesOfSign(const EventFrames& events, const std::vector<double>& frame_times,
                        int sign) {
  const int64_t pixels = events.pixels_per_frame();
  FiringTimes firing;
  firing.begin.assign(pixels + 1, 0);
  const auto fires = [&](float value) { return sign > 0 ? value > 0.0f : value < 0.0f; };
  for (int k = 0; k < events.num_frames(); ++k) {
    const float* values = events.frame_data(k);
    for (int64_t p = 0; p < pixels; ++p) firing.begin[p + 1] += fires(values[p]) ? 1 : 0;
  }
  for (int64_t p = 0; p < pixels; ++p) firing.begin[p + 1] += firing.begin[p];
  firing.times.resize(firing.begin[pixels]);
  std::vector<int64_t> next(firing.begin.begin(), firing.begin.end() - 1);
  for (int k = 0; k < events.num_frames(); ++k) {
    const float* values = events.frame_data(k);
    for (int64_t p = 0; p < pixels; ++p) {
      if (fires(values[p])) firing.times[next[p]++] = frame_times[k];
    }
  }
  for (int64_t p = 0; p < pixels; ++p) {
    std::sort(firing.times.begin() + firing.begin[p], firing.times.begin() + firing.begin[p + 1]);
  }
  return firing;
}

}  // namespace

std::vector<double> EventTimeSlope(const Scene& scene) {
  const EventFrames& events = scene.events;
  const int height = scene.height;
  const int width = scene.width;
  const int64_t pixels = static_cast<int64_t>(height) * width;
  const std::vector<int64_t>& latent_ns = scene.latent_timestamps_ns();
  const double window_ns =
      latent_ns.size() > 1 ? static_cast<double>(latent_ns.back() - latent_ns.front()) : 0.0;

  std::vector<double> frame_times(events.num_frames());
  for (int k = 0; k < events.num_frames(); ++k) {
    frame_times[k] = 0.5 * (static_cast<double>(events.span(k).t_first_ns) +
                            static_cast<double>(events.span(k).t_last_ns));
  }
  const FiringTimes on = TimesOfSign(events, frame_times, +1);
  const FiringTimes off = TimesOfSign(events, frame_times, -1);

  const double unseen = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> slope(pixels, unseen);
  std::vector<double> samples;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int64_t p = static_cast<int64_t>(y) * width + x;
      samples.clear();
      for (const FiringTimes* firing : {&on, &off}) {
        // Time to the nearer of two neighbours, at most the window.
        const auto nearer = [&](bool has_a, int64_t a, bool has_b, int64_t b, double t) {
          double nearest = window_ns;
          if (has_a) nearest = std::min(nearest, firing->Nearest(a, t));
          if (has_b) nearest = std::min(nearest, firing->Nearest(b, t));
          return nearest;
        };
        for (int64_t i = firing->begin[p]; i < firing->begin[p + 1]; ++i) {
          const double t = firing->times[i];
          const double dx = nearer(x > 0, p - 1, x + 1 < width, p + 1, t);
          const double dy = nearer(y > 0, p - width, y + 1 < height, p + width, t);
          samples.push_back(std::hypot(dx, dy));
        }
      }
      if (samples.empty()) continue;
      const auto middle = samples.begin() + static_cast<std::ptrdiff_t>(samples.size() / 2);
      std::nth_element(samples.begin(), middle, samples.end());
      slope[p] = *middle;
    }
  }

  // Pixels without events: the fired pixels around them, else no motion seen.
  constexpr int kFillRadius = 2;
  std::vector<double> filled = slope;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int64_t p = static_cast<int64_t>(y) * width + x;
      if (!std::isnan(slope[p])) continue;
      double sum = 0.0;
      int count = 0;
      for (int yy = std::max(0, y - kFillRadius); yy <= std::min(height - 1, y + kFillRadius);
           ++yy) {
        for (int xx = std::max(0, x - kFillRadius); xx <= std::min(width - 1, x + kFillRadius);
             ++xx) {
          const double value = slope[static_cast<int64_t>(yy) * width + xx];
          if (std::isnan(value)) continue;
          sum += value;
          ++count;
        }
      }
      filled[p] = count > 0 ? sum / count : window_ns;
    }
  }
  return filled;
}

int64_t RampSteps(const Scene& scene, const LatentLayout& layout, double ramp_px, Video* latent) {
  if (!(ramp_px > 0.0)) return 0;
  const int frames = layout.num_latent_frames();
  const int64_t pixels = layout.pixels_per_frame();
  if (frames < 2) return 0;
  const std::vector<double> slope = EventTimeSlope(scene);
  std::vector<double> times(frames);
  for (int t = 0; t < frames; ++t) times[t] = static_cast<double>(latent->timestamp_ns(t));
  // The middle of latent frames [first, last] in time.
  const auto middle = [&](int first, int last) { return 0.5 * (times[first] + times[last]); };
  // in_exposure[t]: the step from latent frame t to t + 1 lies inside a blurred frame's exposure.
  std::vector<bool> in_exposure(frames, false);
  for (const FrameObservation& frame : scene.frames) {
    for (int t = frame.latent_first; t < frame.latent_last; ++t) in_exposure[t] = true;
  }

  int64_t ramped = 0;
  std::vector<double> before(frames);  // a pixel's solved time series
  for (int64_t p = 0; p < pixels; ++p) {
    if (layout.segment_at(0, p) < 0) continue;  // not in the problem
    bool held = false;
    for (int t = 0; t < frames && !held; ++t)
      held = layout.segment(layout.segment_at(t, p)).constant;
    if (held) continue;  // a ring pixel keeps its initial values
    for (int t = 0; t < frames; ++t) before[t] = latent->frame_data(t)[p];
    const double ramp = ramp_px * slope[p];
    int first = 0;  // first frame of the current segment
    while (first < frames) {
      const int64_t segment = layout.segment_at(first, p);
      const int last = layout.segment(segment).last;
      if (last + 1 >= frames) break;
      // The step between frames `last` and `last + 1` becomes a ramp over [begin, step]: it
      // ends where the event says the change was complete.
      const double step = 0.5 * (times[last] + times[last + 1]);
      const double begin = std::max(step - ramp, middle(first, last));
      const double change = before[last + 1] - before[last];
      bool touched = false;
      if (begin < step && change != 0.0 && !in_exposure[last]) {
        for (int t = first; t <= last; ++t) {
          if (times[t] <= begin) continue;
          latent->frame_data(t)[p] += change * (times[t] - begin) / (step - begin);
          touched = true;
        }
      }
      ramped += touched ? 1 : 0;
      first = last + 1;
    }
  }
  return ramped;
}

}  // namespace evfs
