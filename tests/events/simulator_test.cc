#include "events/simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/time.h"
#include "events/scene_synthesizer.h"

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

// Regression (issue 14): noise_rate_hz = 1e12 drew events until memory ran out (bad_alloc). The
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
