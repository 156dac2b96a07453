#include "evfs/events/simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/time.h"
#include "evfs/events/flicker.h"
#include "evfs/events/scene_synthesizer.h"

namespace evfs {
namespace {

// Re-integrated log intensities differ from the simulator's reference levels only by the
// rounding of adding a threshold up to a few hundred times.
constexpr double kRoundTripRoundingTolerance = 1e-9;

/// A small moving scene at 240 fps: smooth motion with edges and textures.
Video SmallSceneVideo(double duration_s) {
  SceneOptions scene;
  scene.width = 64;
  scene.height = 48;
  scene.num_shapes = 3;
  scene.min_shape_size_px = 6.0;
  scene.max_shape_size_px = 14.0;
  scene.duration_s = duration_s;
  scene.background_speed_px_per_s = 60.0;
  return SceneSynthesizer(scene).RenderAtRate(240.0);
}

/// `num_frames` copies of `image`, `frame_interval_ns` apart from t = 0.
Video ConstantVideo(const Image& image, int num_frames, int64_t frame_interval_ns) {
  Video video;
  for (int i = 0; i < num_frames; ++i) video.AppendFrame(image, i * frame_interval_ns);
  return video;
}

/// Options without threshold mismatch, noise or refractory period.
SimulatorOptions IdealOptions() {
  SimulatorOptions options;
  options.threshold_sigma = 0.0;
  return options;
}

TEST(SimulatorOptions, DefaultsAreValidAndBadValuesAreNamed) {
  SimulatorOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.contrast_threshold_neg = 0.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("contrast_threshold_neg"), std::string::npos);
  options = SimulatorOptions();
  options.noise_rate_hz = -1.0;
  EXPECT_FALSE(options.IsValid(nullptr));
  EXPECT_THROW(EventSimulator(4, 4, options), InvalidArgumentError);
}

// ESIM's test: events re-integrated onto the first frame's log intensity stay within one
// threshold of the last frame's at every pixel.
TEST(EventSimulator, RoundTripStaysWithinOneThreshold) {
  const Video video = SmallSceneVideo(0.05);
  SimulatorOptions options = IdealOptions();
  options.contrast_threshold_pos = 0.15;  // unequal, so a swapped threshold shows
  options.contrast_threshold_neg = 0.25;
  const EventStream events = SimulateEvents(video, options);
  ASSERT_GT(events.size(), 1000u);
  EXPECT_EQ(events.width(), video.width());
  EXPECT_EQ(events.height(), video.height());

  Image integrated = (video.frame(0).array() + options.log_eps).log();
  for (size_t i = 0; i < events.size(); ++i) {
    integrated(events.y(i), events.x(i)) +=
        events.polarity(i) > 0 ? options.contrast_threshold_pos : -options.contrast_threshold_neg;
  }
  const Image last = (video.frame(video.num_frames() - 1).array() + options.log_eps).log();
  const Image residual = last - integrated;
  EXPECT_LT(residual.maxCoeff(), options.contrast_threshold_pos + kRoundTripRoundingTolerance);
  EXPECT_GT(residual.minCoeff(), -options.contrast_threshold_neg - kRoundTripRoundingTolerance);
}

TEST(EventSimulator, ConstantVideoGivesNoEvents) {
  const Image gray = Image::Constant(16, 20, 0.4);
  EXPECT_TRUE(SimulateEvents(ConstantVideo(gray, 10, 4166667), SimulatorOptions()).empty());
}

TEST(EventSimulator, EventsAreSortedAndInsideTheirFrameInterval) {
  const Video video = SmallSceneVideo(0.03);
  EventSimulator simulator(video.height(), video.width(), SimulatorOptions());
  simulator.Reset(video.frame(0), video.timestamp_ns(0));
  size_t total = 0;
  for (int t = 1; t < video.num_frames(); ++t) {
    const EventStream events = simulator.Advance(video.frame(t), video.timestamp_ns(t));
    EXPECT_TRUE(events.IsSorted());
    EXPECT_EQ(events.width(), video.width());
    for (size_t i = 0; i < events.size(); ++i) {
      EXPECT_GT(events.t_ns(i), video.timestamp_ns(t - 1));
      EXPECT_LE(events.t_ns(i), video.timestamp_ns(t));
    }
    total += events.size();
  }
  EXPECT_GT(total, 0u);
}

TEST(EventSimulator, IsDeterministicGivenTheSeed) {
  const Video video = SmallSceneVideo(0.03);
  SimulatorOptions options;
  options.noise_rate_hz = 50.0;
  const EventStream first = SimulateEvents(video, options);
  EXPECT_EQ(first, SimulateEvents(video, options));

  // A Reset replays the same sequence on the same simulator.
  EventSimulator simulator(video.height(), video.width(), options);
  for (int run = 0; run < 2; ++run) {
    simulator.Reset(video.frame(0), video.timestamp_ns(0));
    EventStream replay(video.width(), video.height());
    for (int t = 1; t < video.num_frames(); ++t) {
      replay.Append(simulator.Advance(video.frame(t), video.timestamp_ns(t)));
    }
    EXPECT_EQ(replay, first) << "run " << run;
  }

  options.seed += 1;
  EXPECT_FALSE(first == SimulateEvents(video, options));
}

TEST(EventSimulator, NoiseRateGivesTheExpectedCount) {
  constexpr double kRateHz = 10.0;
  constexpr int kSide = 32;
  // Ten intervals of 0.1 s: 1 s of 1024 pixels at 10 Hz, so the count is Poisson with mean
  // 10240 (std dev 101) and the ON count binomial with mean 5120 (std dev 51).
  const Video video =
      ConstantVideo(Image::Constant(kSide, kSide, 0.5), 11, kNanosecondsPerSecond / 10);
  SimulatorOptions options;
  options.noise_rate_hz = kRateHz;
  const EventStream events = SimulateEvents(video, options);
  const double expected = kRateHz * kSide * kSide * 1.0;
  // Five standard deviations: a seeded run fails only if the generator is wrong.
  constexpr double kSigmas = 5.0;
  EXPECT_NEAR(static_cast<double>(events.size()), expected, kSigmas * std::sqrt(expected));
  EXPECT_NEAR(static_cast<double>(events.CountPositive()), expected / 2,
              kSigmas * std::sqrt(expected / 4));
  EXPECT_TRUE(events.IsSorted());
  EXPECT_GT(events.first_t_ns(), 0);
  EXPECT_LE(events.last_t_ns(), kNanosecondsPerSecond);
}

// Regression: noise_rate_hz = 1e12 drew events until memory ran out (bad_alloc). The
// expected count is known before drawing, so it is refused at once, for the whole video and
// for one Advance alike.
TEST(EventSimulator, NoiseBeyondTheEventBudgetIsRefusedBeforeDrawing) {
  const Video video = ConstantVideo(Image::Constant(32, 32, 0.5), 3, kNanosecondsPerSecond / 10);
  SimulatorOptions options;
  options.noise_rate_hz = 1e12;
  try {
    SimulateEvents(video, options);
    ADD_FAILURE() << "expected an InvalidArgumentError";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("max_events"), std::string::npos) << error.what();
  }
  EventSimulator simulator(32, 32, options);
  simulator.Reset(video.frame(0), 0);
  EXPECT_THROW(simulator.Advance(video.frame(1), kNanosecondsPerSecond / 10), InvalidArgumentError);

