// Small hand-made scenes shared by the solver tests.
#ifndef EVFS_TESTS_SOLVER_SOLVER_TEST_SCENES_H_
#define EVFS_TESTS_SOLVER_SOLVER_TEST_SCENES_H_

#include <array>
#include <cstdint>
#include <vector>

#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/scene/scene.h"

namespace evfs {

/// A height × width scene with a constant frame at each end (0.2 at latent frame 0, 0.6 at 3)
/// and three collision steps, with one ON event per {step, y, x} given.
inline Scene MakeSceneWithEvents(int height, int width,
                                 const std::vector<std::array<int, 3>>& events) {
  Scene scene;
  scene.height = height;
  scene.width = width;
  scene.events = EventFrames(height, width);
  for (int k = 0; k < 3; ++k) scene.events.AddFrame({k, k + 1, 10 * k, 10 * k + 5, 1});
  scene.events.set_latent_timestamps_ns({0, 10, 20, 30});
  for (const auto& [step, y, x] : events) scene.events.value(step, y, x) = 1.0f;
  scene.num_events = static_cast<int64_t>(events.size());
  scene.frames.push_back({Image::Constant(height, width, 0.2), 0, 0, "first"});
  scene.frames.push_back({Image::Constant(height, width, 0.6), 3, 3, "last"});
  return scene;
}

/// A smooth texture panning 6 px in 20 ms (300 px/s) under `num_shapes` moving shapes,
/// rendered at 1 kHz, its events simulated with the simulator's defaults, and the
/// interpolation scene between its first and last rendered frames (both sharp and exact).
struct PanningTexture {
  Video rendered;
  Scene scene;
};

inline PanningTexture MakePanningTexture(int width, int height, int num_shapes, uint64_t seed) {
  SceneOptions options;
  options.width = width;
  options.height = height;
  options.duration_s = 0.02;
  options.num_shapes = num_shapes;
  options.background_speed_px_per_s = 300.0;
  options.seed = seed;
  PanningTexture texture;
  texture.rendered = SceneSynthesizer(options).RenderAtRate(1000.0);
  const EventStream events = SimulateEvents(texture.rendered, SimulatorOptions());
  const auto sharp = [&](int t) {
    TimedFrame frame;
    frame.image = texture.rendered.frame(t);
    frame.exposure_begin_ns = frame.exposure_end_ns = texture.rendered.timestamp_ns(t);
    return frame;
  };
  texture.scene = MakeInterpolationScene(sharp(0), sharp(texture.rendered.num_frames() - 1), events,
                                         BinningOptions());
  return texture;
}

}  // namespace evfs

#endif  // EVFS_TESTS_SOLVER_SOLVER_TEST_SCENES_H_
