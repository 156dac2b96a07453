// Time against the active fraction of a scene: a textured scene in which only a band of width
// f·W moves (the rest of the image is the static first frame), events simulated from it, and
// interpolation between its first and last frames with the default options. Skipping should
// make the time follow the active voxels, not the sensor size: the table reports the time per
// unknown, which should stay roughly flat from 5 % to 100 %.
//
//   build/benchmarks/active_fraction_benchmark [--fractions=0,0.05,0.1,0.25,0.5,1] [--repeats=3]

#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "evfs/app/method.h"
#include "evfs/core/metrics.h"
#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/runtime/allocator_tuning.h"
#include "evfs/solver/reconstructor.h"
#include "evfs/solver/sharp_frame_seams.h"

DEFINE_string(fractions, "0,0.05,0.1,0.25,0.5,0.75,1",
              "Comma-separated fractions of the image width that move.");
DEFINE_int32(width, 240, "Sensor width.");
DEFINE_int32(height, 180, "Sensor height.");
DEFINE_int32(repeats, 3, "Runs per fraction; the table gives medians.");
DEFINE_bool(
    shared_structure_tv, evfs::ObjectiveOptions().shared_structure_tv,
    "Spatial TV measured from the structure both frames share (evfs --shared_structure_tv).");
DEFINE_int32(min_latent_steps, evfs::BinningOptions().min_latent_steps,
             "Collision frames split until the window has this many latent steps "
             "(evfs --min_latent_steps).");
DEFINE_double(step_ramp_px, evfs::ReconstructionOptions().step_ramp_px,
              "Steps ramped over the time the scene takes to move this many pixels "
              "(evfs --step_ramp_px).");

namespace evfs {
namespace {

using Clock = std::chrono::steady_clock;

std::vector<double> ParseFractions(const std::string& text) {
  std::vector<double> fractions;
  std::stringstream stream(text);
  for (std::string part; std::getline(stream, part, ',');) {
    if (!part.empty()) fractions.push_back(std::stod(part));
  }
  return fractions;
}

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The moving scene inside columns [0, fraction·width), its first frame elsewhere.
Video BandVideo(double fraction) {
  SceneOptions options;
  options.width = FLAGS_width;
  options.height = FLAGS_height;
  options.duration_s = 0.02;
  options.num_shapes = 6;
  options.background_speed_px_per_s = 300.0;  // a panning background: every pixel moves
  options.seed = 11;
  Video video = SceneSynthesizer(options).RenderAtRate(1000.0);
  const int band = static_cast<int>(fraction * FLAGS_width + 0.5);
  for (int t = 1; t < video.num_frames(); ++t) {
    video.frame(t).rightCols(FLAGS_width - band) = video.frame(0).rightCols(FLAGS_width - band);
  }
  return video;
}

TimedFrame Sharp(const Video& video, int t) {
  TimedFrame frame;
  frame.image = video.frame(t);
  frame.exposure_begin_ns = frame.exposure_end_ns = video.timestamp_ns(t);
  return frame;
}

int Run() {
  std::printf(
      "| active fraction | events | active pixels | unknowns | latent frames | build s "
      "| solve s | µs per unknown | PSNR blend / integration / evfs | gain over blend |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const double fraction : ParseFractions(FLAGS_fractions)) {
    const Video video = BandVideo(fraction);
    const EventStream events = SimulateEvents(video, SimulatorOptions());
    const int last = video.num_frames() - 1, middle = last / 2;
    BinningOptions binning;
    binning.min_latent_steps = FLAGS_min_latent_steps;
    const Scene scene =
        MakeInterpolationScene(Sharp(video, 0), Sharp(video, last), events, binning);
    std::vector<double> build_s, solve_s;
    ReconstructionOptions options;
    options.objective.shared_structure_tv = FLAGS_shared_structure_tv;
    options.step_ramp_px = FLAGS_step_ramp_px;
    Reconstruction result;
    for (int r = 0; r < FLAGS_repeats; ++r) {
      const auto start = Clock::now();
      result = Reconstruct(scene, options);
      // As `evfs reconstruct` finishes (app/method.h ApplySharpFrameSeams).
      if (options.meet_sharp_frames && result.summary.solved) MeetSharpFrames(scene, &result.video);
      const double total = std::chrono::duration<double>(Clock::now() - start).count();
      build_s.push_back(result.summary.build_time_s);
      // Without events there is no solve: report the whole call.
      solve_s.push_back(result.summary.solved ? result.summary.solve_time_s : total);
    }
    const int64_t unknowns = result.summary.problem.variable_parameter_blocks;
    const Image& truth = video.frame(middle);
    const Video blend = InitializeLatentVideo(scene);
    const int index = result.video.NearestFrame(video.timestamp_ns(middle));
    // Without events the answer is the blend itself: no gain to report.
    char gain[32] = "-", scores[64] = "-";
    if (result.summary.solved) {
      MethodOptions integrate;
      integrate.method = Method::kIntegrate;
      const Video integrated = RunMethod(scene, integrate).video;
      const double evfs = Psnr(result.video.frame(index), truth);
      const double blended = Psnr(blend.frame(index), truth);
      std::snprintf(scores, sizeof(scores), "%.2f / %.2f / %.2f dB", blended,
                    Psnr(integrated.frame(index), truth), evfs);
      std::snprintf(gain, sizeof(gain), "%+.2f dB", evfs - blended);
    }
    const double per_unknown =
        unknowns > 0 ? 1e6 * (Median(build_s) + Median(solve_s)) / unknowns : 0.0;
    std::printf("| %.0f %% | %lld | %lld | %lld | %d | %.3f | %.3f | %.1f | %s | %s |\n",
                100.0 * fraction, static_cast<long long>(events.size()),
                static_cast<long long>(result.summary.problem.active_pixels),
                static_cast<long long>(unknowns), scene.num_latent_frames(), Median(build_s),
                Median(solve_s), per_unknown, scores, gain);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  evfs::KeepFreedMemoryForReuse();
  gflags::SetUsageMessage("Reconstruction time against the active fraction of a scene.");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  return evfs::Run();
}
