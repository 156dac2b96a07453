// The method × case matrix: every method of examples/method.h that supports a case, and the main
// Ceres configurations of ceres_lm, on the shared data. Cases: slider_depth prediction, the
// shapes_rotation interpolation and prediction of frame 3 (images.txt line), the eslnet_cups
// deblur (no sharp truth: scored by the mean of the latent frames against the input and the
// Laplacian-variance ratio), and per 240 fps clip with simulated events the interpolation of
// frame 2 from frames 0 and 4 and the deblur of the mean of frames 0–7 (mean PSNR over 0–7).
//
// Every cell runs in its own process (this executable re-executed with --cell) so that its
// peak memory, the child's ru_maxrss, is its own. Iterative methods record a checkpoint per
// iteration (cost, and PSNR against the truth where there is one). Writes into --out:
// methods.csv, methods_checkpoints.csv, methods.md and psnr_time_<case>.png (PSNR against
// time, log axis), and prints the tables and the headline per case with truth: the time
// ceres_lm (default) needs to first reach Adam's final PSNR over Adam's whole time.
//
//   method_benchmark --data=../shared/data --out=build/bench [--quick] [--cases=a,b]
//                    [--methods=ceres_lm,adam,...] [--configs=default,per_voxel,...]
//                    [--config_cases=slider_predict,...] [--clips=nfs_basketball_7,...]
//                    [--clip_crop_px=200] [--cell_timeout_s=600]
#include <gflags/gflags.h>
#include <glog/logging.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "baselines/baseline.h"
#include "benchmarks/benchmark_cases.h"
#include "core/error.h"
#include "core/metrics.h"
#include "core/time.h"
#include "examples/allocator_tuning.h"
#include "examples/method.h"
#include "examples/reconstruct_job.h"
#include "solver/problem_builder.h"

DEFINE_string(data, EVFS_DATA_DIR, "The shared data folder.");
DEFINE_string(out, "build/bench", "Folder for methods.csv, methods.md and the plots.");
DEFINE_string(cases,
              "slider_predict,shapes_interpolate,shapes_predict,cups_deblur,clip_interpolate,"
              "clip_deblur",
              "Comma-separated cases: slider_predict, shapes_interpolate, shapes_predict, "
              "cups_deblur, clip_interpolate and clip_deblur (one case per clip of --clips).");
DEFINE_string(methods, "",
              "Comma-separated methods (ceres_lm, ceres_lbfgs, adam, adam_smooth, blend, copy, "
              "integrate, cf, edi); empty: all.");
DEFINE_string(clips,
              "nfs_basketball_7,adobe240_GOPR9637b,adobe240_GOPR9642,adobe240_IMG_0004b,"
              "adobe240_IMG_0036",
              "Ground-truth clips for clip_interpolate and clip_deblur.");
