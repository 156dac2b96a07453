#include "evfs/scene/exposure_blur.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/events/binning.h"
#include "evfs/events/noise_filter.h"

namespace evfs {

bool ExposureBlurOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check
      .Check(std::isfinite(contrast_threshold) && contrast_threshold > 0.0,
             "contrast_threshold must be positive")
      .Check(std::isfinite(log_offset) && log_offset > 0.0, "log_offset must be positive")
      .Check(std::isfinite(noise_multiple) && noise_multiple >= 0.0,
             "noise_multiple must be 0 or more")
      .NonNegative("flicker_min_reversals", flicker_min_reversals)
      .NonNegative("hot_pixel_factor", hot_pixel_factor)
      .Check(std::isfinite(support_window_ms) && support_window_ms >= 0.0,
             "support_window_ms must be 0 or more");
  return check.Passed(error);
}

double NoiseSigma(const Image& frame, bool leave_out_clipped) {
  const int64_t rows = frame.rows(), cols = frame.cols();
  if (rows < 3 || cols < 3) return 0.0;
  const auto clipped_around = [&frame](int64_t y, int64_t x) {
    for (int64_t dy = -1; dy <= 1; ++dy) {
      for (int64_t dx = -1; dx <= 1; ++dx) {
        if (IsClippedLevel(frame(y + dy, x + dx))) return true;
      }
    }
    return false;
  };
  double sum = 0.0;
  int64_t counted = 0;
  for (int64_t y = 1; y + 1 < rows; ++y) {
    for (int64_t x = 1; x + 1 < cols; ++x) {
      if (leave_out_clipped && clipped_around(y, x)) continue;
      ++counted;
      const double response = frame(y - 1, x - 1) - 2.0 * frame(y - 1, x) + frame(y - 1, x + 1) -
                              2.0 * frame(y, x - 1) + 4.0 * frame(y, x) - 2.0 * frame(y, x + 1) +
                              frame(y + 1, x - 1) - 2.0 * frame(y + 1, x) + frame(y + 1, x + 1);
      sum += std::abs(response);
    }
  }
  constexpr double kHalfPi = 1.5707963267948966;
  if (counted == 0) return 0.0;
  return std::sqrt(kHalfPi) * sum / (6.0 * static_cast<double>(counted));
}

ExposureBlurEstimate ExposureBlur(const Image& frame, const EventStream& all_events,
                                  int64_t begin_ns, int64_t end_ns,
                                  const ExposureBlurOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("exposure blur: " + error);
  if (end_ns <= begin_ns) throw InvalidArgumentError("exposure blur: the exposure is empty");
  const int width = all_events.width(), height = all_events.height();
  if (frame.rows() != height || frame.cols() != width) {
    throw InvalidArgumentError("exposure blur: the frame is " + std::to_string(frame.cols()) + "x" +
                               std::to_string(frame.rows()) + " but the event sensor is " +
                               std::to_string(width) + "x" + std::to_string(height));
  }
  const size_t pixels = static_cast<size_t>(width) * height;
  const int64_t end_exclusive = end_ns + 1;
  const EventStream supported =
      WithoutUnsupportedEvents(all_events.Slice(begin_ns, end_exclusive),
                               static_cast<int64_t>(std::llround(options.support_window_ms * 1e6)));
  const EventStream& events = supported;
  // Hot and flickering pixels tell nothing about motion (Scene leaves their events out too).
  std::vector<uint8_t> ignored(pixels, 0);
  for (const int32_t p :
       MeasurePixelActivity(events, begin_ns, end_exclusive, options.hot_pixel_factor).hot_pixels)
    ignored[static_cast<size_t>(p)] = 1;
  for (const int32_t p :
       FindFlickeringPixels(events, begin_ns, end_exclusive, options.flicker_min_reversals))
    ignored[static_cast<size_t>(p)] = 1;

  // Per pixel, the time integral of exp(C · N(t)) over the exposure, and exp(C · N(t_mid)),
  // walking the events in time order: N changes only at events.
  const double duration = static_cast<double>(end_ns - begin_ns);
  const int64_t mid_ns = begin_ns + (end_ns - begin_ns) / 2;
  std::vector<int32_t> count(pixels, 0);
  std::vector<int64_t> since_ns(pixels, begin_ns);
  std::vector<double> integral(pixels, 0.0), at_mid(pixels, 1.0);
  std::vector<uint8_t> mid_seen(pixels, 0);
  ExposureBlurEstimate estimate;
  const double c = options.contrast_threshold;
  const auto advance = [&](size_t p, int64_t to_ns) {
    const double level = std::exp(c * count[p]);
    if (!mid_seen[p] && to_ns > mid_ns) {
      at_mid[p] = level;
      mid_seen[p] = 1;
    }
    integral[p] += level * static_cast<double>(to_ns - since_ns[p]);
    since_ns[p] = to_ns;
  };
  const size_t last = events.LowerBound(end_exclusive);
  for (size_t i = events.LowerBound(begin_ns); i < last; ++i) {
    if (events.x(i) >= width || events.y(i) >= height) continue;
    const size_t p = static_cast<size_t>(events.y(i)) * width + events.x(i);
    if (ignored[p]) continue;
    advance(p, events.t_ns(i));
    count[p] += events.polarity(i) > 0 ? 1 : -1;
    ++estimate.events;
  }
  double sum_squares = 0.0;
  for (size_t p = 0; p < pixels; ++p) {
    if (ignored[p] || since_ns[p] == begin_ns) continue;  // no event: r = 1, no blur
    advance(p, end_ns);
    const double r = integral[p] / (duration * at_mid[p]);
    const double blur = (frame.data()[p] + options.log_offset) * (1.0 - 1.0 / r);
    sum_squares += blur * blur;
  }
  estimate.predicted_blur_rms = std::sqrt(sum_squares / static_cast<double>(pixels));
  estimate.noise_sigma = NoiseSigma(frame);
  estimate.blurred = estimate.predicted_blur_rms > options.noise_multiple * estimate.noise_sigma;
  char line[200];
  std::snprintf(line, sizeof(line),
                "%s: the events inside the exposure predict a blur of %.4f RMS against the "
                "frame's noise %.4f",
                estimate.blurred ? "blurred" : "sharp", estimate.predicted_blur_rms,
                estimate.noise_sigma);
  estimate.description = line;
  return estimate;
}

}  // namespace evfs
