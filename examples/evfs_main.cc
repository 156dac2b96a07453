// evfs — event-driven video frame synthesis from the command line (docs/guide.md).
//
//   evfs info        --data=DIR [--first=I --last=J]
//   evfs reconstruct --data=DIR --mode=interpolate|predict|deblur --first=I [--last=J]
//                    [--truth=K] --out=OUT [solver and model flags]
//   evfs video       --data=DIR --out=OUT [--fps=N --first=I --last=J --jobs=N --resume
//                    --preview] [--report] [solver and model flags]
//   evfs denoise     --in=RECONSTRUCTION_DIR --out=DIR [--denoiser=FILE.onnx]
//   evfs simulate    --frames=DIR --out=DIR [--threshold_pos=… --threshold_neg=… --seed=…]
//                    [sensor effects, light sources and frame effects]
//   evfs convert     --data=DIR|FILE.h5|FILE.aedat4|FILE.bag --out=FILE.h5|FILE.aedat4|DIR
//   evfs calibrate   --data=DIR [--first=I --last=J] --out=MODEL.json
//   evfs demo        --out=DIR
//
// Flags are read here and nowhere else; every failure that is the user's (a bad file, a bad
// flag) prints one line and exits with status 2.
#include <gflags/gflags.h>
#include <glog/logging.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "app/allocator_tuning.h"
#include "app/calibrate_job.h"
#include "app/crash_guard.h"
#include "app/demo.h"
#include "app/denoise_job.h"
#include "app/evfs_help.h"
#include "app/progress.h"
#include "app/reconstruct_job.h"
#include "app/reports.h"
#include "app/simulate_job.h"
#include "app/version_report.h"
#include "app/video_job.h"
#include "app/video_mpi.h"
#include "core/enum_names.h"
#include "core/error.h"
#include "core/time.h"
#include "core/version.h"
#include "events/binning.h"
#include "events/flicker.h"
#include "events/frame_effects.h"
#include "events/simulator.h"
#include "io/aedat4.h"
#include "io/data_source.h"
#include "io/frame_list.h"
#include "io/hdf5_io.h"
#include "io/output_target.h"
#include "io/text_folder.h"
#include "scene/scene.h"

// Input and output.
DEFINE_string(data, "",
              "Data folder (Event Camera Dataset layout), HDF5 event file or AEDAT 4 "
              "recording (.aedat4, from iniVation DV), AEDAT 2.0/3.1 file (jAER, cAER, "
              "v2e), or ROS 1 bag (.bag: dvs_msgs/EventArray and sensor_msgs/Image).");
DEFINE_string(events_topic, "",
              "ROS bag: the dvs_msgs/EventArray topic; empty: the first one in the bag.");
DEFINE_string(frames_topic, "",
              "ROS bag: the sensor_msgs/Image topic; empty: the first one in the bag.");
DEFINE_string(frames, "", "simulate: folder with images.txt ('t path' lines) and the frames.");
DEFINE_string(out, "",
              "Output folder (reconstruct, simulate, demo) or file (convert to .h5 or .aedat4): "
              "a new one, or an earlier output of the same command with --overwrite. Never "
              "the root, current or home folder, nor the input or a folder around it.");
DEFINE_bool(overwrite, false,
            "Replace --out when it holds an earlier output of the same command "
            "(marked by OUT/.evfs-output, or an .h5/.aedat4 file evfs wrote); nothing else is "
            "replaced.");
// Which frames.
DEFINE_int32(first, -1, "0-based images.txt line of the first (or blurred) frame.");
DEFINE_int32(last, -1,
             "interpolate: the last frame; predict: the frame whose time ends the window "
             "(default first + 1); info: with --first, the window to describe.");
DEFINE_int32(truth, -1, "Frame to score the reconstruction against (PSNR, SSIM); -1: none.");
DEFINE_string(mode, "", "interpolate | predict | deblur.");
DEFINE_double(exposure_s, 0.0,
              "deblur: exposure around the frame's timestamp, when the data "
              "has no exposures.txt. simulate: the written frames' exposure, each the mean of "
              "the scene over it (with exposures.txt); 0: the scene at the timestamp.");
DEFINE_double(fps, 0.0,
              "Resample the latent video to this uniform frame rate; 0 writes the "
              "latent frames themselves.");
DEFINE_string(frame_time, "instant",
              "interpolate, predict: the moment a sharp frame represents. instant: its "
              "timestamp; auto: its timestamp plus the lag that best explains the input frames' "
              "change by the events (evfs info --first --last prints it); a number: that lag in "
              "ms; start | middle | end: the mean over its exposure (exposures.txt, else "
              "--exposure_s) which the timestamp starts, centres or ends.");
// Method.
DEFINE_string(solver, "ceres_lm",
              "Method: ceres_lm (default: Levenberg-Marquardt in Ceres) | "
              "ceres_lbfgs | adam (the paper's optimiser and schedule, true l1) | adam_smooth "
              "(the same on the smoothed objective) | blend | copy | integrate | cf | edi "
              "(classical baselines).");
DEFINE_bool(checkpoints, false,
            "Record cost (and PSNR/SSIM against --truth) at every iteration "
            "of an iterative solver into summary.json.");
DEFINE_int32(adam_iterations, evfs::AdamOptions().max_iterations, "adam, adam_smooth: steps.");
DEFINE_double(adam_learning_rate, evfs::AdamOptions().learning_rate,
              "adam, adam_smooth: initial learning rate (divided by 5 every 200 steps).");
DEFINE_double(contrast_threshold, evfs::BaselineOptions().contrast_threshold,
              "integrate, cf, edi (and --init=events): change one event stands for; 0 derives "
              "it from the data.");
DEFINE_double(blur_sigma_px, evfs::BaselineOptions().blur_sigma_px,
              "integrate: Gaussian blur (pixels) after integration; 0: none.");
DEFINE_double(cf_cutoff_rad_per_s, evfs::BaselineOptions().cutoff_rad_per_s,
              "cf: crossover frequency of the complementary filter.");
// Binning.
DEFINE_string(binning, "auto",
              "auto | collision | stacked. auto: collision binning (the "
              "paper's), unless it gives more than --max_latent_frames frames or "
              "--max_latent_voxels voxels; collision or stacked beyond --max_latent_voxels is "
              "refused.");
DEFINE_int32(max_latent_frames, evfs::BinningOptions().max_latent_frames,
             "auto binning: most latent steps before switching to "
             "stacked equal-time binning with this many frames.");
DEFINE_int32(min_latent_steps, evfs::BinningOptions().min_latent_steps,
             "auto binning: collision frames split in time until the window has this many "
             "latent steps (within --max_latent_frames and --max_latent_voxels); 0: as they are.");
DEFINE_int64(max_latent_voxels, evfs::BinningOptions().max_latent_voxels,
             "Most pixels x latent frames, decided from event counts before anything is "
             "allocated; bounds memory and time (auto binning takes as many steps as fit).");