  // The budget is an option: 10 Hz over 1024 pixels and 0.2 s is about 2048 events.
  options.noise_rate_hz = 10.0;
  options.max_events = 1000;
  EXPECT_THROW(SimulateEvents(video, options), InvalidArgumentError);
  options.max_events = 100000;
  EXPECT_GT(SimulateEvents(video, options).size(), 1000u);
  options.max_events = 0;
  EXPECT_FALSE(options.IsValid(nullptr));
}

TEST(EventSimulator, RefractoryPeriodIsRespected) {
  // Each frame interval (1 ms) ramps every pixel between 0.02 and 0.9, about 19 thresholds of
  // log intensity, so pixels want to fire every ~50 µs.
  constexpr int64_t kFrameIntervalNs = 1000000;
  constexpr int64_t kRefractoryNs = 200000;
  Video video;
  for (int i = 0; i < 6; ++i) {
    video.AppendFrame(Image::Constant(4, 5, i % 2 == 0 ? 0.02 : 0.9), i * kFrameIntervalNs);
  }
  SimulatorOptions options = IdealOptions();
  const size_t unrestricted = SimulateEvents(video, options).size();
  options.refractory_period_ns = kRefractoryNs;
  options.noise_rate_hz = 2000.0;  // noise obeys the refractory period too
  const EventStream events = SimulateEvents(video, options);
  ASSERT_GT(events.size(), 0u);
  EXPECT_LT(events.size(), unrestricted);
  std::vector<int64_t> last_ns(20, -1);
  for (size_t i = 0; i < events.size(); ++i) {
    int64_t& last = last_ns[events.y(i) * 5 + events.x(i)];
    if (last >= 0) {
      EXPECT_GE(events.t_ns(i) - last, kRefractoryNs) << "event " << i;
    }
    last = events.t_ns(i);
  }
}

