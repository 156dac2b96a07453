// One reconstruction job as the CLI, the demo and the benchmarks run it: read a recording,
// build the scene for the requested case, derive α, solve, score against a truth frame and
// write the results. Options arrive filled in; nothing here reads a flag.
#ifndef EVFS_APP_RECONSTRUCT_JOB_H_
#define EVFS_APP_RECONSTRUCT_JOB_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "evfs/app/denoise_job.h"
#include "evfs/app/log_offset_search.h"
#include "evfs/app/method.h"
#include "evfs/core/enum_names.h"
#include "evfs/core/video.h"
#include "evfs/io/data_source.h"
#include "evfs/scene/confidence.h"
#include "evfs/scene/frame_timing.h"
#include "evfs/scene/scene.h"

namespace evfs {

enum class Mode { kInterpolate, kPredict, kDeblur };

inline constexpr EnumName<Mode> kModeNames[] = {
    {Mode::kInterpolate, "interpolate", "frames between two inputs"},
    {Mode::kPredict, "predict", "frames after one sharp input"},
    {Mode::kDeblur, "deblur", "sharp frames inside one blurred exposure"},
};

/// "interpolate", "predict", "deblur" → Mode; throws InvalidArgumentError otherwise.
Mode ParseMode(const std::string& name);
const char* ModeName(Mode mode);

struct ReconstructRequest {
  std::string data_path;           // data folder or HDF5 file
  std::string data_label;          // how summary.json names the data ("": data_path)
  DataSourceOptions data_options;  // the topics of a ROS bag
  Mode mode = Mode::kPredict;
  int first = 0;   // images.txt line (0-based) of the first / blurred frame
  int last = -1;   // interpolate: the last frame; predict: the frame whose time ends the window
                   // (-1: first + 1)
  int truth = -1;  // frame to score against (-1: none)
  double exposure_s = 0.0;  // deblur: exposure around the frame's timestamp when the data has none
  double fps = 0.0;         // > 0: resample the latent video to this uniform rate
  /// Interpolate, predict: the moment each sharp frame (inputs, the predicted frame, the truth)
  /// represents (scene/frame_timing.h); kLag uses frame_lag_s, kAuto estimates it from the
  /// frames first..last other than the truth, with frame_lag's options.
  FrameTime frame_time = FrameTime::kInstant;
  double frame_lag_s = 0.0;
  FrameLagOptions frame_lag;
  BinningOptions binning;
  /// The method and all its settings (objective.event_model.alpha <= 0: derive α from the data).
  MethodOptions method;
  /// Interpolate with the log model: the values of b tried on frames outside the window
  /// (app/log_offset_search.h); the best replaces the model's b. Empty: the model's b.
  std::vector<double> log_offset_search;
  /// Record cost (and PSNR/SSIM against --truth) at every iteration into summary.json.
  bool checkpoints = false;
  /// The residual denoiser after the solve (DenoiseMode::kNone: none).
  DenoiseRequest denoise;
  /// The options the request was made from, each name with its value as text, echoed in
  /// summary.json (ReconstructRequestFromOptions fills it; empty for a request made in code).
  std::vector<std::pair<std::string, std::string>> options;
  /// Sees every iteration of an iterative method (progress output); may be empty.
  IterationCallback progress;
  /// Told each stage as the job reaches it: "read", "bin", then "build" (with `progress`: the
  /// iterations say when the solve starts) or "build and solve"; may be empty.
  std::function<void(const char* stage)> stage;
};

struct TruthScore {
  int index = -1;                                   // images.txt line of the truth frame
  int64_t timestamp_ns = 0;                         // its timestamp
  int latent_index = -1;                            // latent frame nearest to it
  double psnr = 0.0, ssim = 0.0;                    // reconstruction against truth
  double baseline_psnr = 0.0, baseline_ssim = 0.0;  // initialisation (blend or copy) against truth
  Image image;                                      // the truth frame itself
};

struct StageTimes {
  double read_s = 0.0, bin_s = 0.0, build_s = 0.0, solve_s = 0.0, write_s = 0.0, total_s = 0.0;
};

struct ReconstructResult {
  Mode mode = Mode::kPredict;
  int width = 0, height = 0;
  int64_t events = 0;  // events in the window (binned; hot pixels' left out)
  int event_frames = 0;
  int hot_pixels = 0;            // pixels whose events were left out as hot (BinningOptions)
  int64_t hot_pixel_events = 0;  // their events
  int64_t noise_events = 0;      // left out by the background-activity filter
  int saturated_pixels = 0;      // pixels whose events were left out: a frame saturates there
  int64_t saturated_pixel_events = 0;
  int flickering_pixels = 0;  // pixels whose events were left out: they flicker
  int64_t flickering_pixel_events = 0;
  MethodResult run;  // latent video and what the method did
  Video output;      // the latent video, or its resampling at request.fps
  /// The predicted one-sigma error of every pixel of `output` (scene/confidence.h).
  Video confidence;
  ConfidenceModel confidence_model;
  Video baseline;  // blend or copy on the latent timeline (the score's reference)
  bool has_truth = false;
  TruthScore truth;
  /// With a truth: the share of its pixels whose error lies within the predicted one sigma.
  double truth_within_sigma = 0.0;
  StageTimes time;
  DenoiseRecord denoise;  // what the denoiser did (mode none: nothing)
  /// request.frame_time kAuto: the estimate; frame_shift_ns: how far the moment a sharp frame
  /// represents lies after its timestamp (the first frame's exposure middle for start, middle,
  /// end).
  FrameLagEstimate frame_lag;
  /// What ReconstructRequest::log_offset_search chose; empty when it did not run.
  std::optional<LogOffsetChoice> log_offset_choice;
  int64_t frame_shift_ns = 0;
};

/// Runs the job. Throws evfs::Error (InputError, InvalidArgumentError) on bad input.
ReconstructResult RunReconstruction(const ReconstructRequest& request);
/// The same job on a recording already open (or held in memory, as the Python module's arrays
/// are): `source` replaces request.data_path, which is not read.
ReconstructResult RunReconstruction(const ReconstructRequest& request, const DataSource& source);

/// Writes `folder`/frames/NNNNNN.png (16-bit grey), timestamps.txt and summary.json into a new
/// or empty folder: the staging folder of an OutputTarget (io/output_target.h), which makes the
/// output appear whole or not at all. Fills result->time.write_s and total_s before writing the
/// summary.
void WriteReconstruction(const ReconstructRequest& request, ReconstructResult* result,
                         const std::string& folder);

/// summary.json's text (docs/guide.md).
std::string SummaryJson(const ReconstructRequest& request, const ReconstructResult& result);

}  // namespace evfs

#endif  // EVFS_APP_RECONSTRUCT_JOB_H_
