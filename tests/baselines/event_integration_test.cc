#include "evfs/baselines/event_integration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evfs/core/error.h"
#include "evfs/events/simulator.h"
#include "evfs/scene/scene.h"
#include "evfs/tests/baselines/baseline_test_scenes.h"

namespace evfs {
namespace {

// Integration only adds and subtracts doubles: anything above rounding is a bug.
constexpr double kExactTolerance = 1e-12;
// Integration from frame 0 with the simulator's own threshold predicts frame 10 of the 48×40
// scene at 32.06 dB, the copy of frame 0 at 24.36 dB (printed below when this was set); the bar
// sits well below the 7.7 dB gain so that it catches breakage, not noise.
constexpr double kMinGainOverCopyDb = 5.0;

// Events from the synthetic recording with one threshold at every pixel (no mismatch), so that
// the simulator's round trip bounds integration with that threshold exactly.
EventStream EventsWithoutMismatch(const test::SyntheticRecording& recording,
                                  const SimulatorOptions& simulator) {
  SimulatorOptions exact = simulator;
  exact.threshold_sigma = 0.0;
  return SimulateEvents(recording.rendered, exact);
}

TEST(CumulativeEventCount, SumsTheSignedEventsOfTheFramesEndingBeforeEachLatentFrame) {
  const test::SyntheticRecording recording;
  const Scene scene = test::InterpolationScene(recording);
  const Video count = CumulativeEventCount(scene);
  ASSERT_EQ(count.num_frames(), scene.num_latent_frames());
  EXPECT_EQ(count.timestamps_ns(), scene.latent_timestamps_ns());
  EXPECT_EQ(count.frame(0).abs().maxCoeff(), 0.0);
  Image total = Image::Zero(scene.height, scene.width);
  for (int k = 0; k < scene.events.num_frames(); ++k) {
    for (int y = 0; y < scene.height; ++y) {
      for (int x = 0; x < scene.width; ++x) total(y, x) += scene.events.value(k, y, x);
    }
  }
  EXPECT_EQ(test::MaxAbsDifference(count.frame(count.num_frames() - 1), total), 0.0);
}

TEST(CumulativeEventCount, SpreadsAStackedFrameEvenlyOverItsSteps) {
  const test::SyntheticRecording recording;
  BinningOptions binning;
  binning.method = BinningOptions::Method::kStacked;
  binning.stacked.num_frames = 1;
  binning.stacked.steps_per_frame = 4;
  const Scene scene = MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(10),
                                          recording.events, binning);
  const Video count = CumulativeEventCount(scene);
  ASSERT_EQ(count.num_frames(), 5);
  Image frame(scene.height, scene.width);
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) frame(y, x) = scene.events.value(0, y, x);
  }
  for (int t = 0; t <= 4; ++t) {
    EXPECT_LT(test::MaxAbsDifference(count.frame(t), frame * (t / 4.0)), kExactTolerance);
  }
}

TEST(IntegrateEvents, WithTheSensorsThresholdStaysWithinOneThresholdOfTheNextFrame) {
  // The simulator's round trip (events/simulator.h), seen through the scene's event frames:
  // forward log integration with the sensor's threshold and offset lands within one threshold
  // of the frame at the end of the window, at every pixel.
  const test::SyntheticRecording recording;
  const SimulatorOptions simulator;
  const Scene scene =
      MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(10),
                          EventsWithoutMismatch(recording, simulator), BinningOptions());
  BaselineOptions options;
  options.domain = IntegrationDomain::kLog;
  options.log_offset = simulator.log_eps;
  options.clamp_to_unit_range = false;
  const Video latent = IntegrateEvents(scene, options, simulator.contrast_threshold_pos);
  const Image predicted = ImageToDomain(latent.frame(latent.num_frames() - 1),
                                        IntegrationDomain::kLog, simulator.log_eps);
  const Image truth =
      ImageToDomain(recording.rendered.frame(10), IntegrationDomain::kLog, simulator.log_eps);
  EXPECT_LT((predicted - truth).abs().maxCoeff(), simulator.contrast_threshold_pos);
}