TEST(EventSimulator, ThresholdMismatchSpreadsPerPixelCounts) {
  // One ramp seen by every pixel: with identical thresholds all pixels fire equally often;
  // with a spread some fire more than others.
  Video ramp;
  ramp.AppendFrame(Image::Constant(8, 8, 0.05), 0);
  ramp.AppendFrame(Image::Constant(8, 8, 0.9), 1000000);
  const auto count_range = [&ramp](const SimulatorOptions& options) {
    const EventStream events = SimulateEvents(ramp, options);
    std::vector<int> counts(64, 0);
    for (size_t i = 0; i < events.size(); ++i) ++counts[events.y(i) * 8 + events.x(i)];
    const auto [low, high] = std::minmax_element(counts.begin(), counts.end());
    return *high - *low;
  };
  EXPECT_EQ(count_range(IdealOptions()), 0);
  EXPECT_GT(count_range(SimulatorOptions()), 0);
}

TEST(EventSimulator, ExposesThePerPixelThresholdsItFiresAt) {
  // A simulator built with the same options draws the same thresholds as SimulateEvents' own,
  // and integrating the events with each pixel's thresholds lands within one of them.
  const Video video = SmallSceneVideo(0.05);
  const SimulatorOptions options;  // with threshold mismatch
  const EventStream events = SimulateEvents(video, options);
  const EventSimulator simulator(video.height(), video.width(), options);
  const std::vector<double>& on = simulator.threshold_pos();
  const std::vector<double>& off = simulator.threshold_neg();
  ASSERT_EQ(on.size(), static_cast<size_t>(video.height() * video.width()));
  ASSERT_EQ(off.size(), on.size());
  EXPECT_NE(*std::min_element(on.begin(), on.end()), *std::max_element(on.begin(), on.end()));

  Image integrated = (video.frame(0).array() + options.log_eps).log();
  for (size_t i = 0; i < events.size(); ++i) {
    const size_t p = static_cast<size_t>(events.y(i)) * video.width() + events.x(i);
    integrated(events.y(i), events.x(i)) += events.polarity(i) > 0 ? on[p] : -off[p];
  }
  const Image last = (video.frame(video.num_frames() - 1).array() + options.log_eps).log();
  const Image residual = last - integrated;
  for (Eigen::Index p = 0; p < residual.size(); ++p) {
    ASSERT_LT(residual.data()[p], on[p] + kRoundTripRoundingTolerance) << "pixel " << p;
    ASSERT_GT(residual.data()[p], -off[p] - kRoundTripRoundingTolerance) << "pixel " << p;
  }
}

