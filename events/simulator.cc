#include "evfs/events/simulator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/core/time.h"

namespace evfs {
namespace {

/// ESIM's floor on a drawn contrast threshold: a smaller one would fire on every flicker.
constexpr double kMinContrastThreshold = 0.01;

/// Marks a pixel that has not emitted an event since the last Reset.
constexpr int64_t kNeverFired = std::numeric_limits<int64_t>::min();

/// Offset between the seeds of the threshold and the noise generators (2^64 / golden ratio), so
/// that the two streams of draws are unrelated.
constexpr uint64_t kNoiseSeedOffset = 0x9E3779B97F4A7C15ull;

/// Offsets of the leak and hot pixel generators' seeds (further multiples of the same constant),
/// so that turning an effect on leaves the thresholds and the noise of the others unchanged.
constexpr uint64_t kLeakSeedOffset = 2 * kNoiseSeedOffset;
constexpr uint64_t kHotPixelSeedOffset = 3 * kNoiseSeedOffset;       // which pixels are hot
constexpr uint64_t kHotPixelEventSeedOffset = 4 * kNoiseSeedOffset;  // when they fire

/// v2e's dark offset: 20 DN of 8-bit intensity added before the cutoff is scaled by intensity,
/// so a black pixel keeps 20/275 of the full cutoff.
constexpr double kBandwidthDarkOffset = 20.0 / 255.0;

/// Largest 2π · cutoff · Δt of one step of the low-pass (BandwidthMaxStepNs).
constexpr double kMaxLowPassStep = 0.25;

constexpr double kTwoPi = 6.283185307179586476925;

/// Largest sensor side: event coordinates are uint16.
constexpr int kMaxSensorSide = 65536;

std::vector<double> DrawThresholds(double nominal, double sigma, size_t count, Random* random) {
  std::vector<double> thresholds(count, std::max(kMinContrastThreshold, nominal));
  if (sigma > 0.0) {
    for (double& threshold : thresholds) {
      threshold = std::max(kMinContrastThreshold, random->Normal(nominal, sigma));
    }
  }
  return thresholds;
}

/// Events per pixel per second that no change of light causes: background noise, hot pixels
/// and leak (at its nominal rate).
double UnsignalledRateHz(const SimulatorOptions& options) {
  return options.noise_rate_hz + options.hot_pixel_fraction * options.hot_pixel_rate_hz +
         options.leak_rate_hz;
}

/// Expected background noise, hot pixel and leak events of `num_pixels` pixels over
/// `interval_ns`, in double: the product overflows int64 for absurd rates, and it is only
/// compared.
double ExpectedNoiseEvents(const SimulatorOptions& options, double num_pixels, double interval_ns) {
  return UnsignalledRateHz(options) * num_pixels * interval_ns / kNanosecondsPerSecond;
}

/// "noise_rate_hz = 10" or, with hot pixels or leak, the rate of all three.
std::string UnsignalledRateText(const SimulatorOptions& options) {
  if (options.hot_pixel_fraction == 0.0 && options.leak_rate_hz == 0.0) {
    return "noise_rate_hz = " + std::to_string(options.noise_rate_hz);
  }
  return "noise, hot pixels and leak at " + std::to_string(UnsignalledRateHz(options)) +
         " Hz per pixel";
}

/// `count` distinct indices of [0, n), ascending (a partial Fisher–Yates shuffle).
std::vector<int32_t> DrawDistinctPixels(size_t count, size_t n, Random* random) {
  std::vector<int32_t> indices(n);
  for (size_t i = 0; i < n; ++i) indices[i] = static_cast<int32_t>(i);
  for (size_t i = 0; i < count; ++i) {
    std::swap(indices[i], indices[i + random->UniformIndex(n - i)]);
  }
  indices.resize(count);
  std::sort(indices.begin(), indices.end());
  return indices;
}

/// Throws when `expected` events exceed options.max_events; `what` says over what.
void CheckEventBudget(const SimulatorOptions& options, double expected, const std::string& what) {
  if (expected > static_cast<double>(options.max_events)) {
    char count[32];
    std::snprintf(count, sizeof(count), "%.3g", expected);
    throw InvalidArgumentError(
        "simulator: " + what + " " + count +
        " events, more than max_events = " + std::to_string(options.max_events));
  }
}

}  // namespace

int64_t SimulatorOptions::BandwidthMaxStepNs() const {
  if (cutoff_hz <= 0.0) return kNanosecondsPerSecond;
  return std::max<int64_t>(
      1, static_cast<int64_t>(kMaxLowPassStep / (kTwoPi * cutoff_hz) * kNanosecondsPerSecond));
}

bool SimulatorOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.Positive("contrast_threshold_pos", contrast_threshold_pos)
      .Positive("contrast_threshold_neg", contrast_threshold_neg)
      .NonNegative("threshold_sigma", threshold_sigma)
      .Require(refractory_period_ns >= 0, "refractory_period_ns", ">= 0")
      .NonNegative("noise_rate_hz", noise_rate_hz)
      .Positive("log_eps", log_eps)
      .NonNegative("leak_rate_hz", leak_rate_hz)
      .Require(cutoff_hz >= 0.0 && cutoff_hz <= 1e6, "cutoff_hz", "in [0, 1e6] Hz (0: no low-pass)")
      .NonNegative("leak_jitter_fraction", leak_jitter_fraction)
      .Require(hot_pixel_fraction >= 0.0 && hot_pixel_fraction <= 1.0, "hot_pixel_fraction",
               "in [0, 1]")
      .Positive("hot_pixel_rate_hz", hot_pixel_rate_hz)
      .Require(max_events > 0, "max_events", "> 0");
  return check.Passed(error);
}