TEST(IntegrateEvents, PredictsTheNextFrameFarBetterThanTheCopy) {
  const test::SyntheticRecording recording;
  const SimulatorOptions simulator;
  const Scene scene = test::PredictionScene(recording);
  BaselineOptions options;
  options.domain = IntegrationDomain::kLog;
  options.log_offset = simulator.log_eps;
  const double copy = test::PsnrAt(InitializeLatentVideo(scene), recording, 10);
  const double integrated = test::PsnrAt(
      IntegrateEvents(scene, options, simulator.contrast_threshold_pos), recording, 10);
  std::printf("prediction of frame 10: copy %.2f dB, integration %.2f dB\n", copy, integrated);
  EXPECT_GE(integrated, copy + kMinGainOverCopyDb);
}

TEST(IntegrateEvents, ReproducesTheSharpFramesItStartsFrom) {
  const test::SyntheticRecording recording;
  const Scene scene = test::InterpolationScene(recording);
  const int last = scene.num_latent_frames() - 1;
  for (IntegrationDomain domain : {IntegrationDomain::kLinear, IntegrationDomain::kLog}) {
    BaselineOptions options;
    options.domain = domain;
    options.direction = IntegrationDirection::kBackward;
    const Video backward = IntegrateEvents(scene, options, 0.2);
    EXPECT_LT(test::MaxAbsDifference(backward.frame(last), scene.frames[1].image), kExactTolerance);
    options.direction = IntegrationDirection::kForward;
    const Video forward = IntegrateEvents(scene, options, 0.2);
    EXPECT_LT(test::MaxAbsDifference(forward.frame(0), scene.frames[0].image), kExactTolerance);
    options.direction = IntegrationDirection::kBoth;
    const Video both = IntegrateEvents(scene, options, 0.2);
    EXPECT_LT(test::MaxAbsDifference(both.frame(0), scene.frames[0].image), kExactTolerance);
    EXPECT_LT(test::MaxAbsDifference(both.frame(last), scene.frames[1].image), kExactTolerance);
  }
}

TEST(IntegrateEvents, BothDirectionsBlendForwardAndBackwardLinearlyInTime) {
  const test::SyntheticRecording recording;
  const Scene scene = test::InterpolationScene(recording);
  BaselineOptions options;
  options.domain = IntegrationDomain::kLinear;
  options.clamp_to_unit_range = false;
  options.direction = IntegrationDirection::kForward;
  const Video forward = IntegrateEvents(scene, options, 0.1);
  options.direction = IntegrationDirection::kBackward;
  const Video backward = IntegrateEvents(scene, options, 0.1);
  options.direction = IntegrationDirection::kBoth;
  const Video both = IntegrateEvents(scene, options, 0.1);
  const std::vector<int64_t>& latent_ns = scene.latent_timestamps_ns();
  const int last = scene.num_latent_frames() - 1;
  for (int t = 0; t <= last; ++t) {
    const double w = static_cast<double>(latent_ns[t] - latent_ns[0]) /
                     static_cast<double>(latent_ns[last] - latent_ns[0]);
    const Image expected = (1.0 - w) * forward.frame(t) + w * backward.frame(t);
    EXPECT_LT(test::MaxAbsDifference(both.frame(t), expected), kExactTolerance) << t;
  }
}

TEST(IntegrateEvents, BlurSmoothsEachIntegratedFrame) {
  const test::SyntheticRecording recording;
  const Scene scene = test::PredictionScene(recording);
  BaselineOptions options;
  options.clamp_to_unit_range = false;
  const Video sharp = IntegrateEvents(scene, options, 0.1);
  options.blur_sigma_px = 1.0;
  const Video blurred = IntegrateEvents(scene, options, 0.1);
  for (int t = 0; t < sharp.num_frames(); ++t) {
    Image expected = sharp.frame(t);
    GaussianBlurImage(1.0, &expected);
    EXPECT_LT(test::MaxAbsDifference(blurred.frame(t), expected), kExactTolerance);
  }
  EXPECT_LT(LaplacianVariance(blurred.frame(0)), LaplacianVariance(sharp.frame(0)));
}

TEST(IntegrateEvents, NeedsASharpFrame) {
  const test::SyntheticRecording recording;
  EXPECT_THROW(IntegrateEvents(test::DeblurScene(recording), BaselineOptions(), 0.1),
               InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
