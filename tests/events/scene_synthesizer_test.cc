#include "evfs/events/scene_synthesizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/time.h"

namespace evfs {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(SceneOptions, DefaultsAreValidAndBadValuesAreNamed) {
  SceneOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.max_shape_size_px = options.min_shape_size_px / 2;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("max_shape_size_px"), std::string::npos);
  EXPECT_THROW(SceneSynthesizer{options}, InvalidArgumentError);
  options = SceneOptions();
  options.edge_width_px = 0.0;
  EXPECT_FALSE(options.IsValid(nullptr));
}

TEST(SceneSynthesizer, IsDeterministicGivenTheSeed) {
  const SceneOptions options;
  const Image first = SceneSynthesizer(options).Render(0.013);
  EXPECT_TRUE((first == SceneSynthesizer(options).Render(0.013)).all());
  SceneOptions other = options;
  other.seed += 1;
  EXPECT_FALSE((first == SceneSynthesizer(other).Render(0.013)).all());
}

TEST(SceneSynthesizer, ValuesStayInTheUnitRange) {
  SceneOptions options;
  options.num_shapes = 8;
  options.background_speed_px_per_s = 100.0;
  const Video video = SceneSynthesizer(options).RenderAtRate(240.0);
  ASSERT_GT(video.num_frames(), 0);
  for (int t = 0; t < video.num_frames(); ++t) {
    EXPECT_GE(video.frame(t).minCoeff(), 0.0);
    EXPECT_LE(video.frame(t).maxCoeff(), 1.0);
  }
}

TEST(SceneSynthesizer, OnlyPixelsAShapeCanReachChange) {
  SceneOptions options;
  options.num_shapes = 1;
  const SceneSynthesizer scene(options);
  const Image start = scene.Render(0.0);
  const Image end = scene.Render(options.duration_s);
  const int64_t changed = (start != end).count();
  EXPECT_GT(changed, 0);
  // With a still background only the disc the shape can sweep may change: its largest radius
  // plus the distance it travels plus the edge ramp around its starting centre.
  const double sweep_radius = options.max_shape_size_px +
                              options.max_speed_px_per_s * options.duration_s +
                              options.edge_width_px + 1.0;
  EXPECT_LE(static_cast<double>(changed), kPi * sweep_radius * sweep_radius);

  options.background_speed_px_per_s = 200.0;
  const SceneSynthesizer panning(options);
  const int64_t changed_panning = (panning.Render(0.0) != panning.Render(0.01)).count();
  // A 2 px pan moves every background pixel; only flat texture points could stay.
  constexpr double kMinChangedFraction = 0.95;
  EXPECT_GT(static_cast<double>(changed_panning), kMinChangedFraction * start.size());
}

TEST(SceneSynthesizer, RenderMatchesRenderVideo) {
  const SceneSynthesizer scene{SceneOptions()};
  const std::vector<int64_t> timestamps_ns = {0, 4166667, 123456789, 20000000};
  const Video video = scene.RenderVideo(timestamps_ns);
  ASSERT_EQ(video.num_frames(), 4);
  for (int t = 0; t < video.num_frames(); ++t) {
    EXPECT_EQ(video.timestamp_ns(t), timestamps_ns[t]);
    EXPECT_TRUE((video.frame(t).array() == scene.Render(video.timestamp_s(t))).all()) << t;
  }
}

TEST(SceneSynthesizer, RenderAtRateCoversTheDuration) {
  SceneOptions options;
  options.width = 40;
  options.height = 30;
  const SceneSynthesizer scene(options);
  const Video at_240 = scene.RenderAtRate(240.0);  // 0, 1/240, ..., 9/240 <= 0.04 < 10/240
  ASSERT_EQ(at_240.num_frames(), 10);
  EXPECT_EQ(at_240.timestamp_ns(1), 4166667);
  const Video at_100 = scene.RenderAtRate(100.0);  // 0.04 s itself is included
  ASSERT_EQ(at_100.num_frames(), 5);
  EXPECT_EQ(at_100.timestamp_ns(4), 40000000);
  EXPECT_THROW(scene.RenderAtRate(0.0), InvalidArgumentError);
}

TEST(SceneSynthesizer, IsSmoothInTime) {
  SceneOptions options;
  options.num_shapes = 6;
  options.background_speed_px_per_s = 100.0;
  const SceneSynthesizer scene(options);
  // In 1 µs nothing moves more than ~0.0006 px (speed plus rotation at the rim), so with a
  // 1 px edge ramp and textures of slope < 0.2 per px no pixel may change by more than this.
  constexpr double kMaxChangePerMicrosecond = 1e-3;
  for (const double t_s : {0.0, 0.011, 0.027}) {
    const Image change = (scene.Render(t_s + 1e-6) - scene.Render(t_s)).abs();
    EXPECT_LT(change.maxCoeff(), kMaxChangePerMicrosecond) << "t = " << t_s;
  }
}

}  // namespace
}  // namespace evfs
