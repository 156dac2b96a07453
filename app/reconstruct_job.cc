#include "evfs/app/reconstruct_job.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "evfs/app/frame_lag.h"
#include "evfs/app/summary_json.h"
#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/core/time.h"
#include "evfs/io/data_source.h"
#include "evfs/io/image_io.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Most frames --fps may resample the latent video to (a runaway rate would fill memory).
constexpr double kMaxOutputFrames = 10000;

void CheckFrameIndex(const DataSource& source, int index, const char* what) {
  const int count = static_cast<int>(source.frames().size());
  if (count == 0) {
    throw InvalidArgumentError(source.path() + " has 0 frames (" + source.no_frames_reason() +
                               "): a reconstruction needs the frames it starts from");
  }
  if (index < 0 || index >= count) {
    throw InvalidArgumentError(std::string(what) + " frame " + std::to_string(index) +
                               " is out of range: " + source.path() + " has " +
                               std::to_string(count) + " frames (0.." + std::to_string(count - 1) +
                               ")");
  }
}

// What moment a sharp frame represents (ReconstructRequest::frame_time), resolved.
struct SharpFrameTiming {
  FrameTime time = FrameTime::kInstant;
  int64_t lag_ns = 0;       // kAuto (estimated) and kLag
  int64_t exposure_ns = 0;  // kStart, kMiddle, kEnd when the data has no exposures
};

FrameSpan SharpFrameSpan(const DataSource& source, int index, const SharpFrameTiming& timing) {
  const FrameInfo& info = source.frames()[index];
  return ModelledFrameSpan(info.t_ns, info.has_exposure, info.exposure_begin_ns,
                           info.exposure_end_ns, timing.time, timing.lag_ns, timing.exposure_ns);
}

TimedFrame ReadSharpFrame(const DataSource& source, int index, const SharpFrameTiming& timing) {
  TimedFrame frame;
  frame.image = source.ReadImage(index);
  const FrameSpan span = SharpFrameSpan(source, index, timing);
  frame.exposure_begin_ns = span.begin_ns;
  frame.exposure_end_ns = span.end_ns;
  frame.label = source.frames()[index].path;
  return frame;
}

TimedFrame ReadBlurredFrame(const DataSource& source, int index, double exposure_s) {
  const FrameInfo& info = source.frames()[index];
  TimedFrame frame;
  frame.label = info.path;
  if (info.has_exposure) {
    frame.exposure_begin_ns = info.exposure_begin_ns;
    frame.exposure_end_ns = info.exposure_end_ns;
  } else if (exposure_s > 0.0) {
    const int64_t half_ns = SecondsToNanoseconds(exposure_s / 2.0);
    frame.exposure_begin_ns = info.t_ns - half_ns;
    frame.exposure_end_ns = info.t_ns + half_ns;
  } else {
    throw InvalidArgumentError("deblur needs the exposure of " + info.path +
                               ": the data has no exposures.txt entry for it; pass --exposure_s");
  }
  frame.image = source.ReadImage(index);
  return frame;
}

Video Resample(const Video& latent, double fps) {
  const int64_t begin_ns = latent.timestamp_ns(0);
  const int64_t end_ns = latent.timestamp_ns(latent.num_frames() - 1);
  const double step_ns = static_cast<double>(kNanosecondsPerSecond) / fps;  // inf for tiny fps
  // The frame count is bounded in double before any i · step_ns is rounded to int64: a tiny
  // --fps made that product wrap and the loop run forever, allocating.
  const double last_index = std::floor((static_cast<double>(end_ns - begin_ns) + 0.5) / step_ns);
  Video output;
  for (int64_t i = 0; i <= last_index; ++i) {
    const int64_t t_ns = begin_ns + (i == 0 ? 0 : static_cast<int64_t>(std::llround(i * step_ns)));
    if (t_ns > end_ns) break;
    output.AppendFrame(latent.InterpolateAt(t_ns), t_ns);
  }
  return output;
}

}  // namespace

Mode ParseMode(const std::string& name) {
  Mode mode = Mode::kPredict;
  if (!FindName(kModeNames, name, &mode)) {
    throw InvalidArgumentError("unknown mode '" + name + "': expected " +
                               NameList(kModeNames, ", ", " or "));
  }
  return mode;
}

