#include "evfs/app/video_steps.h"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "evfs/app/method.h"
#include "evfs/core/enum_names.h"
#include "evfs/core/error.h"
#include "evfs/core/time.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

// Most output frames a video may have (a runaway --fps would fill the disk).
constexpr int64_t kMaxOutputFrames = 10000000;
// A time beyond any recording's last event, with room to add to it.
constexpr int64_t kFarFutureNs = std::numeric_limits<int64_t>::max() / 4;

// What a window depends on, for the fingerprint of a run.
std::string PlanText(const std::vector<VideoWindow>& windows, const OutputClock& clock) {
  std::ostringstream text;
  for (const VideoWindow& window : windows) {
    int64_t begin = 0, end = 0;
    clock.FramesOf(window, &begin, &end);
    text << window.index << ' ' << NameOf(kVideoWindowKindNames, window.kind);
    for (const VideoWindowFrame& frame : window.frames) {
      text << ' ' << frame.index << (frame.blurred ? "b" : "s");
    }
    text << ' ' << window.begin_ns << ' ' << window.end_ns << ' ' << begin << ' ' << end << '\n';
  }
  return text.str();
}

// The last selected frame's index.
int LastSelectedFrame(const DataSource& data, const VideoWindowOptions& options) {
  const int last_frame = static_cast<int>(data.frames().size()) - 1;
  return options.last >= 0 ? std::min(options.last, last_frame) : last_frame;
}

}  // namespace

Image ReadVideoFrame(const DataSource& data, int index) {
  try {
    return data.ReadImage(index);
  } catch (const InputError& error) {
    throw InputError(error.kind(), error.file(), error.line(),
                     std::string("frame ") + std::to_string(index) + ": " + error.what() +
                         " (--skip_bad_frames goes on across it)");
  }
}

std::vector<int> FindUnreadableFrames(const DataSource& data, const VideoWindowOptions& options) {
  std::vector<int> unreadable;
  for (int i = std::max(options.first, 0); i <= LastSelectedFrame(data, options); ++i) {
    try {
      data.ReadImage(i);
    } catch (const InputError&) {
      unreadable.push_back(i);
    }
  }
  return unreadable;
}

std::vector<std::pair<int, ExposureBlurEstimate>> TestExposures(const DataSource& data,
                                                                const VideoWindowOptions& options) {
  std::vector<std::pair<int, ExposureBlurEstimate>> tests;
  if (!options.blur_from_data || !data.has_events()) return tests;
  for (const int i : SelectedFrames(static_cast<int>(data.frames().size()), options)) {
    int64_t begin_ns = 0, end_ns = 0;
    if (!BlurCandidateExposure(data.frames()[i], options, &begin_ns, &end_ns)) continue;
    tests.emplace_back(i, ExposureBlur(ReadVideoFrame(data, i),
                                       data.ReadEvents(begin_ns, end_ns + 1), begin_ns, end_ns));
  }
  return tests;
}

std::vector<VideoWindow> PlanVideo(const DataSource& data, const VideoWindowOptions& options) {
  // Planned first against a far end, then once more against the last event actually found in
  // the prediction tail.
  std::vector<VideoWindow> windows =
      PlanVideoWindows(data.frames(), data.has_events(), kFarFutureNs, options);
  if (!data.has_events() || windows.back().kind != VideoWindowKind::kPredict) return windows;
  const VideoWindow& tail = windows.back();
  int64_t last_event_ns = 0;
  if (tail.end_ns >= kFarFutureNs) {
    last_event_ns = data.Summarize().t_last_ns;
  } else {
    const EventStream events = data.ReadEvents(tail.frames[0].t_ns, tail.end_ns);
    // No event after the last frame: a time before it, so that no tail is planned.
    last_event_ns = events.empty() ? tail.frames[0].t_ns - 1 : events.last_t_ns();
  }
  return PlanVideoWindows(data.frames(), true, last_event_ns, options);
}

double VideoOutputFps(double requested_fps, const std::vector<VideoWindow>& windows) {
  if (requested_fps != 0.0) return requested_fps;
  int gaps = 0;
  int64_t span_ns = 0;
  for (const VideoWindow& window : windows) {
    if (window.kind != VideoWindowKind::kInterpolate) continue;
    ++gaps;
    span_ns += window.output_end_ns - window.output_begin_ns;
  }
  if (gaps == 0) {
    gaps = 1;
    span_ns = windows.front().output_end_ns - windows.front().output_begin_ns;
  }
  const double observed_rate = gaps / std::max(NanosecondsToSeconds(span_ns), 1e-9);
  return std::max(std::round(kDefaultUpsampling * observed_rate), 1.0);
}

