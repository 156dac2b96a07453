#include "evfs/app/method.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>

#include "evfs/baselines/baseline.h"
#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/core/time.h"
#include "evfs/io/text_folder.h"
#include "evfs/scene/activity_mask.h"
#include "evfs/scene/scene.h"

namespace evfs {
namespace {

using Clock = std::chrono::steady_clock;

// The baseline a classical method runs; only called for those (IsIterative is false).
BaselineMethod AsBaseline(Method method) {
  switch (method) {
    case Method::kBlend:
      return BaselineMethod::kBlend;
    case Method::kCopy:
      return BaselineMethod::kCopy;
    case Method::kIntegrate:
      return BaselineMethod::kIntegrate;
    case Method::kComplementaryFilter:
      return BaselineMethod::kComplementaryFilter;
    case Method::kEdi:
      return BaselineMethod::kEdi;
    case Method::kCeresLm:
    case Method::kCeresLbfgs:
    case Method::kAdam:
    case Method::kAdamSmooth:
      break;
  }
  LOG(FATAL) << MethodName(method) << " is not a baseline";
  return BaselineMethod::kBlend;
}

// Wraps the caller's progress callback, recording a checkpoint per iteration when asked.
IterationCallback Observer(const IterationCallback& progress, bool record_checkpoints,
                           const CheckpointTruth* truth, std::vector<Checkpoint>* checkpoints) {
  if (!record_checkpoints) return progress;
  return [=](const SolverIteration& iteration) {
    Checkpoint checkpoint;
    checkpoint.iteration = iteration.iteration;
    checkpoint.time_s = iteration.elapsed_s;
    checkpoint.cost = iteration.cost;
    if (truth != nullptr && truth->image != nullptr && iteration.latent != nullptr) {
      const Image estimate = iteration.latent->frame(truth->latent_index);
      checkpoint.psnr = Psnr(estimate, *truth->image);
      checkpoint.ssim = Ssim(estimate, *truth->image);
    }
    checkpoints->push_back(checkpoint);
    return progress ? progress(iteration) : true;
  };
}

void RunCeresLm(const Scene& scene, const MethodOptions& options, Video initial,
                const IterationCallback& observer, MethodResult* result) {
  Reconstruction reconstruction =
      Reconstruct(scene, options.reconstruction, std::move(initial), observer);
  const ReconstructionSummary& summary = reconstruction.summary;
  result->video = std::move(reconstruction.video);
  result->solved = summary.solved;
  result->message = summary.solved ? summary.ceres.message : summary.skipped_reason;
  if (summary.solved && !summary.stopped_early.empty()) {
    result->message = "stopped early (" + summary.stopped_early + ") after " +
                      std::to_string(summary.iterations) + " iterations";
  }
  result->iterations = summary.iterations;
  result->initial_cost = summary.initial_cost;
  result->final_cost = summary.final_cost;
  result->build_time_s = summary.build_time_s;
  result->solve_time_s = summary.solve_time_s;
  result->reconstruction = summary;
}

void RunFirstOrder(const Scene& scene, const MethodOptions& options, Video initial,
                   const IterationCallback& observer, MethodResult* result) {
  ReconstructionSummary& summary = result->reconstruction;
  const ObjectiveOptions objective =
      ResolveObjective(scene, options.reconstruction, &summary.model, &summary.alpha_derived);
  result->video = std::move(initial);
  if (scene.num_events == 0) {
    result->message = "no events in the window: the initialisation is the answer";
    summary.skipped_reason = result->message;
    return;
  }
  const ActivityMask mask(scene.events, options.reconstruction.activity_radius_px);
  FirstOrderSummary first_order;
  if (options.method == Method::kCeresLbfgs) {
    first_order = SolveWithLbfgs(scene, objective, mask, options.lbfgs, &result->video, observer,
                                 options.reconstruction.stop);
  } else {
    AdamOptions adam = options.adam;
    adam.penalty = options.method == Method::kAdam ? L1Penalty::kTrueL1 : L1Penalty::kSmoothed;
    adam.bound_intensities = options.reconstruction.bound_intensities;
    first_order = SolveWithAdam(scene, objective, mask, adam, &result->video, observer,
                                options.reconstruction.stop);
    result->parameters = {{"learning_rate", adam.learning_rate},
                          {"decay_every", static_cast<double>(adam.decay_every)},
                          {"decay_factor", adam.decay_factor},
                          {"beta1", adam.beta1},
                          {"beta2", adam.beta2},
                          {"max_iterations", static_cast<double>(adam.max_iterations)}};
  }
  result->solved = true;
  result->message = first_order.termination;
  result->iterations = first_order.iterations;
  result->initial_cost = first_order.initial_cost;
  result->final_cost = first_order.final_cost;
  result->build_time_s = first_order.setup_time_s;
  result->solve_time_s = first_order.solve_time_s;
  summary.solved = true;
  summary.stopped_early = first_order.stopped_early;
  summary.iterations = first_order.iterations;
  summary.initial_cost = first_order.initial_cost;
  summary.final_cost = first_order.final_cost;
  summary.problem.active_pixels = mask.num_active();
  summary.problem.skipped_pixels = mask.num_pixels() - mask.num_active();
  summary.problem.variable_parameter_blocks = first_order.active_voxels;
}

}  // namespace

const char* MethodName(Method method) { return NameOf(kMethodNames, method, "unknown"); }

Method ParseMethod(const std::string& name) {
  Method method = Method::kCeresLm;
  if (!FindName(kMethodNames, name, &method)) {
    throw InvalidArgumentError("unknown method '" + name + "' (one of " + NameList(kMethodNames) +
                               ")");
  }
  return method;
}

std::vector<Method> AllMethods() { return AllValues(kMethodNames); }

bool IsIterative(Method method) {
  return method == Method::kCeresLm || method == Method::kCeresLbfgs || method == Method::kAdam ||
         method == Method::kAdamSmooth;
}

bool MethodSupports(Method method, const Scene& scene, std::string* why_not) {
  if (IsIterative(method)) return true;
  return BaselineSupports(AsBaseline(method), scene, why_not);
}

void CheckMethodSupports(Method method, const Scene& scene, const std::string& what) {
  std::string why_not;
  if (!MethodSupports(method, scene, &why_not)) {
    throw InvalidArgumentError(std::string("--solver=") + MethodName(method) +
                               " cannot reconstruct " + what + ": " + why_not);
  }
}

void CheckResampledOutputFits(double fps, double span_s, int width, int height,
                              const std::string& what) {
  constexpr double kBytesPerPixel = 2 * sizeof(double);  // a frame and its confidence map
  const double frames = std::floor(fps * span_s) + 1.0;
  const double frame_bytes = kBytesPerPixel * width * height;
  if (frames * frame_bytes <= kMaxResampledOutputBytes) return;
  const double most_frames = std::floor(kMaxResampledOutputBytes / frame_bytes);
  char message[400];
  std::snprintf(message, sizeof(message),
                "--fps=%g would resample the %.3f s %s to %.0f frames of %dx%d: %.0f MB with "
                "their confidence maps, more than the %.0f MB evfs holds for them before "
                "writing; lower --fps (at most %.0f here)",
                fps, span_s, what.c_str(), frames, width, height, frames * frame_bytes / 1e6,
                kMaxResampledOutputBytes / 1e6,
                span_s > 0.0 ? std::floor(std::max(most_frames - 1.0, 1.0) / span_s) : 0.0);
  throw InvalidArgumentError(message);
}

void CheckWholeTextRecording(const DataSource& source) {
  if (dynamic_cast<const TextFolderDataSource*>(&source) != nullptr) source.Summarize();
}

void StartSolveClock(MethodOptions* options) {
  options->reconstruction.stop =
      StopCondition::After(options->reconstruction.solver.max_solver_time_in_seconds)
          .WhenRaised(options->interrupt);
}

MethodResult RunMethod(const Scene& scene, const MethodOptions& given_options,
                       const IterationCallback& progress, bool record_checkpoints,
                       const CheckpointTruth* truth) {
  MethodOptions options = given_options;
  if (!options.reconstruction.stop.active()) StartSolveClock(&options);
  MethodResult result;
  result.method = MethodName(options.method);
  if (!IsIterative(options.method)) {
    const auto start = Clock::now();
    BaselineResult baseline = RunBaseline(AsBaseline(options.method), scene, options.baseline);
    result.solve_time_s = SecondsSince(start);
    result.video = std::move(baseline.video);
    result.parameters = std::move(baseline.parameters);
    result.threshold_source = std::move(baseline.threshold_source);
    result.message = "closed form";
    return result;
  }
  if (truth != nullptr && (truth->image == nullptr || truth->latent_index < 0 ||
                           truth->latent_index >= scene.num_latent_frames())) {
    throw InvalidArgumentError("checkpoint truth: no image or a latent index off the timeline");
  }
  Video initial =
      InitialLatentVideo(scene, options.initialization, options.baseline, &result.initialization);
  const IterationCallback observer =
      Observer(progress, record_checkpoints, truth, &result.checkpoints);
  if (options.method == Method::kCeresLm) {
    RunCeresLm(scene, options, std::move(initial), observer, &result);
  } else {
    RunFirstOrder(scene, options, std::move(initial), observer, &result);
  }
  return result;
}

void ApplySharpFrameSeams(const Scene& scene, const MethodOptions& options, MethodResult* result) {
  if (!options.reconstruction.meet_sharp_frames || !IsIterative(options.method) ||
      !result->solved) {
    return;
  }
  result->seams = MeetSharpFrames(scene, &result->video);
}

ConfidenceOptions ConfidenceFor(const MethodOptions& method, const MethodResult& run) {
  ConfidenceOptions options;
  const EventModelParams& params = method.reconstruction.objective.event_model;
  const EventModelEstimate& model = run.reconstruction.model;
  if (params.model == EventModel::kLog) options.log_offset = params.log_offset;
  if (model.change_per_event > 0.0 && params.model == EventModel::kLog) {
    options.change_per_event = model.change_per_event;
    options.off_change_ratio = 1.0 / model.off_alpha_ratio;
  }
  return options;
}

}  // namespace evfs