// ClipCropNote() says why the clips are cropped by default.
DEFINE_int32(clip_crop_px, 160,
             "Keep the central N x N pixels of each clip (0: the whole frame).");
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
  std::string FileStem() const {
    std::string stem = id;
    std::replace(stem.begin(), stem.end(), ':', '_');
    return stem;
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
constexpr char kDefaultConfig[] = "default";
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

struct CellResult {
  std::string status = "ok";  // or why the cell has no result
  double build_s = 0.0;       // problem construction / objective set-up
  double solve_s = 0.0;       // the solve or the baseline, without checkpoint scoring
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  double psnr = 0.0, ssim = 0.0;  // Case::Score(); without truth psnr only
  double sharpness_ratio = 0.0;   // without truth: Laplacian variance of latent / of input
  int latent_frames = 0;
  std::string note;  // how a baseline chose its threshold, or why a solve stopped
  std::vector<Checkpoint> checkpoints;
  // Measured by the parent.
  double wall_s = 0.0;  // the whole child: start, reading, simulation, checkpoints
  double cpu_s = 0.0;   // the child's user + system time: other load on the machine barely moves it
  double peak_memory_mb = 0.0;

  double time_s() const { return build_s + solve_s; }
  bool ok() const { return status == "ok"; }
};

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

// The result file: one "key value" line per field, then "checkpoint it time_s cost psnr ssim"
// lines. Numbers are read back with strtod, which also reads "inf" (the PSNR of a perfect copy).
std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

void WriteCellResult(const CellResult& cell, const std::string& path) {
  std::ofstream out(path);
  out.precision(17);
  out << "status " << OneLine(cell.status) << "\nbuild_s " << cell.build_s << "\nsolve_s "
      << cell.solve_s << "\niterations " << cell.iterations << "\ninitial_cost "
      << cell.initial_cost << "\nfinal_cost " << cell.final_cost << "\npsnr " << cell.psnr
      << "\nssim " << cell.ssim << "\nsharpness_ratio " << cell.sharpness_ratio
      << "\nlatent_frames " << cell.latent_frames << "\nnote " << OneLine(cell.note) << "\n";
  for (const Checkpoint& checkpoint : cell.checkpoints) {
    out << "checkpoint " << checkpoint.iteration << " " << checkpoint.time_s << " "
        << checkpoint.cost << " " << checkpoint.psnr << " " << checkpoint.ssim << "\n";
  }
}

bool ReadCellResult(const std::string& path, CellResult* cell) {
  std::ifstream in(path);
  if (!in) return false;
  for (std::string line; std::getline(in, line);) {
    const size_t space = line.find(' ');
    const std::string key = line.substr(0, space);
    const std::string value = space == std::string::npos ? "" : line.substr(space + 1);
    std::vector<double> numbers;
    std::istringstream fields(value);
    for (std::string field; fields >> field;)
      numbers.push_back(std::strtod(field.c_str(), nullptr));
    numbers.resize(5, 0.0);  // the most a line holds: a checkpoint's five numbers
    if (key == "status") cell->status = value;
    if (key == "note") cell->note = value;
    if (key == "build_s") cell->build_s = numbers[0];
    if (key == "solve_s") cell->solve_s = numbers[0];
    if (key == "iterations") cell->iterations = static_cast<int>(numbers[0]);
    if (key == "initial_cost") cell->initial_cost = numbers[0];
    if (key == "final_cost") cell->final_cost = numbers[0];
    if (key == "psnr") cell->psnr = numbers[0];
    if (key == "ssim") cell->ssim = numbers[0];
    if (key == "sharpness_ratio") cell->sharpness_ratio = numbers[0];
    if (key == "latent_frames") cell->latent_frames = static_cast<int>(numbers[0]);
    if (key == "checkpoint") {
      Checkpoint checkpoint;
      checkpoint.iteration = static_cast<int>(numbers[0]);
      checkpoint.time_s = numbers[1];
      checkpoint.cost = numbers[2];
      checkpoint.psnr = numbers[3];
      checkpoint.ssim = numbers[4];
      cell->checkpoints.push_back(checkpoint);
    }
  }
  return true;
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
  WriteCellResult(cell, FLAGS_cell_result);
  return cell.ok() ? 0 : 3;
}

// ---------------------------------------------------------------------------------------------
// The parent: the matrix, one child per cell.

struct Cell {
  Case c;
  std::string method, config;
  CellResult result;

  std::string Label() const {
    return config == kDefaultConfig ? method : method + " (" + config + ")";
  }
};

std::string DescribeStatus(int status) {
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) {
    return "timed out after " + std::to_string(FLAGS_cell_timeout_s) + " s";
  }
  if (WIFSIGNALED(status)) {
    return "killed by signal " + std::to_string(WTERMSIG(status)) +
           (FLAGS_cell_memory_mb > 0
                ? " (memory limit " + std::to_string(FLAGS_cell_memory_mb) + " MB?)"
                : "");
  }
  return "exited with status " + std::to_string(WEXITSTATUS(status)) + " and no result";
}

