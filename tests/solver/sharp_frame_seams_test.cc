#include "evfs/solver/sharp_frame_seams.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/solver/reconstructor.h"
#include "evfs/tests/solver/solver_test_scenes.h"

namespace evfs {
namespace {

// A 1 × 2 scene on `num_latent` latent frames 10 ns apart (no events: the seams read only the
// frames and the timeline), with the given observations.
Scene TimelineScene(int num_latent, const std::vector<FrameObservation>& frames) {
  Scene scene;
  scene.height = 1;
  scene.width = 2;
  scene.events = EventFrames(1, 2);
  std::vector<int64_t> times;
  for (int t = 0; t < num_latent; ++t) {
    if (t + 1 < num_latent) scene.events.AddFrame({t, t + 1, 10 * t, 10 * t, 0});
    times.push_back(10 * t);
  }
  scene.events.set_latent_timestamps_ns(times);
  scene.frames = frames;
  return scene;
}

// A video on the scene's timeline whose every frame is the constant `value`.
Video ConstantVideo(const Scene& scene, double value) {
  Video video;
  for (const int64_t t : scene.latent_timestamps_ns()) {
    video.AppendFrame(Image::Constant(scene.height, scene.width, value), t);
  }
  return video;
}

TEST(MeetSharpFrames, EachFramesOffsetFadesOutHalfWayToTheOtherFrame) {
  // Frames at latent frames 0 (0.2) and 4 (0.6) of 0 … 40 ns; the solve left 0.3 everywhere.
  // Frame 0's offset −0.1 falls to 0 at 20 ns, frame 4's +0.3 rises from 20 ns.
  Image first = Image::Constant(1, 2, 0.2);
  first(0, 1) = 0.25;
  const Scene scene =
      TimelineScene(5, {{first, 0, 0, "first"}, {Image::Constant(1, 2, 0.6), 4, 4, "last"}});
  Video video = ConstantVideo(scene, 0.3);
  const SharpFrameSeams seams = MeetSharpFrames(scene, &video);
  EXPECT_EQ(seams.frames_met, 2);
  // Offsets −0.1, −0.05 (frame 0) and 0.3, 0.3 (frame 4).
  EXPECT_NEAR(seams.offset_rms, std::sqrt((0.01 + 0.0025 + 0.09 + 0.09) / 4), 1e-12);
  EXPECT_TRUE((video.frame(0) == first).all());
  EXPECT_DOUBLE_EQ(video.frame(1)(0, 0), 0.3 - 0.5 * 0.1);
  EXPECT_DOUBLE_EQ(video.frame(1)(0, 1), 0.3 - 0.5 * 0.05);
  EXPECT_DOUBLE_EQ(video.frame(2)(0, 0), 0.3);  // the middle keeps the solve's value
  EXPECT_DOUBLE_EQ(video.frame(3)(0, 0), 0.3 + 0.5 * 0.3);
  EXPECT_DOUBLE_EQ(video.frame(4)(0, 0), 0.6);
}

TEST(MeetSharpFrames, WithoutAFrameAfterItTheOffsetFadesOutAtTheWindowsEnd) {
  // A prediction: one frame at latent frame 0 of 0 … 40 ns.
  const Scene scene = TimelineScene(5, {{Image::Constant(1, 2, 0.2), 0, 0, "first"}});
  Video video = ConstantVideo(scene, 0.6);
  EXPECT_EQ(MeetSharpFrames(scene, &video).frames_met, 1);
  for (int t = 0; t < 5; ++t) {
    EXPECT_DOUBLE_EQ(video.frame(t)(0, 0), 0.6 - 0.4 * (1.0 - t / 4.0)) << t;
  }
}

TEST(MeetSharpFrames, BlurredFramesAndFramesTheyCoverAreLeft) {
  // A blurred frame over latent frames 2–4 and a sharp frame at 4, inside its exposure: the
  // solve balanced the two there. A sharp frame at 0 fades out half-way to the exposure's
  // start (10 ns).
  const Scene scene = TimelineScene(5, {{Image::Constant(1, 2, 0.2), 0, 0, "sharp"},
                                        {Image::Constant(1, 2, 0.5), 2, 4, "blurred"},
                                        {Image::Constant(1, 2, 0.9), 4, 4, "covered"}});
  Video video = ConstantVideo(scene, 0.4);
  EXPECT_EQ(MeetSharpFrames(scene, &video).frames_met, 1);
  EXPECT_DOUBLE_EQ(video.frame(0)(0, 0), 0.2);
  for (int t = 1; t < 5; ++t) EXPECT_DOUBLE_EQ(video.frame(t)(0, 0), 0.4) << t;
}

TEST(MeetSharpFrames, RefusesAVideoOffTheTimeline) {
  const Scene scene = TimelineScene(5, {{Image::Constant(1, 2, 0.2), 0, 0, "first"}});
  Video video = ConstantVideo(TimelineScene(4, {}), 0.4);
  EXPECT_THROW(MeetSharpFrames(scene, &video), InvalidArgumentError);
}

TEST(MeetSharpFrames, FramesNextToTheObservedOnesGetBetter) {
  // A textured scene panning 6 px in 20 ms between two exact frames: the frames a quarter of
  // the window from each observed frame, solved and then met.
  const PanningTexture texture = MakePanningTexture(64, 48, 3, 5);
  const Video& rendered = texture.rendered;
  const Scene& scene = texture.scene;
  const int last = rendered.num_frames() - 1;
  const Reconstruction result = Reconstruct(scene, ReconstructionOptions());
  ASSERT_TRUE(result.summary.solved);
  Video met = result.video;
  const SharpFrameSeams seams = MeetSharpFrames(scene, &met);
  EXPECT_EQ(seams.frames_met, 2);
  EXPECT_GT(seams.offset_rms, 0.0);
  const auto psnr_at = [&](const Video& video, int t) {
    return Psnr(video.frame(video.NearestFrame(rendered.timestamp_ns(t))), rendered.frame(t));
  };
  double gain = 0.0;
  for (const int t : {last / 4, last - last / 4}) {
    const double before = psnr_at(result.video, t), after = psnr_at(met, t);
    std::printf("frame %d of %d: solved %.2f dB, frames met %.2f dB\n", t, last, before, after);
    gain += after - before;
  }
  EXPECT_GE(gain / 2, 0.3);
  // The observed frames are the output at their own times.
  for (const FrameObservation& frame : scene.frames) {
    EXPECT_TRUE((met.frame(frame.latent_first) == frame.image).all());
  }
}

}  // namespace
}  // namespace evfs
