// `evfs video`: a whole recording to one high-framerate video. The recording is cut into
// windows (app/video_windows.h) that are reconstructed independently and concurrently, each
// reading only its own events, and each writing the output frames it owns; the timestamps,
// summary and MP4 files are assembled at the end.
//
// Resampling. The output runs at a uniform rate: frame n at t_first + n / fps. Each output
// frame is the linear interpolation of the two latent frames of its window around its time
// (Video::InterpolateAt); a sharp observed frame replaces the latent frame at its own time, so
// an output time on an observed frame reproduces that frame exactly and windows meet there.
//
// Resuming. Windows are written into a work folder beside the output, ".NAME.evfs-video-work"
// (app/video_work_folder.h), marked as evfs's by the file .evfs-video-work, which holds the run's
// settings. A window's frames are written under temporary names and renamed; its record
// (windows/WWWWWW.json) is written last, the same way, so a window with a record is complete.
// Unlike an OutputTarget's staging folder, the work folder survives a signal; `--resume`
// reuses the recorded windows when the settings match, and solves the others. Once the output
// is committed (frames hard-linked from the work folder into the OutputTarget's staging folder,
// so an interrupted assembly loses nothing), RemoveVideoWorkFolder deletes it. Without
// --resume an earlier work folder of the same output is discarded; a path there that evfs did
// not mark is never touched.
#ifndef EVFS_APP_VIDEO_JOB_H_
#define EVFS_APP_VIDEO_JOB_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "evfs/app/denoise_job.h"
#include "evfs/app/log_offset_search.h"
#include "evfs/app/method.h"
#include "evfs/app/video_windows.h"
#include "evfs/events/binning.h"
#include "evfs/scene/exposure_blur.h"

namespace evfs {

/// Output frames per observed frame interval when --fps is 0: the upsampling the method is
/// for (a DAVIS frame every 20–50 ms becomes a 200–500 fps video).
inline constexpr double kDefaultUpsampling = 10.0;

/// Slowest output rate: the MP4 encoder keeps the rate as a fraction with a small denominator
/// and refuses rates near 0, and a video that upsamples frames is never slower than 1 fps.
inline constexpr double kMinVideoFps = 1.0;
/// Highest --fps: output times are whole nanoseconds, so a faster rate has no distinct frame
/// times (its step rounds to zero and the output clock would never advance).
inline constexpr double kMaxVideoFps = 1e9;
/// Most --jobs and --threads.
inline constexpr int kMaxThreads = 4096;

/// Where a video job stands, after each window.
struct VideoProgress {
  int windows_done = 0;  // including resumed ones
  int windows_total = 0;
  int windows_resumed = 0;  // taken from an interrupted run
  int64_t events_done = 0;  // events of the windows solved in this run
  double elapsed_s = 0.0;
};

/// How the windows of a video are shared between processes (app/video_mpi.h): one coordinator
/// hands windows out as workers ask for them and assembles the output; the workers solve them
/// and write their frames into the coordinator's work folder (a file system they share).
struct VideoDistribution {
  /// This process is the coordinator: it solves no window itself.
  bool coordinator = false;
  /// Coordinator: hands out the windows in `pending` (indices) on request and returns once
  /// every worker has finished.
  std::function<void(const std::vector<int>& pending)> serve;
  /// Worker: the next window to solve, -1 when there is none. Called by one thread at a time.
  std::function<int()> next;
};

struct VideoRequest {
  std::string data_path;           // data folder, HDF5 or AEDAT 4 file
  std::string data_label;          // how summary.json names the data ("": data_path)
  DataSourceOptions data_options;  // the topics of a ROS bag
  VideoWindowOptions windows;
  double fps = 0.0;              // output rate; 0: kDefaultUpsampling × the observed frame rate
  int jobs = 0;                  // windows solved at once; 0: every core
  int threads_per_window = 0;    // each solve's threads; 0: the cores left, cores / jobs (>= 1)
  bool skip_bad_frames = false;  // leave unreadable frames out instead of failing
  bool resume = false;           // reuse the windows an interrupted run finished
  bool preview = false;          // also preview.mp4: observed | reconstruction | events
  bool report = false;           // also report.html: the run on one offline page
  BinningOptions binning;
  MethodOptions method;  // solver threads are set per window from threads_per_window
  /// The values of b tried for the interpolation windows (app/log_offset_search.h), each on one
  /// of the video's observed frames per ten windows (at most two) reconstructed from their
  /// neighbours. Empty: the model's b.
  std::vector<double> log_offset_search;
  DenoiseRequest denoise;
  /// Everything else that decides the output (the command line's settings); --resume reuses
  /// windows only when it is unchanged.
  std::string settings;
  /// Called with one line when a setting is lowered to what the machine allows (--jobs); may be
  /// empty.
  std::function<void(const std::string&)> notice;
  /// Called after each window, from the worker threads, one call at a time; may be empty.
  std::function<void(const VideoProgress&)> progress;
  /// Windows shared with other processes; null: every window in this one. A worker returns
  /// after its windows, writing nothing into `staging`.
  const VideoDistribution* distribution = nullptr;

  bool IsValid(std::string* error) const;
};

struct VideoResult {
  int width = 0, height = 0;
  double fps = 0.0;
  int windows = 0;
  int windows_resumed = 0;
  /// Windows the interrupted run had finished whose frames or events changed since (--resume):
  /// solved again.
  int windows_changed = 0;
  std::vector<int> skipped_frames;  // left out as unreadable (--skip_bad_frames)
  /// Frames whose exposure was tested (VideoWindowOptions::blur_from_data) and what was found.
  std::vector<std::pair<int, ExposureBlurEstimate>> exposure_tests;
  int64_t output_frames = 0;
  int64_t events = 0;  // events of all windows
  int jobs = 0, threads_per_window = 0;
  double solve_wall_s = 0.0;  // the windows, wall clock
  double total_wall_s = 0.0;
  double windows_per_s = 0.0;  // windows solved in this run / solve_wall_s
  double events_per_s = 0.0;
  std::string codec;     // of video.mp4
  int truth_frames = 0;  // withheld frames scored (frame_step > 1)
  double mean_psnr = 0.0, worst_psnr = 0.0, mean_blend_psnr = 0.0;
  double mean_ssim = 0.0, worst_ssim = 0.0, mean_blend_ssim = 0.0;
  /// The share of the withheld frames' pixels within the predicted one sigma, averaged.
  double mean_within_sigma = 0.0;
  /// What VideoRequest::log_offset_search chose; empty when it did not run.
  std::optional<LogOffsetChoice> log_offset_choice;
};

/// Runs the job: windows into the work folder of `out_path`, then frames/, timestamps.txt,
/// summary.json, video.mp4 (and preview.mp4) into `staging` (an OutputTarget's staging folder,
/// for `out_path`). Throws evfs::Error for bad options or input, InvalidArgumentError when the
/// work folder's path holds something evfs did not mark as its own.
VideoResult RunVideo(const VideoRequest& request, const std::string& out_path,
                     const std::string& staging);

/// One progress line: "[#####.....] 5/10 windows, 12.3 s, ETA 12 s, 41.2 k events/s".
std::string VideoProgressLine(const VideoProgress& progress);

}  // namespace evfs

#endif  // EVFS_APP_VIDEO_JOB_H_
