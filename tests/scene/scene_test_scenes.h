// Small synthetic scenes with ground truth for the solver tests.
#ifndef EVFS_TESTS_SCENE_SCENE_TEST_SCENES_H_
#define EVFS_TESTS_SCENE_SCENE_TEST_SCENES_H_

#include "evfs/core/event_stream.h"
#include "evfs/core/time.h"
#include "evfs/core/video.h"
#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/scene/scene.h"

namespace evfs {
namespace test {

/// Moving textured shapes rendered at 1 kHz for `duration_s`, with simulated events.
struct SyntheticRecording {
  Video rendered;
  EventStream events;

  explicit SyntheticRecording(int width = 48, int height = 40, double duration_s = 0.02,
                              uint64_t seed = 3) {
    SceneOptions options;
    options.width = width;
    options.height = height;
    options.duration_s = duration_s;
    options.num_shapes = 2;
    options.min_shape_size_px = 6.0;
    options.max_shape_size_px = 12.0;
    options.max_speed_px_per_s = 500.0;
    options.seed = seed;
    rendered = SceneSynthesizer(options).RenderAtRate(1000.0);
    events = SimulateEvents(rendered, SimulatorOptions());
  }

  /// The rendered frame at index t as a sharp observation.
  TimedFrame Sharp(int t) const {
    TimedFrame frame;
    frame.image = rendered.frame(t);
    frame.exposure_begin_ns = frame.exposure_end_ns = rendered.timestamp_ns(t);
    frame.label = "rendered frame " + std::to_string(t);
    return frame;
  }

  /// The mean of rendered frames first..last as a blurred observation over their times.
  TimedFrame Blurred(int first, int last) const {
    TimedFrame frame;
    frame.image = Image::Zero(rendered.height(), rendered.width());
    for (int t = first; t <= last; ++t) frame.image += rendered.frame(t);
    frame.image /= (last - first + 1);
    frame.exposure_begin_ns = rendered.timestamp_ns(first);
    frame.exposure_end_ns = rendered.timestamp_ns(last);
    frame.label = "blurred frames " + std::to_string(first) + ".." + std::to_string(last);
    return frame;
  }
};

}  // namespace test
}  // namespace evfs

#endif  // EVFS_TESTS_SCENE_SCENE_TEST_SCENES_H_