// The sensor effects are off by default: a fixed seed gives the very events of the plain ESIM
// model, whichever light-source or effect options are set to their "off" values.
TEST(EventSimulator, EffectsOffGiveTheSameEvents) {
  const Video video = SmallSceneVideo(0.03);
  SimulatorOptions options;
  options.noise_rate_hz = 20.0;
  const EventStream plain = SimulateEvents(video, options);
  ASSERT_GT(plain.size(), 100u);
  SimulatorOptions off = options;
  off.leak_rate_hz = 0.0;
  off.leak_jitter_fraction = 0.5;
  off.hot_pixel_fraction = 0.0;
  off.hot_pixel_rate_hz = 1000.0;
  FlickerOptions no_light;
  no_light.led_x_px = 10.0;
  no_light.mains_depth = 1.0;
  EXPECT_EQ(SimulateEvents(video, off, no_light), plain);

  // Turning hot pixels on leaves the thresholds and the background noise as they were: the
  // hot pixels only add events.
  SimulatorOptions hot = options;
  hot.hot_pixel_fraction = 0.02;
  const EventStream with_hot = SimulateEvents(video, hot);
  const EventSimulator hot_simulator(video.height(), video.width(), hot);
  const std::vector<int32_t>& hot_pixels = hot_simulator.hot_pixels();
  EventStream without_hot(video.width(), video.height());
  for (size_t i = 0; i < with_hot.size(); ++i) {
    const int32_t pixel = with_hot.y(i) * video.width() + with_hot.x(i);
    if (!std::binary_search(hot_pixels.begin(), hot_pixels.end(), pixel)) {
      without_hot.push_back(with_hot.t_ns(i), with_hot.x(i), with_hot.y(i), with_hot.polarity(i));
    }
  }
  EventStream plain_without_hot(video.width(), video.height());
  for (size_t i = 0; i < plain.size(); ++i) {
    const int32_t pixel = plain.y(i) * video.width() + plain.x(i);
    if (!std::binary_search(hot_pixels.begin(), hot_pixels.end(), pixel)) {
      plain_without_hot.push_back(plain.t_ns(i), plain.x(i), plain.y(i), plain.polarity(i));
    }
  }
  EXPECT_EQ(without_hot, plain_without_hot);
}

TEST(EventSimulator, HotPixelsFireAtTheirRate) {
  constexpr int kSide = 100;
  constexpr double kFraction = 0.01;
  constexpr double kRateHz = 200.0;
  // One second of a still scene: only the hot pixels fire, each a Poisson source, so the total
  // is Poisson with mean 100 · 200 = 20000 (std dev 141).
  const Video video =
      ConstantVideo(Image::Constant(kSide, kSide, 0.5), 11, kNanosecondsPerSecond / 10);
  SimulatorOptions options;
  options.hot_pixel_fraction = kFraction;
  options.hot_pixel_rate_hz = kRateHz;
  const EventStream events = SimulateEvents(video, options);
  const EventSimulator simulator(kSide, kSide, options);
  const std::vector<int32_t>& hot = simulator.hot_pixels();
  ASSERT_EQ(hot.size(), 100u);
  EXPECT_TRUE(std::adjacent_find(hot.begin(), hot.end()) == hot.end());  // distinct
  const double expected = kFraction * kSide * kSide * kRateHz;
  // Five standard deviations: a seeded run fails only if the generator is wrong.
  constexpr double kSigmas = 5.0;
  EXPECT_NEAR(static_cast<double>(events.size()), expected, kSigmas * std::sqrt(expected));
  EXPECT_NEAR(static_cast<double>(events.CountPositive()), expected / 2,
              kSigmas * std::sqrt(expected / 4));
  std::vector<int> counts(kSide * kSide, 0);
  for (size_t i = 0; i < events.size(); ++i) ++counts[events.y(i) * kSide + events.x(i)];
  for (int p = 0; p < kSide * kSide; ++p) {
    const bool is_hot = std::binary_search(hot.begin(), hot.end(), p);
    if (!is_hot) {
      ASSERT_EQ(counts[p], 0) << "pixel " << p;
    } else {
      // Poisson with mean 200: below 120 or above 280 is beyond 5.6 standard deviations.
      EXPECT_TRUE(counts[p] > 120 && counts[p] < 280) << counts[p];
    }
  }
  EXPECT_TRUE(events.IsSorted());
}