DEFINE_double(hot_pixel_factor, evfs::BinningOptions().hot_pixel_factor,
              "Leave out the events of hot pixels: those firing more than this many times as "
              "often as the window's busy pixels (the busiest outside the top 1 %); 0 keeps "
              "every event.");
DEFINE_double(saturation_level, evfs::BinningOptions().saturation_level,
              "A frame pixel at or above this level (intensity in [0, 1]) is saturated "
              "(--flicker_min_reversals, --leave_out_saturated); above 1: none is.");
DEFINE_bool(leave_out_saturated, evfs::BinningOptions().leave_out_saturated,
            "Leave out the events of pixels saturated in every frame of the window (the frames "
            "cannot show what they record).");
DEFINE_int32(flicker_min_reversals, evfs::BinningOptions().flicker_min_reversals,
             "Leave out the events of pixels whose events reverse polarity at least this many "
             "times in the window with almost no net change (a blinking LED, a mains-powered "
             "lamp), next to a pixel a frame shows saturated: the frames govern there; 0 keeps "
             "them.");
DEFINE_double(noise_filter_ms, evfs::BinningOptions().noise_filter_ms,
              "Leave out events that no neighbouring pixel confirms within this many ms "
              "(background-activity filter); 0 keeps every event.");
DEFINE_int32(stacked_frames, evfs::BinningOptions().stacked.num_frames,
             "stacked binning: number of event frames.");
// Objective.
DEFINE_double(frame_weight, evfs::ObjectiveOptions().frame_weight, "Weight of the frame term.");
DEFINE_double(event_weight, evfs::ObjectiveOptions().event_weight,
              "lambda_e: weight of the event term.");
DEFINE_double(spatial_tv_weight, evfs::ObjectiveOptions().spatial_tv_weight,
              "lambda_xy: weight of spatial total variation.");
DEFINE_double(temporal_tv_weight, evfs::ObjectiveOptions().temporal_tv_weight,
              "lambda_t: weight of temporal total variation.");
DEFINE_double(alpha, 0.0,
              "alpha of tanh(alpha * dg); 0 derives it from the data's contrast "
              "threshold (printed).");
DEFINE_double(event_saturation, 0.0,
              "c of the event model c tanh(alpha dg / c), >= 1 (1: the paper's); 0 derives it: "
              "above 1 when the change per event is measured between two frames, else 1.");
DEFINE_bool(per_polarity_alpha, evfs::EventModelEstimationOptions().per_polarity,
            "With a derived alpha measured between two frames: measure the change per event "
            "apart for ON and OFF events (DAVIS thresholds differ) and give darkening steps "
            "their own alpha.");
DEFINE_string(event_model, evfs::EventModelName(evfs::ObjectiveOptions().event_model.model),
              "log (g(x) = log(x + b), paper Eq. 1) | linear (g(x) = x, paper Eq. 2) | "
              "FILE.json (written by evfs calibrate: the log model with the measured b, alpha "
              "from the ON threshold and the OFF/ON ratio; --log_offset, --alpha and "
              "--event_saturation given as well win).");
DEFINE_double(log_offset, evfs::ObjectiveOptions().event_model.log_offset,
              "b of the log event model.");
DEFINE_string(spatial_tv, "anisotropic",
              "paper (|dx+dy|) | anisotropic (|dx|+|dy|) | "
              "isotropic (sqrt(dx^2+dy^2)).");
DEFINE_bool(shared_structure_tv, evfs::ObjectiveOptions().shared_structure_tv,
            "Between two sharp frames, measure spatial TV from the structure both frames show in "
            "place (minmod of their differences): texture they share is kept, moved edges are "
            "not.");
DEFINE_double(smoothing_scale, evfs::ObjectiveOptions().smoothing_scale,
              "epsilon of the smoothed l1: sqrt(eps^2 + r^2) - eps.");
DEFINE_bool(bounds, true, "Keep intensities in [0, 1].");
DEFINE_int32(activity_radius_px, evfs::ReconstructionOptions().activity_radius_px,
             "Solve only pixels within this distance of an event of the "
             "window; the others keep their initial value. -1 solves every pixel.");
DEFINE_string(init, evfs::InitializationName(evfs::MethodOptions().initialization),
              "Where the solve starts: blend (the frames blended in time) | events (event "
              "integration from a sharp frame, else EDI for a blurred one).");
DEFINE_bool(merge_quiet_steps, evfs::ReconstructionOptions().merge_quiet_steps,
            "Hold a pixel "
            "constant between the latent steps where it fired (one unknown per quiet run); "
            "false: one unknown per voxel.");
DEFINE_bool(unfired_pixel_changes, evfs::ReconstructionOptions().unfired_pixel_changes,
            "With merged quiet steps, a pixel near the events that never fires gets one change "
            "after the last frame, at the median of its neighbours' events (false: it stays "
            "constant).");
DEFINE_bool(split_independent_parts, evfs::ReconstructionOptions().split_independent_parts,
            "Solve the regions that no term couples as separate problems, concurrently "
            "(one after another with --progress or --checkpoints); false: one problem.");
DEFINE_double(quiet_blend_fraction, evfs::ReconstructionOptions().quiet_blend_fraction,
              "After the solve, pixels no event fired whose sharp frames differ by less than "
              "this fraction of one event's change take the time-weighted blend of the frames "
              "between them; 0: off.");
DEFINE_double(step_ramp_px, evfs::ReconstructionOptions().step_ramp_px,
              "After the solve, each step of a solved pixel becomes a ramp that ends at the step "
              "and lasts the time the scene takes to move this many pixels there (measured "
              "from the events), begun no earlier than the middle of the segment before; 0: "
              "steps stay jumps.");
DEFINE_bool(meet_sharp_frames, evfs::ReconstructionOptions().meet_sharp_frames,
            "After the solve, each sharp frame's latent frame takes the frame's values, the "
            "offset fading out half-way to the next observation (or at the window's end); false: "
            "the solve's values.");
DEFINE_int64(max_problem_mb, evfs::ReconstructionOptions().max_problem_mb,
             "Most memory (MiB) the Ceres problems hold at once, estimated before building: "
             "larger problems are solved in batches of parts, or in overlapping bands of rows, "
             "one after another; <= 0: no limit.");
DEFINE_string(smoothing_continuation, "",
              "Comma-separated smoothing scales solved first, each starting the next, before "
              "--smoothing_scale (e.g. 0.2,0.1); empty: one solve.");
// Ceres.
DEFINE_string(linear_solver, "CGNR",
              "Ceres linear solver: CGNR | SPARSE_NORMAL_CHOLESKY | "
              "ITERATIVE_SCHUR | DENSE_QR ...");
