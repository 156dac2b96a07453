#include "evfs/baselines/baseline.h"

#include <cstdio>
#include <set>

#include "evfs/baselines/complementary_filter.h"
#include "evfs/baselines/event_double_integral.h"
#include "evfs/baselines/event_integration.h"
#include "evfs/baselines/scalar_search.h"
#include "evfs/core/error.h"
#include "evfs/core/metrics.h"
#include "evfs/scene/event_model_estimation.h"
#include "evfs/scene/scene.h"

namespace evfs {
namespace {

bool HasThreshold(BaselineMethod method) {
  return method == BaselineMethod::kIntegrate || method == BaselineMethod::kComplementaryFilter ||
         method == BaselineMethod::kEdi;
}

std::string Range(const BaselineOptions& options) {
  char range[64];
  std::snprintf(range, sizeof(range), "[%g, %g]", options.threshold_search_min,
                options.threshold_search_max);
  return range;
}

// The threshold a method uses and how it was chosen.
struct Threshold {
  double value = 0.0;
  std::string source;
};

// integrate and cf: measured between two sharp frames as the solver measures its change per
// event (the median over pixels of Δg / net count), else the assumed value.
Threshold ThresholdFromFrames(const Scene& scene, const BaselineOptions& options, bool log) {
  EventModelParams model;
  model.model = log ? EventModel::kLog : EventModel::kLinear;
  model.log_offset = options.log_offset;
  EventModelEstimationOptions estimation = options.estimation;
  estimation.per_polarity = false;  // one threshold for both polarities
  const EventModelEstimate estimate = EstimateEventModel(scene, model, estimation);
  return {estimate.change_per_event,
          estimate.estimated_from_frames
              ? "measured between the sharp frames (median change per net event)"
              : "assumed (no two sharp frames to measure it between)"};
}

Video RunWithThreshold(BaselineMethod method, const Scene& scene, const BaselineOptions& options,
                       double contrast_threshold) {
  switch (method) {
    case BaselineMethod::kIntegrate:
      return IntegrateEvents(scene, options, contrast_threshold);
    case BaselineMethod::kComplementaryFilter:
      return ComplementaryFilter(scene, options, contrast_threshold);
    case BaselineMethod::kEdi:
      return EventDoubleIntegral(scene, options, contrast_threshold);
    case BaselineMethod::kBlend:
    case BaselineMethod::kCopy:
      break;
  }
  return InitializeLatentVideo(scene);
}

// The parameters a method used with `threshold`, for summaries.
BaselineResult MakeResult(BaselineMethod method, const Scene& scene, const BaselineOptions& options,
                          const Threshold& threshold) {
  BaselineResult result;
  result.video = RunWithThreshold(method, scene, options, threshold.value);
  if (!HasThreshold(method)) return result;
  result.threshold_source = threshold.source;
  result.parameters.push_back({"contrast_threshold", threshold.value});
  if (method == BaselineMethod::kIntegrate) {
    result.parameters.push_back(
        {"log_domain", options.domain == IntegrationDomain::kLog ? 1.0 : 0.0});
    if (options.domain == IntegrationDomain::kLog) {
      result.parameters.push_back({"log_offset", options.log_offset});
    }
    result.parameters.push_back({"blur_sigma_px", options.blur_sigma_px});
  } else if (method == BaselineMethod::kComplementaryFilter) {
    result.parameters.push_back({"log_offset", options.log_offset});
    result.parameters.push_back({"cutoff_rad_per_s", options.cutoff_rad_per_s});
  } else {
    const EdiSharpness sharpness = EdiSharpnessEnergy(scene, options, threshold.value);
    result.parameters.push_back({"edi_energy", sharpness.energy});
    result.parameters.push_back({"edi_tv_ratio", sharpness.tv_ratio});
    result.parameters.push_back({"edi_edge_correlation", sharpness.edge_correlation});
  }
  return result;
}

void CheckRunnable(BaselineMethod method, const Scene& scene, const BaselineOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("baseline options: " + error);
  if (!BaselineSupports(method, scene, &error)) throw InvalidArgumentError(error);
}

}  // namespace

const char* BaselineName(BaselineMethod method) { return NameOf(kBaselineNames, method); }

BaselineMethod ParseBaseline(const std::string& name) {
  BaselineMethod method = BaselineMethod::kBlend;
  if (!FindName(kBaselineNames, name, &method)) {
    throw InvalidArgumentError("unknown baseline '" + name + "': expected one of " +
                               NameList(kBaselineNames));
  }
  return method;
}

bool BaselineSupports(BaselineMethod method, const Scene& scene, std::string* why_not) {
  const int frames = static_cast<int>(scene.frames.size());
  std::set<int> centres;  // doubled latent centres of the frame observations
  for (const FrameObservation& frame : scene.frames) {
    centres.insert(frame.latent_first + frame.latent_last);
  }
  std::string reason;
  if (frames == 0) {
    reason = "the scene has no frame observation";
  } else if (method == BaselineMethod::kBlend && centres.size() < 2) {
    reason = "blend needs frames at two different times; this scene has one (copy copies it)";
  } else if (method == BaselineMethod::kCopy && frames != 1) {
    reason = "copy needs exactly one frame observation; this scene has " + std::to_string(frames) +
             " (blend blends them)";
  } else if (method == BaselineMethod::kIntegrate && SharpFrameIndices(scene).empty()) {
    reason =
        "integrate starts from a sharp frame; this scene has only blurred ones (edi "
        "deblurs one)";
  } else if (method == BaselineMethod::kEdi &&
             (frames != 1 || scene.frames[0].latent_first == scene.frames[0].latent_last)) {
    reason = "edi deblurs one blurred frame; this scene has " + std::to_string(frames) +
             (frames == 1 ? " sharp frame" : " frame observations");
  }
  if (why_not != nullptr) *why_not = reason;
  return reason.empty();
}

BaselineResult RunBaseline(BaselineMethod method, const Scene& scene,
                           const BaselineOptions& options) {
  CheckRunnable(method, scene, options);
  Threshold threshold;
  if (!HasThreshold(method)) {
    // blend and copy have no threshold.
  } else if (options.contrast_threshold > 0.0) {
    threshold = {options.contrast_threshold, "given"};
  } else if (method == BaselineMethod::kEdi) {
    threshold = {ChooseEdiThreshold(scene, options).contrast_threshold,
                 "EDI sharpness criterion, searched over " + Range(options)};
  } else {
    const bool log =
        method == BaselineMethod::kComplementaryFilter || options.domain == IntegrationDomain::kLog;
    threshold = ThresholdFromFrames(scene, options, log);
  }
  return MakeResult(method, scene, options, threshold);
}

BaselineResult TuneContrastThresholdOnTruth(BaselineMethod method, const Scene& scene,
                                            const BaselineOptions& options, const Image& truth,
                                            int latent_index) {
  if (!HasThreshold(method)) {
    throw InvalidArgumentError(std::string(BaselineName(method)) +
                               " has no contrast threshold to tune");
  }
  CheckRunnable(method, scene, options);
  if (truth.rows() != scene.height || truth.cols() != scene.width) {
    throw InvalidArgumentError("the truth frame's size differs from the scene's");
  }
  if (latent_index < 0 || latent_index >= scene.num_latent_frames()) {
    throw InvalidArgumentError("latent frame " + std::to_string(latent_index) +
                               " is off the scene's timeline (0.." +
                               std::to_string(scene.num_latent_frames() - 1) + ")");
  }
  const ScalarMinimum best = MinimizeOnLogInterval(
      [&](double c) {
        return -Psnr(RunWithThreshold(method, scene, options, c).frame(latent_index), truth);
      },
      options.threshold_search_min, options.threshold_search_max);
  return MakeResult(method, scene, options,
                    {best.argument, "tuned on the truth frame (maximum PSNR over " +
                                        Range(options) + "): an oracle, not a method"});
}

}  // namespace evfs
