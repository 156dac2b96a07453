#include "evfs/baselines/complementary_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "evfs/baselines/event_integration.h"
#include "evfs/core/error.h"
#include "evfs/scene/scene.h"
#include "evfs/tests/baselines/baseline_test_scenes.h"

namespace evfs {
namespace {

// The filter and integration sum the same event values in another order: rounding only.
constexpr double kRoundingTolerance = 1e-9;
constexpr double kThreshold = 0.2;

TEST(ComplementaryFilter, ZeroCutoffIsForwardLogIntegration) {
  const test::SyntheticRecording recording;
  const Scene scene = test::PredictionScene(recording);
  BaselineOptions options;
  options.cutoff_rad_per_s = 0.0;
  options.domain = IntegrationDomain::kLog;
  const Video filtered = ComplementaryFilter(scene, options, kThreshold);
  const Video integrated = IntegrateEvents(scene, options, kThreshold);
  ASSERT_EQ(filtered.num_frames(), integrated.num_frames());
  EXPECT_EQ(filtered.timestamps_ns(), scene.latent_timestamps_ns());
  for (int t = 0; t < filtered.num_frames(); ++t) {
    EXPECT_LT(test::MaxAbsDifference(filtered.frame(t), integrated.frame(t)), kRoundingTolerance)
        << t;
  }
}

TEST(ComplementaryFilter, InfiniteCutoffIsTheFrame) {
  const test::SyntheticRecording recording;
  const Scene scene = test::PredictionScene(recording);
  BaselineOptions options;
  options.cutoff_rad_per_s = std::numeric_limits<double>::infinity();
  const Video filtered = ComplementaryFilter(scene, options, kThreshold);
  for (int t = 0; t < filtered.num_frames(); ++t) {
    EXPECT_LT(test::MaxAbsDifference(filtered.frame(t), scene.frames[0].image), kRoundingTolerance)
        << t;
  }
}

TEST(ComplementaryFilter, AHigherCutoffPullsTheEstimateCloserToTheFrame) {
  const test::SyntheticRecording recording;
  const Scene scene = test::PredictionScene(recording);
  const int last = scene.num_latent_frames() - 1;
  double previous_distance = std::numeric_limits<double>::infinity();
  for (double cutoff : {0.0, 30.0, 300.0, 3000.0}) {
    BaselineOptions options;
    options.cutoff_rad_per_s = cutoff;
    const Video filtered = ComplementaryFilter(scene, options, kThreshold);
    const double distance = (filtered.frame(last) - scene.frames[0].image).abs().mean();
    EXPECT_LT(distance, previous_distance) << "cutoff " << cutoff;
    previous_distance = distance;
  }
}

TEST(ComplementaryFilter, IsCausal) {
  // A frame only acts from its timestamp on: the last frame of an interpolation scene arrives
  // with the last latent frame, after every event, and changes nothing.
  const test::SyntheticRecording recording;
  const Scene scene = test::InterpolationScene(recording);
  Scene other_end = scene;
  other_end.frames[1].image.setConstant(0.5);
  const Video filtered = ComplementaryFilter(scene, BaselineOptions(), kThreshold);
  const Video other = ComplementaryFilter(other_end, BaselineOptions(), kThreshold);
  for (int t = 0; t < filtered.num_frames(); ++t) {
    EXPECT_EQ(test::MaxAbsDifference(filtered.frame(t), other.frame(t)), 0.0) << t;
  }
}

TEST(ComplementaryFilter, NeedsAFrame) {
  const test::SyntheticRecording recording;
  Scene scene = test::PredictionScene(recording);
  scene.frames.clear();
  EXPECT_THROW(ComplementaryFilter(scene, BaselineOptions(), kThreshold), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
