#include "evfs/scene/confidence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "evfs/core/error.h"

namespace evfs {
namespace {

constexpr int kSize = 8;
constexpr int64_t kWindowNs = 30000000;
// The model's arithmetic is in double but the cumulative event counts are stored in float.
constexpr double kTolerance = 1e-6;

TimedFrame Flat(double level, int64_t t_ns) {
  TimedFrame frame;
  frame.image = Image::Constant(kSize, kSize, level);
  frame.exposure_begin_ns = frame.exposure_end_ns = t_ns;
  frame.label = "flat";
  return frame;
}

// Every pixel brightens by two ON events, at a third and two thirds of the window.
EventStream TwoOnEventsEverywhere() {
  EventStream events(kSize, kSize);
  for (const int64_t t : {kWindowNs / 3, 2 * kWindowNs / 3}) {
    for (int y = 0; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) events.push_back(t, x, y, 1);
    }
  }
  return events;
}

Video Constant(const Scene& scene, double level) {
  Video video(scene.height, scene.width, scene.num_latent_frames());
  for (int t = 0; t < video.num_frames(); ++t) {
    video.set_timestamp_ns(t, scene.latent_timestamps_ns()[t]);
    video.frame(t).setConstant(level);
  }
  return video;
}

// Reproducible standard normal samples: Box–Muller on a linear congruential generator, without
// <random>'s implementation-defined distributions.
class Gaussian {
 public:
  explicit Gaussian(uint64_t seed) : state_(seed) {}
  double operator()() {
    const double u = Uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(6.283185307179586 * Uniform());
  }