int64_t CheckVideoOutput(const std::vector<VideoWindow>& windows, const OutputClock& clock,
                         double fps, int width, int height) {
  int64_t ignored = 0, output_frames = 0;
  clock.FramesOf(windows.back(), &ignored, &output_frames);
  if (output_frames > kMaxOutputFrames) {
    throw InvalidArgumentError("--fps=" + std::to_string(fps) + " would make " +
                               std::to_string(output_frames) + " frames, more than " +
                               std::to_string(kMaxOutputFrames));
  }
  // Each window holds its resampled frames and confidence maps until it writes them.
  int64_t longest_ns = 0;
  for (const VideoWindow& window : windows) {
    longest_ns = std::max(longest_ns, window.output_end_ns - window.output_begin_ns);
  }
  CheckResampledOutputFits(fps, NanosecondsToSeconds(longest_ns), width, height, "longest window");
  return output_frames;
}

std::string WorkFolderFingerprint(const std::string& data_path, double fps,
                                  const std::string& settings,
                                  const std::vector<VideoWindow>& windows,
                                  const OutputClock& clock) {
  std::ostringstream fingerprint;
  fingerprint << "data " << fs::absolute(data_path).lexically_normal().string() << "\n"
              << "fps " << fps << "\n"
              << "settings " << settings << "\n"
              << PlanText(windows, clock);
  return fingerprint.str();
}

int64_t AddressSpaceLimit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return 0;
  return static_cast<int64_t>(std::min<rlim_t>(limit.rlim_cur, INT64_MAX));
}

int CapVideoJobs(int jobs, int windows, int cores, int threads_per_window, int64_t pixels,
                 int64_t address_space_bytes, std::string* why) {
  int capped = std::max(jobs, 1);
  const auto lower = [&](int64_t most, const std::string& reason) {
    most = std::max<int64_t>(most, 1);
    if (capped > most) {
      capped = static_cast<int>(most);
      *why = reason;
    }
  };
  lower(static_cast<int64_t>(cores) * kMaxJobsPerCore,
        "at most " + std::to_string(kMaxJobsPerCore) + " per hardware thread (" +
            std::to_string(cores) + ")");
  if (address_space_bytes > 0) {
    // Each job reserves its threads' stacks and holds its window's frames, events and problem;
    // the rest of the address space is the process' own (libraries, the recording's index).
    rlimit stack{};
    int64_t stack_bytes = kDefaultThreadStackBytes;
    if (getrlimit(RLIMIT_STACK, &stack) == 0 && stack.rlim_cur != RLIM_INFINITY) {
      stack_bytes = static_cast<int64_t>(stack.rlim_cur);
    }
    const int64_t per_job = std::max(threads_per_window, 1) * stack_bytes +
                            std::max<int64_t>(pixels, 1) * kWindowBytesPerPixel;
    lower(address_space_bytes / 2 / per_job,
          "the address space limit (ulimit -v, " + std::to_string(address_space_bytes >> 20) +
              " MiB) leaves room for that many windows' stacks and working memory");
  }
  if (windows > 0)
    lower(windows, "there are only " + std::to_string(windows) + " windows to solve");
  return capped;
}

VideoSchedule ScheduleVideo(int requested_jobs, int requested_threads, int pending_windows,
                            int cores, int64_t pixels, int64_t address_space_bytes) {
  const int jobs_asked = requested_jobs > 0 ? requested_jobs : cores;
  // The threads each job would have, for the jobs' memory: before the jobs are capped.
  const int threads_asked =
      requested_threads > 0 ? requested_threads : std::max(1, cores / std::max(1, jobs_asked));
  VideoSchedule schedule;
  std::string why;
  schedule.jobs = CapVideoJobs(jobs_asked, pending_windows, cores, threads_asked, pixels,
                               address_space_bytes, &why);
  if (requested_jobs > 0 && schedule.jobs < requested_jobs) schedule.lowered_because = why;
  schedule.threads_per_window =
      requested_threads > 0 ? requested_threads : std::max(1, cores / schedule.jobs);
  return schedule;
}

void SummarizeTruth(const std::vector<VideoTruthScore>& scores, VideoResult* result) {
  const auto mean_and_worst = [&scores](double VideoTruthScore::*field, double* mean,
                                        double* worst) {
    double sum = 0.0, least = std::numeric_limits<double>::infinity();
    for (const VideoTruthScore& score : scores) {
      sum += score.*field;
      least = std::min(least, score.*field);
    }
    *mean = scores.empty() ? 0.0 : sum / scores.size();
    if (worst != nullptr) *worst = scores.empty() ? 0.0 : least;
  };
  result->truth_frames = static_cast<int>(scores.size());
  mean_and_worst(&VideoTruthScore::psnr, &result->mean_psnr, &result->worst_psnr);
  mean_and_worst(&VideoTruthScore::ssim, &result->mean_ssim, &result->worst_ssim);
  mean_and_worst(&VideoTruthScore::blend_psnr, &result->mean_blend_psnr, nullptr);
  mean_and_worst(&VideoTruthScore::blend_ssim, &result->mean_blend_ssim, nullptr);
  double within_sum = 0.0;
  int within_count = 0;
  for (const VideoTruthScore& score : scores) {
    if (!score.has_within_sigma) continue;
    within_sum += score.within_sigma;
    ++within_count;
  }
  result->mean_within_sigma = within_count > 0 ? within_sum / within_count : 0.0;
}

}  // namespace evfs
