#include "scene/confidence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "core/error.h"

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

// Where the events predict the second frame exactly, nothing is uncertain; where they miss it by
// D, the error between the two events (half of them behind, half ahead) is |D| / 2, and zero at
// the frames (noise-free flat frames).
TEST(Confidence, BridgeBetweenSharpFramesGrowsWithTheFramesGap) {
  ConfidenceOptions options;  // Δg 0.2, b 0.5
  const double agreeing = (0.3 + 0.5) * std::exp(2 * 0.2) - 0.5;
  for (const double second : {agreeing, 0.5}) {
    const Scene scene = MakeInterpolationScene(Flat(0.3, 0), Flat(second, kWindowNs),
                                               TwoOnEventsEverywhere(), BinningOptions());
    ConfidenceModel model;
    const Video sigma = PredictErrorSigma(scene, Constant(scene, 0.4), options, &model);
    ASSERT_EQ(sigma.num_frames(), scene.num_latent_frames());
    const double gap = std::abs(second - agreeing);
    EXPECT_NEAR(model.measured_event_variance, gap * gap * 64 / (64 * 3), kTolerance);
    EXPECT_EQ(model.frame_noise_sigma, 0.0);
    const int middle = sigma.NearestFrame(kWindowNs / 2);
    EXPECT_NEAR(sigma.at(middle, 4, 4), gap / 2, kTolerance) << second;
    EXPECT_NEAR(sigma.at(0, 4, 4), 0.0, kTolerance);
    EXPECT_NEAR(sigma.at(sigma.num_frames() - 1, 4, 4), 0.0, kTolerance);
  }
}

// After a single frame nothing measures the events: each one may be wrong by its own change,
// ((I + b) · Δg), and the errors add as a random walk; a prior per-event variance replaces it.
TEST(Confidence, PredictionGrowsWithTheEventsSinceTheFrame) {
  const Scene scene =
      MakePredictionScene(Flat(0.3, 0), kWindowNs, TwoOnEventsEverywhere(), BinningOptions());
  ConfidenceOptions options;
  ConfidenceModel model;
  const Video sigma = PredictErrorSigma(scene, Constant(scene, 0.3), options, &model);
  EXPECT_LT(model.measured_event_variance, 0.0);
  const int last = sigma.num_frames() - 1;
  EXPECT_NEAR(sigma.at(0, 2, 2), 0.0, kTolerance);
  EXPECT_NEAR(sigma.at(last, 2, 2), std::sqrt(2.0) * 0.8 * 0.2, kTolerance);
  options.prior_event_variance = 0.01;
  EXPECT_NEAR(PredictErrorSigma(scene, Constant(scene, 0.3), options).at(last, 2, 2),
              std::sqrt(2 * 0.01), kTolerance);
}

TEST(Confidence, ShareWithinSigmaCountsThePixelsInsideTheBand) {
  const Image truth = Image::Constant(2, 2, 0.5);
  Image estimate = truth;
  estimate(0, 0) = 0.6;   // error 0.1: outside a 0.05 band
  estimate(1, 1) = 0.53;  // error 0.03: inside
  EXPECT_DOUBLE_EQ(ShareWithinSigma(estimate, truth, Image::Constant(2, 2, 0.05)), 0.75);
  EXPECT_THROW(ShareWithinSigma(estimate, Image::Constant(3, 2, 0.5), Image::Constant(2, 2, 0.1)),
               InvalidArgumentError);
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