const char* ModeName(Mode mode) { return NameOf(kModeNames, mode); }

namespace {

// The request's options, checked before anything is read.
void CheckRequest(const ReconstructRequest& request) {
  std::string error;
  if (!request.method.reconstruction.IsValid(&error)) {
    throw InvalidArgumentError("invalid options: " + error);
  }
  if (!request.binning.IsValid(&error)) throw InvalidArgumentError("invalid binning: " + error);
  if (request.fps < 0.0 || !std::isfinite(request.fps)) {
    throw InvalidArgumentError("--fps must be positive (or 0 for the latent timeline)");
  }
  if (!(request.exposure_s >= 0.0 && request.exposure_s <= kMaxDurationS)) {
    throw InvalidArgumentError("--exposure_s must be between 0 and " +
                               std::to_string(static_cast<int>(kMaxDurationS)) + " seconds");
  }
  CheckDenoiseMode(request.denoise.mode, request.method.method);
  if (request.denoise.mode == DenoiseMode::kPnp && !request.denoise.pnp.IsValid(&error)) {
    throw InvalidArgumentError("invalid plug & play options: " + error);
  }
}

// The frames a request names, checked against the recording; returns the last frame (--last,
// or the one after --first).
int CheckWindowFrames(const DataSource& source, const ReconstructRequest& request) {
  CheckWholeTextRecording(source);
  // From the declared size, before a frame is decoded: a large declared sensor with small
  // compressed frames would otherwise cost its full size in memory first.
  CheckSensorFitsLatentVoxels(source.width(), source.height(), request.binning);
  CheckFrameIndex(source, request.first, "the first");
  const int last = request.last >= 0 ? request.last : request.first + 1;
  if (request.mode != Mode::kDeblur) {
    CheckFrameIndex(source, last, "the last");
    if (last <= request.first) {
      throw InvalidArgumentError("--last (" + std::to_string(last) + ") must come after --first (" +
                                 std::to_string(request.first) + ")");
    }
  }
  if (request.truth >= 0) CheckFrameIndex(source, request.truth, "the truth");
  return last;
}

// The moment each sharp frame represents. Auto estimates the lag from the input frames only
// (interpolate: the two; predict: the first and the one before it), never from the truth.
SharpFrameTiming ResolveFrameTiming(const DataSource& source, const ReconstructRequest& request,
                                    int last, FrameLagEstimate* lag) {
  SharpFrameTiming timing{request.frame_time, SecondsToNanoseconds(request.frame_lag_s),
                          SecondsToNanoseconds(request.exposure_s)};
  if (request.mode != Mode::kDeblur && request.frame_time == FrameTime::kAuto) {
    std::vector<int> inputs = {request.first, last};
    if (request.mode == Mode::kPredict) inputs = {request.first - 1, request.first};
    if (inputs.front() < 0 || inputs.front() == request.truth) inputs = {};
    *lag = EstimateRecordingFrameLag(source, inputs, request.frame_lag);
    timing.lag_ns = lag->lag_ns;
  }
  return timing;
}

// What the window's scene is made of, read from the recording.
struct WindowInputs {
  std::vector<TimedFrame> frames;
  int64_t begin_ns = 0;
  int64_t end_ns = 0;
  EventStream events;
};

// The observed frames of the request's mode, the window they span and its events. Checks that
// --fps can resample the window.
WindowInputs ReadWindowInputs(const DataSource& source, const ReconstructRequest& request, int last,
                              const SharpFrameTiming& timing) {
  WindowInputs inputs;
  switch (request.mode) {
    case Mode::kInterpolate:
      inputs.frames = {ReadSharpFrame(source, request.first, timing),
                       ReadSharpFrame(source, last, timing)};
      inputs.begin_ns = inputs.frames.front().exposure_begin_ns;
      inputs.end_ns = inputs.frames.back().exposure_end_ns;
      break;
    case Mode::kPredict:
      inputs.frames = {ReadSharpFrame(source, request.first, timing)};
      inputs.begin_ns = inputs.frames.front().exposure_begin_ns;
      inputs.end_ns = SharpFrameSpan(source, last, timing).middle_ns();
      break;
    case Mode::kDeblur:
      inputs.frames = {ReadBlurredFrame(source, request.first, request.exposure_s)};
      inputs.begin_ns = inputs.frames.front().exposure_begin_ns;
      inputs.end_ns = inputs.frames.front().exposure_end_ns;
      break;
  }
  const double window_s = NanosecondsToSeconds(inputs.end_ns - inputs.begin_ns);
  if (request.fps * window_s > kMaxOutputFrames) {
    throw InvalidArgumentError("--fps would resample the " + std::to_string(window_s) +
                               " s window to more than " +
                               std::to_string(static_cast<int>(kMaxOutputFrames)) + " frames");
  }
  if (request.fps > 0.0) {
    CheckResampledOutputFits(request.fps, window_s, source.width(), source.height(), "window");
  }
  inputs.events = source.ReadEvents(inputs.begin_ns, inputs.end_ns);
  return inputs;
}

// The scene's counts of events and of the pixels whose events were left out.
void CountSceneEvents(const Scene& scene, ReconstructResult* result) {
  result->events = scene.num_events;
  result->event_frames = scene.events.num_frames();
  result->hot_pixels = static_cast<int>(scene.hot_pixels.size());
  result->hot_pixel_events = scene.hot_pixel_events;
  result->noise_events = scene.noise_events;
  result->saturated_pixels = static_cast<int>(scene.saturated_pixels.size());
  result->saturated_pixel_events = scene.saturated_pixel_events;
  result->flickering_pixels = static_cast<int>(scene.flickering_pixels.size());
  result->flickering_pixel_events = scene.flickering_pixel_events;
}

// The moment the truth frame represents, as for the inputs (deblur: its timestamp); throws
// when it lies outside the window.
int64_t TruthTimestamp(const DataSource& source, const ReconstructRequest& request,
                       const SharpFrameTiming& timing, const WindowInputs& inputs) {
  const int64_t t_ns = request.mode == Mode::kDeblur
                           ? source.frames()[request.truth].t_ns
                           : SharpFrameSpan(source, request.truth, timing).middle_ns();
  if (t_ns < inputs.begin_ns || t_ns > inputs.end_ns) {
    throw InvalidArgumentError("--truth frame " + std::to_string(request.truth) +
                               " lies outside the reconstructed window");
  }
  return t_ns;
}

// The latent frame nearest the truth against it, beside the baseline's, and the share of its
// pixels within the predicted error.
void ScoreTruth(const Video& latent, const Video& baseline, const Video& sigma,
                const Image& truth_image, TruthScore* truth, double* within_sigma) {
  truth->image = truth_image;
  truth->latent_index = latent.NearestFrame(truth->timestamp_ns);
  const Image estimate = latent.frame(truth->latent_index);
  truth->psnr = Psnr(estimate, truth_image);
  truth->ssim = Ssim(estimate, truth_image);
  const Image blend = baseline.frame(truth->latent_index);
  truth->baseline_psnr = Psnr(blend, truth_image);
  truth->baseline_ssim = Ssim(blend, truth_image);
  *within_sigma = ShareWithinSigma(estimate, truth_image, sigma.frame(truth->latent_index));
}

// The request's method with b chosen by ReconstructRequest::log_offset_search: each candidate
// interpolates frames outside the window (never the window's own withheld frames or the truth)
// from their neighbours; see app/log_offset_search.h.
MethodOptions SearchedMethod(const DataSource& source, const ReconstructRequest& request, int last,
                             const SharpFrameTiming& timing, ReconstructResult* result) {
  MethodOptions method = request.method;
  if (request.log_offset_search.empty() || request.mode != Mode::kInterpolate ||
      !SearchesLogOffset(method)) {
    return method;
  }
  const auto start = Clock::now();
  std::vector<int> excluded;
  for (int i = request.first + 1; i < last; ++i) excluded.push_back(i);
  if (request.truth >= 0) excluded.push_back(request.truth);
  const int64_t middle_ns = (SharpFrameSpan(source, request.first, timing).middle_ns() +
                             SharpFrameSpan(source, last, timing).middle_ns()) /
                            2;
  const std::vector<ValidationTriplet> triplets = ValidationTriplets(
      static_cast<int>(source.frames().size()), excluded,
      [&](int i) { return SharpFrameSpan(source, i, timing).middle_ns(); }, middle_ns,
      kLogOffsetSearchTriplets);
  // Each triplet's scene once, solved with every candidate.
  std::vector<ValidationScene> scenes;
  for (const ValidationTriplet& triplet : triplets) {
    const TimedFrame first = ReadSharpFrame(source, triplet.first, timing);
    const TimedFrame after = ReadSharpFrame(source, triplet.last, timing);
    const int64_t begin = first.exposure_begin_ns, end = after.exposure_end_ns;
    scenes.push_back(MakeValidationScene(first, after, source.ReadImage(triplet.middle),
                                         SharpFrameSpan(source, triplet.middle, timing).middle_ns(),
                                         source.ReadEvents(begin, end), begin, end, request.binning,
                                         kValidationSquarePx));
  }
  LogOffsetChoice choice = ChooseLogOffsetOn(request.log_offset_search, triplets, scenes, method,
                                             method.reconstruction.solver.num_threads,
                                             "no three frames to choose it from");
  choice.seconds = SecondsSince(start);
  method.reconstruction.objective.event_model.log_offset = choice.chosen;
  result->log_offset_choice = std::move(choice);
  return method;
}

// The job, reading `given` or, when it is null, the recording at request.data_path: read →
// frame timing → scene → solve → denoise → seams → output and confidence → score.
ReconstructResult RunReconstructionFrom(const ReconstructRequest& request,
                                        const DataSource* given) {
  const auto total_start = Clock::now();
  CheckRequest(request);
  // Loaded before any input is read: a bad weights file fails in milliseconds, not after a solve.
  const std::unique_ptr<Denoiser> denoiser = LoadDenoiser(request.denoise);

  ReconstructResult result;
  result.mode = request.mode;
  const auto stage = [&request](const char* name) {
    if (request.stage) request.stage(name);
  };
  stage("read");
  const auto read_start = Clock::now();
  std::unique_ptr<DataSource> opened;
  if (given == nullptr) opened = DataSource::Open(request.data_path, request.data_options);
  const DataSource& source = given != nullptr ? *given : *opened;
  result.width = source.width();
  result.height = source.height();
  const int last = CheckWindowFrames(source, request);
  const SharpFrameTiming timing = ResolveFrameTiming(source, request, last, &result.frame_lag);
  if (request.mode != Mode::kDeblur) {
    result.frame_shift_ns = SharpFrameSpan(source, request.first, timing).middle_ns() -
                            source.frames()[request.first].t_ns;
  }
  const WindowInputs inputs = ReadWindowInputs(source, request, last, timing);
  const bool score = request.truth >= 0;
  Image truth_image;
  if (score) truth_image = source.ReadImage(request.truth);
  result.time.read_s = SecondsSince(read_start);

  stage("bin");
  const auto bin_start = Clock::now();
  const Scene scene =
      MakeScene(inputs.frames, inputs.events, inputs.begin_ns, inputs.end_ns, request.binning);
  CountSceneEvents(scene, &result);
  result.time.bin_s = SecondsSince(bin_start);

  CheckpointTruth checkpoint_truth;
  if (score) {
    result.truth.timestamp_ns = TruthTimestamp(source, request, timing, inputs);
    checkpoint_truth.image = &truth_image;
    checkpoint_truth.latent_index =
        NearestTimestamp(scene.latent_timestamps_ns(), result.truth.timestamp_ns);
  }
  CheckMethodSupports(request.method.method, scene, "this case");
  stage(request.progress ? "build" : "build and solve");
  const MethodOptions chosen = SearchedMethod(source, request, last, timing, &result);
  MethodOptions method = chosen;
  StartSolveClock(&method);
  result.run = RunMethod(scene, method, request.progress, request.checkpoints,
                         score ? &checkpoint_truth : nullptr);
  result.time.build_s = result.run.build_time_s;
  result.time.solve_s = result.run.solve_time_s;
  if (denoiser != nullptr) {
    stage("denoise");
    result.denoise = DenoiseSolution(*denoiser, request.denoise, scene, chosen, method,
                                     score ? &truth_image : nullptr, result.truth.timestamp_ns,
                                     nullptr, &result.run);
  }
  ApplySharpFrameSeams(scene, chosen, &result.run);

  // Made after the solve, so that the solve does not hold a third latent video.
  result.baseline = InitializeLatentVideo(scene);
  const Video& latent = result.run.video;
  result.output = request.fps > 0.0 ? Resample(latent, request.fps) : latent;
  const Video sigma =
      PredictErrorSigma(scene, latent, ConfidenceFor(chosen, result.run), &result.confidence_model);
  result.confidence = request.fps > 0.0 ? Resample(sigma, request.fps) : sigma;
  if (score) {
    result.truth.index = request.truth;
    ScoreTruth(latent, result.baseline, sigma, truth_image, &result.truth,
               &result.truth_within_sigma);
    result.has_truth = true;
  }
  result.time.total_s = SecondsSince(total_start);
  return result;
}

}  // namespace

