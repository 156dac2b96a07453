// The consumer project's program (tests/package): renders a small synthetic scene, simulates its
// events, and reconstructs the frame halfway between two sharp frames with evfs::solver, all
// through the installed headers and libraries. Exits with 0 when the reconstruction is solved and
// beats the blend of the two frames, as evfs' own tests require on such scenes.
#include <cstdio>
#include <string>

#include "evfs/core/metrics.h"
#include "evfs/core/version.h"
#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/scene/scene.h"
#include "evfs/solver/reconstruction_options.h"
#include "evfs/solver/reconstructor.h"

namespace {

evfs::TimedFrame SharpFrame(const evfs::Video& video, int index) {
  evfs::TimedFrame frame;
  frame.image = video.frame(index);
  frame.exposure_begin_ns = frame.exposure_end_ns = video.timestamp_ns(index);
  frame.label = "rendered frame " + std::to_string(index);
  return frame;
}

}  // namespace

int main() {
  evfs::SceneOptions scene_options;
  scene_options.width = 40;
  scene_options.height = 32;
  scene_options.duration_s = 0.02;
  scene_options.num_shapes = 2;
  scene_options.min_shape_size_px = 6.0;
  scene_options.max_shape_size_px = 12.0;
  scene_options.max_speed_px_per_s = 500.0;
  scene_options.seed = 3;
  const evfs::Video rendered = evfs::SceneSynthesizer(scene_options).RenderAtRate(1000.0);
  const evfs::EventStream events = evfs::SimulateEvents(rendered, evfs::SimulatorOptions());

  const int last = rendered.num_frames() - 1, middle = last / 2;
  const evfs::Scene scene = evfs::MakeInterpolationScene(
      SharpFrame(rendered, 0), SharpFrame(rendered, last), events, evfs::BinningOptions());
  const evfs::ReconstructionOptions options;
  std::string error;
  if (!options.IsValid(&error)) {
    std::fprintf(stderr, "consumer: invalid default options: %s\n", error.c_str());
    return 1;
  }
  const evfs::Reconstruction result = evfs::Reconstruct(scene, options);
  const int64_t middle_ns = rendered.timestamp_ns(middle);
  const evfs::Video blend = evfs::InitializeLatentVideo(scene);
  const double blend_psnr =
      evfs::Psnr(blend.frame(blend.NearestFrame(middle_ns)), rendered.frame(middle));
  const double solved_psnr =
      evfs::Psnr(result.video.frame(result.video.NearestFrame(middle_ns)), rendered.frame(middle));
  std::printf(
      "evfs %s: %zu events, %d latent frames, solved %s; frame %d: blend %.2f dB, evfs %.2f dB\n",
      evfs::kVersion, events.size(), result.video.num_frames(),
      result.summary.solved ? "yes" : "no", middle, blend_psnr, solved_psnr);
  return result.summary.solved && solved_psnr > blend_psnr ? 0 : 1;
}
