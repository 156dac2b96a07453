#include "evfs/app/evfs_options.h"

#include <ceres/types.h>
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <type_traits>

#include "evfs/app/calibrate_job.h"
#include "evfs/app/denoise_job.h"
#include "evfs/app/initialization.h"
#include "evfs/app/log_offset_search.h"
#include "evfs/app/method.h"
#include "evfs/core/enum_names.h"
#include "evfs/core/error.h"
#include "evfs/core/time.h"
#include "evfs/core/value_range.h"
#include "evfs/scene/event_model.h"
#include "evfs/scene/frame_timing.h"
#include "evfs/solver/reconstruction_options.h"

namespace evfs {
namespace {

// A row's default and the values the option accepts: a number's range is declared with it.
struct Accepted {
  OptionValue default_value;
  ValueRange range = ValueRange::Any();
};

Accepted Bool(bool value) { return {value}; }
Accepted Text(const std::string& value) { return {value}; }
Accepted Int32(int32_t value, ValueRange range) { return {value, range}; }
Accepted Int64(int64_t value, ValueRange range) { return {value, range}; }
Accepted Uint64(uint64_t value, ValueRange range) { return {value, range}; }
Accepted Double(double value, ValueRange range) { return {value, range}; }

// A number as a double, to compare with a range; nullopt for a text or a switch.
std::optional<double> NumberOf(const OptionValue& value) {
  return std::visit(
      [](const auto& v) -> std::optional<double> {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, std::string>) {
          return std::nullopt;
        } else {
          return static_cast<double>(v);
        }
      },
      value);
}

// The bindings of the table's rows: the field's path as text (for the table's readers and
// tests/app/evfs_options_test.cc) and a setter of that field, from one mention of the path.
// clang-format off
// The field of EvfsSettings at `path`, set to the option's value (of the field's own type).
#define EVFS_OPTION_FIELD(path)                                                                  \
  #path, [](const OptionValue& value, const std::string&, EvfsSettings* settings) {              \
    settings->path = std::get<std::remove_reference_t<decltype(settings->path)>>(value);         \
  }
// The field at `path` set to `parse` of the option's text.
#define EVFS_OPTION_PARSED(path, parse)                                                          \
  #path, [](const OptionValue& value, const std::string&, EvfsSettings* settings) {              \
    settings->path = parse(std::get<std::string>(value));                                        \
  }
// The enum field at `path` set from one of the names of `table` (core/enum_names.h).
#define EVFS_OPTION_NAMED(path, table)                                                           \
  #path, [](const OptionValue& value, const std::string& flag, EvfsSettings* settings) {         \
    settings->path = ParseName(table, std::get<std::string>(value), flag);                       \
  }
// clang-format on

// An option that sets one field in its own way, named by `field` for the table's readers.
std::pair<std::string, OptionSetter> Custom(const std::string& field, OptionSetter set) {
  return {field, std::move(set)};
}

// An option a command reads itself (a path, how verbosely it runs).
std::pair<std::string, OptionSetter> Unbound() { return {"", nullptr}; }

void SetFrameTime(const OptionValue& value, const std::string&, EvfsSettings* settings) {
  const std::string& text = std::get<std::string>(value);
  ReconstructRequest& request = settings->reconstruct;
  if (!ParseFrameTime(text, &request.frame_time, &request.frame_lag_s)) {
    throw InvalidArgumentError(
        "--frame_time: expected instant, auto, start, middle, end or a lag in ms, got '" + text +
        "'");
  }
}

// A model name, or a calibration file read once every option is known (the model flags given
// beside it win over the file).
void SetEventModel(const OptionValue& value, const std::string& flag, EvfsSettings* settings) {
  const std::string& text = std::get<std::string>(value);
  settings->event_model_file.clear();
  if (IsEventModelFile(text)) {
    settings->event_model_file = text;
  } else {
    settings->reconstruct.method.reconstruction.objective.event_model.model =
        ParseName(kEventModelNames, text, flag);
  }
}

void SetSmoothingContinuation(const OptionValue& value, const std::string& flag,
                              EvfsSettings* settings) {
  settings->reconstruct.method.reconstruction.smoothing_continuation =
      ParseNumberList(std::get<std::string>(value), flag);
}

void SetLogOffsetSearch(const OptionValue& value, const std::string& flag, EvfsSettings* settings) {
  settings->reconstruct.log_offset_search = ParseNumberList(std::get<std::string>(value), flag);
  for (const double b : settings->reconstruct.log_offset_search) {
    if (!(b > 0.0) || !std::isfinite(b)) {
      throw InvalidArgumentError(flag + " values must be finite and > 0");
    }
  }
}

void SetLinearSolver(const OptionValue& value, const std::string& flag, EvfsSettings* settings) {
  const std::string& name = std::get<std::string>(value);
  if (!ceres::StringToLinearSolverType(
          name, &settings->reconstruct.method.reconstruction.solver.linear_solver_type)) {
    throw InvalidArgumentError("unknown " + flag + " " + name);
  }
}

void SetPreconditioner(const OptionValue& value, const std::string& flag, EvfsSettings* settings) {
  const std::string& name = std::get<std::string>(value);
  if (!ceres::StringToPreconditionerType(
          name, &settings->reconstruct.method.reconstruction.solver.preconditioner_type)) {
    throw InvalidArgumentError("unknown " + flag + " " + name);
  }
}

// auto stays until the weights are known (ResolveDenoise).
void SetDenoise(const OptionValue& value, const std::string& flag, EvfsSettings* settings) {
  const std::string& mode = std::get<std::string>(value);
  if (mode != "auto") ParseName(kDenoiseModeNames, mode, flag);
  settings->denoise = mode;
}

void SetRefractoryPeriod(const OptionValue& value, const std::string&, EvfsSettings* settings) {
  settings->simulator.refractory_period_ns = SecondsToNanoseconds(std::get<double>(value));
}

// A row of the table: OptionDefinition less ReadBy, its binding given as (field, setter). The
// help of a bounded option ends with its range.
OptionDefinition Row(const char* name, const char* group, const char* commands, unsigned uses,
                     Accepted accepted, const char* help, std::string field, OptionSetter set) {
  OptionDefinition option;
  option.name = name;
  option.group = group;
  option.commands = commands;
  option.uses = uses;
  option.default_value = std::move(accepted.default_value);
  option.range = accepted.range;
  option.help = help;
  if (option.range.Bounded()) option.help += " Values: " + option.range.Text() + ".";
  option.field = std::move(field);
  option.set = std::move(set);
  return option;
}