DEFINE_string(preconditioner, "JACOBI", "Ceres preconditioner: JACOBI | IDENTITY | ...");
DEFINE_double(eta, evfs::DefaultSolverOptions().eta,
              "Inexact Newton forcing sequence: CG stops at relative residual eta.");
DEFINE_int32(max_iterations, evfs::DefaultSolverOptions().max_num_iterations,
             "Most Levenberg-Marquardt iterations.");
DEFINE_int32(max_linear_iterations, evfs::DefaultSolverOptions().max_linear_solver_iterations,
             "Most CG iterations per LM step.");
DEFINE_double(max_time_s, 1e6,
              "Time budget in seconds of the whole solve of reconstruct (every stage, part, band "
              "and plug & play iteration together) or of each window of video: the solve ends "
              "with the answer it has (summary.json solver.stopped_early says so).");
DEFINE_int32(bounds_line_search_iterations,
             evfs::DefaultSolverOptions().max_num_line_search_step_size_iterations,
             "Steps of Ceres' projected line search after each bounded trust-region step "
             "(0: none; the step is only projected onto the bounds).");
DEFINE_double(function_tolerance, evfs::DefaultSolverOptions().function_tolerance,
              "Stop when the relative cost change falls below this.");
DEFINE_int32(threads, evfs::DefaultSolverOptions().num_threads,
             "Threads for Jacobian evaluation and the linear solver.");
DEFINE_bool(progress, false,
            "Print a line per solver iteration even when stderr is not a "
            "terminal (it slows a solve split into independent parts).");
// The residual denoiser (paper §3.4).
DEFINE_string(denoise, "auto",
              "reconstruct: none | once (the residual denoiser after the solve) | pnp (plug & "
              "play: ADMM between the Ceres problem and the denoiser, ceres_lm only) | auto "
              "(once when --denoiser is given; otherwise none: the shipped network, trained on "
              "simulated events, softens real recordings; BENCHMARKS.md \"Residual denoiser\").");
DEFINE_string(denoiser, "",
              "The denoiser's ONNX weights (reconstruct, denoise); empty: the shipped "
              "models/evfs_denoiser.onnx.");
DEFINE_bool(
    denoise_consistency, evfs::DenoiseRequest().consistency,
    "--denoise=once: keep the recording's own frames as the solve matched them (the "
    "part of the denoiser's correction that would change a frame's exposure mean is "
    "taken out; BENCHMARKS.md \"Residual denoiser\"); false applies the network's correction "
    "as it is.");
DEFINE_bool(denoise_gate, evfs::DenoiseRequest().gate,
            "--denoise=once: weigh the network's correction per pixel by the solve's predicted "
            "error sigma (OUT/confidence), w = sigma^2 / (sigma^2 + tau^2), so that it corrects "
            "only where the solve is unsure.");
DEFINE_double(denoise_gate_tau, evfs::DenoiseRequest().gate_tau,
              "--denoise_gate: tau in intensity units, >= 0; 0: 24 x the frames' noise sigma.");
DEFINE_string(in, "", "denoise: the reconstruction folder (written by evfs reconstruct).");
DEFINE_double(progress_interval_s, 5.0,
              "While a command runs, a line on stderr (stage, "
              "iteration, elapsed time) every this many seconds, terminal or not; 0: none.");
// Video (evfs video).
DEFINE_int32(jobs, 0, "video: windows solved at once; 0: every core.");
DEFINE_bool(resume, false,
            "video: reuse the windows an interrupted run of the same command finished (kept in "
            ".OUT.evfs-video-work beside OUT). A window whose frames or events changed in the "
            "recording since is solved again, and stderr says how many.");
DEFINE_bool(preview, false,
            "video: also preview.mp4, side by side: last observed frame | reconstruction | the "
            "step's events (red ON, blue OFF).");
DEFINE_bool(report, false,
            "video: also report.html, one offline page of the run: the video and preview, "
            "events, iterations, solve time and PSNR per window, confidence maps, settings.");
DEFINE_bool(predict_tail, true,
            "video: predict after the recording's last frame up to the last event.");
DEFINE_double(predict_max_s, 0.0,
              "video: longest prediction after the last frame, seconds; 0: the median gap "
              "between observed frames.");
DEFINE_double(min_blur_exposure_s, 0.0,
              "video: a frame whose exposure is at least this long is deblurred (observed over "
              "its exposure); 0: every frame with a known exposure.");
DEFINE_bool(blur_from_data, evfs::VideoWindowOptions().blur_from_data,
            "video: decide from each frame and the events inside its exposure whether the "
            "exposure blurred it (the blur the events predict against the frame's own noise); "
            "false: every frame with a known exposure of at least --min_blur_exposure_s is "
            "blurred.");
DEFINE_int32(frame_step, 1,
             "video: observe every N-th frame and score the frames between (ground truth); 1: "
             "every frame.");
DEFINE_bool(skip_bad_frames, false,
            "video: leave out missing or unreadable frames and reconstruct across the gap.");
DEFINE_bool(allow_outside_paths, false,
            "read frames that images.txt names outside the recording's folder (absolute paths, "
            "'..').");
// Simulator.
DEFINE_double(threshold_pos, evfs::SimulatorOptions().contrast_threshold_pos,
              "simulate: ON contrast threshold (log intensity).");
DEFINE_double(threshold_neg, evfs::SimulatorOptions().contrast_threshold_neg,
              "simulate: OFF contrast threshold (log intensity).");
DEFINE_double(threshold_sigma, evfs::SimulatorOptions().threshold_sigma,
              "simulate: per-pixel spread (std dev) of the thresholds.");
DEFINE_double(log_eps, evfs::SimulatorOptions().log_eps,
              "simulate: offset b of the sensor's log intensity log(I + b), > 0.");
DEFINE_double(refractory_s, 0.0, "simulate: refractory period in seconds.");
DEFINE_double(noise_rate_hz, evfs::SimulatorOptions().noise_rate_hz,
              "simulate: background noise events per pixel per second.");
DEFINE_uint64(seed, evfs::SimulatorOptions().seed, "simulate: random seed.");
DEFINE_double(leak_rate_hz, evfs::SimulatorOptions().leak_rate_hz,
              "simulate: leak (ON) events per pixel per second (v2e's default: 0.1); 0: none.");
DEFINE_double(leak_jitter_fraction, evfs::SimulatorOptions().leak_jitter_fraction,
              "simulate: per-pixel spread of the leak rate, a fraction of it (v2e).");
DEFINE_double(cutoff_hz, evfs::SimulatorOptions().cutoff_hz,
              "simulate: photoreceptor cutoff frequency at full intensity in Hz, falling with "
              "intensity (v2e); 0: none.");
DEFINE_double(hot_pixel_fraction, evfs::SimulatorOptions().hot_pixel_fraction,
              "simulate: fraction of pixels that are hot, in [0, 1].");
