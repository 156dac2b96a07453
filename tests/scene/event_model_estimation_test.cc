#include "scene/event_model_estimation.h"

#include <gtest/gtest.h>

#include "tests/scene/scene_test_scenes.h"

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

}  // namespace
}  // namespace evfs
