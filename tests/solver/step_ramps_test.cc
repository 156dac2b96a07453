#include "evfs/solver/step_ramps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "evfs/core/metrics.h"
#include "evfs/solver/reconstructor.h"
#include "evfs/tests/solver/solver_test_scenes.h"

namespace evfs {
namespace {

constexpr int64_t kMs = 1000000;

// An edge moving right at one pixel per millisecond over the first three of `width` columns:
// event frame k holds one ON event at every row of column k, at k ms.
Scene EdgeScene(int height, int width) {
  Scene scene;
  scene.height = height;
  scene.width = width;
  scene.events = EventFrames(height, width);
  for (int k = 0; k < 3; ++k) {
    scene.events.AddFrame({k, k + 1, k * kMs, k * kMs, height});
    for (int y = 0; y < height; ++y) scene.events.value(k, y, k) = 1.0f;
  }
  scene.events.set_latent_timestamps_ns({0, kMs, 2 * kMs, 3 * kMs});
  scene.num_events = 3 * height;
  return scene;
}

TEST(EventTimeSlope, IsTheTimeTheEdgeTakesToMoveOnePixel) {
  Scene scene = EdgeScene(3, 8);
  // An OFF event next to column 1 at its own time: another sign, not the same edge.
  scene.events.value(1, 1, 2) = -1.0f;
  const std::vector<double> slope = EventTimeSlope(scene);
  for (int y = 0; y < 3; ++y) {
    // The fired columns: the next column fired 1 ms before or after, the rows above and below
    // at the same time.
    for (int x = 0; x < 3; ++x) {
      if (y == 1 && x == 2) continue;  // also fired OFF, alone of its sign
      EXPECT_DOUBLE_EQ(slope[y * 8 + x], 1.0 * kMs) << y << "," << x;
    }
    // Columns 5–7 have no fired pixel within two columns: no motion seen, the window.
    for (int x = 5; x < 8; ++x) EXPECT_DOUBLE_EQ(slope[y * 8 + x], 3.0 * kMs) << y << "," << x;
  }
  // (1, 2): its ON event is on the edge (1 ms), its OFF event has no OFF neighbour: the window
  // both ways. The median of the two sorted values is the larger.
  const double lone = std::hypot(3.0 * kMs, 3.0 * kMs);
  EXPECT_DOUBLE_EQ(slope[1 * 8 + 2], lone);
  // Columns 3 and 4 take the mean of the fired pixels within two columns and rows.
  for (int y = 0; y < 3; ++y) {
    EXPECT_DOUBLE_EQ(slope[y * 8 + 3], (5.0 * kMs + lone) / 6.0) << y;
    EXPECT_DOUBLE_EQ(slope[y * 8 + 4], (2.0 * kMs + lone) / 3.0) << y;
  }
}

TEST(RampSteps, EndAStepWithARampFromTheMiddleOfTheSegmentBefore) {
  // One pixel of a 1 × 3 scene fires once, at step 1 (latent frames 1 → 2, times 10 and 20 ns):
  // its segments are frames 0–1 and 2–3, the step at 15 ns, the middle of the first at 5 ns.
  // No neighbour fires, so |∇t| is the window both ways: hypot(30, 30) = 42.4 ns.
  const Scene scene = MakeSceneWithEvents(1, 3, {{1, 0, 1}});
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.step_ramp_px = 0.0;
  const Reconstruction steps = Reconstruct(scene, options);
  ASSERT_TRUE(steps.summary.solved);
  EXPECT_EQ(steps.summary.ramped_steps, 0);
  const double before = steps.video.frame(1)(0, 1);
  const double after = steps.video.frame(2)(0, 1);
  ASSERT_NE(before, after);

  // A ramp of 42.4 ns ending at the step begins at the middle of the segment before: 5 → 15 ns.
  options.step_ramp_px = 1.0;
  const Reconstruction ramped = Reconstruct(scene, options);
  EXPECT_EQ(ramped.summary.ramped_steps, 1);
  EXPECT_DOUBLE_EQ(ramped.video.frame(1)(0, 1), before + 0.5 * (after - before));
  // The frames keep their voxels, the segment after the step its value, and the pixels that
  // did not fire their values.
  for (int t = 0; t < 4; ++t) {
    for (int x = 0; x < 3; ++x) {
      if (x == 1 && t == 1) continue;
      EXPECT_EQ(ramped.video.frame(t)(0, x), steps.video.frame(t)(0, x)) << t << "," << x;
    }
  }

  // A ramp of 0.1 × 42.4 = 4.2 ns, 10.8 → 15 ns, reaches no latent frame: nothing changes.
  options.step_ramp_px = 0.1;
  const Reconstruction short_ramp = Reconstruct(scene, options);
  EXPECT_EQ(short_ramp.summary.ramped_steps, 0);
  for (int t = 0; t < 4; ++t)
    EXPECT_EQ(short_ramp.video.frame(t)(0, 1), steps.video.frame(t)(0, 1));
}

TEST(RampSteps, StepsInsideABlurredExposureStayJumps) {
  // Six latent frames 10 ns apart; a sharp frame at latent frame 0 and one blurred over latent
  // frames 3–5. Pixel (0, 1) fires at step 1 (1 → 2), before the exposure; pixel (0, 3) at step
  // 3 (3 → 4), inside it. Both steps have room for a ramp over a latent frame on either side.
  Scene scene;
  scene.height = 1;
  scene.width = 5;
  scene.events = EventFrames(1, 5);
  for (int k = 0; k < 5; ++k) scene.events.AddFrame({k, k + 1, 10 * k, 10 * k + 5, 1});
  scene.events.set_latent_timestamps_ns({0, 10, 20, 30, 40, 50});
  scene.events.value(1, 0, 1) = 1.0f;
  scene.events.value(3, 0, 3) = 1.0f;
  scene.num_events = 2;
  scene.frames.push_back({Image::Constant(1, 5, 0.2), 0, 0, "sharp"});
  scene.frames.push_back({Image::Constant(1, 5, 0.5), 3, 5, "blurred"});
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.step_ramp_px = 0.0;
  const Reconstruction steps = Reconstruct(scene, options);
  ASSERT_TRUE(steps.summary.solved);
  options.step_ramp_px = 1.0;
  const Reconstruction ramped = Reconstruct(scene, options);
  EXPECT_EQ(ramped.summary.ramped_steps, 1);
  EXPECT_NE(ramped.video.frame(1)(0, 1), steps.video.frame(1)(0, 1));
  for (int t = 0; t < 6; ++t) EXPECT_EQ(ramped.video.frame(t)(0, 3), steps.video.frame(t)(0, 3));
}

TEST(RampSteps, FollowASlowlyPanningTextureBetweenTwoFrames) {
  // A smooth texture panning 6 px in 20 ms: each pixel changes over several milliseconds, where
  // the step model puts its whole change at one event.
  const PanningTexture texture = MakePanningTexture(48, 40, 2, 11);
  const Video& rendered = texture.rendered;
  const Scene& scene = texture.scene;
  const int last = rendered.num_frames() - 1;
  ReconstructionOptions options;
  options.step_ramp_px = 0.0;
  const Reconstruction steps = Reconstruct(scene, options);
  options.step_ramp_px = ReconstructionOptions().step_ramp_px;
  ASSERT_GT(options.step_ramp_px, 0.0);
  const Reconstruction ramped = Reconstruct(scene, options);
  ASSERT_TRUE(ramped.summary.solved);
  EXPECT_GT(ramped.summary.ramped_steps, 0);
  const auto psnr_at = [&](const Video& video, int t) {
    return Psnr(video.frame(video.NearestFrame(rendered.timestamp_ns(t))), rendered.frame(t));
  };
  const double step_psnr = psnr_at(steps.video, last / 2);
  const double ramp_psnr = psnr_at(ramped.video, last / 2);
  std::printf("panning texture, middle frame: steps %.2f dB, ramps %.2f dB\n", step_psnr,
              ramp_psnr);
  EXPECT_GE(ramp_psnr, step_psnr + 0.3);
  // The sharp frames' voxels are the solve's.
  for (const FrameObservation& frame : scene.frames) {
    EXPECT_TRUE(
        (ramped.video.frame(frame.latent_first) == steps.video.frame(frame.latent_first)).all());
  }
}

}  // namespace
}  // namespace evfs