DEFINE_double(hot_pixel_rate_hz, evfs::SimulatorOptions().hot_pixel_rate_hz,
              "simulate: events per second of each hot pixel (random polarity).");
DEFINE_double(flicker_led_hz, evfs::FlickerOptions().led_hz,
              "simulate: a blinking LED (square wave) at this frequency in Hz; 0: none. Needs "
              "--flicker_led_xy_px.");
DEFINE_string(flicker_led_xy_px, "", "simulate: the LED disc's centre 'X,Y' in pixels.");
DEFINE_double(flicker_led_radius_px, evfs::FlickerOptions().led_radius_px,
              "simulate: the LED disc's radius in pixels.");
DEFINE_double(flicker_led_intensity, evfs::FlickerOptions().led_intensity,
              "simulate: intensity the lit LED adds (1: white; above 1 saturates the frames).");
DEFINE_double(flicker_led_duty, evfs::FlickerOptions().led_duty,
              "simulate: fraction of each LED period it is lit, in (0, 1).");
DEFINE_double(mains_hz, evfs::FlickerOptions().mains_hz,
              "simulate: a mains lamp's flicker frequency in Hz (100 on 50 Hz mains, 120 on "
              "60 Hz); 0: none.");
DEFINE_double(mains_depth, evfs::FlickerOptions().mains_depth,
              "simulate: the lamp's modulation depth m in [0, 1]: intensity times 1 + m sin(2 pi "
              "f t).");
DEFINE_string(mains_region_px, "",
              "simulate: the region 'X,Y,WIDTH,HEIGHT' in pixels the lamp lights; empty: the "
              "whole frame.");
DEFINE_double(frame_gain, evfs::FrameEffectsOptions().gain,
              "simulate: gain on the written frames before they clip at white (saturation).");
DEFINE_double(read_noise_dn, evfs::FrameEffectsOptions().read_noise_dn,
              "simulate: std dev of the frames' read noise in 8-bit DN.");
DEFINE_double(fpn_offset_dn, evfs::FrameEffectsOptions().fpn_offset_dn,
              "simulate: std dev of the frames' per-pixel offset (fixed pattern) in 8-bit DN.");
DEFINE_double(fpn_gain_sigma, evfs::FrameEffectsOptions().fpn_gain_sigma,
              "simulate: std dev of the frames' per-pixel relative gain (fixed pattern).");

namespace evfs {
namespace {

void Require(bool condition, const std::string& message) {
  if (!condition) throw InvalidArgumentError(message);
}

// --out of `command`, checked (and its staging folder made) before any input is read.
OutputOptions OutputFromFlags(const std::string& command, const std::string& input) {
  OutputOptions options;
  options.path = FLAGS_out;
  options.command = command;
  options.overwrite = FLAGS_overwrite;
  options.inputs = {input};
  return options;
}

// --events_topic, --frames_topic: how --data is read.
DataSourceOptions DataOptionsFromFlags() {
  DataSourceOptions options;
  options.events_topic = FLAGS_events_topic;
  options.frames_topic = FLAGS_frames_topic;
  return options;
}

// The binning flags (reconstruct, and info's window).
BinningOptions BinningFromFlags() {
  BinningOptions binning;
  binning.method = ParseName(kBinningMethodNames, FLAGS_binning, "--binning");
  binning.max_latent_frames = FLAGS_max_latent_frames;
  binning.min_latent_steps = FLAGS_min_latent_steps;
  binning.max_latent_voxels = FLAGS_max_latent_voxels;
  binning.hot_pixel_factor = FLAGS_hot_pixel_factor;
  binning.saturation_level = FLAGS_saturation_level;
  binning.leave_out_saturated = FLAGS_leave_out_saturated;
  binning.flicker_min_reversals = FLAGS_flicker_min_reversals;
  binning.noise_filter_ms = FLAGS_noise_filter_ms;
  binning.stacked.num_frames = FLAGS_stacked_frames;
  return binning;
}

int RunInfo() {
  Require(!FLAGS_data.empty(), "info needs --data=DIR or --data=FILE.h5");
  const auto source = DataSource::Open(FLAGS_data, DataOptionsFromFlags());
  PrintRecording(*source, stdout);
  if (FLAGS_first >= 0 && source->has_events()) {
    const int last = FLAGS_last >= 0 ? FLAGS_last : FLAGS_first + 1;
    PrintWindow(*source, FLAGS_first, last, BinningFromFlags(), FLAGS_binning, stdout);
  }
  if (FLAGS_first >= 0) {
    PrintInfoCalibration(*source, FLAGS_data, FLAGS_first,
                         FLAGS_last >= 0 ? FLAGS_last : FLAGS_first + 1, stdout);
  } else {
    PrintInfoCalibration(*source, FLAGS_data, 0, FLAGS_last, stdout);
  }
  return 0;
}

int RunConvert() {
  Require(!FLAGS_data.empty() && !FLAGS_out.empty(), "convert needs --data and --out");
  OutputOptions options = OutputFromFlags("convert", FLAGS_data);
  if (IsHdf5Path(FLAGS_out)) {
    options.kind = OutputOptions::Kind::kFile;
    options.is_own_file = IsHdf5WrittenByEvfs;
  } else if (IsAedat4Path(FLAGS_out)) {
    options.kind = OutputOptions::Kind::kFile;
    options.is_own_file = IsAedat4WrittenByEvfs;
  }
  OutputTarget out(options);
  ConvertRecording(FLAGS_data, out.staging(), DataOptionsFromFlags());
  out.Commit();
  std::printf("wrote %s\n", out.path().c_str());
  return 0;
}

// "0.2,0.1" → {0.2, 0.1}; "" → {}. Throws InvalidArgumentError naming `flag` for a non-number.
std::vector<double> ParseNumberList(const std::string& list, const char* flag) {
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
      throw InvalidArgumentError(std::string(flag) + " must be comma-separated numbers, not '" +
                                 item + "'");
    }
    numbers.push_back(value);
  }
  return numbers;
}

