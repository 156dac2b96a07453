#include "evfs/scene/frame_timing.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <utility>

#include "evfs/core/error.h"
#include "evfs/tests/scene/scene_test_scenes.h"

namespace evfs {
namespace {

// Frames 20 and 40 of a 60 ms synthetic recording rendered at 1 kHz, stamped `stamp_offset_ns`
// away from the moments they show (a negative offset: the frame shows a moment after its stamp,
// so the lag to find is -stamp_offset_ns).
FrameLagEstimate EstimateWithStampOffset(const test::SyntheticRecording& recording,
                                         int64_t stamp_offset_ns) {
  const Image first = recording.rendered.frame(20), second = recording.rendered.frame(40);
  const FramePair pair{&first, recording.rendered.timestamp_ns(20) + stamp_offset_ns, &second,
                       recording.rendered.timestamp_ns(40) + stamp_offset_ns};
  return EstimateFrameLag({pair}, recording.events, FrameLagOptions());
}

// Events fire only once a change has reached the contrast threshold, so they trail the change
// they stand for: on the simulator's events the estimate lands 0.4 to 1.8 ms late (measured
// over three seeds and four windows). The tests allow 2 ms.
constexpr int64_t kToleranceNs = 2000000;

TEST(FrameLagTest, FindsZeroWhenTheStampsAreTheMomentsShown) {
  const test::SyntheticRecording recording(96, 72, 0.06, 5);
  const FrameLagEstimate estimate = EstimateWithStampOffset(recording, 0);
  EXPECT_LE(std::llabs(estimate.lag_ns), kToleranceNs) << estimate.description;
  EXPECT_GT(estimate.correlation_at_zero, 0.5) << estimate.description;
}

TEST(FrameLagTest, RecoversAFrameShowingAMomentAfterItsStamp) {
  const test::SyntheticRecording recording(96, 72, 0.06, 5);
  const FrameLagEstimate estimate = EstimateWithStampOffset(recording, -5000000);
  EXPECT_TRUE(estimate.estimated) << estimate.description;
  EXPECT_NEAR(estimate.lag_ns, 5000000, kToleranceNs) << estimate.description;
  EXPECT_GT(estimate.correlation, estimate.correlation_at_zero + 0.05) << estimate.description;
  // Restamping the frames moves the estimate by exactly the restamping.
  EXPECT_EQ(estimate.lag_ns - EstimateWithStampOffset(recording, 0).lag_ns, 5000000);
}

TEST(FrameLagTest, RecoversAFrameShowingAMomentBeforeItsStamp) {
  const test::SyntheticRecording recording(96, 72, 0.06, 7);
  const FrameLagEstimate estimate = EstimateWithStampOffset(recording, 3000000);
  EXPECT_TRUE(estimate.estimated) << estimate.description;
  EXPECT_NEAR(estimate.lag_ns, -3000000, kToleranceNs) << estimate.description;
}

TEST(FrameLagTest, CombinesPairsAndSortsTheCurve) {
  const test::SyntheticRecording recording(96, 72, 0.06, 5);
  const int64_t offset_ns = -4000000;
  const auto& video = recording.rendered;
  const Image a = video.frame(15), b = video.frame(30), c = video.frame(45);
  const std::vector<FramePair> pairs = {
      {&a, video.timestamp_ns(15) + offset_ns, &b, video.timestamp_ns(30) + offset_ns},
      {&b, video.timestamp_ns(30) + offset_ns, &c, video.timestamp_ns(45) + offset_ns}};
  const FrameLagEstimate estimate = EstimateFrameLag(pairs, recording.events, FrameLagOptions());
  EXPECT_EQ(estimate.pairs, 2);
  EXPECT_NEAR(estimate.lag_ns, 4000000, kToleranceNs) << estimate.description;
  for (size_t i = 1; i < estimate.curve.size(); ++i) {
    EXPECT_LT(estimate.curve[i - 1].lag_ns, estimate.curve[i].lag_ns);
  }
}

TEST(FrameLagTest, ReportsUnknownWithoutEnoughEvents) {
  const test::SyntheticRecording recording(96, 72, 0.06, 5);
  const Image first = recording.rendered.frame(20), second = recording.rendered.frame(40);
  const FramePair pair{&first, recording.rendered.timestamp_ns(20), &second,
                       recording.rendered.timestamp_ns(40)};
  const FrameLagEstimate estimate = EstimateFrameLag({pair}, EventStream(96, 72), {});
  EXPECT_FALSE(estimate.estimated);
  EXPECT_EQ(estimate.lag_ns, 0);
  EXPECT_NE(estimate.description.find("unknown"), std::string::npos) << estimate.description;
}

TEST(FrameLagTest, RejectsBadInput) {
  const test::SyntheticRecording recording(96, 72, 0.06, 5);
  const Image frame = recording.rendered.frame(20);
  FrameLagOptions options;
  options.min_lag_s = 0.001;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THROW(EstimateFrameLag({}, recording.events, options), InvalidArgumentError);
  const FramePair backwards{&frame, 20, &frame, 10};
  EXPECT_THROW(EstimateFrameLag({backwards}, recording.events, {}), InvalidArgumentError);
  const FramePair wrong_size{&frame, 0, &frame, 10};
  EXPECT_THROW(EstimateFrameLag({wrong_size}, EventStream(10, 10), {}), InvalidArgumentError);
}

TEST(FrameTimeTest, ParsesNamesAndLagsAndWritesThemBack) {
  FrameTime time = FrameTime::kInstant;
  double lag_s = 0.0;
  ASSERT_TRUE(ParseFrameTime("auto", &time, &lag_s));
  EXPECT_EQ(time, FrameTime::kAuto);
  ASSERT_TRUE(ParseFrameTime("-2.5ms", &time, &lag_s));
  EXPECT_EQ(time, FrameTime::kLag);
  EXPECT_DOUBLE_EQ(lag_s, -0.0025);
  EXPECT_EQ(FrameTimeName(time, lag_s), "-2.5");
  ASSERT_TRUE(ParseFrameTime("6", &time, &lag_s));
  EXPECT_DOUBLE_EQ(lag_s, 0.006);
  EXPECT_EQ(FrameTimeName(FrameTime::kMiddle, 0.0), "middle");
  for (const char* bad : {"", "ms", "later", "5 ms", "2000", "nan"}) {
    EXPECT_FALSE(ParseFrameTime(bad, &time, &lag_s)) << bad;
  }
}

TEST(FrameTimeTest, ModelledSpanPlacesTheFrame) {
  const int64_t t = 1000000, lag = 300, exposure = 100;
  const auto span = [&](FrameTime time, bool has_exposure) {
    const FrameSpan s = ModelledFrameSpan(t, has_exposure, t - 40, t + 60, time, lag, exposure);
    return std::make_pair(s.begin_ns, s.end_ns);
  };
  EXPECT_EQ(span(FrameTime::kInstant, true), std::make_pair(t, t));
  EXPECT_EQ(span(FrameTime::kAuto, false), std::make_pair(t + lag, t + lag));
  EXPECT_EQ(span(FrameTime::kLag, false), std::make_pair(t + lag, t + lag));
  EXPECT_EQ(span(FrameTime::kStart, false), std::make_pair(t, t + exposure));
  EXPECT_EQ(span(FrameTime::kMiddle, false), std::make_pair(t - 50, t + 50));
  EXPECT_EQ(span(FrameTime::kEnd, false), std::make_pair(t - exposure, t));
  // The data's exposure wins over the assumed one.
  EXPECT_EQ(span(FrameTime::kStart, true), std::make_pair(t - 40, t + 60));
  EXPECT_THROW(ModelledFrameSpan(t, false, 0, 0, FrameTime::kEnd, 0, 0), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
