#include "app/evfs_help.h"

#include "core/version.h"

namespace evfs {
namespace {

ProgramHelp MakeEvfsHelp() {
  ProgramHelp help;
  help.program = "evfs";
  help.summary = "event-driven video frame synthesis.";
  help.version = kVersion;
  help.commands = {
      {"info", "--data=DIR [--first=I --last=J]",
       "Describe a recording: size, events, frames and exposures; with --first, the window "
       "between two frames and the binning a reconstruction would get; and the event model "
       "evfs calibrate finds on the first frames of the selection."},
      {"reconstruct",
       "--data=DIR --mode=interpolate|predict|deblur --first=I [--last=J] [--truth=K] --out=OUT "
       "[--fps=N] [method, binning, model and solver flags]",
       "Synthesise the latent frames between frames I and J from the frames and the events "
       "(paper §3), into OUT with their timestamps and a summary."},
      {"video",
       "--data=DIR --out=OUT [--fps=N] [--first=I --last=J] [--jobs=N] [--resume] [--preview] "
       "[--report] "
       "[method, binning, model and solver flags]",
       "Reconstruct a whole recording, window by window and in parallel, into one video at a "
       "uniform rate: OUT/frames, timestamps.txt, summary.json and video.mp4."},
      {"denoise", "--in=RECONSTRUCTION_DIR --out=DIR [--denoiser=FILE.onnx]",
       "Apply the residual denoiser (paper §3.4) to every frame of an earlier reconstruction."},
      {"simulate",
       "--frames=DIR --out=DIR [--threshold_pos=0.2 --threshold_neg=0.2 --seed=42] [sensor "
       "effects, light sources and frame effects]",
       "Simulate the events of a sequence of frames, written as a data folder; optionally with "
       "leak, hot pixels, a photoreceptor bandwidth, a blinking LED, a mains lamp and the "
       "frames' exposure, saturation and noise (all off by default)."},
      {"convert", "--data=DIR|FILE.h5|FILE.aedat4|FILE.bag --out=FILE.h5|FILE.aedat4|DIR",
       "Convert a recording between a data folder, HDF5 and AEDAT 4 (or from AEDAT 2.0/3.1 or a "
       "ROS bag)."},
      {"calibrate", "--data=DIR [--first=I --last=J] --out=MODEL.json",
       "Measure the event model of a recording from its own frames and events (the offset b, "
       "the ON and OFF thresholds, their spread, the background event rate), each with its "
       "standard error, into MODEL.json for --event_model=MODEL.json."},
      {"demo", "--out=DIR",
       "Run a synthetic scene through the whole pipeline and score every mode against its "
       "ground truth."},
  };
  help.notes =
      "DIR is a folder in the Event Camera Dataset layout (events.txt 't x y p', images.txt\n"
      "'t path', images/, optional exposures.txt 'path t_start t_end'), an .h5 file or an\n"
      ".aedat4 recording (iniVation DV: events and frames), an AEDAT 2.0/3.1 file (jAER,\n"
      "cAER, v2e: DAVIS events and APS frames; read only), or a ROS 1 .bag (dvs_msgs/EventArray\n"
      "and sensor_msgs/Image topics, chosen by --events_topic/--frames_topic; read only).\n"
      "I, J, K are 0-based lines of images.txt. Example:\n"
      "  evfs reconstruct --data=../shared/data/slider_depth_70_71 --mode=predict --first=0 "
      "--last=1 \\\n      --truth=1 --out=out/slider\n";
  help.groups = {"data",   "output",   "method",    "binning", "model",
                 "solver", "denoiser", "simulator", "progress"};
  help.flags = {
      // Which data and which frames.
      {"data", "data", "info reconstruct convert video calibrate"},
      {"events_topic", "data", "info reconstruct convert video"},
      {"frames_topic", "data", "info reconstruct convert video"},
      {"frames", "data", "simulate"},
      {"mode", "data", "reconstruct"},
      {"first", "data", "info reconstruct video calibrate"},
      {"last", "data", "info reconstruct video calibrate"},
      {"truth", "data", "reconstruct"},
      {"exposure_s", "data", "reconstruct video simulate"},
      {"frame_time", "data", "reconstruct"},
      // What is written.
      {"out", "output", "reconstruct denoise simulate convert demo video calibrate"},
      {"overwrite", "output", "reconstruct denoise simulate convert demo video calibrate"},
      {"fps", "output", "reconstruct video"},
      // The method and its own settings.
      {"solver", "method", "reconstruct video"},
      {"init", "method", "reconstruct video"},
      {"checkpoints", "method", "reconstruct"},
      {"adam_iterations", "method", "reconstruct video"},
      {"adam_learning_rate", "method", "reconstruct video"},
      {"contrast_threshold", "method", "reconstruct video"},
      {"blur_sigma_px", "method", "reconstruct video"},
      {"cf_cutoff_rad_per_s", "method", "reconstruct video"},
      // Events into event frames (info shows the binning a reconstruction would get).
      {"binning", "binning", "info reconstruct video"},
      {"max_latent_frames", "binning", "info reconstruct video"},
      {"min_latent_steps", "binning", "info reconstruct video"},
      {"max_latent_voxels", "binning", "info reconstruct video"},
      {"hot_pixel_factor", "binning", "info reconstruct video"},
      {"saturation_level", "binning", "info reconstruct video calibrate"},
      {"leave_out_saturated", "binning", "info reconstruct video"},
      {"flicker_min_reversals", "binning", "info reconstruct video"},
      {"noise_filter_ms", "binning", "info reconstruct video"},
      {"stacked_frames", "binning", "info reconstruct video"},
      // The objective and the unknowns.
      {"frame_weight", "model", "reconstruct video"},
      {"event_weight", "model", "reconstruct video"},
      {"spatial_tv_weight", "model", "reconstruct video"},
      {"temporal_tv_weight", "model", "reconstruct video"},
      {"alpha", "model", "reconstruct video"},
      {"event_model", "model", "reconstruct video"},
      {"event_saturation", "model", "reconstruct video"},
      {"per_polarity_alpha", "model", "reconstruct video"},
      {"log_offset", "model", "reconstruct video"},
      {"spatial_tv", "model", "reconstruct video"},
      {"shared_structure_tv", "model", "reconstruct video"},
      {"smoothing_scale", "model", "reconstruct video"},
      {"smoothing_continuation", "model", "reconstruct video"},
      {"bounds", "model", "reconstruct video"},
      {"activity_radius_px", "model", "reconstruct video"},
      {"merge_quiet_steps", "model", "reconstruct video"},
      {"unfired_pixel_changes", "model", "reconstruct video"},
      {"split_independent_parts", "model", "reconstruct video"},
      {"max_problem_mb", "model", "reconstruct video"},
      {"quiet_blend_fraction", "model", "reconstruct video"},
      {"step_ramp_px", "model", "reconstruct video"},
      {"meet_sharp_frames", "model", "reconstruct video"},
      // Ceres.
      {"linear_solver", "solver", "reconstruct video"},
      {"preconditioner", "solver", "reconstruct video"},
      {"eta", "solver", "reconstruct video"},
      {"max_iterations", "solver", "reconstruct video"},
      {"max_linear_iterations", "solver", "reconstruct video"},
      {"max_time_s", "solver", "reconstruct video"},
      {"bounds_line_search_iterations", "solver", "reconstruct video"},
      {"function_tolerance", "solver", "reconstruct video"},
      {"threads", "solver", "reconstruct video"},
      // The residual denoiser.
      {"in", "denoiser", "denoise"},
      {"denoise", "denoiser", "reconstruct video"},
      {"denoiser", "denoiser", "reconstruct denoise video"},
      {"denoise_consistency", "denoiser", "reconstruct video"},
      {"denoise_gate", "denoiser", "reconstruct video"},
      {"denoise_gate_tau", "denoiser", "reconstruct video"},
      // evfs video's own.
      {"jobs", "solver", "video"},
      {"resume", "output", "video"},
      {"preview", "output", "video"},
      {"report", "output", "video"},
      {"predict_tail", "data", "video"},
      {"predict_max_s", "data", "video"},
      {"min_blur_exposure_s", "data", "video"},
      {"blur_from_data", "data", "video"},
      {"frame_step", "data", "video"},
      {"skip_bad_frames", "data", "video"},
      {"allow_outside_paths", "data", "info reconstruct convert video simulate calibrate"},
      // The event simulator.
      {"threshold_pos", "simulator", "simulate"},
      {"threshold_neg", "simulator", "simulate"},
      {"threshold_sigma", "simulator", "simulate"},
      {"log_eps", "simulator", "simulate"},
      {"refractory_s", "simulator", "simulate"},
      {"noise_rate_hz", "simulator", "simulate"},
      {"seed", "simulator", "simulate"},
      {"leak_rate_hz", "simulator", "simulate"},
      {"leak_jitter_fraction", "simulator", "simulate"},
      {"cutoff_hz", "simulator", "simulate"},
      {"hot_pixel_fraction", "simulator", "simulate"},
      {"hot_pixel_rate_hz", "simulator", "simulate"},
      {"flicker_led_hz", "simulator", "simulate"},
      {"flicker_led_xy_px", "simulator", "simulate"},
      {"flicker_led_radius_px", "simulator", "simulate"},
      {"flicker_led_intensity", "simulator", "simulate"},
      {"flicker_led_duty", "simulator", "simulate"},
      {"mains_hz", "simulator", "simulate"},
      {"mains_depth", "simulator", "simulate"},
      {"mains_region_px", "simulator", "simulate"},
      {"frame_gain", "simulator", "simulate"},
      {"read_noise_dn", "simulator", "simulate"},
      {"fpn_offset_dn", "simulator", "simulate"},
      {"fpn_gain_sigma", "simulator", "simulate"},
      // What a running command prints.
      {"progress", "progress", "reconstruct"},
      {"progress_interval_s", "progress", "*"},
  };
  return help;
}

}  // namespace

const ProgramHelp& EvfsHelp() {
  static const ProgramHelp* const help = new ProgramHelp(MakeEvfsHelp());
  return *help;
}

}  // namespace evfs
