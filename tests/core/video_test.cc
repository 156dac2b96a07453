#include "evfs/core/video.h"

#include <gtest/gtest.h>

#include "evfs/core/error.h"

namespace evfs {
namespace {

TEST(Video, FramesAreContiguousAndRowMajor) {
  Video video(2, 3, 4);
  video.at(2, 1, 0) = 5.0;
  EXPECT_EQ(video.data()[2 * 6 + 1 * 3 + 0], 5.0);
  EXPECT_EQ(video.frame(2)(1, 0), 5.0);
  EXPECT_EQ(video.num_frames(), 4);
  EXPECT_EQ(video.pixels_per_frame(), 6);
}

TEST(Video, AppendFrameSetsSizeAndTimestamp) {
  Video video;
  EXPECT_TRUE(video.empty());
  video.AppendFrame(Image::Constant(2, 3, 0.25), 100);
  video.AppendFrame(Image::Constant(2, 3, 0.75), 300);
  EXPECT_EQ(video.height(), 2);
  EXPECT_EQ(video.width(), 3);
  EXPECT_EQ(video.timestamp_ns(1), 300);
  EXPECT_DOUBLE_EQ(video.timestamp_s(1), 3e-7);
  EXPECT_THROW(video.AppendFrame(Image::Constant(3, 2, 0.5), 400), InvalidArgumentError);
  EXPECT_EQ(video.num_frames(), 2);
}

TEST(Video, NearestFrameAndInterpolation) {
  Video video;
  video.AppendFrame(Image::Constant(1, 1, 0.0), 0);
  video.AppendFrame(Image::Constant(1, 1, 1.0), 100);
  video.AppendFrame(Image::Constant(1, 1, 0.0), 200);
  EXPECT_EQ(video.NearestFrame(-5), 0);
  EXPECT_EQ(video.NearestFrame(49), 0);
  EXPECT_EQ(video.NearestFrame(50), 0);  // ties go to the earlier frame
  EXPECT_EQ(video.NearestFrame(51), 1);
  EXPECT_EQ(video.NearestFrame(1000), 2);
  EXPECT_EQ(NearestTimestamp(video.timestamps_ns(), 150), 1);  // the same rule on timestamps
  EXPECT_EQ(NearestTimestamp({7}, -3), 0);
  EXPECT_DOUBLE_EQ(video.InterpolateAt(25)(0, 0), 0.25);
  EXPECT_DOUBLE_EQ(video.InterpolateAt(150)(0, 0), 0.5);
  EXPECT_DOUBLE_EQ(video.InterpolateAt(-10)(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(video.InterpolateAt(100)(0, 0), 1.0);
}

}  // namespace
}  // namespace evfs