 private:
  double Uniform() {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return (static_cast<double>(state_ >> 11) + 0.5) / 9007199254740992.0;
  }
  uint64_t state_;
};

// The frames' blend on the scene's timeline, plus `offset` everywhere.
Video Blend(const Scene& scene, double first, double second, double offset = 0.0) {
  Video video = Constant(scene, 0.0);
  for (int t = 0; t < video.num_frames(); ++t) {
    const double w = static_cast<double>(video.timestamp_ns(t)) / kWindowNs;
    video.frame(t).setConstant((1.0 - w) * first + w * second + offset);
  }
  return video;
}

// Two frames a window apart and one event at (event_x, event_y), so that the frames' other pixels
// are still: the confidence of an estimate at 0.5 throughout, and the model behind it.
struct StillPair {
  ConfidenceModel model;
  Video sigma;
};
StillPair PredictOverStillPair(TimedFrame first, TimedFrame second, int event_x, int event_y) {
  first.exposure_begin_ns = first.exposure_end_ns = 0;
  second.exposure_begin_ns = second.exposure_end_ns = kWindowNs;
  first.label = second.label = "still";
  EventStream events(first.image.cols(), first.image.rows());
  events.push_back(kWindowNs / 2, event_x, event_y, 1);
  const Scene scene = MakeInterpolationScene(first, second, events, BinningOptions());
  StillPair result;
  result.sigma = PredictErrorSigma(scene, Constant(scene, 0.5), ConfidenceOptions(), &result.model);
  return result;
}

// Where the events predict the second frame exactly, nothing is uncertain; where they miss it by
// D, the error of a pixel that fired, between its two events (half of them behind, half ahead),
// is |D| / √2 (2 · D² · s(1 − s) at s = 1/2), and zero at the frames (noise-free flat frames). An
// estimate that departs from the frames' blend by δ adds (δ / 2)².
TEST(Confidence, BridgeBetweenSharpFramesGrowsWithTheFramesGap) {
  ConfidenceOptions options;  // Δg 0.2, b 0.5
  const double agreeing = (0.3 + 0.5) * std::exp(2 * 0.2) - 0.5;
  for (const double second : {agreeing, 0.5}) {
    const Scene scene = MakeInterpolationScene(Flat(0.3, 0), Flat(second, kWindowNs),
                                               TwoOnEventsEverywhere(), BinningOptions());
    ConfidenceModel model;
    const Video sigma = PredictErrorSigma(scene, Blend(scene, 0.3, second), options, &model);
    ASSERT_EQ(sigma.num_frames(), scene.num_latent_frames());
    const double gap = std::abs(second - agreeing);
    EXPECT_NEAR(model.measured_event_variance, gap * gap * 64 / (64 * 3), kTolerance);
    EXPECT_EQ(model.frame_noise_sigma, 0.0);
    const int middle = sigma.NearestFrame(kWindowNs / 2);
    EXPECT_NEAR(sigma.at(middle, 4, 4), gap / std::sqrt(2.0), kTolerance) << second;
    EXPECT_NEAR(sigma.at(0, 4, 4), 0.0, kTolerance);
    EXPECT_NEAR(sigma.at(sigma.num_frames() - 1, 4, 4), 0.0, kTolerance);
    const double departure = 0.1;
    EXPECT_NEAR(
        PredictErrorSigma(scene, Blend(scene, 0.3, second, departure), options).at(middle, 4, 4),
        std::sqrt(gap * gap / 2 + departure * departure / 4), kTolerance);
  }
}

// A pixel that fired no event between two sharp frames changed by less than a threshold; the
// solve follows that change, and what is left is a share of its own gap: 0.35 · D² · s(1 − s),
// s the time fraction.
TEST(Confidence, AQuietPixelBetweenSharpFramesFollowsItsOwnGap) {
  const double agreeing = (0.3 + 0.5) * std::exp(2 * 0.2) - 0.5;
  const EventStream everywhere = TwoOnEventsEverywhere();
  EventStream events(kSize, kSize);
  for (size_t i = 0; i < everywhere.size(); ++i) {
    if (everywhere.x(i) == 4 && everywhere.y(i) == 4) continue;
    events.push_back(everywhere.t_ns(i), everywhere.x(i), everywhere.y(i), everywhere.polarity(i));
  }
  TimedFrame second = Flat(agreeing, kWindowNs);
  const double quiet_gap = 0.05;
  second.image(4, 4) = 0.3 + quiet_gap;
  const Scene scene = MakeInterpolationScene(Flat(0.3, 0), second, events, BinningOptions());
  ConfidenceModel model;
  const Video sigma =
      PredictErrorSigma(scene, Blend(scene, 0.3, agreeing), ConfidenceOptions(), &model);
  const int middle = sigma.NearestFrame(kWindowNs / 2);
  const double s = static_cast<double>(sigma.timestamp_ns(middle)) / kWindowNs;
  // The frames' noise (the one bright pixel reads as some): the truth's, and the two frames'
  // that the blend at s carries.
  const double noise = model.frame_noise_sigma;
  const double frames_noise = noise * noise * (1.0 + s * s + (1.0 - s) * (1.0 - s));
  EXPECT_NEAR(sigma.at(middle, 4, 4),
              std::sqrt(0.35 * quiet_gap * quiet_gap * s * (1.0 - s) + frames_noise), kTolerance);
  // The noise read is small beside the gap, so the gap's share is what the band shows.
  EXPECT_LT(noise, quiet_gap / 2);
}

// After a single frame nothing measures the events: each one may be wrong by the threshold's
// spread, ((I + b) · σ_C), and the errors add as a random walk; a prior per-event variance
// replaces it. Away from the frame, where the scene moved, the change not yet recorded adds
// half of ((I + b) · Δg)² / 12, and an estimate that departs from the frame by δ adds δ² / 5.
TEST(Confidence, PredictionGrowsWithTheEventsSinceTheFrame) {
  const Scene scene =
      MakePredictionScene(Flat(0.3, 0), kWindowNs, TwoOnEventsEverywhere(), BinningOptions());
  ConfidenceOptions options;
  ConfidenceModel model;
  const Video sigma = PredictErrorSigma(scene, Constant(scene, 0.3), options, &model);
  EXPECT_LT(model.measured_event_variance, 0.0);
  const int last = sigma.num_frames() - 1;
  const double unrecorded = 0.5 * 0.8 * 0.2 * 0.8 * 0.2 / 12.0;
  EXPECT_NEAR(sigma.at(0, 2, 2), 0.0, kTolerance);
  EXPECT_NEAR(sigma.at(last, 2, 2), std::sqrt(2.0 * 0.8 * 0.03 * 0.8 * 0.03 + unrecorded),
              kTolerance);
  options.prior_event_variance = 0.01;
  EXPECT_NEAR(PredictErrorSigma(scene, Constant(scene, 0.3), options).at(last, 2, 2),
              std::sqrt(2 * 0.01 + unrecorded), kTolerance);
  // The estimate at the frame is the frame; after it, 0.1 above.
  Video departed = Constant(scene, 0.4);
  departed.frame(0).setConstant(0.3);
  const Video wider = PredictErrorSigma(scene, departed, options);
  const double unrecorded_at_04 = 0.5 * 0.9 * 0.2 * 0.9 * 0.2 / 12.0;
  EXPECT_NEAR(wider.at(last, 2, 2), std::sqrt(2 * 0.01 + unrecorded_at_04 + 0.1 * 0.1 / 5),
              kTolerance);
  EXPECT_NEAR(wider.at(0, 2, 2), 0.0, kTolerance);
}

// After a frame, a pixel that fired no event may still have changed, by less than a threshold:
// by its gradient times how far the scene around it moved (the events nearby per unit of
// gradient), at most one threshold (I + b) · Δg, of which the band takes 0.35 of the square. On
// a flat estimate, or where nothing around it fired, there is nothing for it to have changed by.
TEST(Confidence, AQuietPixelAfterAFrameMayHaveChangedWithTheMotionAroundIt) {
  // A ramp of g = log(I + b) along x, 0.1 per pixel: half a threshold.
  Image ramp(kSize, kSize);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) ramp(y, x) = std::exp(std::log(0.2 + 0.5) + 0.1 * x) - 0.5;
  }
  TimedFrame frame = Flat(0.0, 0);
  frame.image = ramp;
  const EventStream everywhere = TwoOnEventsEverywhere();
  EventStream around(kSize, kSize);
  for (size_t i = 0; i < everywhere.size(); ++i) {
    if (everywhere.x(i) == 4 && everywhere.y(i) == 4) continue;
    around.push_back(everywhere.t_ns(i), everywhere.x(i), everywhere.y(i), everywhere.polarity(i));
  }
  const auto sigma_at_quiet_pixel = [&](const EventStream& events, const Image& estimate,
                                        double* noise) {
    const Scene scene = MakePredictionScene(frame, kWindowNs, events, BinningOptions());
    Video video = Constant(scene, 0.0);
    for (int t = 0; t < video.num_frames(); ++t) video.frame(t) = estimate;
    ConfidenceModel model;
    const Video sigma = PredictErrorSigma(scene, video, ConfidenceOptions(), &model);
    *noise = model.frame_noise_sigma;
    EXPECT_NEAR(sigma.at(0, 4, 4), std::sqrt(2.0) * model.frame_noise_sigma, kTolerance);
    return sigma.at(sigma.num_frames() - 1, 4, 4);
  };
  double noise = 0.0;
  // Its neighbours fired two events each on a gradient of half a threshold per pixel: about
  // four pixels of motion, two thresholds at this pixel's gradient, taken as one.
  const double threshold = (ramp(4, 4) + 0.5) * 0.2;
  EXPECT_NEAR(sigma_at_quiet_pixel(around, ramp, &noise),
              std::sqrt(0.35 * threshold * threshold + 2.0 * noise * noise), kTolerance);
  EXPECT_GT(threshold * threshold, 10 * noise * noise);
  // On a flat estimate, and where no event fired, only the frame's noise is left.
  EXPECT_NEAR(sigma_at_quiet_pixel(around, Image::Constant(kSize, kSize, 0.2), &noise),
              std::sqrt(2.0) * noise, kTolerance);
  EXPECT_NEAR(sigma_at_quiet_pixel(EventStream(kSize, kSize), ramp, &noise), std::sqrt(2.0) * noise,
              kTolerance);
}

