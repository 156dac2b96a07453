// The method × case matrix: every method of app/method.h that supports a case, and the main
// Ceres configurations of ceres_lm, on the shared data. Cases: slider_depth prediction, the
// shapes_rotation interpolation and prediction of frame 3 (images.txt line), the eslnet_cups
// deblur (no sharp truth: scored by the mean of the latent frames against the input and the
// Laplacian-variance ratio), and per 240 fps clip with simulated events the interpolation of
// frame 2 from frames 0 and 4 and the deblur of the mean of frames 0–7 (mean PSNR over 0–7).
//
// Every cell runs in its own process (this executable re-executed with --cell,
// benchmarks/cell_runner.h) so that its peak memory, the child's ru_maxrss, is its own.
// Iterative methods record a checkpoint per iteration (cost, and PSNR against the truth where
// there is one). Writes into --out methods.csv, methods_checkpoints.csv and methods.md
// (benchmarks/method_results.h), and prints the tables and the headline per case with truth: the
// time ceres_lm (default) needs to first reach Adam's final PSNR over Adam's whole time.
// benchmarks/plot_methods.py draws the PSNR-against-time plots, psnr_time_<case>.png, from the
// CSV files; methods.md links them.
//
//   method_benchmark --data=../shared/data --out=build/bench [--quick] [--cases=a,b]
//                    [--methods=ceres_lm,adam,...] [--configs=default,per_voxel,...]
//                    [--config_cases=slider_predict,...] [--clips=nfs_basketball_7,...]
//                    [--clip_crop_px=200] [--cell_timeout_s=600]
#include <gflags/gflags.h>
#include <glog/logging.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evfs/app/method.h"
#include "evfs/app/reconstruct_job.h"
#include "evfs/baselines/baseline.h"
#include "evfs/benchmarks/benchmark_cases.h"
#include "evfs/benchmarks/cell_runner.h"
#include "evfs/benchmarks/method_results.h"
#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/core/time.h"
#include "evfs/runtime/allocator_tuning.h"
#include "evfs/scene/scene.h"

DEFINE_string(data, EVFS_DATA_DIR, "The shared data folder.");
DEFINE_string(out, "build/bench",
              "Folder for methods.csv, methods_checkpoints.csv and methods.md (and the plots "
              "benchmarks/plot_methods.py draws from them).");
DEFINE_string(cases,
              "slider_predict,shapes_interpolate,shapes_predict,cups_deblur,clip_interpolate,"
              "clip_deblur",
              "Comma-separated cases: slider_predict, shapes_interpolate, shapes_predict, "
              "cups_deblur, clip_interpolate and clip_deblur (one case per clip of --clips).");
DEFINE_string(methods, "",
              "Comma-separated methods (ceres_lm, ceres_lbfgs, adam, adam_smooth, blend, copy, "
              "integrate, cf, edi); empty: all.");
DEFINE_string(clips, EVFS_BENCHMARK_CLIPS,
              "Ground-truth clips for clip_interpolate and clip_deblur.");
// ClipCropNote() says why the clips are cropped by default.
DEFINE_int32(clip_crop_px, 160, "Keep the central N x N pixels of each clip (0: the whole frame).");
DEFINE_bool(quick, false,
            "Only slider_predict and shapes_interpolate, every method but ceres_lbfgs (unless "
            "--methods names it) in its default configuration: no Ceres variants, no edi oracle.");
DEFINE_string(configs, "default,sparse_cholesky,eta_0.01,per_voxel",
              "Comma-separated ceres_lm configurations: default (CGNR + Jacobi, eta 0.1, merged "
              "quiet steps), sparse_cholesky, eta_0.01, per_voxel.");
DEFINE_string(config_cases, "slider_predict,shapes_interpolate",
              "Cases that run every --configs variant; the others run ceres_lm in its default "
              "configuration only.");
DEFINE_int32(cell_timeout_s, 600, "A cell still running after this many seconds is stopped.");
// A third of this 24 GB machine, which other work shares: a runaway cell (sparse Cholesky or the
// per-voxel layout on a large scene) fails alone instead of starving the machine.
DEFINE_int32(cell_memory_mb, 8192,
             "Address-space limit of each cell's process, MB (RLIMIT_AS); 0: none.");
DEFINE_string(cell, "", "Internal: run one cell 'case,method,config' and write --cell_result.");
DEFINE_string(cell_result, "", "Internal: where --cell writes its result.");

