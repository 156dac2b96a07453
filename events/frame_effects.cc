#include "evfs/events/frame_effects.h"

#include <algorithm>
#include <cmath>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/core/time.h"

namespace evfs {
namespace {

/// Full scale of the 8-bit frames, in DN.
constexpr double kFullScaleDn = 255.0;

/// Longest exposure: longer than any frame camera's, and it bounds the samples of a window.
constexpr double kMaxExposureS = 10.0;

/// Fewest samples of an exposure window, so that a window shorter than a light source's sub-step
/// still averages the motion across it.
constexpr int64_t kMinExposureSamples = 16;

/// Samples per frame interval of an exposure without light sources: the scene is linear in
/// intensity between frames, so a few samples per interval average it closely.
constexpr int64_t kSamplesPerFrameInterval = 4;

/// Offsets of the fixed-pattern and read-noise seeds from `seed` (2^64 / golden ratio times 5
/// and 6: unrelated to each other and to the event simulator's streams from the same seed).
constexpr uint64_t kFixedPatternSeedOffset = 5 * 0x9E3779B97F4A7C15ull;
constexpr uint64_t kReadNoiseSeedOffset = 6 * 0x9E3779B97F4A7C15ull;

}  // namespace

bool FrameEffectsOptions::enabled() const {
  return exposure_s > 0.0 || gain != 1.0 || read_noise_dn > 0.0 || fpn_offset_dn > 0.0 ||
         fpn_gain_sigma > 0.0;
}

bool FrameEffectsOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.Require(exposure_s >= 0.0 && exposure_s <= kMaxExposureS, "exposure_s", "in [0, 10] s")
      .Positive("gain", gain)
      .NonNegative("read_noise_dn", read_noise_dn)
      .NonNegative("fpn_offset_dn", fpn_offset_dn)
      .Require(fpn_gain_sigma >= 0.0 && fpn_gain_sigma < 1.0, "fpn_gain_sigma", "in [0, 1)");
  return check.Passed(error);
}

Image SceneAt(const Video& frames, const FlickerOptions& flicker, int64_t t_ns) {
  Image scene = frames.InterpolateAt(t_ns);
  AddLightSources(flicker, t_ns, &scene);
  return scene;
}

std::vector<int64_t> ExposureSampleTimes(int64_t begin_ns, int64_t end_ns, int64_t max_step_ns) {
  const double length_ns = static_cast<double>(end_ns - begin_ns);
  const int64_t num_samples = std::max<int64_t>(
      kMinExposureSamples,
      static_cast<int64_t>(
          std::ceil(length_ns / static_cast<double>(std::max<int64_t>(1, max_step_ns)))));
  std::vector<int64_t> times(num_samples);
  for (int64_t i = 0; i < num_samples; ++i) {
    times[i] = begin_ns + std::llround(length_ns * (static_cast<double>(i) + 0.5) /
                                       static_cast<double>(num_samples));
  }
  return times;
}

Image ExposedScene(const Video& frames, const FlickerOptions& flicker, int64_t begin_ns,
                   int64_t end_ns, int64_t max_step_ns) {
  const std::vector<int64_t> times = ExposureSampleTimes(begin_ns, end_ns, max_step_ns);
  Image sum = Image::Zero(frames.height(), frames.width());
  for (const int64_t t_ns : times) sum += SceneAt(frames, flicker, t_ns);
  return sum / static_cast<double>(times.size());
}

FrameReadout::FrameReadout(int height, int width, const FrameEffectsOptions& options)
    : options_(options), read_noise_random_(options.seed + kReadNoiseSeedOffset) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("frame effects: " + error);
  if (height <= 0 || width <= 0) {
    throw InvalidArgumentError("FrameReadout: a frame of " + std::to_string(width) + "x" +
                               std::to_string(height));
  }
  gain_ = Image::Constant(height, width, options.gain);
  offset_ = Image::Zero(height, width);
  Random pattern_random(options.seed + kFixedPatternSeedOffset);
  if (options.fpn_gain_sigma > 0.0) {
    for (Eigen::Index p = 0; p < gain_.size(); ++p) {
      gain_.data()[p] *= 1.0 + pattern_random.Normal(0.0, options.fpn_gain_sigma);
    }
  }
  if (options.fpn_offset_dn > 0.0) {
    for (Eigen::Index p = 0; p < offset_.size(); ++p) {
      offset_.data()[p] = pattern_random.Normal(0.0, options.fpn_offset_dn) / kFullScaleDn;
    }
  }
}

Image FrameReadout::Read(const Image& exposed) {
  if (exposed.rows() != gain_.rows() || exposed.cols() != gain_.cols()) {
    throw InvalidArgumentError("FrameReadout::Read: a frame of " + std::to_string(exposed.cols()) +
                               "x" + std::to_string(exposed.rows()) + ", sensor is " +
                               std::to_string(gain_.cols()) + "x" + std::to_string(gain_.rows()));
  }
  Image value = gain_ * exposed + offset_;
  if (options_.read_noise_dn > 0.0) {
    for (Eigen::Index p = 0; p < value.size(); ++p) {
      value.data()[p] += read_noise_random_.Normal(0.0, options_.read_noise_dn) / kFullScaleDn;
    }
  }
  return (value.max(0.0).min(1.0) * kFullScaleDn).round() / kFullScaleDn;
}

std::vector<RecordedFrame> RecordFrames(const Video& frames, const FlickerOptions& flicker,
                                        const FrameEffectsOptions& options) {
  if (frames.empty()) throw InvalidArgumentError("RecordFrames: the video has no frames");
  std::string error;
  if (!flicker.IsValid(&error) || !options.IsValid(&error)) {
    throw InvalidArgumentError("RecordFrames: " + error);
  }
  std::vector<RecordedFrame> recorded(frames.num_frames());
  if (!flicker.enabled() && !options.enabled()) {
    for (int t = 0; t < frames.num_frames(); ++t) recorded[t].image = frames.frame(t);
    return recorded;
  }
  int64_t max_step_ns = flicker.enabled() ? flicker.MaxStepNs() : kNanosecondsPerSecond;
  for (int t = 1; t < frames.num_frames(); ++t) {
    const int64_t interval_ns = frames.timestamp_ns(t) - frames.timestamp_ns(t - 1);
    if (interval_ns > 0) {
      max_step_ns =
          std::min(max_step_ns, std::max<int64_t>(1, interval_ns / kSamplesPerFrameInterval));
    }
  }
  const int64_t half_exposure_ns = SecondsToNanoseconds(options.exposure_s / 2.0);
  const int64_t first_ns = frames.timestamp_ns(0);
  const int64_t last_ns = frames.timestamp_ns(frames.num_frames() - 1);
  FrameReadout readout(frames.height(), frames.width(), options);
  for (int t = 0; t < frames.num_frames(); ++t) {
    const int64_t t_ns = frames.timestamp_ns(t);
    RecordedFrame& frame = recorded[t];
    if (half_exposure_ns > 0) {
      frame.has_exposure = true;
      frame.exposure_begin_ns = std::max(first_ns, t_ns - half_exposure_ns);
      frame.exposure_end_ns = std::min(last_ns, t_ns + half_exposure_ns);
      frame.image = readout.Read(ExposedScene(frames, flicker, frame.exposure_begin_ns,
                                              frame.exposure_end_ns, max_step_ns));
    } else {
      frame.image = readout.Read(SceneAt(frames, flicker, t_ns));
    }
  }
  return recorded;
}

}  // namespace evfs