// Where no pixel of a 3x3 neighbourhood fired between two sharp frames, their difference is
// their noise: the model measures it there (robustly, around the median difference, so that a
// change of exposure between the frames does not count), not from one frame's texture.
TEST(Confidence, FrameNoiseIsMeasuredWhereTheSceneHoldsStill) {
  constexpr int kWide = 64;
  const double sigma_noise = 0.01;
  TimedFrame first, second;
  first.image = Image::Constant(kWide, kWide, 0.4);
  second.image = Image::Constant(kWide, kWide, 0.45);  // a brighter exposure, not noise
  Gaussian gaussian(12345);
  for (int y = 0; y < kWide; ++y) {
    for (int x = 0; x < kWide; ++x) {
      // Texture both frames share (a fixed pattern) and the frames' own temporal noise.
      const double texture = ((x / 4 + y / 4) % 2) * 0.2;
      first.image(y, x) += texture + sigma_noise * gaussian();
      second.image(y, x) += texture + sigma_noise * gaussian();
    }
  }
  const ConfidenceModel model = PredictOverStillPair(first, second, 10, 10).model;
  EXPECT_NEAR(model.frame_noise_sigma, sigma_noise, 0.1 * sigma_noise);
  EXPECT_NE(model.description.find("measured where the scene holds still"), std::string::npos)
      << model.description;
}

