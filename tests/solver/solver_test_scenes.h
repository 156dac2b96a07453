// Small hand-made scenes shared by the solver tests.
#ifndef EVFS_TESTS_SOLVER_SOLVER_TEST_SCENES_H_
#define EVFS_TESTS_SOLVER_SOLVER_TEST_SCENES_H_

#include <array>
#include <cstdint>
#include <vector>

#include "scene/scene.h"

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

}  // namespace evfs

#endif  // EVFS_TESTS_SOLVER_SOLVER_TEST_SCENES_H_
