#include "solver/scene.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/solver/solver_test_scenes.h"

namespace evfs {
namespace {

TEST(Scene, InterpolationTiesFramesToTheEndsOfTheTimeline) {
  const testing::SyntheticRecording recording;
  const Scene scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20),
                                             recording.events, BinningOptions());
  ASSERT_EQ(scene.frames.size(), 2u);
  const int last = scene.num_latent_frames() - 1;
  EXPECT_GT(last, 1);
  EXPECT_EQ(scene.frames[0].latent_first, 0);
  EXPECT_EQ(scene.frames[0].latent_last, 0);
  EXPECT_EQ(scene.frames[1].latent_first, last);
  EXPECT_EQ(scene.frames[1].latent_last, last);
  EXPECT_EQ(scene.latent_timestamps_ns().front(), recording.rendered.timestamp_ns(0));
  EXPECT_EQ(scene.latent_timestamps_ns().back(), recording.rendered.timestamp_ns(20));
  EXPECT_GT(scene.num_events, 0);
}

TEST(Scene, BlurredFrameSpansItsExposure) {
  const testing::SyntheticRecording recording;
  BinningOptions binning;
  binning.method = BinningOptions::Method::kStacked;
  binning.stacked.num_frames = 10;
  const Scene scene = MakeDeblurScene(recording.Blurred(0, 20), recording.events, binning);
  ASSERT_EQ(scene.frames.size(), 1u);
  EXPECT_EQ(scene.num_latent_frames(), 11);
  EXPECT_EQ(scene.frames[0].latent_first, 0);
  EXPECT_EQ(scene.frames[0].latent_last, 10);
}

TEST(Scene, AutoBinningFallsBackToStackedWhenCollisionFramesAreTooMany) {
  const testing::SyntheticRecording recording;
  const int64_t end_ns = recording.rendered.timestamp_ns(20);
  const Scene collision = MakePredictionScene(recording.Sharp(0), end_ns, recording.events,
                                              BinningOptions());
  ASSERT_GT(collision.events.num_frames(), 6);  // the premise: more than the limits below
  BinningOptions binning;
  binning.max_latent_frames = 5;
  const Scene capped =
      MakePredictionScene(recording.Sharp(0), end_ns, recording.events, binning);
  EXPECT_EQ(capped.events.num_frames(), 5);
  EXPECT_EQ(capped.num_latent_frames(), 6);
  EXPECT_EQ(capped.num_events, collision.num_events);
}

TEST(Scene, AutoBinningKeepsWithinTheVoxelBudget) {
  const testing::SyntheticRecording recording;
  BinningOptions binning;
  const int64_t pixels = recording.events.width() * recording.events.height();
  binning.max_latent_voxels = pixels * 7;  // 7 latent frames: 6 steps
  const Scene scene = MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(20),
                                          recording.events, binning);
  EXPECT_EQ(scene.num_latent_frames(), 7);
  binning.max_latent_voxels = 1;  // never fewer than 4 steps
  const Scene tiny = MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(20),
                                         recording.events, binning);
  EXPECT_EQ(tiny.events.num_frames(), 4);
}

TEST(Scene, RejectsBadWindowsAndSizes) {
  const testing::SyntheticRecording recording;
  EXPECT_THROW(MakePredictionScene(recording.Sharp(10), recording.rendered.timestamp_ns(5),
                                   recording.events, BinningOptions()),
               InvalidArgumentError);
  TimedFrame wrong_size = recording.Sharp(0);
  wrong_size.image = Image::Zero(5, 5);
  EXPECT_THROW(MakeInterpolationScene(wrong_size, recording.Sharp(10), recording.events,
                                      BinningOptions()),
               InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
