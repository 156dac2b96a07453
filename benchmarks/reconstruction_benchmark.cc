// Reconstruction quality and wall time with the default options on the shared data: the real
// DAVIS snippets (slider_depth prediction, shapes_rotation interpolation, eslnet_cups deblur)
// and the 240 fps clips with events simulated by `evfs simulate`'s defaults (interpolation of
// frame 2 from frames 0 and 4; deblurring the mean of frames 0–7). Prints a Markdown table and
// optionally writes CSV.
//
//   reconstruction_benchmark --data=../shared/data [--cases=slider,shapes,cups,clips]
//                            [--clips=nfs_basketball_7,adobe240_GOPR9637b,...] [--csv=FILE]
//                            [--solver=METHOD [--contrast_threshold=C]] [--denoise=none|auto]
//
// The DAVIS cases run without the residual denoiser unless --denoise says otherwise (auto: as
// `evfs reconstruct` runs by default); the clips are always the solve alone.
//
// --solver runs another method of `evfs reconstruct --solver` on the same cases (a case it does
// not support is skipped, with a line on stderr); the table's evfs column is then that method.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evfs/app/denoise_job.h"
#include "evfs/app/reconstruct_job.h"
#include "evfs/benchmarks/benchmark_cases.h"
#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/core/time.h"
#include "evfs/events/simulator.h"
#include "evfs/runtime/allocator_tuning.h"
#include "evfs/solver/reconstructor.h"

DEFINE_string(data, EVFS_DATA_DIR, "The shared data folder.");
DEFINE_string(cases, "slider,shapes,cups,clips", "Comma-separated cases to run.");
DEFINE_string(clips, EVFS_BENCHMARK_CLIPS, "Ground-truth clips for the simulated-event cases.");
DEFINE_string(csv, "", "Also write the rows as CSV to this file.");
DEFINE_string(denoise, "none",
              "The DAVIS cases' residual denoiser, as evfs reconstruct's --denoise: none (the "
              "solve alone), auto (evfs' default: the shipped denoiser, once) or once.");
// Overrides of the defaults, for exploring them; the published figures use none.
DEFINE_double(alpha, evfs::ObjectiveOptions().event_model.alpha, "alpha; 0 derives it.");
DEFINE_double(alpha_times_change, evfs::EventModelEstimationOptions().alpha_times_change,
              "derived alpha times the change of g one event stands for.");
DEFINE_string(event_model, evfs::EventModelName(evfs::ObjectiveOptions().event_model.model),
              "log | linear: the event model's intensity transform g.");
DEFINE_double(log_offset, evfs::ObjectiveOptions().event_model.log_offset,
              "b of the log event model.");
DEFINE_double(measured_saturation, evfs::EventModelEstimationOptions().measured_saturation,
              "c of the event model when the change per event is measured between frames.");
DEFINE_double(frame_weight, evfs::ObjectiveOptions().frame_weight, "weight of the frame term.");
DEFINE_double(event_weight, evfs::ObjectiveOptions().event_weight, "lambda_e.");
DEFINE_double(temporal_tv_weight, evfs::ObjectiveOptions().temporal_tv_weight, "lambda_t.");
DEFINE_double(spatial_tv_weight, evfs::ObjectiveOptions().spatial_tv_weight, "lambda_xy.");
DEFINE_bool(merge_quiet_steps, evfs::ReconstructionOptions().merge_quiet_steps,
            "one unknown per quiet run of a pixel (false: per voxel).");
DEFINE_bool(split_independent_parts, evfs::ReconstructionOptions().split_independent_parts,
            "solve uncoupled regions as separate concurrent problems (false: one problem).");
DEFINE_double(step_ramp_px, evfs::ReconstructionOptions().step_ramp_px,
              "steps ramped over the time the scene takes to move this many pixels.");
DEFINE_int64(max_problem_mb, evfs::ReconstructionOptions().max_problem_mb,
             "Most memory (MiB) the Ceres problems hold at once; <= 0: no limit.");