// Runs the cell in a child (this executable with --cell) and collects its result, wall time and
// peak resident memory.
CellResult RunCellProcess(const Cell& cell, const std::string& result_path) {
  fs::remove(result_path);
  std::vector<std::string> args = {"/proc/self/exe",
                                   "--cell=" + cell.c.id + "," + cell.method + "," + cell.config,
                                   "--cell_result=" + result_path, "--data=" + FLAGS_data,
                                   "--clip_crop_px=" + std::to_string(FLAGS_clip_crop_px)};
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  const auto start = Clock::now();
  const pid_t pid = fork();
  PCHECK(pid >= 0) << "fork";
  if (pid == 0) {
    // A pending alarm, the death signal and the limits survive execv: SIGALRM ends a cell that
    // runs too long, SIGKILL one whose parent was stopped.
    alarm(static_cast<unsigned>(FLAGS_cell_timeout_s));
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (FLAGS_cell_memory_mb > 0) {
      const rlim_t bytes = static_cast<rlim_t>(FLAGS_cell_memory_mb) << 20;
      const struct rlimit limit = {bytes, bytes};
      setrlimit(RLIMIT_AS, &limit);
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  struct rusage usage {};
  PCHECK(wait4(pid, &status, 0, &usage) == pid) << "wait4";
  CellResult result;
  if (!ReadCellResult(result_path, &result)) result.status = DescribeStatus(status);
  fs::remove(result_path);
  result.wall_s = SecondsSince(start);
  result.cpu_s = usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
                 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  result.peak_memory_mb = usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
  return result;
}

// What runs: the methods in AllMethods() order, ceres_lm in each of `ceres_configs`, and edi
// also with its threshold tuned on the truth when `edi_oracle`.
struct Plan {
  std::vector<Method> methods;
  std::vector<std::string> ceres_configs;
  std::vector<std::string> config_cases;  // the cases that run every ceres_configs variant
  bool edi_oracle = true;
};

// The cells of `c`; the unsupported methods with the reason go to `not_run`.
std::vector<Cell> PlanCells(const Case& c, const Plan& plan, std::vector<std::string>* not_run) {
  const Scene probe = ProbeScene(c.mode);
  std::vector<Cell> cells;
  for (Method method : plan.methods) {
    std::string why_not;
    if (!MethodSupports(method, probe, &why_not)) {
      not_run->push_back(std::string(MethodName(method)) + ": " + why_not);
      continue;
    }
    const auto add = [&](const std::string& config) {
      cells.push_back(Cell{c, MethodName(method), config, CellResult()});
    };
    if (method != Method::kCeresLm) add(kDefaultConfig);
    if (method == Method::kCeresLm) {
      const bool variants = std::find(plan.config_cases.begin(), plan.config_cases.end(),
                                      c.id) != plan.config_cases.end();
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

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

// ---------------------------------------------------------------------------------------------
// The headline: ceres_lm (default) against an Adam run of the same case.

struct Headline {
  std::string against;        // "adam" or "adam_smooth"
  double target_psnr = 0.0;   // the Adam run's final PSNR
  double against_time_s = 0;  // its build + solve
  double reach_s = -1.0;      // ceres_lm's build + solve time to first reach it; < 0: never
  double best_psnr = 0.0;     // ceres_lm's best checkpoint
  double ceres_psnr = 0.0;    // ceres_lm's final PSNR
  double ratio() const {
    return reach_s < 0 ? std::numeric_limits<double>::infinity() : reach_s / against_time_s;
  }
  double psnr_difference() const { return ceres_psnr - target_psnr; }
  bool ceres_loses() const { return ratio() > 1.0 || psnr_difference() < 0.0; }
};

const Cell* FindCell(const std::vector<Cell>& cells, const std::string& method,
                     const std::string& config) {
  for (const Cell& cell : cells) {
    if (cell.method == method && cell.config == config && cell.result.ok()) return &cell;
  }
  return nullptr;
}

std::vector<Headline> Headlines(const std::vector<Cell>& cells) {
  std::vector<Headline> headlines;
  const Cell* ceres = FindCell(cells, MethodName(Method::kCeresLm), kDefaultConfig);
  if (ceres == nullptr || !ceres->c.has_truth) return headlines;
  for (Method adam : {Method::kAdam, Method::kAdamSmooth}) {
    const Cell* against = FindCell(cells, MethodName(adam), kDefaultConfig);
    if (against == nullptr) continue;
    Headline headline;
    headline.against = against->method;
    headline.target_psnr = against->result.psnr;
    headline.against_time_s = against->result.time_s();
    headline.ceres_psnr = ceres->result.psnr;
    headline.best_psnr = ceres->result.psnr;
    for (const Checkpoint& checkpoint : ceres->result.checkpoints) {
      headline.best_psnr = std::max(headline.best_psnr, checkpoint.psnr);
      if (headline.reach_s < 0 && checkpoint.psnr >= headline.target_psnr) {
        headline.reach_s = ceres->result.build_s + checkpoint.time_s;
      }
    }
    headlines.push_back(headline);
  }
  return headlines;
}

std::string DescribeHeadline(const Headline& h) {
  std::string text = "ceres_lm vs " + h.against + ": " + h.against + " ends at " +
                     Format("%.2f dB", h.target_psnr) + " after " +
                     Format("%.2f s", h.against_time_s) + "; ceres_lm ";
  if (h.reach_s < 0) {
    text += "never reaches it (best " + Format("%.2f dB", h.best_psnr) + ")";
  } else {
    text += "reaches it at " + Format("%.2f s", h.reach_s) + ": ratio " + Format("%.3f", h.ratio());
  }
  text += "; final PSNR ceres_lm - " + h.against + " = " + Format("%+.2f dB", h.psnr_difference());
  if (h.ceres_loses()) {
    text += ".  CERES LOSES:";
    if (h.ratio() > 1.0) text += " slower to Adam's PSNR";
    if (h.ratio() > 1.0 && h.psnr_difference() < 0.0) text += " and";
    if (h.psnr_difference() < 0.0) text += " lower final PSNR";
  }
  return text;
}

// ---------------------------------------------------------------------------------------------
// The PSNR-against-time plot of one case, drawn with OpenCV.

struct Series {
  std::string label;
  std::vector<cv::Point2d> curve;  // (time s, PSNR dB) per checkpoint
  cv::Point2d marker;              // the finished method
};

// Distinct colours (BGR), cycled.
const cv::Scalar kPalette[] = {
    {180, 119, 31},  {14, 127, 255}, {44, 160, 44},   {40, 39, 214},
    {189, 103, 148}, {75, 86, 140},  {194, 119, 227}, {127, 127, 127},
    {34, 189, 188},  {207, 190, 23}, {0, 0, 0},       {120, 200, 250},
};

// Times below this are drawn at it: a log axis has no zero (a baseline can take microseconds).
constexpr double kMinPlotTimeS = 1e-3;

// Returns false, writing nothing, when no series has a finite point.
bool DrawPlot(const std::string& title, const std::string& y_label,
              const std::vector<Series>& series, const std::string& path) {
  constexpr int kWidth = 1100, kHeight = 650, kLeft = 80, kRight = 330, kTop = 60, kBottom = 60;
  const int plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  double t_min = std::numeric_limits<double>::infinity(), t_max = 0.0;
  double y_min = t_min, y_max = -t_min;
  const auto extend = [&](const cv::Point2d& p) {
    if (!std::isfinite(p.y)) return;
    const double t = std::max(p.x, kMinPlotTimeS);
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
    y_min = std::min(y_min, p.y);
    y_max = std::max(y_max, p.y);
  };
  for (const Series& s : series) {
    extend(s.marker);
    for (const cv::Point2d& p : s.curve) extend(p);
  }
  if (series.empty() || !std::isfinite(t_min)) return false;
  const double x_lo = std::floor(std::log10(t_min));
  const double x_hi = std::max(std::ceil(std::log10(t_max)), x_lo + 1.0);
  y_min = std::floor(y_min - 0.5);
  y_max = std::ceil(y_max + 0.5);
  double y_step = 1.0;
  for (double step : {1.0, 2.0, 5.0, 10.0}) {
    y_step = step;
    if ((y_max - y_min) / step <= 12) break;
  }
  const auto to_pixel = [&](const cv::Point2d& p) {
    const double x = (std::log10(std::max(p.x, kMinPlotTimeS)) - x_lo) / (x_hi - x_lo);
    const double y = (y_max - p.y) / (y_max - y_min);
    return cv::Point(kLeft + static_cast<int>(std::lround(x * plot_w)),
                     kTop + static_cast<int>(std::lround(y * plot_h)));
  };

  cv::Mat image(kHeight, kWidth, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar grid(225, 225, 225), ink(0, 0, 0);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  for (double decade = x_lo; decade <= x_hi; decade += 1.0) {
    const cv::Point bottom = to_pixel({std::pow(10.0, decade), y_min});
    cv::line(image, bottom, {bottom.x, kTop}, grid, 1);
    cv::putText(image, Format("%g s", std::pow(10.0, decade)), {bottom.x - 20, bottom.y + 22}, font,
                0.45, ink, 1, cv::LINE_AA);
    for (int minor = 2; minor < 10 && decade < x_hi; ++minor) {
      const cv::Point tick = to_pixel({minor * std::pow(10.0, decade), y_min});
      cv::line(image, tick, {tick.x, tick.y - 5}, ink, 1);
    }
  }
  for (double y = y_min; y <= y_max + 1e-9; y += y_step) {
    const cv::Point left = to_pixel({std::pow(10.0, x_lo), y});
    cv::line(image, left, {kLeft + plot_w, left.y}, grid, 1);
    cv::putText(image, Format("%g", y), {left.x - 40, left.y + 5}, font, 0.45, ink, 1, cv::LINE_AA);
  }
  cv::rectangle(image, {kLeft, kTop}, {kLeft + plot_w, kTop + plot_h}, ink, 1);
  cv::putText(image, title, {kLeft, 25}, font, 0.55, ink, 1, cv::LINE_AA);
  cv::putText(image, y_label, {kLeft, kTop - 10}, font, 0.45, ink, 1, cv::LINE_AA);
  cv::putText(image, "time (s, log): build + solve, without reading and scoring",
              {kLeft + plot_w / 2 - 200, kHeight - 15}, font, 0.45, ink, 1, cv::LINE_AA);

  for (size_t i = 0; i < series.size(); ++i) {
    const Series& s = series[i];
    const cv::Scalar colour = kPalette[i % (sizeof(kPalette) / sizeof(kPalette[0]))];
    for (size_t k = 1; k < s.curve.size(); ++k) {
      if (!std::isfinite(s.curve[k - 1].y) || !std::isfinite(s.curve[k].y)) continue;
      cv::line(image, to_pixel(s.curve[k - 1]), to_pixel(s.curve[k]), colour, 1, cv::LINE_AA);
    }
    if (std::isfinite(s.marker.y)) {
      cv::circle(image, to_pixel(s.marker), 5, colour, cv::FILLED, cv::LINE_AA);
      cv::circle(image, to_pixel(s.marker), 5, ink, 1, cv::LINE_AA);
    }
    const cv::Point legend(kLeft + plot_w + 20, kTop + 10 + 22 * static_cast<int>(i));
    cv::circle(image, legend, 5, colour, cv::FILLED, cv::LINE_AA);
    cv::putText(image, s.label, {legend.x + 12, legend.y + 5}, font, 0.42, ink, 1, cv::LINE_AA);
  }
  return cv::imwrite(path, image);
}

bool PlotCase(const Case& c, const std::vector<Cell>& cells, const std::string& path) {
  std::vector<Series> series;
  for (const Cell& cell : cells) {
    if (!cell.result.ok()) continue;
    Series s;
    s.label = cell.Label() + Format(": %.2f dB", cell.result.psnr);
    s.marker = {cell.result.time_s(), cell.result.psnr};
    if (c.has_truth) {
      for (const Checkpoint& checkpoint : cell.result.checkpoints) {
        s.curve.push_back({cell.result.build_s + checkpoint.time_s, checkpoint.psnr});
      }
    }
    series.push_back(s);
  }
  return DrawPlot(c.Title(), "PSNR (dB), " + c.Score(), series, path);
}

// ---------------------------------------------------------------------------------------------
// Tables.

std::string CsvQuoted(const std::string& text) {
  std::string quoted = "\"";
  for (char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return quoted + "\"";
}

std::string TableHeader(const Case& c) {
  return c.has_truth ? "| method | config | time | iterations | PSNR | SSIM | peak memory | "
                       "cell wall / CPU |\n|---|---|---|---|---|---|---|---|\n"
                     : "| method | config | time | iterations | mean vs input PSNR | "
                       "Laplacian variance ratio | peak memory | cell wall / CPU |\n"
                       "|---|---|---|---|---|---|---|---|\n";
}

std::string WallAndCpu(const CellResult& r) {
  return Format("%.1f s", r.wall_s) + " / " + Format("%.1f s", r.cpu_s);
}

std::string TableRow(const Cell& cell) {
  const CellResult& r = cell.result;
  if (!r.ok()) {
    return "| " + cell.method + " | " + cell.config + " | " + r.status + " | | | | " +
           Format("%.0f MB", r.peak_memory_mb) + " | " + WallAndCpu(r) + " |\n";
  }
  const std::string second =
      cell.c.has_truth ? Format("%.4f", r.ssim) : Format("x%.2f", r.sharpness_ratio);
  return "| " + cell.method + " | " + cell.config + " | " + Format("%.2f s", r.time_s()) + " | " +
         std::to_string(r.iterations) + " | " + Format("%.2f dB", r.psnr) + " | " + second + " | " +
         Format("%.0f MB", r.peak_memory_mb) + " | " + WallAndCpu(r) + " |\n";
}

struct CaseReport {
  Case c;
  std::vector<Cell> cells;
  std::vector<std::string> not_run;
  std::vector<Headline> headlines;
  std::string plot;  // file name of the PSNR-against-time plot in --out; empty: none
};

void WriteCsv(const std::vector<CaseReport>& reports, const fs::path& out) {
  std::ofstream csv(out / "methods.csv");
  csv << "case,data,mode,score,method,config,status,time_s,build_s,solve_s,iterations,"
         "initial_cost,final_cost,psnr_db,ssim,sharpness_ratio,latent_frames,peak_memory_mb,"
         "cell_wall_s,cell_cpu_s,note\n";
  std::ofstream checkpoints(out / "methods_checkpoints.csv");
  checkpoints << "case,method,config,iteration,time_s,cost,psnr_db,ssim\n";
  for (const CaseReport& report : reports) {
    for (const Cell& cell : report.cells) {
      const CellResult& r = cell.result;
      csv << cell.c.id << "," << cell.c.data << "," << ModeName(cell.c.mode) << ","
          << CsvQuoted(cell.c.Score()) << "," << cell.method << "," << cell.config << ","
          << CsvQuoted(r.status) << "," << r.time_s() << "," << r.build_s << "," << r.solve_s << ","
          << r.iterations << "," << r.initial_cost << "," << r.final_cost << "," << r.psnr << ","
          << r.ssim << "," << r.sharpness_ratio << "," << r.latent_frames << "," << r.peak_memory_mb
          << "," << r.wall_s << "," << r.cpu_s << "," << CsvQuoted(r.note) << "\n";
      for (const Checkpoint& checkpoint : r.checkpoints) {
        // Time as in methods.csv: build + solve so far.
        checkpoints << cell.c.id << "," << cell.method << "," << cell.config << ","
                    << checkpoint.iteration << "," << r.build_s + checkpoint.time_s << ","
                    << checkpoint.cost << "," << checkpoint.psnr << "," << checkpoint.ssim << "\n";
      }
    }
  }
}

std::string Markdown(const std::vector<CaseReport>& reports, const std::string& machine,
                     const std::string& cases, double total_s) {
  std::string md = "# Reconstruction methods on the shared data\n\n";
  md += "Machine: " + machine + ". Total " + Format("%.0f s", total_s) + " for the run below.\n\n";
  md += "Command: `method_benchmark --data=" + FLAGS_data + " --out=" + FLAGS_out +
        (FLAGS_quick ? " --quick" : "") +
        (FLAGS_methods.empty() ? "" : " --methods=" + FLAGS_methods) +
        " --clip_crop_px=" + std::to_string(FLAGS_clip_crop_px) +
        (FLAGS_quick ? "" : " --configs=" + FLAGS_configs + " --config_cases=" + FLAGS_config_cases) +
        "`; cases: " + cases;
  if (cases.find("clip_") != std::string::npos) {
    md += "; clips: " + FLAGS_clips + " (" +
          ClipCropNote() + ")";
  }
  md += ".\n\n";
  md +=
      "time: the method's build + solve (problem construction or objective set-up, and the "
      "iterations; without reading the data, simulating events and scoring checkpoints). cell "
      "wall / CPU: the whole child process, its wall time and its user + system CPU time (the "
      "solvers use 2 threads; other load on the machine stretches the wall time, barely the "
      "CPU time). peak memory: the child's maximum resident set size. Each cell may run " +
      std::to_string(FLAGS_cell_timeout_s) + " s and address " +
      (FLAGS_cell_memory_mb > 0 ? std::to_string(FLAGS_cell_memory_mb) + " MB"
                                : std::string("unlimited memory")) +
      ". "
      "ceres_lm configurations: ";
  for (const SolverConfig& config : kCeresConfigs) {
    md += std::string(config.name) + " = " + config.description + "; ";
  }
  md += std::string(kTunedConfig) + ": edi with its contrast threshold tuned on truth frame " +
        std::to_string(kClipTunedFrame) + " (an oracle, not a method).\n";
  for (const CaseReport& report : reports) {
    md += "\n## " + report.c.Title() + "\n\n";
    md += "Case `" + report.c.id + "`; PSNR/SSIM: " + report.c.Score() + ".\n\n";
    md += TableHeader(report.c);
    for (const Cell& cell : report.cells) md += TableRow(cell);
    if (!report.not_run.empty()) {
      md += "\nNot supported: ";
      for (const std::string& line : report.not_run) md += line + "; ";
      md += "\n";
    }
    if (!report.plot.empty()) md += "\n![PSNR against time](" + report.plot + ")\n";
  }
  md +=
      "\n## Headline: ceres_lm (default) against Adam\n\n"
      "ratio: the time ceres_lm needs to first reach the Adam run's final PSNR (its build + "
      "solve time at that checkpoint) over the Adam run's build + solve time; below 1 Ceres is "
      "faster.\n\n"
      "| case | against | Adam final PSNR | Adam time | ceres_lm reaches it at | ratio | "
      "ceres_lm final PSNR | difference | verdict |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const CaseReport& report : reports) {
    for (const Headline& h : report.headlines) {
      md += "| " + report.c.id + " | " + h.against + " | " + Format("%.2f dB", h.target_psnr) +
            " | " + Format("%.2f s", h.against_time_s) + " | " +
            (h.reach_s < 0 ? "never (best " + Format("%.2f dB)", h.best_psnr)
                           : Format("%.2f s", h.reach_s)) +
            " | " + (h.reach_s < 0 ? std::string("∞") : Format("%.3f", h.ratio())) + " | " +
            Format("%.2f dB", h.ceres_psnr) + " | " + Format("%+.2f dB", h.psnr_difference()) +
            " | " + (h.ceres_loses() ? "**Ceres loses**" : "Ceres wins") + " |\n";
    }
  }
  return md;
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
    report.c = c;
    report.cells = PlanCells(c, plan, &report.not_run);
    std::printf("\n## %s\n\n%s", c.Title().c_str(), TableHeader(c).c_str());
    for (Cell& cell : report.cells) {
      cell.result = RunCellProcess(cell, result_path);
      std::printf("%s", TableRow(cell).c_str());
      std::fflush(stdout);
    }
    report.headlines = Headlines(report.cells);
    const std::string plot = "psnr_time_" + c.FileStem() + ".png";
    if (PlotCase(c, report.cells, (out / plot).string())) report.plot = plot;
    reports.push_back(std::move(report));
  }
  const double total_s = SecondsSince(start);

  WriteCsv(reports, out);
  std::ofstream(out / "methods.md") << Markdown(reports, machine, cases, total_s);
  std::printf("\n## Headline: ceres_lm (default) against Adam\n");
  for (const CaseReport& report : reports) {
    for (const Headline& h : report.headlines) {
      std::printf("%s: %s\n", report.c.id.c_str(), DescribeHeadline(h).c_str());
    }
  }
  std::printf(
      "\ntotal %.0f s; wrote %s/{methods.csv,methods_checkpoints.csv,methods.md,"
      "psnr_time_*.png}\n",
      total_s, out.string().c_str());
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