TEST(EventSimulator, LeakFiresOnEventsAtItsRate) {
  constexpr int kSide = 32;
  constexpr double kLeakHz = 2.0;
  constexpr double kDurationS = 10.0;
  // Ten seconds of a still scene at 2 Hz: each pixel's leak reaches its threshold 20 times on
  // average.
  const Video video = ConstantVideo(Image::Constant(kSide, kSide, 0.5), 11, kNanosecondsPerSecond);
  SimulatorOptions options;
  options.leak_rate_hz = kLeakHz;
  const EventStream events = SimulateEvents(video, options);
  EXPECT_EQ(events.CountPositive(), events.size());
  const double per_pixel = static_cast<double>(events.size()) / (kSide * kSide);
  // A pixel fires floor(rate · duration + phase) times with the phase uniform in [0, 1), whose
  // mean is rate · duration; over 1024 pixels the 10 % rate spread leaves a standard error of
  // 0.06 events.
  constexpr double kMeanTolerance = 0.3;
  EXPECT_NEAR(per_pixel, kLeakHz * kDurationS, kMeanTolerance);

  // Without spread every pixel fires exactly 20 times (its phase is less than one threshold);
  // with it the counts spread wider.
  const auto count_range = [&video](const SimulatorOptions& leak_options) {
    const EventStream leak_events = SimulateEvents(video, leak_options);
    std::vector<int> counts(kSide * kSide, 0);
    for (size_t i = 0; i < leak_events.size(); ++i) {
      ++counts[leak_events.y(i) * kSide + leak_events.x(i)];
    }
    const auto [low, high] = std::minmax_element(counts.begin(), counts.end());
    return std::make_pair(*low, *high);
  };
  SimulatorOptions uniform = options;
  uniform.leak_jitter_fraction = 0.0;
  uniform.threshold_sigma = 0.0;
  const auto [uniform_low, uniform_high] = count_range(uniform);
  EXPECT_EQ(uniform_low, 20);
  EXPECT_EQ(uniform_high, 20);
  const auto [low, high] = count_range(options);
  EXPECT_GT(high - low, 2);
}

// A 1 kHz LED between 240 fps frames: every period gives one ON and one OFF burst inside the
// disc, none outside, and the net change over whole periods is zero.
TEST(EventSimulator, BlinkingLedFiresAtItsFrequency) {
  constexpr int64_t kFrameIntervalNs = 4166667;
  constexpr int kNumFrames = 13;  // 12 intervals: 50 ms, 50 LED periods
  constexpr double kLedHz = 1000.0;
  const Video video = ConstantVideo(Image::Constant(24, 32, 0.3), kNumFrames, kFrameIntervalNs);
  FlickerOptions flicker;
  flicker.led_hz = kLedHz;
  flicker.led_x_px = 10.0;
  flicker.led_y_px = 12.0;
  flicker.led_radius_px = 3.0;
  const SimulatorOptions options = IdealOptions();
  const EventStream events = SimulateEvents(video, options, flicker);
  ASSERT_GT(events.size(), 0u);
  std::vector<std::vector<int8_t>> polarities(24 * 32);
  for (size_t i = 0; i < events.size(); ++i) {
    ASSERT_TRUE(InLedDisc(flicker, events.x(i), events.y(i))) << events.x(i) << "," << events.y(i);
    polarities[events.y(i) * 32 + events.x(i)].push_back(events.polarity(i));
  }
  const double duration_s = NanosecondsToSeconds(video.timestamp_ns(kNumFrames - 1));
  const int expected_periods = static_cast<int>(std::lround(kLedHz * duration_s));
  for (int y = 0; y < 24; ++y) {
    for (int x = 0; x < 32; ++x) {
      const std::vector<int8_t>& pixel = polarities[y * 32 + x];
      if (!InLedDisc(flicker, x, y)) continue;
      // Bursts: runs of equal polarity. The LED is lit at t = 0, so the first burst is OFF.
      int bursts = 0;
      int net = 0;
      for (size_t i = 0; i < pixel.size(); ++i) {
        if (i == 0 || pixel[i] != pixel[i - 1]) ++bursts;
        net += pixel[i];
      }
      ASSERT_FALSE(pixel.empty());
      EXPECT_EQ(pixel.front(), -1);
      // 50 periods from lit to lit: 50 OFF and 50 ON bursts, the last ON where the LED comes
      // on again at 50 ms (the last frame time is the 50th rising edge, or just past it).
      EXPECT_NEAR(bursts, 2 * expected_periods, 1) << x << "," << y;
      // Equal thresholds: the same number of ON and OFF events per period.
      EXPECT_LE(std::abs(net), 3) << x << "," << y;
    }
  }

  // Without sub-steps the frames alone would alias the LED: the sub-steps are what resolves it.
  EXPECT_GT(events.size(), SimulateEvents(video, options).size());
}