int RunSimulate() {
  Require(!FLAGS_frames.empty() && !FLAGS_out.empty(), "simulate needs --frames=DIR and --out=DIR");
  SimulatorOptions options;
  options.contrast_threshold_pos = FLAGS_threshold_pos;
  options.contrast_threshold_neg = FLAGS_threshold_neg;
  options.threshold_sigma = FLAGS_threshold_sigma;
  options.log_eps = FLAGS_log_eps;
  options.refractory_period_ns = SecondsToNanoseconds(FLAGS_refractory_s);
  options.noise_rate_hz = FLAGS_noise_rate_hz;
  options.seed = FLAGS_seed;
  options.leak_rate_hz = FLAGS_leak_rate_hz;
  options.leak_jitter_fraction = FLAGS_leak_jitter_fraction;
  options.cutoff_hz = FLAGS_cutoff_hz;
  options.hot_pixel_fraction = FLAGS_hot_pixel_fraction;
  options.hot_pixel_rate_hz = FLAGS_hot_pixel_rate_hz;
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("simulator: " + error);

  FlickerOptions flicker;
  flicker.led_hz = FLAGS_flicker_led_hz;
  if (flicker.led_hz != 0.0 || !FLAGS_flicker_led_xy_px.empty()) {
    const std::vector<double> xy = ParseNumberList(FLAGS_flicker_led_xy_px, "--flicker_led_xy_px");
    Require(xy.size() == 2, "--flicker_led_hz needs --flicker_led_xy_px=X,Y (the LED's centre)");
    Require(flicker.led_hz != 0.0, "--flicker_led_xy_px needs --flicker_led_hz");
    flicker.led_x_px = xy[0];
    flicker.led_y_px = xy[1];
  }
  flicker.led_radius_px = FLAGS_flicker_led_radius_px;
  flicker.led_intensity = FLAGS_flicker_led_intensity;
  flicker.led_duty = FLAGS_flicker_led_duty;
  flicker.mains_hz = FLAGS_mains_hz;
  flicker.mains_depth = FLAGS_mains_depth;
  if (!FLAGS_mains_region_px.empty()) {
    const std::vector<double> region = ParseNumberList(FLAGS_mains_region_px, "--mains_region_px");
    Require(
        region.size() == 4 &&
            std::all_of(region.begin(), region.end(),
                        [](double v) { return v >= 0.0 && v <= 65536.0 && v == std::floor(v); }),
        "--mains_region_px must be X,Y,WIDTH,HEIGHT: four whole numbers in [0, 65536]");
    flicker.mains_x_px = static_cast<int>(region[0]);
    flicker.mains_y_px = static_cast<int>(region[1]);
    flicker.mains_width_px = static_cast<int>(region[2]);
    flicker.mains_height_px = static_cast<int>(region[3]);
  }
  if (!flicker.IsValid(&error)) throw InvalidArgumentError("light sources: " + error);

  FrameEffectsOptions frame_effects;
  frame_effects.exposure_s = FLAGS_exposure_s;
  frame_effects.gain = FLAGS_frame_gain;
  frame_effects.read_noise_dn = FLAGS_read_noise_dn;
  frame_effects.fpn_offset_dn = FLAGS_fpn_offset_dn;
  frame_effects.fpn_gain_sigma = FLAGS_fpn_gain_sigma;
  frame_effects.seed = FLAGS_seed;
  if (!frame_effects.IsValid(&error)) throw InvalidArgumentError("frame effects: " + error);

  OutputTarget out(OutputFromFlags("simulate", FLAGS_frames));
  const SimulateSummary summary =
      SimulateRecording(FLAGS_frames, options, out.staging(), flicker, frame_effects);
  out.Commit();
  std::printf("simulated %lld events over %d frames (%dx%d) into %s\n",
              static_cast<long long>(summary.events), summary.frames, summary.width, summary.height,
              out.path().c_str());
  return 0;
}

// Whether flag `name` was left at its default (not given on the command line).
bool FlagIsDefault(const char* name) {
  gflags::CommandLineFlagInfo info;
  gflags::GetCommandLineFlagInfo(name, &info);
  return info.is_default;
}

int RunCalibrate() {
  Require(!FLAGS_data.empty(), "calibrate needs --data=DIR or --data=FILE.h5");
  Require(!FLAGS_out.empty(), "calibrate needs --out=MODEL.json");
  Require(IsEventModelFile(FLAGS_out), "calibrate: --out must name a .json file");
  Require(FLAGS_first >= -1 && FLAGS_last >= -1,
          "--first, --last: a frame number must be 0 or more");
  CalibrateRequest request;
  request.data_path = FLAGS_data;
  request.first = FLAGS_first;
  request.last = FLAGS_last;
  request.options.saturation_level = FLAGS_saturation_level;
  OutputOptions options = OutputFromFlags("calibrate", FLAGS_data);
  options.kind = OutputOptions::Kind::kFile;
  options.is_own_file = [](const std::string& path) {
    std::ifstream file(path);
    std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    return text.find("\"evfs_calibration\"") != std::string::npos;
  };
  OutputTarget out(options);
  const CalibrateResult result = RunCalibration(request);
  WriteCalibration(request, result, out.staging());
  out.Commit();
  PrintCalibration(request, result, out.path(), stdout);
  return 0;
}