// Under a saturated (or black) region the still pixels' difference is exactly zero: they show no
// noise and must not hide the noise of the rest. Three quarters of the frame clipped white and
// an eighth black, the rest noisy: the noise is the rest's.
TEST(Confidence, ClippedPixelsDoNotHideTheFramesNoise) {
  constexpr int kWide = 64;
  const double sigma_noise = 0.01;
  Gaussian gaussian(777);
  TimedFrame first, second;
  first.image = Image::Constant(kWide, kWide, 1.0);
  second.image = Image::Constant(kWide, kWide, 1.0);
  for (int y = 0; y < kWide; ++y) {
    for (int x = 0; x < kWide; ++x) {
      if (y < 8) {
        first.image(y, x) = second.image(y, x) = 0.0;
      } else if (y < 16) {
        first.image(y, x) = 0.5 + sigma_noise * gaussian();
        second.image(y, x) = 0.5 + sigma_noise * gaussian();
      }
    }
  }
  const StillPair pair = PredictOverStillPair(first, second, 40, 40);
  const ConfidenceModel& model = pair.model;
  EXPECT_NEAR(model.frame_noise_sigma, sigma_noise, 0.15 * sigma_noise);
  EXPECT_NE(model.description.find("measured where the scene holds still"), std::string::npos)
      << model.description;
  // A quiet pixel of the white region between the frames: its band is the frames' noise, not 0.
  EXPECT_GT(pair.sigma.frame(pair.sigma.num_frames() / 2)(30, 10), 0.5 * sigma_noise);
}