EventSimulator::EventSimulator(int height, int width, const SimulatorOptions& options)
    : height_(height),
      width_(width),
      options_(options),
      noise_random_(options.seed + kNoiseSeedOffset),
      hot_pixel_random_(options.seed + kHotPixelEventSeedOffset) {
  std::string error;
  OptionChecker size_check;
  size_check.InRange("height", height, 1, kMaxSensorSide)
      .InRange("width", width, 1, kMaxSensorSide);
  if (!options.IsValid(&error) || !size_check.Passed(&error)) {
    throw InvalidArgumentError("EventSimulator: " + error);
  }
  const size_t num_pixels = static_cast<size_t>(height) * width;
  Random threshold_random(options.seed);
  threshold_pos_ = DrawThresholds(options.contrast_threshold_pos, options.threshold_sigma,
                                  num_pixels, &threshold_random);
  threshold_neg_ = DrawThresholds(options.contrast_threshold_neg, options.threshold_sigma,
                                  num_pixels, &threshold_random);
  if (options.leak_rate_hz > 0.0) {
    Random leak_random(options.seed + kLeakSeedOffset);
    leak_per_s_.resize(num_pixels);
    leak_start_.resize(num_pixels);
    for (size_t p = 0; p < num_pixels; ++p) {
      const double rate_hz =
          std::max(0.0, leak_random.Normal(options.leak_rate_hz,
                                           options.leak_jitter_fraction * options.leak_rate_hz));
      leak_per_s_[p] = rate_hz * threshold_pos_[p];
      leak_start_[p] = leak_random.Uniform() * threshold_pos_[p];
    }
  }
  if (options.hot_pixel_fraction > 0.0) {
    const size_t count = static_cast<size_t>(std::llround(options.hot_pixel_fraction * num_pixels));
    Random hot_pixel_choice(options.seed + kHotPixelSeedOffset);
    hot_pixels_ = DrawDistinctPixels(count, num_pixels, &hot_pixel_choice);
  }
}