namespace evfs {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Why the clips are cropped, for the report.
std::string ClipCropNote() {
  if (FLAGS_clip_crop_px <= 0) return "whole frames";
  const std::string side = std::to_string(FLAGS_clip_crop_px);
  return "cropped to their central " + side + "x" + side +
         " pixels so that the full suite stays within 20 minutes on 2 cores (at 200x200, the "
         "size of nfs_basketball_7, it took 22 minutes with the log event model; at 500x500 "
         "with all 48 latent frames the adobe240 clips alone would take longer); "
         "--clip_crop_px=0 runs the whole frames";
}

// ---------------------------------------------------------------------------------------------
// Cases and configurations.

// A held-out frame (or a deblur) of a real snippet, run through RunReconstruction as
// `evfs reconstruct` runs it; indices are images.txt lines.
struct SnippetCase {
  const char* id;
  const char* data;
  Mode mode;
  int first, last, truth;  // truth -1: no sharp truth
};

constexpr SnippetCase kSnippetCases[] = {
    {"slider_predict", "slider_depth_70_71", Mode::kPredict, 0, 1, 1},
    {"shapes_interpolate", "shapes_rotation_13_20", Mode::kInterpolate, 2, 4, 3},
    {"shapes_predict", "shapes_rotation_13_20", Mode::kPredict, 2, 3, 3},
    {"cups_deblur", "eslnet_cups_blur", Mode::kDeblur, 1, -1, -1},
};
constexpr char kClipInterpolate[] = "clip_interpolate";
constexpr char kClipDeblur[] = "clip_deblur";
// The clip deblur's EDI oracle tunes its threshold on this frame, the middle of the exposure.
constexpr int kClipTunedFrame = kClipFrames / 2;

struct Case {
  std::string id;    // "slider_predict", "clip_deblur:nfs_basketball_7"
  std::string data;  // folder under --data
  Mode mode = Mode::kPredict;
  bool clip = false;  // simulated events from a ground-truth clip
  int first = 0, last = -1, truth = -1;
  bool has_truth = false;