TEST(EventSimulator, MainsLampFiresWithinItsRegionAtTwiceThePeriod) {
  constexpr int64_t kFrameIntervalNs = 4166667;
  constexpr int kNumFrames = 25;  // 100 ms: 10 periods of a 100 Hz lamp
  const Video video = ConstantVideo(Image::Constant(16, 16, 0.4), kNumFrames, kFrameIntervalNs);
  FlickerOptions flicker;
  flicker.mains_hz = 100.0;
  flicker.mains_depth = 0.5;
  flicker.mains_x_px = 4;
  flicker.mains_y_px = 2;
  flicker.mains_width_px = 8;
  flicker.mains_height_px = 6;
  const EventStream events = SimulateEvents(video, IdealOptions(), flicker);
  ASSERT_GT(events.size(), 0u);
  std::vector<std::vector<int8_t>> polarities(16 * 16);
  for (size_t i = 0; i < events.size(); ++i) {
    ASSERT_TRUE(InMainsRegion(flicker, events.x(i), events.y(i)));
    polarities[events.y(i) * 16 + events.x(i)].push_back(events.polarity(i));
  }
  // log(1.5 / 0.5) = 1.1 per half period: five threshold crossings each way, and a sign change
  // at every extremum, 20 per 10 periods.
  const std::vector<int8_t>& pixel = polarities[5 * 16 + 6];
  int changes = 0;
  for (size_t i = 1; i < pixel.size(); ++i) changes += pixel[i] != pixel[i - 1];
  EXPECT_NEAR(changes, 20, 1);
}