void EventSimulator::CheckFrame(const Image& frame, const char* caller) const {
  if (frame.rows() != height_ || frame.cols() != width_) {
    throw InvalidArgumentError(std::string("EventSimulator::") + caller + ": frame of " +
                               std::to_string(frame.cols()) + "x" + std::to_string(frame.rows()) +
                               ", sensor is " + std::to_string(width_) + "x" +
                               std::to_string(height_));
  }
  if (!frame.isFinite().all() || (frame < 0.0).any()) {
    throw InvalidArgumentError(std::string("EventSimulator::") + caller +
                               ": intensities must be finite and >= 0");
  }
}

void EventSimulator::Reset(const Image& first_frame, int64_t t_ns) {
  CheckFrame(first_frame, "Reset");
  const size_t num_pixels = threshold_pos_.size();
  log_intensity_.resize(num_pixels);
  for (size_t p = 0; p < num_pixels; ++p) {
    log_intensity_[p] = std::log(first_frame.data()[p] + options_.log_eps);
  }
  reference_ = log_intensity_;
  last_event_ns_.assign(num_pixels, kNeverFired);
  leak_ = leak_start_;
  noise_random_ = Random(options_.seed + kNoiseSeedOffset);
  hot_pixel_random_ = Random(options_.seed + kHotPixelEventSeedOffset);
  t_ns_ = t_ns;
  started_ = true;
}

void EventSimulator::AddSignalEvents(const Image& next_frame, int64_t t_ns,
                                     std::vector<PendingEvent>* out) {
  const double interval_ns = static_cast<double>(t_ns - t_ns_);
  const double interval_s = interval_ns / kNanosecondsPerSecond;
  const int64_t num_pixels = static_cast<int64_t>(log_intensity_.size());
  const bool leaks = !leak_.empty();
  for (int64_t p = 0; p < num_pixels; ++p) {
    // The signal compared with the reference is L plus the leak so far (the reference falling
    // is the signal rising); both are linear in time between the frames.
    const double leak_before = leaks ? leak_[p] : 0.0;
    const double leak_after = leaks ? leak_before + leak_per_s_[p] * interval_s : 0.0;
    if (leaks) leak_[p] = leak_after;
    const double log_before = log_intensity_[p] + leak_before;
    double log_after_frame = std::log(next_frame.data()[p] + options_.log_eps);
    if (options_.cutoff_hz > 0.0) {
      // v2e's photoreceptor: the cutoff scales with the new intensity (plus the dark offset).
      const double intensity =
          (next_frame.data()[p] + kBandwidthDarkOffset) / (1.0 + kBandwidthDarkOffset);
      const double step = std::min(1.0, kTwoPi * options_.cutoff_hz * intensity * interval_s);
      log_after_frame = log_intensity_[p] + step * (log_after_frame - log_intensity_[p]);
    }
    log_intensity_[p] = log_after_frame;
    const double log_after = log_after_frame + leak_after;
    if (log_after == log_before) continue;
    // The signal moves monotonically between the frames, and |signal - reference| < C held at
    // the previous frame, so only crossings in the direction of the change are possible.
    const int8_t polarity = log_after > log_before ? 1 : -1;
    const double threshold = polarity > 0 ? threshold_pos_[p] : threshold_neg_[p];
    double& reference = reference_[p];
    while (polarity * (log_after - reference) >= threshold) {
      reference += polarity * threshold;
      const double fraction =
          std::clamp((reference - log_before) / (log_after - log_before), 0.0, 1.0);
      const int64_t offset_ns = std::llround(fraction * interval_ns);
      out->push_back({t_ns_ + std::clamp<int64_t>(offset_ns, 1, t_ns - t_ns_),
                      static_cast<int32_t>(p), polarity});
    }
  }
}