// The request of the reconstruct flags; `with_mode` false for `video`, which has no --mode.
ReconstructRequest RequestFromFlags(bool with_mode = true) {
  ReconstructRequest request;
  request.data_path = FLAGS_data;
  request.data_options = DataOptionsFromFlags();
  if (with_mode) request.mode = ParseMode(FLAGS_mode);
  request.first = FLAGS_first;
  request.last = FLAGS_last;
  request.truth = FLAGS_truth;
  request.exposure_s = FLAGS_exposure_s;
  request.fps = FLAGS_fps;
  if (!ParseFrameTime(FLAGS_frame_time, &request.frame_time, &request.frame_lag_s)) {
    throw InvalidArgumentError(
        "--frame_time: expected instant, auto, start, middle, end or a lag in ms, got '" +
        FLAGS_frame_time + "'");
  }

  request.binning = BinningFromFlags();

  MethodOptions& method = request.method;
  method.method = ParseMethod(FLAGS_solver);
  method.initialization = ParseInitialization(FLAGS_init);
  method.adam.max_iterations = FLAGS_adam_iterations;
  method.adam.learning_rate = FLAGS_adam_learning_rate;
  method.adam.num_threads = FLAGS_threads;
  method.lbfgs.num_threads = FLAGS_threads;
  method.baseline.contrast_threshold = FLAGS_contrast_threshold;
  method.baseline.blur_sigma_px = FLAGS_blur_sigma_px;
  method.baseline.cutoff_rad_per_s = FLAGS_cf_cutoff_rad_per_s;
  request.checkpoints = FLAGS_checkpoints;

  ReconstructionOptions& options = method.reconstruction;
  ObjectiveOptions& objective = options.objective;
  objective.frame_weight = FLAGS_frame_weight;
  objective.event_weight = FLAGS_event_weight;
  objective.spatial_tv_weight = FLAGS_spatial_tv_weight;
  objective.temporal_tv_weight = FLAGS_temporal_tv_weight;
  objective.event_model.alpha = FLAGS_alpha;
  objective.event_model.log_offset = FLAGS_log_offset;
  objective.event_model.saturation = FLAGS_event_saturation;
  options.estimation.per_polarity = FLAGS_per_polarity_alpha;
  objective.smoothing_scale = FLAGS_smoothing_scale;
  if (IsEventModelFile(FLAGS_event_model)) {
    // The calibrated model; a model flag given on the command line as well wins.
    ApplyEventModelFile(FLAGS_event_model, options.estimation, !FlagIsDefault("log_offset"),
                        !FlagIsDefault("alpha"), !FlagIsDefault("event_saturation"),
                        &objective.event_model);
  } else {
    objective.event_model.model = ParseName(kEventModelNames, FLAGS_event_model, "--event_model");
  }
  objective.spatial_tv = ParseName(kSpatialTvNames, FLAGS_spatial_tv, "--spatial_tv");
  objective.shared_structure_tv = FLAGS_shared_structure_tv;
  options.bound_intensities = FLAGS_bounds;
  options.activity_radius_px = FLAGS_activity_radius_px;
  options.merge_quiet_steps = FLAGS_merge_quiet_steps;
  options.unfired_pixel_changes = FLAGS_unfired_pixel_changes;
  options.split_independent_parts = FLAGS_split_independent_parts;
  options.max_problem_mb = FLAGS_max_problem_mb;
  options.quiet_blend_fraction = FLAGS_quiet_blend_fraction;
  options.step_ramp_px = FLAGS_step_ramp_px;
  options.meet_sharp_frames = FLAGS_meet_sharp_frames;
  options.smoothing_continuation =
      ParseNumberList(FLAGS_smoothing_continuation, "--smoothing_continuation");

  ceres::Solver::Options& solver = options.solver;
  Require(ceres::StringToLinearSolverType(FLAGS_linear_solver, &solver.linear_solver_type),
          "unknown --linear_solver " + FLAGS_linear_solver);
  Require(ceres::StringToPreconditionerType(FLAGS_preconditioner, &solver.preconditioner_type),
          "unknown --preconditioner " + FLAGS_preconditioner);
  solver.eta = FLAGS_eta;
  solver.max_num_iterations = FLAGS_max_iterations;
  solver.max_linear_solver_iterations = FLAGS_max_linear_iterations;
  solver.max_solver_time_in_seconds = FLAGS_max_time_s;
  solver.function_tolerance = FLAGS_function_tolerance;
  solver.max_num_line_search_step_size_iterations = FLAGS_bounds_line_search_iterations;
  solver.num_threads = FLAGS_threads;

  request.denoise.denoiser.weights_path = FLAGS_denoiser;
  request.denoise.consistency = FLAGS_denoise_consistency;
  request.denoise.gate = FLAGS_denoise_gate;
  request.denoise.gate_tau = FLAGS_denoise_gate_tau;
  if (FLAGS_denoise == "auto") {
    request.denoise.mode = AutoDenoiseMode(FLAGS_denoiser);
  } else {
    request.denoise.mode = ParseName(kDenoiseModeNames, FLAGS_denoise, "--denoise");
  }
  return request;
}

int RunDenoise() {
  Require(!FLAGS_in.empty(), "denoise needs --in=RECONSTRUCTION_DIR");
  Require(!FLAGS_out.empty(), "denoise needs --out=DIR");
  DenoiseRequest request;
  request.mode = DenoiseMode::kOnce;
  request.denoiser.weights_path = FLAGS_denoiser;
  OutputTarget out(OutputFromFlags("denoise", FLAGS_in));
  const std::unique_ptr<Denoiser> denoiser = LoadDenoiser(request);
  const DenoiseRecord record = DenoiseReconstructionFolder(FLAGS_in, *denoiser, out.staging());
  out.Commit();
  std::printf("denoised %d frames with %s in %.3f s into %s\n", record.stats.frames,
              record.weights_path.c_str(), record.stats.time_s, out.path().c_str());
  return 0;
}

int RunReconstruct(ProgressReporter* progress) {
  Require(!FLAGS_data.empty(), "reconstruct needs --data=DIR or --data=FILE.h5");
  Require(!FLAGS_out.empty(), "reconstruct needs --out=DIR");
  Require(FLAGS_first >= -1,
          "--first=" + std::to_string(FLAGS_first) + ": a frame number must be 0 or more");
  Require(FLAGS_first >= 0, "reconstruct needs --first=I (a 0-based images.txt line)");
  ReconstructRequest request = RequestFromFlags();
  OutputTarget out(OutputFromFlags("reconstruct", FLAGS_data));
  // A line per iteration on a terminal; elsewhere the solve keeps its speed (an iteration
  // callback solves independent parts one after another).
  if (FLAGS_progress || ::isatty(STDERR_FILENO)) request.progress = progress->callback();
  request.stage = [progress](const char* stage) { progress->StartStage(stage); };
  ReconstructResult result = RunReconstruction(request);
  progress->StartStage("write");
  WriteReconstruction(request, &result, out.staging());
  out.Commit();

  PrintReconstruction(request, result, out.path(), stdout);
  return 0;
}

// Every flag that decides `evfs video`'s output, for --resume to check: all of evfs' own
// flags but those that only say where, how fast or how verbosely.
std::string VideoSettings() {
  static const char* const kNotSettings[] = {
      "out", "overwrite", "resume", "jobs", "threads", "progress", "progress_interval_s", "report"};
  std::string settings;
  std::vector<gflags::CommandLineFlagInfo> flags;
  gflags::GetAllFlags(&flags);
  for (const gflags::CommandLineFlagInfo& flag : flags) {
    if (flag.filename != __FILE__) continue;  // not one of evfs' own (MainHelp)
    if (std::find(std::begin(kNotSettings), std::end(kNotSettings), flag.name) !=
        std::end(kNotSettings)) {
      continue;
    }
    settings += flag.name + "=" + flag.current_value + " ";
  }
  // A calibration file edited in place keeps its path: its bytes decide the model.
  if (IsEventModelFile(FLAGS_event_model)) {
    settings += "event_model_file_bytes=" + EventModelFileFingerprint(FLAGS_event_model) + " ";
  }
  return settings;
}

