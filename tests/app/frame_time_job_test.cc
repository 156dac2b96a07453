// --frame_time through the reconstruction job (app/reconstruct_job.h) on the shared DAVIS
// snippet shapes_rotation_13_20: where the sharp frames are placed on the latent timeline.
#include <gtest/gtest.h>

#include <filesystem>

#include "evfs/app/reconstruct_job.h"
#include "evfs/core/error.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

// Interpolation of frame 19 from 18 and 20 (lines 2, 4 → 3) with the blend baseline (no solve).
ReconstructRequest ShapesInterpolation(const std::string& data_dir) {
  ReconstructRequest request;
  request.data_path = (std::filesystem::path(data_dir) / "shapes_rotation_13_20").string();
  request.mode = Mode::kInterpolate;
  request.first = 2;
  request.last = 4;
  request.truth = 3;
  request.method.method = Method::kBlend;
  return request;
}

TEST(FrameTimeJob, GivenLagMovesTheWindowAndTheTruth) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  ReconstructRequest request = ShapesInterpolation(data_dir);
  const ReconstructResult instant = RunReconstruction(request);
  request.frame_time = FrameTime::kLag;
  request.frame_lag_s = 0.002;
  const ReconstructResult shifted = RunReconstruction(request);
  EXPECT_EQ(instant.frame_shift_ns, 0);
  EXPECT_EQ(shifted.frame_shift_ns, 2000000);
  const Video& a = instant.run.video;
  const Video& b = shifted.run.video;
  EXPECT_EQ(b.timestamp_ns(0), a.timestamp_ns(0) + 2000000);
  EXPECT_EQ(b.timestamp_ns(b.num_frames() - 1), a.timestamp_ns(a.num_frames() - 1) + 2000000);
  EXPECT_EQ(shifted.truth.timestamp_ns, instant.truth.timestamp_ns + 2000000);
}

TEST(FrameTimeJob, AutoEstimatesFromTheInputFramesOnly) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  ReconstructRequest request = ShapesInterpolation(data_dir);
  request.frame_time = FrameTime::kAuto;
  const ReconstructResult result = RunReconstruction(request);
  EXPECT_EQ(result.frame_lag.pairs, 1);  // frames 18 and 20, not the truth 19
  EXPECT_EQ(result.frame_shift_ns, result.frame_lag.lag_ns);
  EXPECT_NE(SummaryJson(request, result).find("\"frame_timing\""), std::string::npos);
  // A prediction from the recording's first frame has no earlier frame to pair it with.
  request.mode = Mode::kPredict;
  request.first = 0;
  request.last = 1;
  request.truth = 1;
  request.method.method = Method::kCopy;
  const ReconstructResult predicted = RunReconstruction(request);
  EXPECT_FALSE(predicted.frame_lag.estimated);
  EXPECT_EQ(predicted.frame_shift_ns, 0);
}

TEST(FrameTimeJob, ExposureModelsNeedAnExposure) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  ReconstructRequest request = ShapesInterpolation(data_dir);
  request.frame_time = FrameTime::kMiddle;
  EXPECT_THROW(RunReconstruction(request), InvalidArgumentError);
  request.frame_time = FrameTime::kStart;
  request.exposure_s = 0.004;
  const ReconstructResult result = RunReconstruction(request);
  EXPECT_EQ(result.frame_shift_ns, 2000000);               // the middle of [t, t + 4 ms]
  EXPECT_EQ(result.run.video.timestamp_ns(0), 821216000);  // the exposure starts the window
}

}  // namespace
}  // namespace evfs