  std::string Title() const {
    if (clip && mode == Mode::kDeblur) {
      return data + ": deblur the mean of frames 0-7 (truth: frames 0-7, mean PSNR)";
    }
    if (clip) return data + ": interpolate frame 2 from frames 0 and 4 (simulated events)";
    const std::string base = data + ": " + ModeName(mode) + " frame ";
    switch (mode) {
      case Mode::kInterpolate:
        return base + std::to_string(truth) + " from frames " + std::to_string(first) + " and " +
               std::to_string(last);
      case Mode::kPredict:
        return base + std::to_string(last) + " from frame " + std::to_string(first);
      case Mode::kDeblur:
        return base + std::to_string(first) + " (no sharp truth)";
    }
    return base;
  }
  // What the PSNR and SSIM columns measure.
  std::string Score() const {
    if (!has_truth) return "mean of latent frames vs input";
    if (clip && mode == Mode::kDeblur) return "mean over frames 0-7";
    return "frame " + std::to_string(clip ? kClipTruthFrame : truth);
  }
  // What the tables say of it.
  CaseSummary Summary() const {
    return CaseSummary{id, data, ModeName(mode), Title(), Score(), has_truth};
  }
  // Its plot's name: plot_methods.py names it the same way.
  std::string PlotName() const {
    std::string stem = id;
    std::replace(stem.begin(), stem.end(), ':', '_');
    return "psnr_time_" + stem + ".png";
  }
};

Case FindCase(const std::string& id) {
  for (const std::string kind : {kClipInterpolate, kClipDeblur}) {
    if (id.rfind(kind + ":", 0) != 0) continue;
    Case c;
    c.id = id;
    c.data = id.substr(kind.size() + 1);
    c.mode = kind == kClipDeblur ? Mode::kDeblur : Mode::kInterpolate;
    c.clip = true;
    c.has_truth = true;
    return c;
  }
  std::string names;
  for (const SnippetCase& snippet : kSnippetCases) {
    if (id == snippet.id) {
      Case c;
      c.id = id;
      c.data = snippet.data;
      c.mode = snippet.mode;
      c.first = snippet.first;
      c.last = snippet.last;
      c.truth = snippet.truth;
      c.has_truth = snippet.truth >= 0;
      return c;
    }
    names += std::string(snippet.id) + ", ";
  }
  throw InvalidArgumentError("unknown case '" + id + "' (one of " + names + kClipInterpolate +
                             ", " + kClipDeblur + ")");
}

// --cases with clip_interpolate and clip_deblur expanded over --clips.
std::vector<Case> SelectedCases(const std::string& cases, const std::string& clips) {
  std::vector<Case> selected;
  for (const std::string& name : SplitCommaList(cases)) {
    if (name == kClipInterpolate || name == kClipDeblur) {
      for (const std::string& clip : SplitCommaList(clips)) {
        selected.push_back(FindCase(name + ":" + clip));
      }
    } else {
      selected.push_back(FindCase(name));
    }
  }
  return selected;
}

// ceres_lm's configurations; every other method runs in kDefaultConfig only.
struct SolverConfig {
  const char* name;
  const char* description;
};
constexpr SolverConfig kCeresConfigs[] = {
    {kDefaultConfig, "CGNR + Jacobi, eta 0.1, merged quiet steps"},
    {"sparse_cholesky", "SPARSE_NORMAL_CHOLESKY"},
    {"eta_0.01", "CGNR + Jacobi, eta 0.01"},
    {"per_voxel", "one unknown per voxel (merge_quiet_steps=false)"},
};
// edi with its contrast threshold tuned on a truth frame: an oracle, listed as such.
constexpr char kTunedConfig[] = "tuned_on_truth";

MethodOptions CellOptions(Method method, const std::string& config) {
  MethodOptions options;
  options.method = method;
  if (config == kDefaultConfig || config == kTunedConfig) return options;
  if (method != Method::kCeresLm) {
    throw InvalidArgumentError("configuration '" + config + "' is for ceres_lm only");
  }
  if (config == "sparse_cholesky") {
    options.reconstruction.solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  } else if (config == "eta_0.01") {
    options.reconstruction.solver.eta = 0.01;
  } else if (config == "per_voxel") {
    options.reconstruction.merge_quiet_steps = false;
  } else {
    throw InvalidArgumentError("unknown configuration '" + config + "'");
  }
  return options;
}

// Which methods a case supports depends only on its frame observations (how many, sharp or
// blurred), so a 2×2 scene of the same preset answers MethodSupports without reading the data.
Scene ProbeScene(Mode mode) {
  constexpr int64_t kEndNs = 1000;
  const Image image = Image::Constant(2, 2, 0.5);
  EventStream events(2, 2);
  for (int64_t t_ns = 100; t_ns < kEndNs; t_ns += 200) events.push_back(t_ns, 0, 0, 1);
  const TimedFrame first{image, 0, 0, "probe"};
  const BinningOptions binning;
  switch (mode) {
    case Mode::kInterpolate:
      return MakeInterpolationScene(first, TimedFrame{image, kEndNs, kEndNs, "probe"}, events,
                                    binning);
    case Mode::kPredict:
      return MakePredictionScene(first, kEndNs, events, binning);
    case Mode::kDeblur:
      return MakeDeblurScene(TimedFrame{image, 0, kEndNs, "probe"}, events, binning);
  }
  return Scene();
}

// ---------------------------------------------------------------------------------------------
// One cell, in the child process.

void FillFromRun(const MethodResult& run, CellResult* cell) {
  cell->build_s = run.build_time_s;
  cell->solve_s = run.solve_time_s;
  cell->iterations = run.iterations;
  cell->initial_cost = run.initial_cost;
  cell->final_cost = run.final_cost;
  cell->latent_frames = run.video.num_frames();
  cell->note = run.threshold_source.empty() ? run.message : run.threshold_source;
  cell->checkpoints = run.checkpoints;
}

CellResult RunSnippetCell(const Case& c, const MethodOptions& options) {
  ReconstructRequest request;
  request.data_path = (fs::path(FLAGS_data) / c.data).string();
  request.mode = c.mode;
  request.first = c.first;
  request.last = c.last;
  request.truth = c.truth;
  request.method = options;
  request.checkpoints = IsIterative(options.method);
  const ReconstructResult result = RunReconstruction(request);
  CellResult cell;
  FillFromRun(result.run, &cell);
  if (result.has_truth) {
    cell.psnr = result.truth.psnr;
    cell.ssim = result.truth.ssim;
  } else {
    const DeblurWithoutTruthScore score =
        ScoreDeblurWithoutTruth(result.run.video, result.baseline.frame(0));
    cell.psnr = score.mean_vs_input_psnr;
    cell.sharpness_ratio = score.latent_sharpness / score.input_sharpness;
  }
  return cell;
}

CellResult RunClipCell(const Case& c, const MethodOptions& options, const std::string& config) {
  const SimulatedClip clip = LoadSimulatedClip(FLAGS_data, c.data, FLAGS_clip_crop_px);
  const bool deblur = c.mode == Mode::kDeblur;
  const Scene scene = deblur ? MakeClipDeblurScene(clip, BinningOptions())
                             : MakeClipInterpolationScene(clip, BinningOptions());
  const Video timeline = InitializeLatentVideo(scene);
  CellResult cell;
  Video latent;
  if (config == kTunedConfig) {
    const Image truth = clip.frames.frame(kClipTunedFrame);
    const auto start = Clock::now();
    BaselineResult tuned = TuneContrastThresholdOnTruth(
        ParseBaseline(MethodName(options.method)), scene, options.baseline, truth,
        timeline.NearestFrame(clip.frames.timestamp_ns(kClipTunedFrame)));
    cell.solve_s = SecondsSince(start);
    cell.note = tuned.threshold_source;
    latent = std::move(tuned.video);
  } else {
    const Image truth = clip.frames.frame(kClipTruthFrame);
    const CheckpointTruth checkpoint_truth{
        &truth, timeline.NearestFrame(clip.frames.timestamp_ns(kClipTruthFrame))};
    // The deblur's score covers eight frames: the checkpoints' PSNR is recomputed per iterate.
    std::vector<double> deblur_psnr;
    IterationCallback progress;
    if (deblur) {
      progress = [&](const SolverIteration& iteration) {
        deblur_psnr.push_back(ScoreClipDeblur(*iteration.latent, clip, Psnr));
        return true;
      };
    }
    MethodResult run = RunMethod(scene, options, progress, IsIterative(options.method),
                                 deblur ? nullptr : &checkpoint_truth);
    FillFromRun(run, &cell);
    if (deblur) {
      CHECK_EQ(deblur_psnr.size(), cell.checkpoints.size());
      for (size_t i = 0; i < deblur_psnr.size(); ++i) cell.checkpoints[i].psnr = deblur_psnr[i];
    }
    latent = std::move(run.video);
  }
  cell.latent_frames = latent.num_frames();
  if (deblur) {
    cell.psnr = ScoreClipDeblur(latent, clip, Psnr);
    cell.ssim = ScoreClipDeblur(latent, clip, Ssim);
  } else {
    const Image estimate =
        latent.frame(latent.NearestFrame(clip.frames.timestamp_ns(kClipTruthFrame)));
    cell.psnr = Psnr(estimate, clip.frames.frame(kClipTruthFrame));
    cell.ssim = Ssim(estimate, clip.frames.frame(kClipTruthFrame));
  }
  return cell;
}

// --cell=case,method,config: runs it and writes --cell_result; the exit status says whether it
// ran.
int RunChild() {
  const std::vector<std::string> parts = SplitCommaList(FLAGS_cell);
  CellResult cell;
  try {
    if (parts.size() != 3) throw InvalidArgumentError("--cell must be 'case,method,config'");
    const Case c = FindCase(parts[0]);
    const MethodOptions options = CellOptions(ParseMethod(parts[1]), parts[2]);
    cell = c.clip ? RunClipCell(c, options, parts[2]) : RunSnippetCell(c, options);
  } catch (const std::exception& error) {
    cell.status = std::string("error: ") + error.what();
  }
  std::ofstream(FLAGS_cell_result) << CellResultText(cell);
  return cell.ok() ? 0 : 3;
}

// ---------------------------------------------------------------------------------------------
// The parent: the matrix, one child per cell.

// What runs: the methods in AllMethods() order, ceres_lm in each of `ceres_configs`, and edi
// also with its threshold tuned on the truth when `edi_oracle`.
struct Plan {
  std::vector<Method> methods;
  std::vector<std::string> ceres_configs;
  std::vector<std::string> config_cases;  // the cases that run every ceres_configs variant
  bool edi_oracle = true;
};

// The cells of `c`; the unsupported methods with the reason go to `not_run`.
std::vector<MethodCell> PlanCells(const Case& c, const Plan& plan,
                                  std::vector<std::string>* not_run) {
  const Scene probe = ProbeScene(c.mode);
  std::vector<MethodCell> cells;
  for (Method method : plan.methods) {
    std::string why_not;
    if (!MethodSupports(method, probe, &why_not)) {
      not_run->push_back(std::string(MethodName(method)) + ": " + why_not);
      continue;
    }
    const auto add = [&](const std::string& config) {
      cells.push_back(MethodCell{MethodName(method), config, CellResult()});
    };
    if (method != Method::kCeresLm) add(kDefaultConfig);
    if (method == Method::kCeresLm) {
      const bool variants = std::find(plan.config_cases.begin(), plan.config_cases.end(), c.id) !=
                            plan.config_cases.end();
      for (const std::string& config : plan.ceres_configs) {
        if (variants || config == kDefaultConfig) add(config);
      }
    }
    // Only the clip deblur has both a blurred input and sharp truth frames.
    if (method == Method::kEdi && plan.edi_oracle && c.has_truth) add(kTunedConfig);
  }
  return cells;
}

std::vector<Method> SelectedMethods() {
  std::vector<Method> selected;
  if (FLAGS_methods.empty()) {
    // L-BFGS takes its 500 iterations in about 80 s per small case here: too slow for --quick.
    for (Method method : AllMethods()) {
      if (!FLAGS_quick || method != Method::kCeresLbfgs) selected.push_back(method);
    }
    return selected;
  }
  for (Method method : AllMethods()) {
    for (const std::string& name : SplitCommaList(FLAGS_methods)) {
      if (ParseMethod(name) == method) selected.push_back(method);
    }
  }
  return selected;
}

// --methods, --configs and --quick.
Plan SelectedPlan() {
  Plan plan;
  plan.edi_oracle = !FLAGS_quick;
  plan.ceres_configs =
      FLAGS_quick ? std::vector<std::string>{kDefaultConfig} : SplitCommaList(FLAGS_configs);
  plan.config_cases = SplitCommaList(FLAGS_config_cases);
  for (const std::string& config : plan.ceres_configs) {
    CellOptions(Method::kCeresLm, config);  // throws for an unknown configuration
  }
  plan.methods = SelectedMethods();
  return plan;
}

// The machine, as `nproc` and /proc/cpuinfo's model name give it.
std::string MachineLine() {
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  const int cores = sched_getaffinity(0, sizeof(cpus), &cpus) == 0 ? CPU_COUNT(&cpus) : 0;
  std::string model = "unknown CPU";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  // Other work on the machine slows every cell: the load says how much to trust the times.
  std::string load = "?";
  std::ifstream("/proc/loadavg") >> load;
  return std::to_string(cores) + " cores (nproc), " + model + ", load average " + load +
         " at the start";
}

// Runs `cell` of `c` in a child process (this executable with --cell) and collects its result.
CellResult RunCell(const Case& c, const MethodCell& cell, const std::string& result_path) {
  const CellRun run =
      RunCellProcess({"/proc/self/exe", "--cell=" + c.id + "," + cell.method + "," + cell.config,
                      "--cell_result=" + result_path, "--data=" + FLAGS_data,
                      "--clip_crop_px=" + std::to_string(FLAGS_clip_crop_px)},
                     result_path, CellLimits{FLAGS_cell_timeout_s, FLAGS_cell_memory_mb});
  CellResult result;
  if (run.has_result) {
    result = ParseCellResult(run.result);
  } else {
    result.status = run.failure;
  }
  result.wall_s = run.wall_s;
  result.cpu_s = run.cpu_s;
  result.peak_memory_mb = run.peak_memory_mb;
  return result;
}

// methods.md's account of the run: the command, and what the columns measure.
std::string AboutTheRun(const std::string& cases) {
  std::string about =
      "Command: `method_benchmark --data=" + FLAGS_data + " --out=" + FLAGS_out +
      (FLAGS_quick ? " --quick" : "") +
      (FLAGS_methods.empty() ? "" : " --methods=" + FLAGS_methods) +
      " --clip_crop_px=" + std::to_string(FLAGS_clip_crop_px) +
      (FLAGS_quick ? "" : " --configs=" + FLAGS_configs + " --config_cases=" + FLAGS_config_cases) +
      "`; cases: " + cases;
  if (cases.find("clip_") != std::string::npos) {
    about += "; clips: " + FLAGS_clips + " (" + ClipCropNote() + ")";
  }
  about += ".\n\n";
  about +=
      "time: the method's build + solve (problem construction or objective set-up, and the "
      "iterations; without reading the data, simulating events and scoring checkpoints). cell "
      "wall / CPU: the whole child process, its wall time and its user + system CPU time (the "
      "solvers use 2 threads; other load on the machine stretches the wall time, barely the "
      "CPU time). peak memory: the child's maximum resident set size. Each cell may run " +
      std::to_string(FLAGS_cell_timeout_s) + " s and address " +
      (FLAGS_cell_memory_mb > 0 ? std::to_string(FLAGS_cell_memory_mb) + " MB"
                                : std::string("unlimited memory")) +
      ". ceres_lm configurations: ";
  for (const SolverConfig& config : kCeresConfigs) {
    about += std::string(config.name) + " = " + config.description + "; ";
  }
  about += std::string(kTunedConfig) + ": edi with its contrast threshold tuned on truth frame " +
           std::to_string(kClipTunedFrame) + " (an oracle, not a method).\n";
  return about;
}

// A case's plot is drawn when a cell has a PSNR to mark (plot_methods.py decides the same).
bool HasPlot(const std::vector<MethodCell>& cells) {
  return std::any_of(cells.begin(), cells.end(), [](const MethodCell& cell) {
    return cell.result.ok() && std::isfinite(cell.result.psnr);
  });
}

int RunParent() {
  if (FLAGS_data.empty() || !fs::is_directory(FLAGS_data)) {
    std::fprintf(stderr, "no data folder '%s': pass --data=../shared/data\n", FLAGS_data.c_str());
    return 2;
  }
  if (FLAGS_cell_timeout_s <= 0) throw InvalidArgumentError("--cell_timeout_s must be > 0");
  if (FLAGS_cell_memory_mb < 0) throw InvalidArgumentError("--cell_memory_mb must be >= 0");
  const std::string cases = FLAGS_quick ? "slider_predict,shapes_interpolate" : FLAGS_cases;
  const Plan plan = SelectedPlan();
  const fs::path out(FLAGS_out);
  fs::create_directories(out);
  const std::string result_path = (out / ".cell_result.txt").string();
  const std::vector<Case> selected = SelectedCases(cases, FLAGS_clips);
  const std::string machine = MachineLine();
  std::printf("machine: %s\n", machine.c_str());
  const auto start = Clock::now();

  std::vector<CaseReport> reports;
  for (const Case& c : selected) {
    CaseReport report;
    report.summary = c.Summary();
    report.cells = PlanCells(c, plan, &report.not_run);
    std::printf("\n## %s\n\n%s", c.Title().c_str(), TableHeader(c.has_truth).c_str());
    for (MethodCell& cell : report.cells) {
      cell.result = RunCell(c, cell, result_path);
      std::printf("%s", TableRow(cell, c.has_truth).c_str());
      std::fflush(stdout);
    }
    report.headlines = Headlines(report.cells, c.has_truth);
    if (HasPlot(report.cells)) report.plot = c.PlotName();
    reports.push_back(std::move(report));
  }
  const double total_s = SecondsSince(start);

  std::ofstream methods_csv(out / "methods.csv");
  std::ofstream checkpoints_csv(out / "methods_checkpoints.csv");
  WriteCsv(reports, methods_csv, checkpoints_csv);
  std::ofstream(out / "methods.md") << Markdown(reports, machine, total_s, AboutTheRun(cases));
  std::printf("\n## Headline: ceres_lm (default) against Adam\n");
  for (const CaseReport& report : reports) {
    for (const Headline& h : report.headlines) {
      std::printf("%s: %s\n", report.summary.id.c_str(), DescribeHeadline(h).c_str());
    }
  }
  std::printf(
      "\ntotal %.0f s; wrote %s/{methods.csv,methods_checkpoints.csv,methods.md}; plots: "
      "benchmarks/plot_methods.py %s\n",
      total_s, out.string().c_str(), out.string().c_str());
  return 0;
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  evfs::KeepFreedMemoryForReuse();
  gflags::SetUsageMessage("every reconstruction method on every case of the shared data");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  try {
    return FLAGS_cell.empty() ? evfs::RunParent() : evfs::RunChild();
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "method_benchmark: %s\n", error.what());
    return 2;
  }
}