// 8-bit frames whose noise is under one grey level: most still pixels differ by 0 or ±1 level,
// so the median absolute difference reads one level (1.4826 / √2 ≈ 1.05 levels) whatever the
// noise. The share of differences that round to zero resolves it; at 8 levels few differences
// are zero and the median reads it. A uniform texture under the noise, so that the scene's level
// falls anywhere within a step, and a brighter second exposure by two levels, which is not noise.
TEST(Confidence, EightBitFramesNoiseUnderOneLevelIsMeasuredFromTheDifferencesAtZero) {
  constexpr int kWide = 96;
  constexpr double kLevel = 1.0 / 255.0;
  for (const double noise_levels : {0.3, 0.6, 1.5, 8.0}) {
    Gaussian gaussian(4242);
    // The scene's level at each pixel: 60 to 160 grey levels, fractions spread evenly.
    const auto recorded = [&](double exposure_shift) {
      TimedFrame frame;
      frame.image = Image::Constant(kWide, kWide, 0.0);
      for (int p = 0; p < kWide * kWide; ++p) {
        const double golden = p * 0.6180339887 - std::floor(p * 0.6180339887);
        const double level = 60.0 + 100.0 * golden + exposure_shift;
        frame.image(p / kWide, p % kWide) = std::round(level + noise_levels * gaussian()) * kLevel;
      }
      return frame;
    };
    const TimedFrame first = recorded(0.0);
    const TimedFrame second = recorded(2.0);
    const ConfidenceModel model = PredictOverStillPair(first, second, 10, 10).model;
    EXPECT_NEAR(model.frame_noise_sigma, noise_levels * kLevel, 0.1 * noise_levels * kLevel)
        << noise_levels << " levels";
    EXPECT_NE(model.description.find("measured where the scene holds still"), std::string::npos)
        << model.description;
  }
}

TEST(Confidence, ShareWithinSigmaCountsThePixelsInsideTheBand) {
  const Image truth = Image::Constant(2, 2, 0.5);  // 127.5: not a whole 8-bit level
  Image estimate = truth;
  estimate(0, 0) = 0.6;   // error 0.1: outside a 0.05 band
  estimate(1, 1) = 0.53;  // error 0.03: inside
  EXPECT_DOUBLE_EQ(ShareWithinSigma(estimate, truth, Image::Constant(2, 2, 0.05)), 0.75);
  EXPECT_THROW(ShareWithinSigma(estimate, Image::Constant(3, 2, 0.5), Image::Constant(2, 2, 0.1)),
               InvalidArgumentError);
}

// An 8-bit truth gives the scene only to within half a level: a pixel counts with the share of
// its level's bin within the band, so the count moves smoothly as the band widens.
TEST(Confidence, ShareWithinSigmaOfAnEightBitTruthCountsTheShareOfItsBin) {
  constexpr double kLevel = 1.0 / 255.0;
  const Image truth = Image::Constant(1, 2, 128 * kLevel);
  EXPECT_DOUBLE_EQ(QuantisationStep(truth), kLevel);
  EXPECT_DOUBLE_EQ(QuantisationStep(Image::Constant(1, 2, 0.5)), 0.0);
  Image estimate = truth;
  estimate(0, 1) += kLevel;  // one level off
  // A quarter-level band: the exact pixel keeps [−1/4, 1/4] of its bin [−1/2, 1/2] (half), the
  // other pixel none.
  EXPECT_NEAR(ShareWithinSigma(estimate, truth, Image::Constant(1, 2, kLevel / 4)), 0.25, 1e-12);
  // One level: the exact pixel's whole bin, half of the other's.
  EXPECT_NEAR(ShareWithinSigma(estimate, truth, Image::Constant(1, 2, kLevel)), 0.75, 1e-12);
  // Counting |error| <= band would give 0.5 and 1.
}

TEST(Confidence, RejectsBadOptionsAndMismatchedVideos) {
  const Scene scene =
      MakePredictionScene(Flat(0.3, 0), kWindowNs, TwoOnEventsEverywhere(), BinningOptions());
  ConfidenceOptions options;
  options.change_per_event = 0.0;
  EXPECT_THROW(PredictErrorSigma(scene, Constant(scene, 0.3), options), InvalidArgumentError);
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("change_per_event"), std::string::npos) << error;
  EXPECT_THROW(PredictErrorSigma(scene, Video(kSize, kSize, 2), ConfidenceOptions()),
               InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
