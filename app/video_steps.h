// The steps of `evfs video` (RunVideo, app/video_job.h) that decide what a run does before any
// window is solved, and the one that sums up its windows afterwards. RunVideo calls them in
// this order:
//
//   FindUnreadableFrames → TestExposures → PlanVideo → VideoOutputFps → CheckVideoOutput →
//   WorkFolderFingerprint → (work folder, windows to reuse) → ScheduleVideo → (solve the windows) →
//   (assemble frames and MP4) → SummarizeTruth → (summary.json)
//
// Each takes only what it reads and returns what the next one needs, so each is tested on its
// own (tests/app/video_steps_test.cc); the steps in parentheses write files and stay in
// video_job.cc.
#ifndef EVFS_APP_VIDEO_STEPS_H_
#define EVFS_APP_VIDEO_STEPS_H_

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "evfs/app/video_job.h"
#include "evfs/app/video_windows.h"
#include "evfs/core/video.h"
#include "evfs/io/data_source.h"
#include "evfs/scene/exposure_blur.h"

namespace evfs {

/// Frame `index` of `data`; an unreadable frame's InputError names the frame and the flag that
/// goes on across it.
Image ReadVideoFrame(const DataSource& data, int index);

/// The frames of the selection (options.first..last) that cannot be read, in order: what
/// --skip_bad_frames leaves out.
std::vector<int> FindUnreadableFrames(const DataSource& data, const VideoWindowOptions& options);

/// Each selected frame whose known exposure may have blurred it (BlurCandidateExposure), with
/// what its image and the events inside its exposure say. Empty when the recording has no
/// events or options.blur_from_data is off.
std::vector<std::pair<int, ExposureBlurEstimate>> TestExposures(const DataSource& data,
                                                                const VideoWindowOptions& options);

/// The windows of the recording. A prediction tail after the last frame ends at the last event
/// found there; no tail is planned when there is none.
std::vector<VideoWindow> PlanVideo(const DataSource& data, const VideoWindowOptions& options);

/// The output rate: `requested_fps`, or when it is 0, kDefaultUpsampling × the observed frames'
/// mean rate over the interpolation windows (over the one window's span when there are none),
/// rounded, at least 1.
double VideoOutputFps(double requested_fps, const std::vector<VideoWindow>& windows);

/// The number of output frames `windows` make on `clock`. Throws InvalidArgumentError when they
/// are more than a video may have, or when the longest window's resampled frames at `fps` do
/// not fit in memory (CheckResampledOutputFits).
int64_t CheckVideoOutput(const std::vector<VideoWindow>& windows, const OutputClock& clock,
                         double fps, int width, int height);

/// What must not change for --resume to reuse windows: the recording's absolute path, the
/// rate, the settings and each window's plan.
std::string WorkFolderFingerprint(const std::string& data_path, double fps,
                                  const std::string& settings,
                                  const std::vector<VideoWindow>& windows,
                                  const OutputClock& clock);

/// Most --jobs per hardware thread: more only adds threads waiting for a core.
constexpr int kMaxJobsPerCore = 4;
/// The stack a thread reserves when RLIMIT_STACK is unlimited (glibc's default).
constexpr int64_t kDefaultThreadStackBytes = int64_t{8} << 20;
/// Working memory of one window per sensor pixel: its latent frames, event frames and problem
/// (a rough upper bound for the windows evfs video plans, tens of latent steps).
constexpr int64_t kWindowBytesPerPixel = 4096;

/// The jobs (windows solved at once) `jobs` asked for, lowered to: kMaxJobsPerCore × `cores`,
/// the jobs whose thread stacks and window memory fit in half of `address_space_bytes` (0: no
/// limit), and `windows` (when positive). Sets `why` to the reason of the last lowering.
int CapVideoJobs(int jobs, int windows, int cores, int threads_per_window, int64_t pixels,
                 int64_t address_space_bytes, std::string* why);

/// The process' address space limit (RLIMIT_AS) in bytes; 0 when unlimited.
int64_t AddressSpaceLimit();

/// How the windows are solved in this process.
struct VideoSchedule {
  int jobs = 1;                 // windows solved at once
  int threads_per_window = 1;   // each solve's threads
  std::string lowered_because;  // why the --jobs asked for were lowered; empty when they were not
};

/// The jobs and threads for `pending_windows` windows: `requested_jobs` (0: one per core) capped
/// by CapVideoJobs, and `requested_threads` per window (0: the cores shared by the jobs, >= 1).
VideoSchedule ScheduleVideo(int requested_jobs, int requested_threads, int pending_windows,
                            int cores, int64_t pixels, int64_t address_space_bytes);

/// One withheld frame scored against the video (--frame_step); a score that was not a number
/// counts as 0.
struct VideoTruthScore {
  double psnr = 0.0, ssim = 0.0;
  double blend_psnr = 0.0, blend_ssim = 0.0;
  bool has_within_sigma = false;
  double within_sigma = 0.0;
};

/// Sets the truth fields of `result` (truth_frames, the means, the worst) from every withheld
/// frame's score; the means of an empty list are 0.
void SummarizeTruth(const std::vector<VideoTruthScore>& scores, VideoResult* result);

}  // namespace evfs

#endif  // EVFS_APP_VIDEO_STEPS_H_