void EventSimulator::AddNoiseEvents(int64_t t_ns, std::vector<PendingEvent>* out) {
  if (options_.noise_rate_hz <= 0.0) return;
  // Independent Poisson processes per pixel are one Poisson process over the sensor at the
  // summed rate whose events land on uniformly drawn pixels.
  const uint64_t num_pixels = log_intensity_.size();
  const double rate_per_ns =
      options_.noise_rate_hz * static_cast<double>(num_pixels) / kNanosecondsPerSecond;
  const double interval_ns = static_cast<double>(t_ns - t_ns_);
  for (double elapsed_ns = noise_random_.Exponential(rate_per_ns); elapsed_ns <= interval_ns;
       elapsed_ns += noise_random_.Exponential(rate_per_ns)) {
    // A Poisson draw can exceed its mean; the budget holds for the events actually drawn too.
    if (static_cast<int64_t>(out->size()) >= options_.max_events) {
      CheckEventBudget(options_, static_cast<double>(out->size()) + 1.0,
                       "the noise between two frames makes");
    }
    const int64_t offset_ns = std::clamp<int64_t>(std::llround(elapsed_ns), 1, t_ns - t_ns_);
    const int32_t pixel = static_cast<int32_t>(noise_random_.UniformIndex(num_pixels));
    out->push_back({t_ns_ + offset_ns, pixel, noise_random_.Sign()});
  }
}

void EventSimulator::AddHotPixelEvents(int64_t t_ns, std::vector<PendingEvent>* out) {
  if (hot_pixels_.empty()) return;
  // The budget was checked with the noise; as there, the events actually drawn are bounded too.
  const double rate_per_ns = options_.hot_pixel_rate_hz / kNanosecondsPerSecond;
  const double interval_ns = static_cast<double>(t_ns - t_ns_);
  for (const int32_t pixel : hot_pixels_) {
    for (double elapsed_ns = hot_pixel_random_.Exponential(rate_per_ns); elapsed_ns <= interval_ns;
         elapsed_ns += hot_pixel_random_.Exponential(rate_per_ns)) {
      if (static_cast<int64_t>(out->size()) >= options_.max_events) {
        CheckEventBudget(options_, static_cast<double>(out->size()) + 1.0,
                         "the hot pixels between two frames make");
      }
      const int64_t offset_ns = std::clamp<int64_t>(std::llround(elapsed_ns), 1, t_ns - t_ns_);
      out->push_back({t_ns_ + offset_ns, pixel, hot_pixel_random_.Sign()});
    }
  }
}

EventStream EventSimulator::Advance(const Image& next_frame, int64_t t_ns) {
  if (!started_) throw InvalidArgumentError("EventSimulator::Advance: called before Reset");
  CheckFrame(next_frame, "Advance");
  if (t_ns <= t_ns_) {
    throw InvalidArgumentError("EventSimulator::Advance: frame time " + std::to_string(t_ns) +
                               " ns is not after the previous frame's " + std::to_string(t_ns_) +
                               " ns");
  }
  std::vector<PendingEvent> pending;
  AddSignalEvents(next_frame, t_ns, &pending);
  if (UnsignalledRateHz(options_) > 0.0) {
    // Checked before drawing: at an absurd rate the noise loops would fill memory.
    CheckEventBudget(options_,
                     static_cast<double>(pending.size()) +
                         ExpectedNoiseEvents(options_, static_cast<double>(log_intensity_.size()),
                                             static_cast<double>(t_ns - t_ns_)),
                     UnsignalledRateText(options_) + " between two frames gives about");
  }
  AddNoiseEvents(t_ns, &pending);
  AddHotPixelEvents(t_ns, &pending);
  std::stable_sort(pending.begin(), pending.end(),
                   [](const PendingEvent& a, const PendingEvent& b) {
                     return a.t_ns != b.t_ns ? a.t_ns < b.t_ns : a.pixel < b.pixel;
                   });

  EventStream events(width_, height_);
  events.reserve(pending.size());
  for (const PendingEvent& event : pending) {
    int64_t& last_ns = last_event_ns_[event.pixel];
    if (last_ns != kNeverFired && event.t_ns - last_ns < options_.refractory_period_ns) continue;
    last_ns = event.t_ns;
    events.push_back(event.t_ns, static_cast<uint16_t>(event.pixel % width_),
                     static_cast<uint16_t>(event.pixel / width_), event.polarity);
  }
  t_ns_ = t_ns;
  return events;
}