DEFINE_string(init, evfs::InitializationName(evfs::MethodOptions().initialization),
              "blend | events: where the solve starts.");
DEFINE_string(solver, evfs::MethodName(evfs::MethodOptions().method),
              "the method (as evfs reconstruct --solver); the published figures use ceres_lm.");
DEFINE_double(contrast_threshold, evfs::BaselineOptions().contrast_threshold,
              "integrate, cf, edi and the events start (--init=events): the change one event "
              "stands for; 0 derives it (edi: its sharpness search).");
DEFINE_bool(whole_objective, false,
            "after each clip solve, print to stderr the objective of its answer evaluated as one "
            "problem (no memory budget), to compare a banded solve with the whole one");
DEFINE_int32(clip_crop_px, 0, "Keep the central N x N pixels of each clip (0: whole frames).");
DEFINE_int32(max_iterations, evfs::ReconstructionOptions().solver.max_num_iterations,
             "most Levenberg-Marquardt iterations.");
DEFINE_int64(max_latent_voxels, evfs::BinningOptions().max_latent_voxels,
             "auto binning's voxel budget.");
DEFINE_double(hot_pixel_factor, evfs::BinningOptions().hot_pixel_factor,
              "hot pixel rule of the binning (0: keep every event).");

namespace evfs {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Row {
  std::string data, method_case, metric;
  double baseline = 0.0, evfs = 0.0;
  std::string baseline_name;
  int latent_frames = 0;
  double wall_s = 0.0;
};

bool Wants(const std::string& name) {
  for (const std::string& c : SplitCommaList(FLAGS_cases)) {
    if (c == name) return true;
  }
  return false;
}

ReconstructionOptions Options() {
  ReconstructionOptions options;
  options.objective.event_model.alpha = FLAGS_alpha;
  options.objective.event_model.log_offset = FLAGS_log_offset;
  options.estimation.alpha_times_change = FLAGS_alpha_times_change;
  options.estimation.measured_saturation = FLAGS_measured_saturation;
  options.solver.max_num_iterations = FLAGS_max_iterations;
  if (!ParseEventModel(FLAGS_event_model, &options.objective.event_model.model)) {
    throw InvalidArgumentError("--event_model: linear or log, got '" + FLAGS_event_model + "'");
  }
  options.objective.spatial_tv_weight = FLAGS_spatial_tv_weight;
  options.objective.frame_weight = FLAGS_frame_weight;
  options.objective.event_weight = FLAGS_event_weight;
  options.objective.temporal_tv_weight = FLAGS_temporal_tv_weight;
  options.merge_quiet_steps = FLAGS_merge_quiet_steps;
  options.split_independent_parts = FLAGS_split_independent_parts;
  options.max_problem_mb = FLAGS_max_problem_mb;
  options.step_ramp_px = FLAGS_step_ramp_px;
  return options;
}

BinningOptions Binning() {
  BinningOptions binning;
  binning.max_latent_voxels = FLAGS_max_latent_voxels;
  binning.hot_pixel_factor = FLAGS_hot_pixel_factor;
  return binning;
}

MethodOptions MethodFromFlags() {
  MethodOptions method;
  method.method = ParseMethod(FLAGS_solver);
  method.reconstruction = Options();
  method.baseline.contrast_threshold = FLAGS_contrast_threshold;
  method.initialization = ParseInitialization(FLAGS_init);
  return method;
}

// Whether --solver runs on `scene`; if not, says so on stderr.
bool Supported(const std::string& name, const char* kind, const Scene& scene) {
  std::string why_not;
  if (MethodSupports(MethodFromFlags().method, scene, &why_not)) return true;
  std::fprintf(stderr, "%s %s: skipped, %s\n", name.c_str(), kind, why_not.c_str());
  return false;
}

// PSNR rows compare by difference, other rows (sharpness) by ratio; rows without a baseline
// (baseline_name "-") by neither.
void PrintRow(const Row& row) {
  char baseline[64] = "-", gain[32] = "-";
  if (row.baseline_name != "-") {
    std::snprintf(baseline, sizeof(baseline), "%s %.2f", row.baseline_name.c_str(), row.baseline);
    if (row.metric.find("PSNR") != std::string::npos) {
      std::snprintf(gain, sizeof(gain), "%+.2f dB", row.evfs - row.baseline);
    } else {
      std::snprintf(gain, sizeof(gain), "x%.2f", row.evfs / row.baseline);
    }
  }
  char solve[64] = "- | -";  // oracle rows solve nothing
  if (row.latent_frames > 0) {
    std::snprintf(solve, sizeof(solve), "%d | %.1f s", row.latent_frames, row.wall_s);
  }
  std::printf("| %s | %s | %s | %s | %.2f | %s | %s |\n", row.data.c_str(), row.method_case.c_str(),
              row.metric.c_str(), baseline, row.evfs, gain, solve);
  std::fflush(stdout);
}

DenoiseRequest DenoiseFromFlags() {
  DenoiseRequest denoise;
  denoise.mode = FLAGS_denoise == "auto" ? AutoDenoiseMode("")
                                         : ParseName(kDenoiseModeNames, FLAGS_denoise, "--denoise");
  return denoise;
}

// A held-out frame of a real snippet, through the same job as `evfs reconstruct`.
Row RunTruthCase(const std::string& snippet, Mode mode, int first, int last, int truth) {
  ReconstructRequest request;
  request.data_path = (fs::path(FLAGS_data) / snippet).string();
  request.mode = mode;
  request.first = first;
  request.last = last;
  request.truth = truth;
  request.method = MethodFromFlags();
  request.binning = Binning();
  request.denoise = DenoiseFromFlags();
  const auto start = Clock::now();
  const ReconstructResult result = RunReconstruction(request);
  Row row{snippet,
          ModeName(mode),
          "PSNR dB (frame " + std::to_string(truth) + ")",
          result.truth.baseline_psnr,
          result.truth.psnr,
          mode == Mode::kInterpolate ? "blend" : "copy",
          result.run.video.num_frames(),
          SecondsSince(start)};
  return row;
}

// eslnet cups: no sharp truth. The mean of the latent frames must reproduce the blurred input,
// and the latent frames must be sharper than it (variance of the Laplacian).
std::vector<Row> RunCupsDeblur(int frame) {
  ReconstructRequest request;
  request.data_path = (fs::path(FLAGS_data) / "eslnet_cups_blur").string();
  request.mode = Mode::kDeblur;
  request.first = frame;
  request.method = MethodFromFlags();
  request.binning = Binning();
  request.denoise = DenoiseFromFlags();
  const auto start = Clock::now();
  const ReconstructResult result = RunReconstruction(request);
  const double wall_s = SecondsSince(start);
  const int latent_frames = result.run.video.num_frames();
  const DeblurWithoutTruthScore score =
      ScoreDeblurWithoutTruth(result.run.video, result.baseline.frame(0));
  const std::string name = "eslnet_cups_blur #" + std::to_string(frame);
  return {
      Row{name, "deblur", "mean of latent frames vs input, PSNR dB", 0.0, score.mean_vs_input_psnr,
          "-", latent_frames, wall_s},
      Row{name, "deblur", "variance of Laplacian ×1e3 (mean of latent)",
          1e3 * score.input_sharpness, 1e3 * score.latent_sharpness, "input", latent_frames,
          wall_s},
  };
}

// What a method that reads each pixel on its own could reach with the simulator's sensor
// model known: its log offset b and either every pixel's own thresholds (`own_thresholds`) or
// only the nominal ones (C = 0.2, what a user could know). L = log(I + b) is followed
// piecewise linearly in time through frame 0, each of the pixel's threshold crossings (where L
// equals the level its events have reached) and frame 4, read at frame 2. The simulator moves L
// linearly between frames, so with each pixel's own thresholds this is exact where L does not
// bend between the crossings around frame 2, and for a pixel without events it is the blend (in
// L). It is an estimate, not a bound: where L turns between crossings (nfs_basketball_7
// flickers from frame to frame) it loses to the blend.
double CrossingInterpolationOracle(const SimulatedClip& clip, bool own_thresholds) {
  const SimulatorOptions sensor;
  const EventSimulator simulator(clip.frames.height(), clip.frames.width(), sensor);
  const int width = clip.frames.width();
  const Image& first = clip.frames.frame(kClipFirstFrame);
  const Image& last = clip.frames.frame(kClipLastFrame);
  const auto t_first = static_cast<double>(clip.frames.timestamp_ns(kClipFirstFrame));
  const auto t_truth = static_cast<double>(clip.frames.timestamp_ns(kClipTruthFrame));
  const auto t_last = static_cast<double>(clip.frames.timestamp_ns(kClipLastFrame));
  const auto log_of = [&sensor](double intensity) { return std::log(intensity + sensor.log_eps); };
  // Per pixel: the level its events have reached, and the knots (time, L) just before and just
  // after frame 2 (the latter at frame 4 until a crossing after frame 2 is seen).
  const Eigen::Index num_pixels = first.size();
  std::vector<double> level(num_pixels), before_t(num_pixels, t_first), before_level(num_pixels),
      after_t(num_pixels, t_last), after_level(num_pixels);
  std::vector<bool> after_seen(num_pixels, false);
  for (Eigen::Index p = 0; p < num_pixels; ++p) {
    level[p] = before_level[p] = log_of(first.data()[p]);
    after_level[p] = log_of(last.data()[p]);
  }
  const EventStream& events = clip.events;
  for (size_t i = 0; i < events.size(); ++i) {
    const auto t = static_cast<double>(events.t_ns(i));
    if (t <= t_first || t > t_last) continue;
    const size_t p = static_cast<size_t>(events.y(i)) * width + events.x(i);
    if (after_seen[p]) continue;
    if (events.polarity(i) > 0) {
      level[p] += own_thresholds ? simulator.threshold_pos()[p] : sensor.contrast_threshold_pos;
    } else {
      level[p] -= own_thresholds ? simulator.threshold_neg()[p] : sensor.contrast_threshold_neg;
    }
    if (t <= t_truth) {
      before_t[p] = t;
      before_level[p] = level[p];
    } else {
      after_t[p] = t;
      after_level[p] = level[p];
      after_seen[p] = true;
    }
  }
  Image estimate(first.rows(), first.cols());
  for (Eigen::Index p = 0; p < num_pixels; ++p) {
    const double fraction = (t_truth - before_t[p]) / (after_t[p] - before_t[p]);
    const double log_estimate = before_level[p] + fraction * (after_level[p] - before_level[p]);
    estimate.data()[p] = std::max(0.0, std::exp(log_estimate) - sensor.log_eps);
  }
  return Psnr(estimate, clip.frames.frame(kClipTruthFrame));
}

// --whole_objective: the objective at a ceres_lm answer of the whole problem (one problem, no
// memory budget), on stderr. A solve in bands minimises overlapping problems whose own costs do
// not add up to the whole's; this puts both on one scale.
void PrintWholeObjective(const std::string& name, const char* kind, const Scene& scene,
                         const MethodResult& run) {
  if (!FLAGS_whole_objective || run.method != MethodName(Method::kCeresLm)) return;
  ReconstructionOptions whole = Options();
  whole.max_problem_mb = 0;
  whole.solver.max_num_iterations = 1;
  const Reconstruction at_answer = Reconstruct(scene, whole, &run.video);
  std::fprintf(stderr, "%s %s: whole objective at the answer %.9g (solved as %lld batches)\n",
               name.c_str(), kind, at_answer.summary.initial_cost,
               static_cast<long long>(run.reconstruction.problem.batches));
}

// A clip case's answer by --solver, as `evfs reconstruct` gives it: the method from the --init
// start, then the sharp frames met (app/method.h ApplySharpFrameSeams).
Video SolveClip(const std::string& name, const char* kind, const Scene& scene) {
  const MethodOptions method = MethodFromFlags();
  MethodResult run = RunMethod(scene, method);
  PrintWholeObjective(name, kind, scene, run);
  ApplySharpFrameSeams(scene, method, &run);
  return std::move(run.video);
}

// The interpolation row and, after it, the two crossing-interpolation oracle rows (which
// solve nothing); none when --solver does not interpolate.
std::vector<Row> RunClipInterpolation(const std::string& name, const SimulatedClip& clip) {
  const auto start = Clock::now();
  const Scene scene = MakeClipInterpolationScene(clip, Binning());
  if (!Supported(name, "interpolate", scene)) return {};
  const Video video = SolveClip(name, "interpolate", scene);
  const int index = video.NearestFrame(clip.frames.timestamp_ns(kClipTruthFrame));
  const Image& truth = clip.frames.frame(kClipTruthFrame);
  const double blend_psnr = Psnr(InitializeLatentVideo(scene).frame(index), truth);
  const Row interpolation{name,
                          "interpolate",
                          "PSNR dB (frame 2 from 0, 4)",
                          blend_psnr,
                          Psnr(video.frame(index), truth),
                          "blend",
                          video.num_frames(),
                          SecondsSince(start)};
  const Row nominal{name,
                    "interpolate",
                    "PSNR dB, per pixel through the crossings at the nominal threshold (oracle)",
                    blend_psnr,
                    CrossingInterpolationOracle(clip, false),
                    "blend",
                    0,
                    0.0};
  const Row own{name,
                "interpolate",
                "PSNR dB, per pixel through the crossings at each pixel's threshold (oracle)",
                blend_psnr,
                CrossingInterpolationOracle(clip, true),
                "blend",
                0,
                0.0};
  return {interpolation, nominal, own};
}

// The mean over frames 0-7 of the PSNR of estimate(sharp frame t) against sharp frame t.
template <typename Estimate>
double MeanPsnrOverClip(const SimulatedClip& clip, const Estimate& estimate) {
  double psnr = 0.0;
  for (int t = 0; t < kClipFrames; ++t) {
    const Image& sharp = clip.frames.frame(t);
    psnr += Psnr(estimate(sharp), sharp) / kClipFrames;
  }
  return psnr;
}

// Two oracles that split the blurred frame's error into its two parts, the overall brightness of
// each frame and everything else:
// * brightness-blind: every sharp frame exactly, rescaled to the blurred frame's mean, i.e. a
//   deblur that recovers everything except a change of overall brightness between frames;
// * brightness-only: the blurred frame rescaled to each sharp frame's mean, i.e. one that
//   recovers each frame's overall brightness and nothing else.
// Where the frames flicker by less than the simulator's threshold (nfs_basketball_7), the events
// record the brightness changes only at the few pixels that fire, so a deblur is held near the
// brightness-blind row.
double BrightnessBlindOracle(const SimulatedClip& clip, const Image& blurred) {
  return MeanPsnrOverClip(clip, [&blurred](const Image& sharp) -> Image {
    return sharp * (blurred.mean() / sharp.mean());
  });
}

double BrightnessOnlyOracle(const SimulatedClip& clip, const Image& blurred) {
  return MeanPsnrOverClip(clip, [&blurred](const Image& sharp) -> Image {
    return (blurred * (sharp.mean() / blurred.mean())).cwiseMin(1.0);
  });
}

// The deblur row and, after it, the two brightness oracle rows (which solve nothing); none when
// --solver does not deblur.
std::vector<Row> RunClipDeblur(const std::string& name, const SimulatedClip& clip) {
  const auto start = Clock::now();
  const Image blurred = ClipBlurredFrame(clip).image;
  const Scene scene = MakeClipDeblurScene(clip, Binning());
  if (!Supported(name, "deblur", scene)) return {};
  const Video video = SolveClip(name, "deblur", scene);
  const double blurred_psnr =
      MeanPsnrOverClip(clip, [&blurred](const Image&) -> const Image& { return blurred; });
  const Row deblur{name,
                   "deblur",
                   "PSNR dB (mean over frames 0-7)",
                   blurred_psnr,
                   ScoreClipDeblur(video, clip, Psnr),
                   "blurred",
                   video.num_frames(),
                   SecondsSince(start)};
  const Row blind{name,
                  "deblur",
                  "PSNR dB, sharp frames at the blurred brightness (oracle)",
                  blurred_psnr,
                  BrightnessBlindOracle(clip, blurred),
                  "blurred",
                  0,
                  0.0};
  const Row only{name,
                 "deblur",
                 "PSNR dB, blurred frame at each sharp frame's brightness (oracle)",
                 blurred_psnr,
                 BrightnessOnlyOracle(clip, blurred),
                 "blurred",
                 0,
                 0.0};
  return {deblur, blind, only};
}

int Main() {
  if (FLAGS_data.empty() || !fs::is_directory(FLAGS_data)) {
    std::fprintf(stderr, "no data folder '%s': pass --data=../shared/data\n", FLAGS_data.c_str());
    return 2;
  }
  std::printf(
      "| data | case | metric | baseline | evfs | gain | latent frames | wall |\n"
      "|---|---|---|---|---|---|---|---|\n");
  std::vector<Row> rows;
  const auto add = [&rows](const Row& row) {
    PrintRow(row);
    rows.push_back(row);
  };
  // A DAVIS case --solver does not support is skipped with RunReconstruction's reason.
  const auto davis_case = [](const char* name, const auto& run) {
    try {
      run();
    } catch (const InvalidArgumentError& error) {
      if (MethodFromFlags().method == Method::kCeresLm) throw;
      std::fprintf(stderr, "%s: skipped, %s\n", name, error.what());
    }
  };
  if (Wants("slider")) {
    davis_case("slider_depth_70_71",
               [&] { add(RunTruthCase("slider_depth_70_71", Mode::kPredict, 0, 1, 1)); });
  }
  if (Wants("shapes")) {
    davis_case("shapes_rotation_13_20",
               [&] { add(RunTruthCase("shapes_rotation_13_20", Mode::kInterpolate, 2, 4, 3)); });
  }
  if (Wants("cups")) {
    davis_case("eslnet_cups_blur", [&] {
      for (const Row& row : RunCupsDeblur(1)) add(row);
    });
  }
  if (Wants("clips")) {
    for (const std::string& name : SplitCommaList(FLAGS_clips)) {
      const SimulatedClip clip = LoadSimulatedClip(FLAGS_data, name, FLAGS_clip_crop_px);
      for (const Row& row : RunClipInterpolation(name, clip)) add(row);
      for (const Row& row : RunClipDeblur(name, clip)) add(row);
    }
  }
  if (!FLAGS_csv.empty()) {
    std::ofstream csv(FLAGS_csv);
    csv << "data,case,metric,baseline_name,baseline,evfs,latent_frames,wall_s\n";
    for (const Row& row : rows) {
      csv << row.data << "," << row.method_case << ",\"" << row.metric << "\"," << row.baseline_name
          << "," << row.baseline << "," << row.evfs << "," << row.latent_frames << "," << row.wall_s
          << "\n";
    }
  }
  return 0;
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  evfs::KeepFreedMemoryForReuse();
  gflags::SetUsageMessage("reconstruction quality and time on the shared data, default options");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  try {
    return evfs::Main();
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "reconstruction_benchmark: %s\n", error.what());
    return 2;
  }
}
