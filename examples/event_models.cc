// The event model as a library user sets it: a synthetic scene rendered by the library, its
// events simulated, frame 0 and the last frame given, and the middle frame reconstructed under
// three event models — the paper's linear g(x) = x, and g(x) = log(x + b) for two offsets b —
// each scored against the rendered truth. No recording is needed.
//
//   event_models
#include <cstdio>
#include <exception>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/reconstructor.h"

int main() {
  try {
    evfs::SceneOptions scene_options;
    scene_options.width = 96;
    scene_options.height = 72;
    scene_options.duration_s = 0.02;
    const evfs::Video rendered = evfs::SceneSynthesizer(scene_options).RenderAtRate(1000.0);
    const evfs::EventStream events = evfs::SimulateEvents(rendered, evfs::SimulatorOptions());
    const int last = rendered.num_frames() - 1, middle = last / 2;

    const auto frame = [&](int i) {
      evfs::TimedFrame timed;
      timed.image = rendered.frame(i);
      timed.exposure_begin_ns = timed.exposure_end_ns = rendered.timestamp_ns(i);
      return timed;
    };
    const evfs::Scene scene =
        evfs::MakeInterpolationScene(frame(0), frame(last), events, evfs::BinningOptions());
    const evfs::Image& truth = rendered.frame(middle);
    const evfs::Video blend = evfs::InitializeLatentVideo(scene);
    const int blend_index = blend.NearestFrame(rendered.timestamp_ns(middle));
    std::printf("%lld events; blend of the two frames: %.2f dB\n",
                static_cast<long long>(events.size()), evfs::Psnr(blend.frame(blend_index), truth));

    struct Model {
      const char* name;
      evfs::EventModel model;
      double log_offset;
    };
    for (const Model& model : std::vector<Model>{{"linear g(x) = x", evfs::EventModel::kLinear, 0},
                                                 {"log(x + 0.5)", evfs::EventModel::kLog, 0.5},
                                                 {"log(x + 0.01)", evfs::EventModel::kLog, 0.01}}) {
      evfs::ReconstructionOptions options;
      options.objective.event_model.model = model.model;
      if (model.model == evfs::EventModel::kLog) {
        options.objective.event_model.log_offset = model.log_offset;
      }
      options.objective.event_model.alpha = 0.0;  // derived from the two frames
      const evfs::Reconstruction result = evfs::Reconstruct(scene, options);
      const int index = result.video.NearestFrame(rendered.timestamp_ns(middle));
      std::printf("%-16s alpha %.2f: %.2f dB\n", model.name, result.summary.model.alpha,
                  evfs::Psnr(result.video.frame(index), truth));
    }
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 1;
  }
}