ReconstructResult RunReconstruction(const ReconstructRequest& request) {
  return RunReconstructionFrom(request, nullptr);
}

ReconstructResult RunReconstruction(const ReconstructRequest& request, const DataSource& source) {
  return RunReconstructionFrom(request, &source);
}

namespace {

using Json = nlohmann::ordered_json;

void AddCeresLm(const ReconstructionOptions& options, const ReconstructionSummary& summary,
                Json* solver) {
  Json& json = *solver;
  json["linear_solver"] = ceres::LinearSolverTypeToString(options.solver.linear_solver_type);
  json["preconditioner"] = ceres::PreconditionerTypeToString(options.solver.preconditioner_type);
  json["eta"] = Number(options.solver.eta);
  json["max_iterations"] = options.solver.max_num_iterations;
  json["function_tolerance"] = Number(options.solver.function_tolerance);
  json["threads"] = options.solver.num_threads;
  if (!summary.solved) return;
  json["termination"] = ceres::TerminationTypeToString(summary.ceres.termination_type);
  // Where Ceres' time went (its own accounting), and its passes over the residual blocks.
  json.update(CeresWorkJson(summary.ceres));
  json["successful_steps"] = summary.ceres.num_successful_steps;
  json["unsuccessful_steps"] = summary.ceres.num_unsuccessful_steps;
  json["linear_solver_iterations"] = summary.linear_solver_iterations;
}

Json ModelJson(const ObjectiveOptions& objective, const ReconstructionSummary& summary) {
  Json json;
  json["event_model"] = EventModelName(objective.event_model.model);
  json["alpha"] = Number(summary.model.alpha);
  json["alpha_derived"] = summary.alpha_derived;
  json["event_saturation"] = Number(summary.model.saturation);
  json["off_alpha_ratio"] = Number(summary.model.off_alpha_ratio);
  if (summary.alpha_derived) {
    json["change_per_event"] = Number(summary.model.change_per_event);
    json["change_measured_from_frames"] = summary.model.estimated_from_frames;
  }
  json["frame_weight"] = Number(objective.frame_weight);
  json["event_weight"] = Number(objective.event_weight);
  json["spatial_tv_weight"] = Number(objective.spatial_tv_weight);
  json["temporal_tv_weight"] = Number(objective.temporal_tv_weight);
  json["log_temporal_tv_reversals"] = objective.log_temporal_tv_reversals;
  json["spatial_tv"] = SpatialTvName(objective.spatial_tv);
  json["shared_structure_tv"] = objective.shared_structure_tv;
  json["smoothing_scale"] = Number(objective.smoothing_scale);
  return json;
}

void AddProblem(const ReconstructionOptions& options, const ProblemStatistics& problem,
                Json* summary) {
  Json& json = *summary;
  json["pixels"] = {
      {"active", problem.active_pixels},
      {"skipped", problem.skipped_pixels},
      {"activity_radius_px", options.activity_radius_px},
      {"merge_quiet_steps", options.merge_quiet_steps},
      {"unfired_pixel_changes", options.unfired_pixel_changes},
      {"quiet_blend_fraction", Number(options.quiet_blend_fraction)},
      {"step_ramp_px", Number(options.step_ramp_px)},
      {"meet_sharp_frames", options.meet_sharp_frames},
  };
  Json continuation = Json::array();
  for (const double scale : options.smoothing_continuation) continuation.push_back(Number(scale));
  json["problem"] = {
      {"independent_parts", problem.parts},
      {"split_independent_parts", options.split_independent_parts},
      {"batches", problem.batches},
      {"estimated_mb", Number(static_cast<double>(problem.estimated_bytes) / (1 << 20))},
      {"max_problem_mb", options.max_problem_mb},
      {"smoothing_continuation", continuation},
      {"parameter_blocks", problem.parameter_blocks},
      {"unknowns", problem.variable_parameter_blocks},
      {"residual_blocks", problem.residual_blocks()},
      {"frame_residuals", problem.frame_residuals},
      {"event_residuals", problem.event_residuals},
      {"spatial_tv_residuals", problem.spatial_tv_residuals},
      {"temporal_tv_residuals", problem.temporal_tv_residuals},
      {"log_temporal_tv_pixels", problem.log_temporal_tv_pixels},
  };
  if (options.objective.shared_structure_tv) {
    json["problem"]["shared_structure_tv"] = {
        {"frames_correlation", Number(problem.shared_structure_correlation)},
        {"applied", problem.shared_structure_applied},
    };
  }
}

}  // namespace