EventStream SimulateEvents(const Video& frames, const SimulatorOptions& options,
                           const FlickerOptions& flicker) {
  if (frames.empty()) throw InvalidArgumentError("SimulateEvents: the video has no frames");
  std::string error;
  if (!flicker.IsValid(&error)) throw InvalidArgumentError("SimulateEvents: " + error);
  EventSimulator simulator(frames.height(), frames.width(), options);
  // The whole video's noise, checked before simulating anything.
  const double num_pixels = static_cast<double>(frames.width()) * frames.height();
  const double duration_ns = static_cast<double>(frames.timestamp_ns(frames.num_frames() - 1)) -
                             static_cast<double>(frames.timestamp_ns(0));
  CheckEventBudget(options, ExpectedNoiseEvents(options, num_pixels, duration_ns),
                   UnsignalledRateText(options) + " over " + std::to_string(frames.width()) + "x" +
                       std::to_string(frames.height()) + " pixels and " +
                       std::to_string(duration_ns / kNanosecondsPerSecond) + " s gives about");
  EventStream events(frames.width(), frames.height());
  if (!flicker.enabled() && options.cutoff_hz <= 0.0) {
    simulator.Reset(frames.frame(0), frames.timestamp_ns(0));
    for (int t = 1; t < frames.num_frames(); ++t) {
      events.Append(simulator.Advance(frames.frame(t), frames.timestamp_ns(t)));
      CheckEventBudget(options, static_cast<double>(events.size()), "the video makes");
    }
    return events;
  }

  // The scene at t_ns: `log_before` and `log_after` (the log intensities of the frames around
  // it) interpolated at `fraction`, as the simulator interpolates between frames, plus the
  // light sources.
  const auto scene_at = [&](const Image& log_before, const Image& log_after, double fraction,
                            int64_t t_ns) {
    Image scene =
        ((log_before + fraction * (log_after - log_before)).exp() - options.log_eps).max(0.0);
    AddLightSources(flicker, t_ns, &scene);
    return scene;
  };
  const int64_t max_step_ns =
      std::min(flicker.enabled() ? flicker.MaxStepNs() : kNanosecondsPerSecond,
               options.BandwidthMaxStepNs());
  Image frame = frames.frame(0);
  AddLightSources(flicker, frames.timestamp_ns(0), &frame);
  simulator.Reset(frame, frames.timestamp_ns(0));
  Image log_after = (frames.frame(0) + options.log_eps).log();
  for (int t = 1; t < frames.num_frames(); ++t) {
    const Image log_before = log_after;
    log_after = (frames.frame(t) + options.log_eps).log();
    const int64_t begin_ns = frames.timestamp_ns(t - 1);
    const int64_t interval_ns = frames.timestamp_ns(t) - begin_ns;
    // Sub-steps at least 1 ns apart, so their rounded times increase strictly. A frame time not
    // after the previous one gives none, and Advance names it.
    const int64_t num_steps = (interval_ns + max_step_ns - 1) / max_step_ns;
    for (int64_t step = 1; step < num_steps; ++step) {
      const int64_t t_ns =
          begin_ns + std::llround(static_cast<double>(interval_ns) * step / num_steps);
      const double fraction = static_cast<double>(t_ns - begin_ns) / interval_ns;
      events.Append(simulator.Advance(scene_at(log_before, log_after, fraction, t_ns), t_ns));
      CheckEventBudget(options, static_cast<double>(events.size()), "the video makes");
    }
    frame = frames.frame(t);
    AddLightSources(flicker, frames.timestamp_ns(t), &frame);
    events.Append(simulator.Advance(frame, frames.timestamp_ns(t)));
    CheckEventBudget(options, static_cast<double>(events.size()), "the video makes");
  }
  return events;
}

}  // namespace evfs