int RunVideoCommand(ProgressReporter* progress) {
  Require(!FLAGS_data.empty(), "video needs --data=DIR or --data=FILE.h5");
  Require(!FLAGS_out.empty(), "video needs --out=DIR");
  Require(FLAGS_first >= -1,
          "--first=" + std::to_string(FLAGS_first) + ": a frame number must be 0 or more");
  Require(FLAGS_last >= -1,
          "--last=" + std::to_string(FLAGS_last) + ": a frame number must be 0 or more");
  const ReconstructRequest reconstruct = RequestFromFlags(/*with_mode=*/false);
  VideoRequest request;
  request.data_path = FLAGS_data;
  request.data_options = reconstruct.data_options;
  request.windows.first = std::max(FLAGS_first, 0);
  request.windows.last = FLAGS_last;
  request.windows.predict_tail = FLAGS_predict_tail;
  request.windows.predict_max_s = FLAGS_predict_max_s;
  request.windows.min_blur_exposure_s = FLAGS_min_blur_exposure_s;
  request.windows.blur_from_data = FLAGS_blur_from_data;
  request.windows.exposure_s = FLAGS_exposure_s;
  request.windows.frame_step = FLAGS_frame_step;
  request.fps = FLAGS_fps;
  request.jobs = FLAGS_jobs;
  // --threads given: every window's solve uses it; otherwise the cores left by --jobs.
  gflags::CommandLineFlagInfo threads;
  gflags::GetCommandLineFlagInfo("threads", &threads);
  request.threads_per_window = threads.is_default ? 0 : FLAGS_threads;
  request.skip_bad_frames = FLAGS_skip_bad_frames;
  request.resume = FLAGS_resume;
  request.preview = FLAGS_preview;
  request.report = FLAGS_report;
  request.binning = reconstruct.binning;
  request.method = reconstruct.method;
  request.denoise = reconstruct.denoise;
  request.settings = VideoSettings();
  request.notice = [](const std::string& line) {
    std::fprintf(stderr, "evfs video: %s\n", line.c_str());
  };
  std::string error;
  if (!request.IsValid(&error)) throw InvalidArgumentError(error);
  // Under mpirun: rank 0 writes, the other ranks solve the windows it hands out.
  std::unique_ptr<MpiVideoSession> mpi;
  if (LaunchedAsMpiJob()) mpi = std::make_unique<MpiVideoSession>();
  if (mpi != nullptr && mpi->rank() != 0) {
    const std::string out_path = mpi->Broadcast("");
    if (out_path.empty()) return kExitUserError;  // rank 0 refused --out and said why
    request.distribution = &mpi->distribution();
    try {
      RunVideo(request, out_path, "");
    } catch (const Error& failure) {
      std::fprintf(stderr, "evfs video: rank %d: %s\n", mpi->rank(), failure.what());
      std::fflush(stderr);
      mpi->WorkerFailed();  // rank 0 cleans up, then ends every rank
      return kExitUserError;
    }
    mpi->WorkerFinished();
    return 0;
  }
  std::unique_ptr<OutputTarget> target;
  try {
    target = std::make_unique<OutputTarget>(OutputFromFlags("video", FLAGS_data));
  } catch (const Error&) {
    if (mpi != nullptr) mpi->Broadcast("");
    throw;
  }
  OutputTarget& out = *target;
  if (mpi != nullptr) {
    mpi->Broadcast(out.path());
    request.distribution = &mpi->distribution();
  }
  const bool terminal = ::isatty(STDERR_FILENO);
  request.progress = [progress, terminal](const VideoProgress& state) {
    const std::string line = VideoProgressLine(state);
    if (terminal) {
      std::fprintf(stderr, "\r%s", line.c_str());
      if (state.windows_done == state.windows_total) std::fputc('\n', stderr);
    } else {
      progress->StartStage(line);
    }
  };
  progress->StartStage("windows");
  VideoResult result;
  try {
    result = RunVideo(request, out.path(), out.staging());
  } catch (const Error& failure) {
    if (mpi == nullptr) throw;
    // The workers wait for windows: one line, then every rank ends.
    std::fprintf(stderr, "evfs video: %s\n", failure.what());
    target.reset();
    mpi->Abort(kExitUserError);
  }
  out.Commit();
  RemoveVideoWorkFolder(out.path());
  for (const int frame : result.skipped_frames) {
    std::fprintf(stderr, "evfs video: left out unreadable frame %d\n", frame);
  }
  std::printf(
      "%d windows (%d resumed), %lld events, %lld frames at %g fps (%dx%d) into %s\n"
      "%.2f windows/s, %.0f events/s with %d jobs x %d threads; video.mp4 codec %s\n",
      result.windows, result.windows_resumed, static_cast<long long>(result.events),
      static_cast<long long>(result.output_frames), result.fps, result.width, result.height,
      out.path().c_str(), result.windows_per_s, result.events_per_s, result.jobs,
      result.threads_per_window, result.codec.c_str());
  if (result.truth_frames > 0) {
    std::printf(
        "%d withheld frames: PSNR mean %.2f dB (worst %.2f, blend %.2f), SSIM mean %.4f "
        "(worst %.4f, blend %.4f)\n",
        result.truth_frames, result.mean_psnr, result.worst_psnr, result.mean_blend_psnr,
        result.mean_ssim, result.worst_ssim, result.mean_blend_ssim);
  }
  return 0;
}

int RunCommand(const std::string& command) {
  SetFramePathsMayLeaveFolder(FLAGS_allow_outside_paths);
  Require(std::isfinite(FLAGS_progress_interval_s) && FLAGS_progress_interval_s >= 0.0,
          "--progress_interval_s must be a number of seconds, 0 or more");
  // Lines on stderr while the command runs, only when it runs long (app/progress.h).
  ProgressOptions progress_options;
  progress_options.prefix = "evfs " + command;
  progress_options.interval_s = FLAGS_progress_interval_s;
  progress_options.every_iteration = FLAGS_progress || ::isatty(STDERR_FILENO);
  ProgressReporter progress(progress_options);
  if (command == "info") return RunInfo();
  if (command == "reconstruct") return RunReconstruct(&progress);
  if (command == "video") return RunVideoCommand(&progress);
  if (command == "simulate") return RunSimulate();
  if (command == "convert") return RunConvert();
  if (command == "calibrate") return RunCalibrate();
  if (command == "denoise") return RunDenoise();
  if (command == "demo") {
    Require(!FLAGS_out.empty(), "demo needs --out=DIR");
    OutputTarget out(OutputFromFlags("demo", ""));
    const int status = RunDemo(out.staging(), out.path());
    out.Commit();
    std::printf("results written to %s\n", out.path().c_str());
    return status;
  }
  throw InvalidArgumentError(
      "unknown command '" + command +
      "': expected info, reconstruct, video, denoise, simulate, convert, calibrate or demo "
      "(evfs --help)");
}

// What a value of a flag of gflags type `type` must look like.
std::string ExpectedValue(const std::string& type) {
  if (type == "bool") return "true or false";
  if (type == "int32") return "a whole number (32-bit)";
  if (type == "int64") return "a whole number";
  if (type == "uint32" || type == "uint64") return "a whole number, 0 or more";
  if (type == "double") return "a number";
  return "a " + type;
}

