#include "evfs/events/frame_effects.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/time.h"
#include "evfs/events/flicker.h"

namespace evfs {
namespace {

/// Half of one 8-bit step: the most a quantised frame differs from the value it quantises.
constexpr double kHalfStep = 0.5 / 255.0;

/// Rounding of a mean over a few dozen samples, far below one 8-bit step.
constexpr double kMeanRounding = 1e-12;

/// `num_frames` frames `interval_ns` apart from t = 0, frame i constant at values[i].
Video ConstantFrames(int height, int width, const std::vector<double>& values,
                     int64_t interval_ns) {
  Video video;
  for (size_t i = 0; i < values.size(); ++i) {
    video.AppendFrame(Image::Constant(height, width, values[i]),
                      static_cast<int64_t>(i) * interval_ns);
  }
  return video;
}

/// Population standard deviation of `image`'s values.
double StdDev(const Image& image) { return std::sqrt((image - image.mean()).square().mean()); }

TEST(FrameEffectsOptions, DefaultsChangeNothingAndBadValuesAreNamed) {
  FrameEffectsOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  EXPECT_FALSE(options.enabled());
  options.gain = 0.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("gain"), std::string::npos) << error;
  options = FrameEffectsOptions();
  options.read_noise_dn = -1.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("read_noise_dn"), std::string::npos) << error;
  options = FrameEffectsOptions();
  options.exposure_s = 20.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("exposure_s"), std::string::npos) << error;
  options = FrameEffectsOptions();
  options.fpn_gain_sigma = 1.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THROW(FrameReadout(4, 4, options), InvalidArgumentError);

  // Without effects and light sources the frames come back untouched, not quantised.
  const Video video = ConstantFrames(3, 5, {0.123456, 0.654321}, 1000000);
  const std::vector<RecordedFrame> frames =
      RecordFrames(video, FlickerOptions(), FrameEffectsOptions());
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_TRUE((frames[0].image == video.frame(0)).all());
  EXPECT_TRUE((frames[1].image == video.frame(1)).all());
  EXPECT_FALSE(frames[0].has_exposure);
}

TEST(FrameReadout, GainSaturatesBrightPartsAndQuantises) {
  FrameEffectsOptions options;
  options.gain = 2.0;
  FrameReadout readout(1, 3, options);
  Image exposed(1, 3);
  exposed << 0.1, 0.3, 0.7;
  const Image frame = readout.Read(exposed);
  EXPECT_NEAR(frame(0, 0), 0.2, kHalfStep);
  EXPECT_NEAR(frame(0, 1), 0.6, kHalfStep);
  EXPECT_EQ(frame(0, 2), 1.0);  // 1.4 clips
  for (Eigen::Index p = 0; p < frame.size(); ++p) {
    EXPECT_EQ(frame.data()[p] * 255.0, std::round(frame.data()[p] * 255.0));
  }
}

TEST(FrameReadout, ReadNoiseHasItsStandardDeviationAndChangesEveryFrame) {
  constexpr double kReadNoiseDn = 3.0;
  FrameEffectsOptions options;
  options.read_noise_dn = kReadNoiseDn;
  FrameReadout readout(64, 64, options);
  const Image gray = Image::Constant(64, 64, 0.5);
  const Image first = readout.Read(gray);
  const Image second = readout.Read(gray);
  EXPECT_FALSE((first == second).all());
  // Quantisation adds a variance of 1/12 DN²; the std dev of 4096 samples is within 1.1 % of
  // the truth (one standard error), 5 % is beyond four standard errors.
  constexpr double kRelativeTolerance = 0.05;
  const double expected_dn = std::sqrt(kReadNoiseDn * kReadNoiseDn + 1.0 / 12.0);
  EXPECT_NEAR(StdDev(first) * 255.0, expected_dn, kRelativeTolerance * expected_dn);
  EXPECT_NEAR(StdDev(second) * 255.0, expected_dn, kRelativeTolerance * expected_dn);
  EXPECT_NEAR(first.mean(), 0.5, kHalfStep);
}

TEST(FrameReadout, FixedPatternIsTheSameInEveryFrameAndSeeded) {
  constexpr double kOffsetDn = 2.0;
  FrameEffectsOptions options;
  options.fpn_offset_dn = kOffsetDn;
  options.fpn_gain_sigma = 0.02;
  FrameReadout readout(64, 64, options);
  const Image gray = Image::Constant(64, 64, 0.5);
  const Image first = readout.Read(gray);
  EXPECT_TRUE((first == readout.Read(gray)).all());
  // Offset 2 DN and gain 2 % of 127.5 DN = 2.55 DN, independent: about 3.2 DN, before
  // quantisation (1/12 DN²). The sample std dev of 4096 pixels is within 5 % (four standard
  // errors).
  constexpr double kRelativeTolerance = 0.05;
  const double expected_dn = std::sqrt(kOffsetDn * kOffsetDn + 2.55 * 2.55 + 1.0 / 12.0);
  EXPECT_NEAR(StdDev(first) * 255.0, expected_dn, kRelativeTolerance * expected_dn);
  EXPECT_TRUE((FrameReadout(64, 64, options).Read(gray) == first).all());
  options.seed += 1;
  EXPECT_FALSE((FrameReadout(64, 64, options).Read(gray) == first).all());
}