// v2e's photoreceptor: after the same step of log intensity, a bright pixel follows within a
// few of its time constants 1 / (2π · 100 Hz) = 1.6 ms, a dim one (cutoff scaled by its
// intensity) several times slower, and without the low-pass both fire within the step.
TEST(EventSimulator, BandwidthFallsWithIntensity) {
  constexpr int64_t kFrameIntervalNs = 1000000;
  constexpr int kNumFrames = 61;  // 60 ms: past the dim pixels' third time constant
  Image dim_before = Image::Constant(8, 16, 0.05);
  Image after = Image::Constant(8, 16, 0.1);
  dim_before.rightCols(8) = 0.5;  // the right half is bright
  after.rightCols(8) = 1.0;       // the same step of log intensity on both sides
  Video video;
  video.AppendFrame(dim_before, 0);
  for (int t = 1; t < kNumFrames; ++t) video.AppendFrame(after, t * kFrameIntervalNs);

  const auto mean_times_ms = [&video](const SimulatorOptions& options) {
    const EventStream events = SimulateEvents(video, options);
    EXPECT_EQ(events.CountPositive(), events.size());
    // ln 2 is three thresholds of 0.2 at every pixel, low-pass or not.
    EXPECT_EQ(events.size(), 3u * 8 * 16);
    double dim_ms = 0.0, bright_ms = 0.0;
    for (size_t i = 0; i < events.size(); ++i) {
      (events.x(i) < 8 ? dim_ms : bright_ms) += events.t_ns(i) * 1e-6;
    }
    return std::make_pair(dim_ms / (events.size() / 2.0), bright_ms / (events.size() / 2.0));
  };
  SimulatorOptions options = IdealOptions();
  const auto [dim_instant_ms, bright_instant_ms] = mean_times_ms(options);
  EXPECT_LE(dim_instant_ms, 1.0);
  EXPECT_LE(bright_instant_ms, 1.0);
  options.cutoff_hz = 100.0;
  const auto [dim_ms, bright_ms] = mean_times_ms(options);
  // Crossings at 29, 58 and 88 % of the step: -τ ln(1 - f) averages 1.1 τ, during and after
  // the 1 ms ramp, with τ = 1.6 ms bright and 9.6 ms dim. The bounds leave room for the ramp and
  // the discrete steps, and exclude the instant response (about 0.5 ms).
  EXPECT_GT(bright_ms, 1.2);
  EXPECT_LT(bright_ms, 4.0);
  EXPECT_GT(dim_ms, 3.0 * bright_ms);
  EXPECT_LT(dim_ms, 25.0);
}

TEST(EventSimulator, RejectsBadEffectOptions) {
  SimulatorOptions options;
  std::string error;
  options.hot_pixel_fraction = 1.5;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("hot_pixel_fraction"), std::string::npos) << error;
  options = SimulatorOptions();
  options.leak_rate_hz = -0.1;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("leak_rate_hz"), std::string::npos) << error;
  options = SimulatorOptions();
  options.hot_pixel_rate_hz = 0.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("hot_pixel_rate_hz"), std::string::npos) << error;
  options = SimulatorOptions();
  options.cutoff_hz = -1.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("cutoff_hz"), std::string::npos) << error;

  FlickerOptions flicker;
  EXPECT_TRUE(flicker.IsValid(&error)) << error;
  flicker.led_hz = 0.5;
  EXPECT_FALSE(flicker.IsValid(&error));
  EXPECT_NE(error.find("led_hz"), std::string::npos) << error;
  flicker = FlickerOptions();
  flicker.mains_depth = 1.5;
  EXPECT_FALSE(flicker.IsValid(&error));
  EXPECT_NE(error.find("mains_depth"), std::string::npos) << error;
  flicker = FlickerOptions();
  flicker.led_duty = 1.0;
  EXPECT_FALSE(flicker.IsValid(&error));
  const Video video = ConstantVideo(Image::Constant(4, 4, 0.5), 2, 1000000);
  EXPECT_THROW(SimulateEvents(video, SimulatorOptions(), flicker), InvalidArgumentError);
}

TEST(EventSimulator, RejectsBadFramesAndTimes) {
  EventSimulator simulator(4, 5, SimulatorOptions());
  const Image frame = Image::Constant(4, 5, 0.5);
  EXPECT_THROW(simulator.Advance(frame, 10), InvalidArgumentError);  // before Reset
  EXPECT_THROW(simulator.Reset(Image::Constant(5, 4, 0.5), 0), InvalidArgumentError);
  simulator.Reset(frame, 100);
  EXPECT_THROW(simulator.Advance(frame, 100), InvalidArgumentError);
  EXPECT_THROW(simulator.Advance(Image::Constant(4, 5, -0.1), 200), InvalidArgumentError);
  EXPECT_THROW(EventSimulator(0, 5, SimulatorOptions()), InvalidArgumentError);
  EXPECT_THROW(SimulateEvents(Video(), SimulatorOptions()), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
