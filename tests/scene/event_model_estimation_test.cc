#include "evfs/scene/event_model_estimation.h"

#include <gtest/gtest.h>

#include <string>

#include "evfs/events/simulator.h"
#include "evfs/tests/scene/scene_test_scenes.h"

namespace evfs {
namespace {

// The simulator's median threshold is 0.2; the median of per-pixel ratios of log change to net
// event count is biased low by up to one threshold per pixel's rounding, so allow 25 %.
constexpr double kThresholdTolerance = 0.05;

TEST(EventModelEstimation, MeasuresTheSimulatorsThresholdWithTheLogModel) {
  const test::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  EventModelParams log_model;
  log_model.model = EventModel::kLog;
  log_model.log_offset = SimulatorOptions().log_eps;  // the simulator's own log
  const EventModelEstimationOptions options;
  const EventModelEstimate estimate = EstimateEventModel(scene, log_model, options);
  EXPECT_TRUE(estimate.estimated_from_frames);
  EXPECT_NEAR(estimate.change_per_event, SimulatorOptions().contrast_threshold_pos,
              kThresholdTolerance);
  EXPECT_DOUBLE_EQ(estimate.alpha, options.alpha_times_change / estimate.change_per_event);
  EXPECT_NE(estimate.description.find("measured"), std::string::npos);
}

// A sensor whose OFF threshold is lower than its ON one (as a DAVIS's are): measured per
// polarity, the change of one ON event and of one OFF event are the two thresholds, and their
// ratio becomes the OFF slope; measured together they give one value between them.
TEST(EventModelEstimation, MeasuresOnAndOffThresholdsApart) {
  const test::SyntheticRecording recording(64, 48, 0.03, 5);
  SimulatorOptions sensor;
  sensor.contrast_threshold_pos = 0.3;
  sensor.contrast_threshold_neg = 0.15;
  const EventStream events = SimulateEvents(recording.rendered, sensor);
  const Scene scene =
      MakeInterpolationScene(recording.Sharp(0), recording.Sharp(30), events, BinningOptions());
  EventModelParams log_model;
  log_model.model = EventModel::kLog;
  log_model.log_offset = sensor.log_eps;
  EventModelEstimationOptions options;
  options.min_pixels = 20;
  const EventModelEstimate estimate = EstimateEventModel(scene, log_model, options);
  ASSERT_TRUE(estimate.estimated_from_frames);
  // Each median is biased by a pixel's rounding (a change between n and n + 1 thresholds gives
  // n events) by up to a third here; the ratio of the two is what the model takes.
  EXPECT_NEAR(estimate.change_per_event, 0.3, 0.3 * 0.35);
  EXPECT_NEAR(estimate.change_per_event / estimate.off_alpha_ratio, 0.15, 0.15 * 0.35);
  EXPECT_NEAR(estimate.off_alpha_ratio, 2.0, 2.0 * 0.2);
  EXPECT_NE(estimate.description.find("OFF"), std::string::npos) << estimate.description;

  options.per_polarity = false;
  const EventModelEstimate together = EstimateEventModel(scene, log_model, options);
  EXPECT_EQ(together.off_alpha_ratio, 1.0);
  EXPECT_GT(together.change_per_event, 0.15 * 0.9);
  EXPECT_LT(together.change_per_event, 0.3 * 1.1);
}

TEST(EventModelEstimation, FallsBackToTheAssumedChangeWithOneFrame) {
  const test::SyntheticRecording recording;
  const Scene scene = MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(20),
                                          recording.events, BinningOptions());
  const EventModelEstimationOptions options;
  const EventModelEstimate linear = EstimateEventModel(scene, EventModelParams(), options);
  EXPECT_FALSE(linear.estimated_from_frames);
  EXPECT_DOUBLE_EQ(linear.change_per_event, options.assumed_linear_change);
  EventModelParams log_model;
  log_model.model = EventModel::kLog;
  const EventModelEstimate log = EstimateEventModel(scene, log_model, options);
  EXPECT_DOUBLE_EQ(log.change_per_event, options.assumed_contrast_threshold);
  EXPECT_NE(log.description.find("assumed"), std::string::npos);
}

// Two blurred frames and no sharp one (a video of long exposures): each stands at the middle of
// its exposure, and the change between them per net event still measures the threshold. One
// blurred frame alone cannot tell, and the assumed change is used.
TEST(EventModelEstimation, MeasuresTheThresholdBetweenTwoBlurredFrames) {
  const test::SyntheticRecording recording(48, 40, 0.04);
  const TimedFrame first = recording.Blurred(0, 6), last = recording.Blurred(28, 34);
  const Scene scene = MakeScene({first, last}, recording.events, recording.rendered.timestamp_ns(0),
                                recording.rendered.timestamp_ns(34) + 1, BinningOptions());
  EventModelParams log_model;
  log_model.model = EventModel::kLog;
  log_model.log_offset = SimulatorOptions().log_eps;
  EventModelEstimationOptions options;
  options.per_polarity = false;
  const EventModelEstimate estimate = EstimateEventModel(scene, log_model, options);
  ASSERT_TRUE(estimate.estimated_from_frames) << estimate.description;
  EXPECT_NEAR(estimate.change_per_event, SimulatorOptions().contrast_threshold_pos,
              2.0 * kThresholdTolerance);
  EXPECT_NE(estimate.description.find("blurred frames"), std::string::npos) << estimate.description;

  const Scene deblur = MakeDeblurScene(first, recording.events, BinningOptions());
  EXPECT_FALSE(EstimateEventModel(deblur, log_model, options).estimated_from_frames);
}

}  // namespace
}  // namespace evfs