// gflags reports a flag it cannot parse in its own words, possibly on several lines, and exits
// with status 1. This reads the command line as gflags will (--name=value, --name value,
// --name and --noname for booleans, "--" ending the flags) and tries each value in a
// FlagSaver's scope, which puts every flag back. Returns the first problem, "" when none.
// --flagfile is only checked for being readable; gflags reports what is inside it.
std::string FirstFlagError(int argc, char** argv) {
  const gflags::FlagSaver put_flags_back;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument.size() < 2 || argument[0] != '-') continue;  // the command, or "-"
    const size_t dashes = argument[1] == '-' ? 2 : 1;
    if (argument.size() == dashes) break;  // "--"
    const size_t equals = argument.find('=');
    const bool has_value = equals != std::string::npos;
    const std::string name =
        argument.substr(dashes, has_value ? equals - dashes : std::string::npos);
    gflags::CommandLineFlagInfo info;
    if (!gflags::GetCommandLineFlagInfo(name.c_str(), &info)) {
      gflags::CommandLineFlagInfo negated;
      if (!has_value && name.rfind("no", 0) == 0 &&
          gflags::GetCommandLineFlagInfo(name.substr(2).c_str(), &negated) &&
          negated.type == "bool") {
        continue;
      }
      return "unknown flag --" + name + " (evfs --help lists the flags)";
    }
    std::string value;
    if (has_value) {
      value = argument.substr(equals + 1);
    } else if (info.type == "bool") {
      value = "true";
    } else if (i + 1 < argc) {
      value = argv[++i];
    } else {
      return "--" + name + " needs a value";
    }
    if (name == "flagfile") {
      std::stringstream files(value);
      for (std::string file; std::getline(files, file, ',');) {
        if (!std::ifstream(file)) return "--flagfile=" + value + ": cannot read " + file;
      }
      continue;
    }
    if (gflags::SetCommandLineOption(name.c_str(), value.c_str()).empty()) {
      return "--" + name + "=" + value + ": expected " + ExpectedValue(info.type);
    }
  }
  return "";
}

std::string FlagValue(const char* name) {
  std::string value;
  gflags::GetCommandLineOption(name, &value);
  return value;
}

// evfs' help (app/evfs_help.h), its own flags being those defined in this file: gflags records
// the __FILE__ of each DEFINE_, so that renaming the file changes nothing.
const ProgramHelp& MainHelp() {
  static const ProgramHelp help = [] {
    ProgramHelp main_help = EvfsHelp();
    main_help.flags_file = __FILE__;
    return main_help;
  }();
  return help;
}

// gflags' help flags print and then exit with status 1; help asked for is a success. --help
// and --helpshort show evfs' own flags by group (app/evfs_help.h), only the command's when one
// is given; --helpfull shows every flag, glog's and gflags' too, as gflags does. Returns true
// when help was asked for and printed; throws InvalidArgumentError for an unknown command.
bool ShowHelpAskedFor(int argc, char** argv) {
  if (FlagValue("help") == "true" || FlagValue("helpshort") == "true") {
    const std::string text =
        argc >= 2 ? CommandHelpText(MainHelp(), argv[1]) : ProgramHelpText(MainHelp());
    std::fputs(text.c_str(), stdout);
  } else if (FlagValue("helpfull") == "true" || FlagValue("helppackage") == "true") {
    gflags::ShowUsageWithFlags(argv[0]);
  } else if (!FlagValue("helpon").empty()) {
    gflags::ShowUsageWithFlagsRestrict(argv[0], ("/" + FlagValue("helpon") + ".").c_str());
  } else if (!FlagValue("helpmatch").empty()) {
    gflags::ShowUsageWithFlagsRestrict(argv[0], FlagValue("helpmatch").c_str());
  } else {
    return false;
  }
  return true;
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  evfs::KeepFreedMemoryForReuse();
  gflags::SetUsageMessage(evfs::EvfsHelp().summary + "\n\n" + evfs::UsageLines(evfs::EvfsHelp()) +
                          "\nRun 'evfs --help' for evfs' own flags by group.");
  gflags::SetVersionString(evfs::kVersion);
  // Libraries' log messages (Ceres' dump of a residual block it could not evaluate, its
  // "Terminating: ...") are for developers: shown with --minloglevel=0. What failed is evfs'
  // own one line.
  gflags::SetCommandLineOptionWithMode("minloglevel", "3", gflags::SET_FLAGS_DEFAULT);
  // A flag gflags cannot parse is a user error like any other: one line, status 2.
  const std::string flag_error = evfs::FirstFlagError(argc, argv);
  if (!flag_error.empty()) {
    std::fprintf(stderr, "evfs: %s\n", flag_error.c_str());
    return evfs::kExitUserError;
  }
  gflags::ParseCommandLineNonHelpFlags(&argc, &argv, true);
  try {
    if (evfs::ShowHelpAskedFor(argc, argv)) return evfs::kExitSuccess;
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "evfs: %s\n", error.what());
    return evfs::kExitUserError;
  }
  if (evfs::FlagValue("version") == "true") {
    std::fputs(evfs::VersionReport().c_str(), stdout);
    return evfs::kExitSuccess;
  }
  gflags::HandleCommandLineHelpFlags();  // --helpxml (status 1)
  FLAGS_logtostderr = true;
  google::InitGoogleLogging(argv[0]);
  if (argc != 2) {
    std::fprintf(stderr, "evfs: expected one command; see 'evfs --help'\n");
    return 2;
  }
  const std::string command = argv[1];
  // A failed CHECK is evfs' bug, not the user's: one line, status 3 (app/crash_guard.h).
  evfs::InstallInternalErrorReporting("evfs " + command);
  const auto run = [&command] {
    try {
      return evfs::RunCommand(command);
    } catch (const evfs::SolverError& error) {
      std::fprintf(stderr, "evfs %s: %s\n", command.c_str(), error.what());
      return static_cast<int>(evfs::kExitSolverFailure);
    } catch (const evfs::Error& error) {
      std::fprintf(stderr, "evfs %s: %s\n", command.c_str(), error.what());
      return 2;
    } catch (const std::bad_alloc&) {
      // Memory beyond what the machine (or ulimit -v) gives, past every limit checked from
      // the declared sizes: one line and kExitUnexpected (core/error.h).
      std::fprintf(stderr,
                   "evfs %s: out of memory (a smaller window, --fps, --jobs or input, or more "
                   "memory)\n",
                   command.c_str());
      return static_cast<int>(evfs::kExitUnexpected);
    } catch (const std::system_error& error) {
      std::fprintf(stderr, "evfs %s: the system refused a resource: %s\n", command.c_str(),
                   error.what());
      return static_cast<int>(evfs::kExitUnexpected);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "evfs %s: unexpected error: %s\n", command.c_str(), error.what());
      return 1;
    }
  };
  // Every command runs in a worker process: a signal or a crash there leaves no unfinished
  // output (the parent removes it), and a corrupt .h5 file that crashes libhdf5 is a user error
  // (app/crash_guard.h). `convert --overwrite` opens the .h5 file it would replace.
  std::string hdf5_path;
  if (evfs::IsHdf5Path(FLAGS_data)) {
    hdf5_path = FLAGS_data;
  } else if (FLAGS_overwrite && evfs::IsHdf5Path(FLAGS_out)) {
    hdf5_path = FLAGS_out;
  }
  return evfs::RunInChildProcess(run, "evfs " + command, hdf5_path);
}
