#include "solver/problem_builder.h"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/solver/solver_test_scenes.h"

namespace evfs {
namespace {

// A 5×4 scene with one frame at each end and three collision steps whose events are set by
// hand, so that every count and the cost can be written down.
Scene MakeTinyScene() {
  Scene scene;
  scene.height = 4;
  scene.width = 5;
  scene.events = EventFrames(4, 5);
  for (int k = 0; k < 3; ++k) scene.events.AddFrame({k, k + 1, 10 * k, 10 * k + 5, 1});
  scene.events.set_latent_timestamps_ns({0, 10, 20, 30});
  scene.events.value(1, 2, 3) = 1.0f;
  scene.num_events = 1;
  scene.frames.push_back({Image::Constant(4, 5, 0.2), 0, 0, "first"});
  scene.frames.push_back({Image::Constant(4, 5, 0.6), 3, 3, "last"});
  return scene;
}

TEST(ProblemBuilder, BuildsOneResidualPerTermAndPixel) {
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = -1;  // every pixel
  Video latent = InitializeLatentVideo(scene);
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  const ProblemStatistics& stats = built->statistics();
  constexpr int kPixels = 20, kLatent = 4, kSteps = 3;
  EXPECT_EQ(stats.parameter_blocks, kPixels * kLatent);
  EXPECT_EQ(stats.frame_residuals, 2 * kPixels);
  EXPECT_EQ(stats.event_residuals, kSteps * kPixels);
  // Anisotropic TV: horizontal (4 rows × 4) plus vertical (3 rows × 5) differences per frame.
  EXPECT_EQ(stats.spatial_tv_residuals, kLatent * (4 * 4 + 3 * 5));
  EXPECT_EQ(stats.temporal_tv_residuals, kSteps * kPixels);
  EXPECT_EQ(built->problem().NumResidualBlocks(), stats.residual_blocks());
  // Shared cost functions: 2 frame values, 2 event values (0 and 1), TV difference (spatial
  // and temporal each keep their own).
  EXPECT_EQ(stats.distinct_cost_functions, 2 + 2 + 1 + 1);
}

TEST(ProblemBuilder, ZeroWeightTermsAreNotBuilt) {
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = -1;
  options.objective.spatial_tv_weight = 0.0;
  options.objective.temporal_tv_weight = 0.0;
  Video latent = InitializeLatentVideo(scene);
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  EXPECT_EQ(built->statistics().spatial_tv_residuals, 0);
  EXPECT_EQ(built->statistics().temporal_tv_residuals, 0);
  EXPECT_EQ(built->problem().NumResidualBlocks(), 20 * 2 + 20 * 3);
}

TEST(ProblemBuilder, CostMatchesTheObjectiveWrittenOut) {
  // Only the frame term on a blend: each frame is matched exactly except that the latent ends
  // are shifted by 0.1, so the cost is 2 frames × 20 pixels × (sqrt(ε² + 0.1²) − ε) / 20.
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = -1;
  options.objective.event_weight = 0.0;
  options.objective.spatial_tv_weight = 0.0;
  options.objective.temporal_tv_weight = 0.0;
  Video latent = InitializeLatentVideo(scene);
  latent.frame(0) += 0.1;
  latent.frame(3) -= 0.1;
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  double cost = 0.0;
  built->problem().Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  const double eps = options.objective.smoothing_scale;
  const double expected = 2.0 * (std::sqrt(eps * eps + 0.01) - eps);
  constexpr double kTolerance = 1e-12;  // a handful of double additions
  EXPECT_NEAR(cost, expected, kTolerance);
}

TEST(ProblemBuilder, PixelsFarFromEventsAreSkipped) {
  // The only event is at (x 3, y 2); with radius 1 the active pixels are x 2..4, y 1..3 (9).
  const Scene scene = MakeTinyScene();
  ReconstructionOptions options;
  options.objective.event_model.alpha = 5.0;
  options.activity_radius_px = 1;
  Video latent = InitializeLatentVideo(scene);
  const auto built = ProblemBuilder(scene, options).Build(&latent);
  const ProblemStatistics& stats = built->statistics();
  constexpr int kActive = 9, kLatent = 4, kSteps = 3;
  EXPECT_EQ(stats.active_pixels, kActive);
  EXPECT_EQ(stats.skipped_pixels, 20 - kActive);
  EXPECT_EQ(stats.frame_residuals, 2 * kActive);
  EXPECT_EQ(stats.event_residuals, kSteps * kActive);
  EXPECT_EQ(stats.temporal_tv_residuals, kSteps * kActive);
  // Ring: columns x = 1 for rows 0..3 (4) and row y = 0 for x = 2..4 (3): 7 constant pixels.
  EXPECT_EQ(stats.parameter_blocks, kLatent * (kActive + 7));
  // Horizontal differences touching an active pixel: rows 1..3 × pairs (1,2),(2,3),(3,4) = 9;
  // vertical: columns 2..4 × pairs (0,1),(1,2),(2,3) = 9; per latent frame.
  EXPECT_EQ(stats.spatial_tv_residuals, kLatent * (9 + 9));
}

TEST(ProblemBuilder, InitialisationBlendsLinearlyInTime) {
  const Scene scene = MakeTinyScene();
  const Video latent = InitializeLatentVideo(scene);
  ASSERT_EQ(latent.num_frames(), 4);
  EXPECT_NEAR(latent.at(0, 1, 1), 0.2, 1e-12);
  EXPECT_NEAR(latent.at(1, 1, 1), 0.2 + 0.4 / 3.0, 1e-12);
  EXPECT_NEAR(latent.at(3, 1, 1), 0.6, 1e-12);
  EXPECT_EQ(latent.timestamp_ns(2), 20);
}

}  // namespace
}  // namespace evfs