std::string SummaryJson(const ReconstructRequest& request, const ReconstructResult& result) {
  const MethodResult& run = result.run;
  const ReconstructionSummary& summary = run.reconstruction;
  const ReconstructionOptions& options = request.method.reconstruction;
  const bool iterative = IsIterative(request.method.method);
  Json json;
  json["mode"] = ModeName(result.mode);
  json["data"] = request.data_label.empty() ? request.data_path : request.data_label;
  json["width"] = result.width;
  json["height"] = result.height;
  json["events"] = result.events;
  json["hot_pixels"] = result.hot_pixels;
  json["hot_pixel_events"] = result.hot_pixel_events;
  json["noise_events"] = result.noise_events;
  // Pixels where the frames govern: their events were left out, rule by rule.
  json["frames_govern"] = {
      {"hot", {{"pixels", result.hot_pixels}, {"events", result.hot_pixel_events}}},
      {"saturated",
       {{"pixels", result.saturated_pixels}, {"events", result.saturated_pixel_events}}},
      {"flickering",
       {{"pixels", result.flickering_pixels}, {"events", result.flickering_pixel_events}}}};
  json["event_frames"] = result.event_frames;
  json["latent_frames"] = run.video.num_frames();
  json["output_frames"] = result.output.num_frames();
  if (result.mode != Mode::kDeblur) {
    // The moment the sharp frames were taken to represent (--frame_time).
    Json timing = {
        {"frame_time", FrameTimeName(request.frame_time, request.frame_lag_s)},
        {"shift_ms", Number(1e3 * NanosecondsToSeconds(result.frame_shift_ns))},
    };
    if (request.frame_time == FrameTime::kAuto) {
      const FrameLagEstimate& lag = result.frame_lag;
      timing["lag_estimated"] = lag.estimated;
      timing["lag_ms"] = Number(1e3 * NanosecondsToSeconds(lag.lag_ns));
      timing["peak_lag_ms"] = Number(1e3 * NanosecondsToSeconds(lag.peak_lag_ns));
      timing["correlation"] = Number(lag.peak_correlation);
      timing["correlation_at_zero"] = Number(lag.correlation_at_zero);
      timing["frame_pairs"] = lag.pairs;
    }
    json["frame_timing"] = std::move(timing);
  }
  Json solver;
  solver["name"] = run.method;
  solver["message"] = run.message;
  if (!run.reconstruction.stopped_early.empty()) {
    solver["stopped_early"] = run.reconstruction.stopped_early;
  }
  if (iterative) {
    solver["initialization"] = run.initialization;
    solver["bounds"] = options.bound_intensities;
  }
  if (request.method.method == Method::kCeresLm) AddCeresLm(options, summary, &solver);
  if (!run.parameters.empty()) {
    Json& parameters = solver["parameters"];
    for (const BaselineParameter& parameter : run.parameters) {
      parameters[parameter.name] = Number(parameter.value);
    }
  }
  if (!run.threshold_source.empty()) solver["threshold_source"] = run.threshold_source;
  json["solver"] = std::move(solver);
  if (iterative) {
    json["model"] = ModelJson(options.objective, summary);
    if (result.log_offset_choice) {
      json["model"]["log_offset"] = Number(result.log_offset_choice->chosen);
      json["model"]["log_offset_search"] = LogOffsetChoiceJson(*result.log_offset_choice);
    }
    json["solved"] = run.solved;
    json["iterations"] = run.iterations;
    json["initial_cost"] = Number(run.initial_cost);
    json["final_cost"] = Number(run.final_cost);
    AddProblem(options, summary.problem, &json);
    json["pixels"]["ramped_steps"] = summary.ramped_steps;
    json["pixels"]["sharp_frames_met"] = run.seams.frames_met;
    json["pixels"]["sharp_frame_offset_rms"] = Number(run.seams.offset_rms);
  }
  json["time_s"] = {
      {"read", Number(result.time.read_s)},   {"bin", Number(result.time.bin_s)},
      {"build", Number(result.time.build_s)}, {"solve", Number(result.time.solve_s)},
      {"write", Number(result.time.write_s)}, {"total", Number(result.time.total_s)},
  };
  json["denoiser"] = DenoiseJson(result.denoise);
  json["confidence"] = {
      {"folder", "confidence"},
      {"meaning",
       "predicted one-sigma error of each output pixel's intensity (scene/confidence.h)"},
      {"scale", "sigma = png value / 65535, intensities in [0, 1]"},
      {"model", result.confidence_model.description}};
  if (result.has_truth) {
    const TruthScore& truth = result.truth;
    json["truth"] = {
        {"index", truth.index},
        {"timestamp_s", NanosecondsToSeconds(truth.timestamp_ns)},
        {"latent_index", truth.latent_index},
        {"psnr", Number(truth.psnr)},
        {"ssim", Number(truth.ssim)},
        {"baseline", result.mode == Mode::kInterpolate ? "blend" : "copy"},
        {"baseline_psnr", Number(truth.baseline_psnr)},
        {"baseline_ssim", Number(truth.baseline_ssim)},
        {"within_predicted_sigma", Number(result.truth_within_sigma)},
    };
  }
  if (!run.checkpoints.empty()) {
    Json& checkpoints = json["checkpoints"];
    for (const Checkpoint& checkpoint : run.checkpoints) {
      Json entry = {
          {"iteration", checkpoint.iteration},
          {"time_s", Number(checkpoint.time_s)},
          {"cost", Number(checkpoint.cost)},
      };
      if (result.has_truth) {
        entry["psnr"] = Number(checkpoint.psnr);
        entry["ssim"] = Number(checkpoint.ssim);
      }
      checkpoints.push_back(std::move(entry));
    }
  }
  if (!request.options.empty()) {
    // The options the run was made from, as the option table names and prints them.
    Json& options = json["options"];
    for (const auto& [name, value] : request.options) options[name] = value;
  }
  return json.dump(2);
}

void WriteReconstruction(const ReconstructRequest& request, ReconstructResult* result,
                         const std::string& folder) {
  const auto write_start = Clock::now();
  const fs::path out(folder);
  const int threads = request.method.reconstruction.solver.num_threads;
  WriteFrameSequence(folder, result->output, threads);
  WriteImageSequence((out / "confidence").string(), result->confidence, threads);
  result->time.write_s = SecondsSince(write_start);
  result->time.total_s += result->time.write_s;
  std::ofstream summary(out / "summary.json");
  summary << SummaryJson(request, *result) << "\n";
  summary.close();
  if (!summary) {
    throw InputError(InputError::Kind::kUnwritable, (out / "summary.json").string(), 0,
                     "cannot write the summary");
  }
}

}  // namespace evfs