TEST(RecordFrames, ExposureIsTheMeanOfTheSceneOverItsWindow) {
  // Frames at 0, 10, 20 ms, intensity linear in time: 0.2 + 20 t.
  const Video video = ConstantFrames(4, 6, {0.2, 0.4, 0.6}, 10000000);
  FrameEffectsOptions options;
  options.exposure_s = 0.010;
  const std::vector<RecordedFrame> frames = RecordFrames(video, FlickerOptions(), options);
  ASSERT_EQ(frames.size(), 3u);
  // The middle window [5, 15] ms averages a linear ramp to its midpoint; the others are cut to
  // the video's span: [0, 5] ms and [15, 20] ms.
  EXPECT_TRUE(frames[1].has_exposure);
  EXPECT_EQ(frames[1].exposure_begin_ns, 5000000);
  EXPECT_EQ(frames[1].exposure_end_ns, 15000000);
  EXPECT_EQ(frames[0].exposure_begin_ns, 0);
  EXPECT_EQ(frames[0].exposure_end_ns, 5000000);
  EXPECT_EQ(frames[2].exposure_begin_ns, 15000000);
  EXPECT_EQ(frames[2].exposure_end_ns, 20000000);
  EXPECT_NEAR(frames[1].image(2, 3), 0.4, kHalfStep);
  EXPECT_NEAR(frames[0].image(2, 3), 0.25, kHalfStep);
  EXPECT_NEAR(frames[2].image(2, 3), 0.55, kHalfStep);

  // And the exposed scene is the mean of the scene at its sample times.
  const std::vector<int64_t> times = ExposureSampleTimes(5000000, 15000000, 2500000);
  ASSERT_EQ(times.size(), 16u);
  Image mean = Image::Zero(4, 6);
  for (const int64_t t_ns : times) mean += SceneAt(video, FlickerOptions(), t_ns);
  mean /= static_cast<double>(times.size());
  EXPECT_LT(
      (ExposedScene(video, FlickerOptions(), 5000000, 15000000, 2500000) - mean).abs().maxCoeff(),
      kMeanRounding);
}

// A 100 Hz lamp at full depth: frames taken at an instant swing with the lamp, frames exposed
// over two whole periods see its mean, the scene itself.
TEST(RecordFrames, ExposureOverWholePeriodsAveragesTheLampOut) {
  const Video video = ConstantFrames(4, 4, std::vector<double>(6, 0.4), 10000000);
  FlickerOptions flicker;
  flicker.mains_hz = 100.0;
  flicker.mains_depth = 1.0;
  FrameEffectsOptions options;
  const std::vector<RecordedFrame> instant = RecordFrames(video, flicker, options);
  options.exposure_s = 0.020;
  const std::vector<RecordedFrame> exposed = RecordFrames(video, flicker, options);
  for (int t : {2, 3}) {  // windows [10, 30] and [20, 40] ms lie inside the video
    EXPECT_NEAR(exposed[t].image(1, 1), 0.4, kHalfStep) << t;
  }
  // At 10 ms the lamp is at sin(2π) = 0; a quarter period later, between frames, it peaks.
  flicker.mains_hz = 25.0;  // period 40 ms: frame 1 (10 ms) at the crest
  const std::vector<RecordedFrame> crest = RecordFrames(video, flicker, FrameEffectsOptions());
  EXPECT_NEAR(crest[1].image(0, 0), 0.8, kHalfStep);
  EXPECT_NEAR(instant[1].image(0, 0), 0.4, kHalfStep);
}

TEST(RecordFrames, TheLedSaturatesTheFramesWhereItShines) {
  constexpr int64_t kFrameIntervalNs = 4166667;
  const Video video = ConstantFrames(24, 32, std::vector<double>(6, 0.3), kFrameIntervalNs);
  FlickerOptions flicker;
  flicker.led_hz = 1000.0;
  flicker.led_x_px = 10.0;
  flicker.led_y_px = 12.0;
  flicker.led_radius_px = 3.0;
  const std::vector<RecordedFrame> frames = RecordFrames(video, flicker, FrameEffectsOptions());
  for (int t = 0; t < video.num_frames(); ++t) {
    const bool lit = LedIsOn(flicker, video.timestamp_ns(t));
    for (int y = 0; y < 24; ++y) {
      for (int x = 0; x < 32; ++x) {
        const double expected = lit && InLedDisc(flicker, x, y) ? 1.0 : 0.3;
        ASSERT_NEAR(frames[t].image(y, x), expected, kHalfStep) << t << ": " << x << "," << y;
      }
    }
  }
  // The LED is lit at 0 ms and dark at 12.5 ms (frame 3, phase 0.5).
  EXPECT_TRUE(LedIsOn(flicker, 0));
  EXPECT_FALSE(LedIsOn(flicker, 3 * kFrameIntervalNs));
  EXPECT_EQ(frames[0].image(12, 10), 1.0);
  EXPECT_NEAR(frames[3].image(12, 10), 0.3, kHalfStep);
}

}  // namespace
}  // namespace evfs