OptionDefinition Row(const char* name, const char* group, const char* commands, unsigned uses,
                     Accepted accepted, const char* help,
                     std::pair<std::string, OptionSetter> binding) {
  return Row(name, group, commands, uses, std::move(accepted), help, std::move(binding.first),
             std::move(binding.second));
}

std::vector<OptionDefinition> MakeEvfsOptions() {
  // Each row: name, group, the commands that read it, OptionUse bits, default, help, binding.
  return {
      Row("data", "data", "info reconstruct convert video calibrate", 0, Text(""),
          "Data folder (Event Camera Dataset layout), HDF5 event file or AEDAT 4 recording "
          "(.aedat4, from iniVation DV), AEDAT 2.0/3.1 file (jAER, cAER, v2e), or ROS 1 bag (.bag: "
          "dvs_msgs/EventArray and sensor_msgs/Image).",
          EVFS_OPTION_FIELD(reconstruct.data_path)),
      Row("events_topic", "data", "info reconstruct convert video", kReconstructKey, Text(""),
          "ROS bag: the dvs_msgs/EventArray topic; empty: the first one in the bag.",
          EVFS_OPTION_FIELD(reconstruct.data_options.events_topic)),
      Row("frames_topic", "data", "info reconstruct convert video", kReconstructKey, Text(""),
          "ROS bag: the sensor_msgs/Image topic; empty: the first one in the bag.",
          EVFS_OPTION_FIELD(reconstruct.data_options.frames_topic)),
      Row("frames", "data", "simulate", 0, Text(""),
          "simulate: folder with images.txt ('t path' lines) and the frames.", Unbound()),
      Row("mode", "data", "reconstruct", 0, Text(""), "interpolate | predict | deblur.",
          EVFS_OPTION_PARSED(reconstruct.mode, ParseMode)),
      Row("first", "data", "info reconstruct video calibrate", 0,
          Int32(-1, ValueRange::AtLeast(0).Or(-1)),
          "0-based images.txt line of the first (or blurred) frame.",
          EVFS_OPTION_FIELD(reconstruct.first)),
      Row("last", "data", "info reconstruct video calibrate", 0,
          Int32(-1, ValueRange::AtLeast(0).Or(-1)),
          "interpolate: the last frame; predict: the frame whose time ends the window (default "
          "first + 1); info: with --first, the window to describe.",
          EVFS_OPTION_FIELD(reconstruct.last)),
      Row("truth", "data", "reconstruct", 0, Int32(-1, ValueRange::AtLeast(0).Or(-1)),
          "Frame to score the reconstruction against (PSNR, SSIM); -1: none.",
          EVFS_OPTION_FIELD(reconstruct.truth)),
      Row("exposure_s", "data", "reconstruct video simulate", kReconstructKey,
          Double(0.0, ValueRange::Between(0.0, kMaxDurationS)),
          "deblur: exposure around the frame's timestamp, when the data has no exposures.txt. "
          "simulate: the written frames' exposure, each the mean of the scene over it (with "
          "exposures.txt); 0: the scene at the timestamp.",
          EVFS_OPTION_FIELD(reconstruct.exposure_s)),
      Row("frame_time", "data", "reconstruct", kReconstructKey, Text("instant"),
          "interpolate, predict: the moment a sharp frame represents. instant: its timestamp; "
          "auto: its timestamp plus the lag that best explains the input frames' change by the "
          "events (evfs info --first --last prints it); a number: that lag in ms; start | middle | "
          "end: the mean over its exposure (exposures.txt, else --exposure_s) which the timestamp "
          "starts, centres or ends.",
          Custom("reconstruct.frame_time", SetFrameTime)),
      Row("out", "output", "reconstruct denoise simulate convert demo video calibrate",
          kNotInFingerprint, Text(""),
          "Output folder (reconstruct, simulate, demo) or file (convert to .h5 or .aedat4): a new "
          "one, or an earlier output of the same command with --overwrite. Never the root, current "
          "or home folder, nor the input or a folder around it.",
          Unbound()),
      Row("overwrite", "output", "reconstruct denoise simulate convert demo video calibrate",
          kNotInFingerprint, Bool(false),
          "Replace --out when it holds an earlier output of the same command (marked by "
          "OUT/.evfs-output, or an .h5/.aedat4 file evfs wrote); nothing else is replaced.",
          Unbound()),
      Row("fps", "output", "reconstruct video", kReconstructKey,
          Double(0.0, ValueRange::AtLeast(0.0)),
          "Resample the latent video to this uniform frame rate; 0 writes the latent frames "
          "themselves.",
          EVFS_OPTION_FIELD(reconstruct.fps)),
      Row("solver", "method", "reconstruct video", kReconstructKey, Text("ceres_lm"),
          "Method: ceres_lm (default: Levenberg-Marquardt in Ceres) | ceres_lbfgs | adam (the "
          "paper's optimiser and schedule, true l1) | adam_smooth (the same on the smoothed "
          "objective) | blend | copy | integrate | cf | edi (classical baselines).",
          EVFS_OPTION_PARSED(reconstruct.method.method, ParseMethod)),
      Row("init", "method", "reconstruct video", kReconstructKey,
          Text(InitializationName(MethodOptions().initialization)),
          "Where the solve starts: blend (the frames blended in time) | events (event integration "
          "from a sharp frame, else EDI for a blurred one).",
          EVFS_OPTION_PARSED(reconstruct.method.initialization, ParseInitialization)),
      Row("checkpoints", "method", "reconstruct", kReconstructKey, Bool(false),
          "Record cost (and PSNR/SSIM against --truth) at every iteration of an iterative solver "
          "into summary.json.",
          EVFS_OPTION_FIELD(reconstruct.checkpoints)),
      Row("adam_iterations", "method", "reconstruct video", kReconstructKey,
          Int32(AdamOptions().max_iterations, ValueRange::AtLeast(0)), "adam, adam_smooth: steps.",
          EVFS_OPTION_FIELD(reconstruct.method.adam.max_iterations)),
      Row("adam_learning_rate", "method", "reconstruct video", kReconstructKey,
          Double(AdamOptions().learning_rate, ValueRange::Above(0.0)),
          "adam, adam_smooth: initial learning rate (divided by 5 every 200 steps).",
          EVFS_OPTION_FIELD(reconstruct.method.adam.learning_rate)),
      Row("contrast_threshold", "method", "reconstruct video", kReconstructKey,
          Double(BaselineOptions().contrast_threshold, ValueRange::Any()),
          "integrate, cf, edi (and --init=events): change one event stands for; 0 derives it from "
          "the data.",
          EVFS_OPTION_FIELD(reconstruct.method.baseline.contrast_threshold)),
      Row("blur_sigma_px", "method", "reconstruct video", kReconstructKey,
          Double(BaselineOptions().blur_sigma_px, ValueRange::AtLeast(0.0)),
          "integrate: Gaussian blur (pixels) after integration; 0: none.",
          EVFS_OPTION_FIELD(reconstruct.method.baseline.blur_sigma_px)),
      Row("cf_cutoff_rad_per_s", "method", "reconstruct video", kReconstructKey,
          Double(BaselineOptions().cutoff_rad_per_s, ValueRange::AtLeast(0.0).WithInfinity()),
          "cf: crossover frequency of the complementary filter.",
          EVFS_OPTION_FIELD(reconstruct.method.baseline.cutoff_rad_per_s)),
      Row("binning", "binning", "info reconstruct video", kReconstructKey, Text("auto"),
          "auto | collision | stacked. auto: collision binning (the paper's), unless it gives more "
          "than --max_latent_frames frames or --max_latent_voxels voxels; collision or stacked "
          "beyond --max_latent_voxels is refused.",
          EVFS_OPTION_NAMED(reconstruct.binning.method, kBinningMethodNames)),
      Row("max_latent_frames", "binning", "info reconstruct video", kReconstructKey,
          Int32(BinningOptions().max_latent_frames, ValueRange::AtLeast(1)),
          "auto binning: most latent steps before switching to stacked equal-time binning with "
          "this many frames.",
          EVFS_OPTION_FIELD(reconstruct.binning.max_latent_frames)),
      Row("min_latent_steps", "binning", "info reconstruct video", kReconstructKey,
          Int32(BinningOptions().min_latent_steps, ValueRange::AtLeast(0)),
          "auto binning: collision frames split in time until the window has this many latent "
          "steps (within --max_latent_frames and --max_latent_voxels); 0: as they are.",
          EVFS_OPTION_FIELD(reconstruct.binning.min_latent_steps)),
      Row("max_latent_voxels", "binning", "info reconstruct video", kReconstructKey,
          Int64(BinningOptions().max_latent_voxels, ValueRange::AtLeast(1)),
          "Most pixels x latent frames, decided from event counts before anything is allocated; "
          "bounds memory and time (auto binning takes as many steps as fit).",
          EVFS_OPTION_FIELD(reconstruct.binning.max_latent_voxels)),
      Row("hot_pixel_factor", "binning", "info reconstruct video", kReconstructKey,
          Double(BinningOptions().hot_pixel_factor, ValueRange::AtLeast(0.0)),
          "Leave out the events of hot pixels: those firing more than this many times as often as "
          "the window's busy pixels (the busiest outside the top 1 %); 0 keeps every event.",
          EVFS_OPTION_FIELD(reconstruct.binning.hot_pixel_factor)),
      Row("saturation_level", "binning", "info reconstruct video calibrate", kReconstructKey,
          Double(BinningOptions().saturation_level, ValueRange::Above(0.0)),
          "A frame pixel at or above this level (intensity in [0, 1]) is saturated "
          "(--flicker_min_reversals, --leave_out_saturated); above 1: none is.",
          EVFS_OPTION_FIELD(reconstruct.binning.saturation_level)),
      Row("leave_out_saturated", "binning", "info reconstruct video", kReconstructKey,
          Bool(BinningOptions().leave_out_saturated),
          "Leave out the events of pixels saturated in every frame of the window (the frames "
          "cannot show what they record).",
          EVFS_OPTION_FIELD(reconstruct.binning.leave_out_saturated)),
      Row("flicker_min_reversals", "binning", "info reconstruct video", kReconstructKey,
          Int32(BinningOptions().flicker_min_reversals, ValueRange::AtLeast(0)),
          "Leave out the events of pixels whose events reverse polarity at least this many times "
          "in the window with almost no net change (a blinking LED, a mains-powered lamp), next to "
          "a pixel a frame shows saturated: the frames govern there; 0 keeps them.",
          EVFS_OPTION_FIELD(reconstruct.binning.flicker_min_reversals)),
      Row("noise_filter_ms", "binning", "info reconstruct video", kReconstructKey,
          Double(BinningOptions().noise_filter_ms,
                 ValueRange::Between(0.0, BinningOptions::kMaxNoiseFilterMs)),
          "Leave out events that no neighbouring pixel confirms within this many ms "
          "(background-activity filter); 0 keeps every event.",
          EVFS_OPTION_FIELD(reconstruct.binning.noise_filter_ms)),
      Row("stacked_frames", "binning", "info reconstruct video", kReconstructKey,
          Int32(BinningOptions().stacked.num_frames, ValueRange::AtLeast(1)),
          "stacked binning: number of event frames.",
          EVFS_OPTION_FIELD(reconstruct.binning.stacked.num_frames)),
      Row("frame_weight", "model", "reconstruct video", kReconstructKey,
          Double(ObjectiveOptions().frame_weight, ValueRange::AtLeast(0.0)),
          "Weight of the frame term.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.frame_weight)),
      Row("event_weight", "model", "reconstruct video", kReconstructKey,
          Double(ObjectiveOptions().event_weight, ValueRange::AtLeast(0.0)),
          "lambda_e: weight of the event term.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.event_weight)),
      Row("spatial_tv_weight", "model", "reconstruct video", kReconstructKey,
          Double(ObjectiveOptions().spatial_tv_weight, ValueRange::AtLeast(0.0)),
          "lambda_xy: weight of spatial total variation.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.spatial_tv_weight)),
      Row("temporal_tv_weight", "model", "reconstruct video", kReconstructKey,
          Double(ObjectiveOptions().temporal_tv_weight, ValueRange::AtLeast(0.0)),
          "lambda_t: weight of temporal total variation.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.temporal_tv_weight)),
      Row("log_temporal_tv_reversals", "model", "reconstruct video", kReconstructKey,
          Int32(ObjectiveOptions().log_temporal_tv_reversals, ValueRange::AtLeast(0)),
          "Pixels whose events reverse polarity at least this many times in the window (a "
          "flickering light) get temporal TV in g = log(H + b), where a brightening step and the "
          "darkening one that undoes it cost alike; |dH| makes them drift dark. 0: |dH| "
          "everywhere.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.log_temporal_tv_reversals)),
      Row("alpha", "model", "reconstruct video", kReconstructKey,
          Double(0.0, ValueRange::AtMost(ObjectiveOptions::kMaxAlpha)),
          "alpha of tanh(alpha * dg); 0 derives it from the data's contrast threshold (printed).",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.event_model.alpha)),
      Row("event_model", "model", "reconstruct video", kReconstructKey,
          Text(EventModelName(ObjectiveOptions().event_model.model)),
          "log (g(x) = log(x + b), paper Eq. 1) | linear (g(x) = x, paper Eq. 2) | FILE.json "
          "(written by evfs calibrate: the log model with the measured b, alpha from the ON "
          "threshold and the OFF/ON ratio; --log_offset, --alpha and --event_saturation given as "
          "well win).",
          Custom("reconstruct.method.reconstruction.objective.event_model.model", SetEventModel)),
      Row("event_saturation", "model", "reconstruct video", kReconstructKey,
          Double(0.0, ValueRange::AtLeast(1.0).Or(0.0)),
          "c of the event model c tanh(alpha dg / c) (1: the paper's); 0 derives it: above 1 "
          "when the change per event is measured between two frames, else 1.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.event_model.saturation)),
      Row("per_polarity_alpha", "model", "reconstruct video", kReconstructKey,
          Bool(EventModelEstimationOptions().per_polarity),
          "With a derived alpha measured between two frames: measure the change per event apart "
          "for ON and OFF events (DAVIS thresholds differ) and give darkening steps their own "
          "alpha.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.estimation.per_polarity)),
      Row("log_offset", "model", "reconstruct video", kReconstructKey,
          Double(ObjectiveOptions().event_model.log_offset, ValueRange::Above(0.0)),
          "b of the log event model.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.event_model.log_offset)),
      Row("log_offset_search", "model", "reconstruct video", kReconstructKey | kNumberList,
          Text(kDefaultLogOffsetSearch),
          "Comma-separated values of b tried for the windows between two frames (not when "
          "--log_offset or a calibrated --event_model gives b): each reconstructs up to two "
          "frames of the recording from their neighbours (reconstruct: the nearest the window "
          "does not use, nor --truth; video: one of its observed frames per ten windows), and "
          "the best replaces --log_offset there; without three such frames, or empty: "
          "--log_offset.",
          Custom("reconstruct.log_offset_search", SetLogOffsetSearch)),
      Row("spatial_tv", "model", "reconstruct video", kReconstructKey, Text("anisotropic"),
          "paper (|dx+dy|) | anisotropic (|dx|+|dy|) | isotropic (sqrt(dx^2+dy^2)).",
          EVFS_OPTION_NAMED(reconstruct.method.reconstruction.objective.spatial_tv,
                            kSpatialTvNames)),
      Row("shared_structure_tv", "model", "reconstruct video", kReconstructKey,
          Bool(ObjectiveOptions().shared_structure_tv),
          "Between two sharp frames, measure spatial TV from the structure both frames show in "
          "place (minmod of their differences): texture they share is kept, moved edges are not.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.shared_structure_tv)),
      Row("smoothing_scale", "model", "reconstruct video", kReconstructKey,
          Double(ObjectiveOptions().smoothing_scale, ValueRange::Above(0.0)),
          "epsilon of the smoothed l1: sqrt(eps^2 + r^2) - eps.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.objective.smoothing_scale)),
      Row("smoothing_continuation", "model", "reconstruct video", kReconstructKey | kNumberList,
          Text(""),
          "Comma-separated smoothing scales solved first, each starting the next, before "
          "--smoothing_scale (e.g. 0.2,0.1); empty: one solve.",
          Custom("reconstruct.method.reconstruction.smoothing_continuation",
                 SetSmoothingContinuation)),
      Row("bounds", "model", "reconstruct video", kReconstructKey, Bool(true),
          "Keep intensities in [0, 1].",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.bound_intensities)),
      Row("activity_radius_px", "model", "reconstruct video", kReconstructKey,
          Int32(ReconstructionOptions().activity_radius_px, ValueRange::AtLeast(0).Or(-1)),
          "Solve only pixels within this distance of an event of the window; the others keep their "
          "initial value. -1 solves every pixel.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.activity_radius_px)),
      Row("merge_quiet_steps", "model", "reconstruct video", kReconstructKey,
          Bool(ReconstructionOptions().merge_quiet_steps),
          "Hold a pixel constant between the latent steps where it fired (one unknown per quiet "
          "run); false: one unknown per voxel.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.merge_quiet_steps)),
      Row("unfired_pixel_changes", "model", "reconstruct video", kReconstructKey,
          Bool(ReconstructionOptions().unfired_pixel_changes),
          "With merged quiet steps, a pixel near the events that never fires gets one change after "
          "the last frame, at the median of its neighbours' events (false: it stays constant).",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.unfired_pixel_changes)),
      Row("ring_tolerance", "model", "reconstruct video", kReconstructKey,
          Double(ReconstructionOptions().ring_tolerance, ValueRange::Between(0.0, 1.0)),
          "With merged quiet steps, a pixel held constant next to the solved ones (the ring) "
          "enters the problem as one constant until its initial value has moved more than this "
          "(intensity in [0, 1]; 0: a new constant at every change). The output keeps the ring's "
          "own values.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.ring_tolerance)),
      Row("split_independent_parts", "model", "reconstruct video", kReconstructKey,
          Bool(ReconstructionOptions().split_independent_parts),
          "Solve the regions that no term couples as separate problems, concurrently (one after "
          "another with --progress or --checkpoints); false: one problem.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.split_independent_parts)),
      Row("max_problem_mb", "model", "reconstruct video", kReconstructKey,
          Int64(ReconstructionOptions().max_problem_mb,
                ValueRange::AtMost(ReconstructionOptions::kMaxProblemMb)),
          "Most memory (MiB) the Ceres problems hold at once, estimated before building: larger "
          "problems are solved in batches of parts, or in overlapping bands of rows, one after "
          "another; <= 0: no limit.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.max_problem_mb)),
      Row("quiet_blend_fraction", "model", "reconstruct video", kReconstructKey,
          Double(ReconstructionOptions().quiet_blend_fraction,
                 ValueRange::Between(0.0, ReconstructionOptions::kMaxQuietBlendFraction)),
          "After the solve, pixels no event fired whose sharp frames differ by less than this "
          "fraction of one event's change take the time-weighted blend of the frames between them; "
          "0: off.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.quiet_blend_fraction)),
      Row("step_ramp_px", "model", "reconstruct video", kReconstructKey,
          Double(ReconstructionOptions().step_ramp_px,
                 ValueRange::Between(0.0, ReconstructionOptions::kMaxStepRampPx)),
          "After the solve, each step of a solved pixel becomes a ramp that ends at the step and "
          "lasts the time the scene takes to move this many pixels there (measured from the "
          "events), begun no earlier than the middle of the segment before; 0: steps stay jumps.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.step_ramp_px)),
      Row("meet_sharp_frames", "model", "reconstruct video", kReconstructKey,
          Bool(ReconstructionOptions().meet_sharp_frames),
          "After the solve, each sharp frame's latent frame takes the frame's values, the offset "
          "fading out half-way to the next observation (or at the window's end); false: the "
          "solve's values.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.meet_sharp_frames)),
      Row("linear_solver", "solver", "reconstruct video", kReconstructKey, Text("CGNR"),
          "Ceres linear solver: CGNR | SPARSE_NORMAL_CHOLESKY | ITERATIVE_SCHUR | DENSE_QR ...",
          Custom("reconstruct.method.reconstruction.solver.linear_solver_type", SetLinearSolver)),
      Row("preconditioner", "solver", "reconstruct video", kReconstructKey, Text("JACOBI"),
          "Ceres preconditioner: JACOBI | IDENTITY | SUBSET (each pixel's temporal chain "
          "factorised "
          "exactly: fewer CG steps, dearer ones) | ...",
          Custom("reconstruct.method.reconstruction.solver.preconditioner_type",
                 SetPreconditioner)),
      Row("eta", "solver", "reconstruct video", kReconstructKey,
          Double(DefaultSolverOptions().eta, ValueRange::Above(0.0)),
          "Inexact Newton forcing sequence: CG stops at relative residual eta.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.solver.eta)),
      Row("max_iterations", "solver", "reconstruct video", kReconstructKey,
          Int32(DefaultSolverOptions().max_num_iterations, ValueRange::AtLeast(0)),
          "Most Levenberg-Marquardt iterations.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.solver.max_num_iterations)),
      Row("max_linear_iterations", "solver", "reconstruct video", kReconstructKey,
          Int32(DefaultSolverOptions().max_linear_solver_iterations, ValueRange::AtLeast(1)),
          "Most CG iterations per LM step.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.solver.max_linear_solver_iterations)),
      Row("max_time_s", "solver", "reconstruct video", kReconstructKey,
          Double(1e6, ValueRange::AtLeast(0.0)),
          "Time budget in seconds of the whole solve of reconstruct (every stage, part, band and "
          "plug & play iteration together) or of each window of video: the solve ends with the "
          "answer it has (summary.json solver.stopped_early says so).",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.solver.max_solver_time_in_seconds)),
      Row("bounds_line_search_iterations", "solver", "reconstruct video", kReconstructKey,
          Int32(DefaultSolverOptions().max_num_line_search_step_size_iterations,
                ValueRange::AtLeast(0)),
          "Steps of Ceres' projected line search after each bounded trust-region step (0: none; "
          "the step is only projected onto the bounds).",
          EVFS_OPTION_FIELD(
              reconstruct.method.reconstruction.solver.max_num_line_search_step_size_iterations)),
      Row("function_tolerance", "solver", "reconstruct video", kReconstructKey,
          Double(DefaultSolverOptions().function_tolerance, ValueRange::AtLeast(0.0)),
          "Stop when the relative cost change falls below this.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.solver.function_tolerance)),
      Row("threads", "solver", "reconstruct video", kReconstructKey | kNotInFingerprint,
          Int32(DefaultSolverOptions().num_threads, ValueRange::Between(1, kMaxThreads)),
          "Threads for Jacobian evaluation and the linear solver.",
          EVFS_OPTION_FIELD(reconstruct.method.reconstruction.solver.num_threads)),
      Row("in", "denoiser", "denoise", 0, Text(""),
          "denoise: the reconstruction folder (written by evfs reconstruct).", Unbound()),
      Row("denoise", "denoiser", "reconstruct video", kReconstructKey, Text("auto"),
          "reconstruct: none | once (the residual denoiser after the solve) | pnp (plug & play: "
          "ADMM between the Ceres problem and the denoiser, ceres_lm only) | auto (once when "
          "--denoiser is given; otherwise none: the shipped network, trained on simulated events, "
          "softens real recordings; BENCHMARKS.md \"Residual denoiser\").",
          Custom("denoise", SetDenoise)),
      Row("denoiser", "denoiser", "reconstruct denoise video", kReconstructKey, Text(""),
          "The denoiser's ONNX weights (reconstruct, denoise); empty: the shipped "
          "models/evfs_denoiser.onnx.",
          EVFS_OPTION_FIELD(reconstruct.denoise.denoiser.weights_path)),
      Row("denoise_consistency", "denoiser", "reconstruct video", kReconstructKey,
          Bool(DenoiseRequest().consistency),
          "--denoise=once: keep the recording's own frames as the solve matched them (the part of "
          "the denoiser's correction that would change a frame's exposure mean is taken out; "
          "BENCHMARKS.md \"Residual denoiser\"); false applies the network's correction as it "
          "is.",
          EVFS_OPTION_FIELD(reconstruct.denoise.consistency)),
      Row("denoise_gate", "denoiser", "reconstruct video", kReconstructKey,
          Bool(DenoiseRequest().gate),
          "--denoise=once: weigh the network's correction per pixel by the solve's predicted "
          "error sigma (OUT/confidence), w = sigma^2 / (sigma^2 + tau^2), so that it corrects "
          "only where the solve is unsure.",
          EVFS_OPTION_FIELD(reconstruct.denoise.gate)),
      Row("denoise_gate_tau", "denoiser", "reconstruct video", kReconstructKey,
          Double(DenoiseRequest().gate_tau, ValueRange::AtLeast(0.0)),
          "--denoise_gate: tau in intensity units; 0: 24 x the frames' noise sigma.",
          EVFS_OPTION_FIELD(reconstruct.denoise.gate_tau)),
      Row("jobs", "solver", "video", kNotInFingerprint,
          Int32(0, ValueRange::Between(0, kMaxThreads)),
          "video: windows solved at once; 0: every core.", EVFS_OPTION_FIELD(video.jobs)),
      Row("resume", "output", "video", kNotInFingerprint, Bool(false),
          "video: reuse the windows an interrupted run of the same command finished (kept in "
          ".OUT.evfs-video-work beside OUT). A window whose frames or events changed in the "
          "recording since is solved again, and stderr says how many.",
          EVFS_OPTION_FIELD(video.resume)),
      Row("preview", "output", "video", 0, Bool(false),
          "video: also preview.mp4, side by side: last observed frame | reconstruction | the "
          "step's events (red ON, blue OFF).",
          EVFS_OPTION_FIELD(video.preview)),
      Row("report", "output", "reconstruct video", kNotInFingerprint, Bool(false),
          "video, reconstruct: also report.html, one offline page of the run: the video and "
          "preview, events, iterations, solve time and PSNR per window (reconstruct: the "
          "frames, truth and baseline, the solve), confidence maps, event model, settings.",
          EVFS_OPTION_FIELD(video.report)),
      Row("predict_tail", "data", "video", 0, Bool(true),
          "video: predict after the recording's last frame up to the last event.",
          EVFS_OPTION_FIELD(video.windows.predict_tail)),
      Row("predict_max_s", "data", "video", 0, Double(0.0, ValueRange::Between(0.0, kMaxDurationS)),
          "video: longest prediction after the last frame, seconds; 0: the median gap between "
          "observed frames.",
          EVFS_OPTION_FIELD(video.windows.predict_max_s)),
      Row("min_blur_exposure_s", "data", "video", 0,
          Double(0.0, ValueRange::Between(0.0, kMaxDurationS)),
          "video: a frame whose exposure is at least this long is deblurred (observed over its "
          "exposure); 0: every frame with a known exposure.",
          EVFS_OPTION_FIELD(video.windows.min_blur_exposure_s)),
      Row("blur_from_data", "data", "video", 0, Bool(VideoWindowOptions().blur_from_data),
          "video: decide from each frame and the events inside its exposure whether the exposure "
          "blurred it (the blur the events predict against the frame's own noise); false: every "
          "frame with a known exposure of at least --min_blur_exposure_s is blurred.",
          EVFS_OPTION_FIELD(video.windows.blur_from_data)),
      Row("frame_step", "data", "video", 0, Int32(1, ValueRange::Between(1, 1000000)),
          "video: observe every N-th frame and score the frames between (ground truth); 1: every "
          "frame.",
          EVFS_OPTION_FIELD(video.windows.frame_step)),
      Row("skip_bad_frames", "data", "video", 0, Bool(false),
          "video: leave out missing or unreadable frames and reconstruct across the gap.",
          EVFS_OPTION_FIELD(video.skip_bad_frames)),
      Row("allow_outside_paths", "data", "info reconstruct convert video simulate calibrate", 0,
          Bool(false),
          "read frames that images.txt names outside the recording's folder (absolute paths, "
          "'..').",
          Unbound()),
      Row("threshold_pos", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().contrast_threshold_pos, ValueRange::Above(0.0)),
          "simulate: ON contrast threshold (log intensity).",
          EVFS_OPTION_FIELD(simulator.contrast_threshold_pos)),
      Row("threshold_neg", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().contrast_threshold_neg, ValueRange::Above(0.0)),
          "simulate: OFF contrast threshold (log intensity).",
          EVFS_OPTION_FIELD(simulator.contrast_threshold_neg)),
      Row("threshold_sigma", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().threshold_sigma, ValueRange::AtLeast(0.0)),
          "simulate: per-pixel spread (std dev) of the thresholds.",
          EVFS_OPTION_FIELD(simulator.threshold_sigma)),
      Row("log_eps", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().log_eps, ValueRange::Above(0.0)),
          "simulate: offset b of the sensor's log intensity log(I + b).",
          EVFS_OPTION_FIELD(simulator.log_eps)),
      Row("refractory_s", "simulator", "simulate", kSimulateKey,
          Double(0.0, ValueRange::AtLeast(0.0)), "simulate: refractory period in seconds.",
          Custom("simulator.refractory_period_ns", SetRefractoryPeriod)),
      Row("noise_rate_hz", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().noise_rate_hz, ValueRange::AtLeast(0.0)),
          "simulate: background noise events per pixel per second.",
          EVFS_OPTION_FIELD(simulator.noise_rate_hz)),
      Row("seed", "simulator", "simulate", kSimulateKey,
          Uint64(SimulatorOptions().seed, ValueRange::AtLeast(0)), "simulate: random seed.",
          EVFS_OPTION_FIELD(simulator.seed)),
      Row("leak_rate_hz", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().leak_rate_hz, ValueRange::AtLeast(0.0)),
          "simulate: leak (ON) events per pixel per second (v2e's default: 0.1); 0: none.",
          EVFS_OPTION_FIELD(simulator.leak_rate_hz)),
      Row("leak_jitter_fraction", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().leak_jitter_fraction, ValueRange::AtLeast(0.0)),
          "simulate: per-pixel spread of the leak rate, a fraction of it (v2e).",
          EVFS_OPTION_FIELD(simulator.leak_jitter_fraction)),
      Row("cutoff_hz", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().cutoff_hz, ValueRange::Between(0.0, 1e6)),
          "simulate: photoreceptor cutoff frequency at full intensity in Hz, falling with "
          "intensity (v2e); 0: none.",
          EVFS_OPTION_FIELD(simulator.cutoff_hz)),
      Row("hot_pixel_fraction", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().hot_pixel_fraction, ValueRange::Between(0.0, 1.0)),
          "simulate: fraction of pixels that are hot.",
          EVFS_OPTION_FIELD(simulator.hot_pixel_fraction)),
      Row("hot_pixel_rate_hz", "simulator", "simulate", kSimulateKey,
          Double(SimulatorOptions().hot_pixel_rate_hz, ValueRange::Above(0.0)),
          "simulate: events per second of each hot pixel (random polarity).",
          EVFS_OPTION_FIELD(simulator.hot_pixel_rate_hz)),
      Row("flicker_led_hz", "simulator", "simulate", 0,
          Double(FlickerOptions().led_hz, ValueRange::Between(1.0, 1e5).Or(0.0)),
          "simulate: a blinking LED (square wave) at this frequency in Hz; 0: none. Needs "
          "--flicker_led_xy_px.",
          EVFS_OPTION_FIELD(flicker.led_hz)),
      Row("flicker_led_xy_px", "simulator", "simulate", 0, Text(""),
          "simulate: the LED disc's centre 'X,Y' in pixels.", Unbound()),
      Row("flicker_led_radius_px", "simulator", "simulate", 0,
          Double(FlickerOptions().led_radius_px, ValueRange::Above(0.0)),
          "simulate: the LED disc's radius in pixels.", EVFS_OPTION_FIELD(flicker.led_radius_px)),
      Row("flicker_led_intensity", "simulator", "simulate", 0,
          Double(FlickerOptions().led_intensity, ValueRange::Above(0.0)),
          "simulate: intensity the lit LED adds (1: white; above 1 saturates the frames).",
          EVFS_OPTION_FIELD(flicker.led_intensity)),
      Row("flicker_led_duty", "simulator", "simulate", 0,
          Double(FlickerOptions().led_duty, ValueRange::Inside(0.0, 1.0)),
          "simulate: fraction of each LED period it is lit.", EVFS_OPTION_FIELD(flicker.led_duty)),
      Row("mains_hz", "simulator", "simulate", 0,
          Double(FlickerOptions().mains_hz, ValueRange::Between(1.0, 1e5).Or(0.0)),
          "simulate: a mains lamp's flicker frequency in Hz (100 on 50 Hz mains, 120 on 60 Hz); 0: "
          "none.",
          EVFS_OPTION_FIELD(flicker.mains_hz)),
      Row("mains_depth", "simulator", "simulate", 0,
          Double(FlickerOptions().mains_depth, ValueRange::Between(0.0, 1.0)),
          "simulate: the lamp's modulation depth m: intensity times 1 + m sin(2 pi f t).",
          EVFS_OPTION_FIELD(flicker.mains_depth)),
      Row("mains_region_px", "simulator", "simulate", 0, Text(""),
          "simulate: the region 'X,Y,WIDTH,HEIGHT' in pixels the lamp lights; empty: the whole "
          "frame.",
          Unbound()),
      Row("frame_gain", "simulator", "simulate", 0,
          Double(FrameEffectsOptions().gain, ValueRange::Above(0.0)),
          "simulate: gain on the written frames before they clip at white (saturation).",
          EVFS_OPTION_FIELD(frame_effects.gain)),
      Row("read_noise_dn", "simulator", "simulate", 0,
          Double(FrameEffectsOptions().read_noise_dn, ValueRange::AtLeast(0.0)),
          "simulate: std dev of the frames' read noise in 8-bit DN.",
          EVFS_OPTION_FIELD(frame_effects.read_noise_dn)),
      Row("fpn_offset_dn", "simulator", "simulate", 0,
          Double(FrameEffectsOptions().fpn_offset_dn, ValueRange::AtLeast(0.0)),
          "simulate: std dev of the frames' per-pixel offset (fixed pattern) in 8-bit DN.",
          EVFS_OPTION_FIELD(frame_effects.fpn_offset_dn)),
      Row("fpn_gain_sigma", "simulator", "simulate", 0,
          Double(FrameEffectsOptions().fpn_gain_sigma, ValueRange::From(0.0, 1.0)),
          "simulate: std dev of the frames' per-pixel relative gain (fixed pattern).",
          EVFS_OPTION_FIELD(frame_effects.fpn_gain_sigma)),
      Row("progress", "progress", "reconstruct", kNotInFingerprint, Bool(false),
          "Print a line per solver iteration even when stderr is not a terminal (it slows a solve "
          "split into independent parts).",
          Unbound()),
      Row("progress_interval_s", "progress", "*", kNotInFingerprint,
          Double(5.0, ValueRange::AtLeast(0.0)),
          "While a command runs, a line on stderr (stage, iteration, elapsed time) every this many "
          "seconds, terminal or not; 0: none.",
          Unbound()),
  };
}

#undef EVFS_OPTION_FIELD
#undef EVFS_OPTION_PARSED
#undef EVFS_OPTION_NAMED

std::vector<std::string> Words(const std::string& text) {
  std::istringstream stream(text);
  std::vector<std::string> words;
  for (std::string word; stream >> word;) words.push_back(word);
  return words;
}

// Copies the thread count to every solver, resolves --denoise=auto, reads a calibrated event
// model and leaves a given b unsearched, as the options given say.
void FinishReconstructRequest(const OptionValues& values, EvfsSettings* settings) {
  ReconstructRequest& request = settings->reconstruct;
  MethodOptions& method = request.method;
  method.adam.num_threads = method.reconstruction.solver.num_threads;
  method.lbfgs.num_threads = method.reconstruction.solver.num_threads;
  // A b given, or read from a calibrated model, is not searched unless the search is asked for.
  if ((values.Given("log_offset") || !settings->event_model_file.empty()) &&
      !values.Given("log_offset_search")) {
    request.log_offset_search.clear();
  }
  if (!settings->event_model_file.empty()) {
    ReconstructionOptions& reconstruction = method.reconstruction;
    ApplyEventModelFile(settings->event_model_file, reconstruction.estimation,
                        values.Given("log_offset"), values.Given("alpha"),
                        values.Given("event_saturation"), &reconstruction.objective.event_model);
  }
  DenoiseRequest& denoise = request.denoise;
  if (settings->denoise == "auto") {
    denoise.mode = AutoDenoiseMode(denoise.denoiser.weights_path);
  } else {
    denoise.mode = ParseName(kDenoiseModeNames, settings->denoise, "--denoise");
  }
}

// Storage of the gflags flags registered from the table; never freed, as gflags' own.
template <typename T>
void RegisterFlag(const OptionDefinition& option, const T& default_value, const char* filename) {
  T* current = new T(default_value);
  T* default_storage = new T(default_value);
  gflags::FlagRegisterer(option.name.c_str(), option.help.c_str(), filename, current,
                         default_storage);
}

}  // namespace

bool OptionDefinition::ReadBy(const std::string& command) const {
  if (commands == "*") return true;
  const std::vector<std::string> readers = Words(commands);
  return std::find(readers.begin(), readers.end(), command) != readers.end();
}

const std::vector<OptionDefinition>& EvfsOptions() {
  static const std::vector<OptionDefinition>* const options =
      new std::vector<OptionDefinition>(MakeEvfsOptions());
  return *options;
}

const std::vector<std::string>& EvfsOptionGroups() {
  static const std::vector<std::string>* const groups =
      new std::vector<std::string>{"data",   "output",   "method",    "binning", "model",
                                   "solver", "denoiser", "simulator", "progress"};
  return *groups;
}

const OptionDefinition* FindEvfsOption(const std::string& name) {
  for (const OptionDefinition& option : EvfsOptions()) {
    if (option.name == name) return &option;
  }
  return nullptr;
}

std::vector<FlagHelp> EvfsFlagHelp() {
  std::vector<FlagHelp> rows;
  for (const OptionDefinition& option : EvfsOptions()) {
    rows.push_back({option.name, option.group, option.commands});
  }
  return rows;
}

std::string OptionValueText(const OptionValue& value) {
  char text[64];
  switch (value.index()) {
    case 0:
      return std::get<bool>(value) ? "true" : "false";
    case 1:
      return std::to_string(std::get<int32_t>(value));
    case 2:
      std::snprintf(text, sizeof(text), "%" PRId64, std::get<int64_t>(value));
      return text;
    case 3:
      std::snprintf(text, sizeof(text), "%" PRIu64, std::get<uint64_t>(value));
      return text;
    case 4:
      std::snprintf(text, sizeof(text), "%.17g", std::get<double>(value));
      return text;
    default:
      return std::get<std::string>(value);
  }
}

OptionValues::OptionValues() {
  for (const OptionDefinition& option : EvfsOptions()) {
    values_[option.name] = option.default_value;
  }
}

void OptionValues::Set(const std::string& name, OptionValue value) {
  const auto it = values_.find(name);
  CHECK(it != values_.end()) << "no option --" << name;
  CHECK_EQ(it->second.index(), value.index()) << "--" << name << ": a value of another type";
  const ValueRange& range = FindEvfsOption(name)->range;
  const std::optional<double> number = NumberOf(value);
  if (number && !range.Contains(*number)) {
    throw InvalidArgumentError("--" + name + " must be " + range.Text() + ", not " +
                               RangeNumberText(*number));
  }
  it->second = std::move(value);
  given_.insert(name);
}

const OptionValue& OptionValues::Get(const std::string& name) const {
  const auto it = values_.find(name);
  CHECK(it != values_.end()) << "no option --" << name;
  return it->second;
}

void OptionValues::Apply(const std::string& prefix, EvfsSettings* settings,
                         const std::set<std::string>& skip) const {
  for (const OptionDefinition& option : EvfsOptions()) {
    if (option.field.empty() || option.field.compare(0, prefix.size(), prefix) != 0) continue;
    if (skip.count(option.name)) continue;
    option.set(Get(option.name), "--" + option.name, settings);
  }
}

BinningOptions BinningFromOptions(const OptionValues& values) {
  EvfsSettings settings;
  values.Apply("reconstruct.binning.", &settings);
  return settings.reconstruct.binning;
}

ReconstructRequest ReconstructRequestFromOptions(const OptionValues& values, bool with_mode) {
  EvfsSettings settings;
  std::set<std::string> skip;
  if (!with_mode) skip.insert("mode");
  values.Apply("reconstruct.", &settings, skip);
  values.Apply("denoise", &settings);
  FinishReconstructRequest(values, &settings);
  if (with_mode) settings.reconstruct.options = OptionsReadBy(values, "reconstruct");
  return settings.reconstruct;
}

std::vector<std::pair<std::string, std::string>> OptionsReadBy(const OptionValues& values,
                                                               const std::string& command) {
  std::vector<std::pair<std::string, std::string>> options;
  for (const OptionDefinition& option : EvfsOptions()) {
    if (option.ReadBy(command) && !(option.uses & kNotInFingerprint))
      options.emplace_back(option.name, OptionValueText(values.Get(option.name)));
  }
  std::sort(options.begin(), options.end());
  return options;
}

VideoRequest VideoRequestFromOptions(const OptionValues& values) {
  const ReconstructRequest reconstruct = ReconstructRequestFromOptions(values, false);
  EvfsSettings settings;
  values.Apply("video.", &settings);
  VideoRequest request = settings.video;
  request.data_path = reconstruct.data_path;
  request.data_options = reconstruct.data_options;
  request.windows.first = std::max(reconstruct.first, 0);
  request.windows.last = reconstruct.last;
  request.windows.exposure_s = reconstruct.exposure_s;
  request.fps = reconstruct.fps;
  // --threads given: every window's solve uses it; otherwise the cores left by --jobs.
  request.threads_per_window =
      values.Given("threads") ? reconstruct.method.reconstruction.solver.num_threads : 0;
  request.binning = reconstruct.binning;
  request.method = reconstruct.method;
  request.log_offset_search = reconstruct.log_offset_search;
  request.denoise = reconstruct.denoise;
  request.settings = VideoFingerprint(values);
  return request;
}

std::string VideoFingerprint(const OptionValues& values) {
  std::vector<const OptionDefinition*> options;
  for (const OptionDefinition& option : EvfsOptions()) {
    if (!(option.uses & kNotInFingerprint)) options.push_back(&option);
  }
  std::sort(options.begin(), options.end(),
            [](const OptionDefinition* a, const OptionDefinition* b) { return a->name < b->name; });
  std::string settings;
  for (const OptionDefinition* option : options) {
    settings += option->name + "=" + OptionValueText(values.Get(option->name)) + " ";
  }
  // A calibration file edited in place keeps its path: its bytes decide the model.
  const std::string& event_model = values.String("event_model");
  if (IsEventModelFile(event_model)) {
    settings += "event_model_file_bytes=" + EventModelFileFingerprint(event_model) + " ";
  }
  return settings;
}

SimulatorOptions SimulatorFromOptions(const OptionValues& values) {
  EvfsSettings settings;
  values.Apply("simulator.", &settings);
  return settings.simulator;
}

FlickerOptions FlickerFromOptions(const OptionValues& values) {
  EvfsSettings settings;
  values.Apply("flicker.", &settings);
  return settings.flicker;
}

FrameEffectsOptions FrameEffectsFromOptions(const OptionValues& values) {
  EvfsSettings settings;
  values.Apply("frame_effects.", &settings);
  FrameEffectsOptions frame_effects = settings.frame_effects;
  // The frames' exposure and noise are those of the recording the simulator writes.
  frame_effects.exposure_s = values.Double("exposure_s");
  frame_effects.seed = std::get<uint64_t>(values.Get("seed"));
  return frame_effects;
}

std::vector<double> ParseNumberList(const std::string& list, const std::string& flag) {
  std::vector<double> numbers;
  std::stringstream stream(list);
  for (std::string item; std::getline(stream, item, ',');) {
    size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size()) {
      throw InvalidArgumentError(flag + " must be comma-separated numbers, not '" + item + "'");
    }
    numbers.push_back(value);
  }
  return numbers;
}

void RegisterEvfsFlags(const char* filename) {
  for (const OptionDefinition& option : EvfsOptions()) {
    std::visit([&](const auto& value) { RegisterFlag(option, value, filename); },
               option.default_value);
  }
}

OptionValues OptionValuesFromFlags() {
  OptionValues values;
  for (const OptionDefinition& option : EvfsOptions()) {
    gflags::CommandLineFlagInfo info;
    CHECK(gflags::GetCommandLineFlagInfo(option.name.c_str(), &info)) << option.name;
    if (info.is_default) continue;
    std::visit(
        [&](const auto& default_value) {
          using T = std::decay_t<decltype(default_value)>;
          values.Set(option.name, *static_cast<const T*>(info.flag_ptr));
        },
        option.default_value);
  }
  return values;
}

}  // namespace evfs
