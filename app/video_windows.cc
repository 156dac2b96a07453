#include "evfs/app/video_windows.h"

#include <algorithm>
#include <cmath>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/core/time.h"

namespace evfs {
namespace {

VideoWindowFrame ObservedFrame(const std::vector<FrameInfo>& frames, int index,
                               const VideoWindowOptions& options) {
  const FrameInfo& info = frames[index];
  VideoWindowFrame frame;
  frame.index = index;
  frame.t_ns = info.t_ns;
  frame.exposure_begin_ns = frame.exposure_end_ns = info.t_ns;
  int64_t begin_ns = 0, end_ns = 0;
  const bool found_sharp = std::find(options.sharp_frames.begin(), options.sharp_frames.end(),
                                     index) != options.sharp_frames.end();
  if (BlurCandidateExposure(info, options, &begin_ns, &end_ns) && !found_sharp) {
    frame.blurred = true;
    frame.exposure_begin_ns = begin_ns;
    frame.exposure_end_ns = end_ns;
  }
  return frame;
}

int64_t MedianGapNs(const std::vector<FrameInfo>& frames, const std::vector<int>& observed) {
  std::vector<int64_t> gaps;
  for (size_t k = 0; k + 1 < observed.size(); ++k) {
    gaps.push_back(frames[observed[k + 1]].t_ns - frames[observed[k]].t_ns);
  }
  if (gaps.empty()) return 0;
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  return gaps[gaps.size() / 2];
}

}  // namespace

bool BlurCandidateExposure(const FrameInfo& info, const VideoWindowOptions& options,
                           int64_t* begin_ns, int64_t* end_ns) {
  *begin_ns = *end_ns = info.t_ns;
  if (info.has_exposure) {
    *begin_ns = info.exposure_begin_ns;
    *end_ns = info.exposure_end_ns;
  } else if (options.exposure_s > 0.0) {
    const int64_t half_ns = SecondsToNanoseconds(options.exposure_s / 2.0);
    *begin_ns = info.t_ns - half_ns;
    *end_ns = info.t_ns + half_ns;
  }
  const int64_t min_ns = SecondsToNanoseconds(options.min_blur_exposure_s);
  return *end_ns > *begin_ns && *end_ns - *begin_ns >= min_ns;
}

std::vector<int> SelectedFrames(int frame_count, const VideoWindowOptions& options) {
  const int last = options.last >= 0 ? std::min(options.last, frame_count - 1) : frame_count - 1;
  std::vector<int> selected;
  for (int i = std::max(options.first, 0); i <= last; i += std::max(options.frame_step, 1)) {
    if (std::find(options.excluded_frames.begin(), options.excluded_frames.end(), i) ==
        options.excluded_frames.end()) {
      selected.push_back(i);
    }
  }
  return selected;
}

bool VideoWindowOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.Require(first >= 0, "--first", "0 or more")
      .Require(last == -1 || last >= first, "--last", "-1 (the last frame) or at least --first")
      .Require(predict_max_s >= 0.0 && predict_max_s <= kMaxDurationS, "--predict_max_s",
               "between 0 and 3600 seconds")
      .Require(min_blur_exposure_s >= 0.0 && min_blur_exposure_s <= kMaxDurationS,
               "--min_blur_exposure_s", "between 0 and 3600 seconds")
      .Require(exposure_s >= 0.0 && exposure_s <= kMaxDurationS, "--exposure_s",
               "between 0 and 3600 seconds")
      .InRange("--frame_step", frame_step, 1, 1000000);
  return check.Passed(error);
}

std::vector<VideoWindow> PlanVideoWindows(const std::vector<FrameInfo>& frames, bool has_events,
                                          int64_t last_event_ns,
                                          const VideoWindowOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError(error);
  const int count = static_cast<int>(frames.size());
  if (count == 0)
    throw InvalidArgumentError("the recording has no frames: a video starts from one");
  const int first = options.first;
  const int last = options.last >= 0 ? options.last : count - 1;
  if (first >= count || last >= count) {
    throw InvalidArgumentError("--first/--last select frames " + std::to_string(first) + ".." +
                               std::to_string(last) + " but the recording has " +
                               std::to_string(count) + " frames (0.." + std::to_string(count - 1) +
                               ")");
  }

  const auto excluded = [&options](int index) {
    return std::find(options.excluded_frames.begin(), options.excluded_frames.end(), index) !=
           options.excluded_frames.end();
  };
  const std::vector<int> observed = SelectedFrames(count, options);
  if (observed.empty()) {
    throw InvalidArgumentError("every selected frame is left out: nothing to start from");
  }

  std::vector<VideoWindow> windows;
  for (size_t k = 0; k + 1 < observed.size(); ++k) {
    const int i = observed[k], j = observed[k + 1];
    VideoWindow window;
    window.kind = VideoWindowKind::kInterpolate;
    window.frames = {ObservedFrame(frames, i, options), ObservedFrame(frames, j, options)};
    for (int withheld = i + 1; withheld < j; ++withheld) {
      if (!excluded(withheld)) window.truth_frames.push_back(withheld);
    }
    window.begin_ns = window.frames.front().exposure_begin_ns;
    window.end_ns = window.frames.back().exposure_end_ns;
    window.output_begin_ns = frames[i].t_ns;
    window.output_end_ns = frames[j].t_ns;
    windows.push_back(window);
  }

  const int last_observed = observed.back();
  const VideoWindowFrame last_frame = ObservedFrame(frames, last_observed, options);
  const int64_t max_tail_ns = options.predict_max_s > 0.0
                                  ? SecondsToNanoseconds(options.predict_max_s)
                                  : MedianGapNs(frames, observed);
  // Events are read up to, not including, the window's end: one past the last event holds it.
  int64_t tail_end_ns = has_events ? last_event_ns + 1 : last_frame.t_ns;
  if (max_tail_ns > 0) tail_end_ns = std::min(tail_end_ns, last_frame.t_ns + max_tail_ns);
  if (options.predict_tail && last_observed == count - 1 && tail_end_ns > last_frame.t_ns) {
    VideoWindow window;
    window.kind = VideoWindowKind::kPredict;
    window.frames = {last_frame};
    window.begin_ns = last_frame.exposure_begin_ns;
    window.end_ns = std::max(tail_end_ns, last_frame.exposure_end_ns);
    window.output_begin_ns = last_frame.t_ns;
    window.output_end_ns = window.end_ns;
    windows.push_back(window);
  } else if (windows.empty() && last_frame.blurred) {
    VideoWindow window;
    window.kind = VideoWindowKind::kDeblur;
    window.frames = {last_frame};
    window.begin_ns = last_frame.exposure_begin_ns;
    window.end_ns = last_frame.exposure_end_ns;
    window.output_begin_ns = window.begin_ns;
    window.output_end_ns = window.end_ns;
    windows.push_back(window);
  }
  if (windows.empty()) {
    throw InvalidArgumentError(
        "frame " + std::to_string(last_observed) +
        " alone leaves nothing to reconstruct: select two frames or more (--first/--last), a "
        "blurred frame (--exposure_s), or the last frame with events after it");
  }
  windows.back().owns_end = true;
  for (size_t i = 0; i < windows.size(); ++i) windows[i].index = static_cast<int>(i);
  return windows;
}

int64_t OutputClock::TimeNs(int64_t n) const {
  return t0_ns_ +
         static_cast<int64_t>(std::llround(static_cast<double>(n) * kNanosecondsPerSecond / fps_));
}

void OrderLongestFirst(const std::vector<VideoWindow>& windows, std::vector<int>* indices) {
  const auto cost = [&windows](int index) {
    const VideoWindow& window = windows[index];
    return std::make_pair(window.end_ns - window.begin_ns,
                          window.kind != VideoWindowKind::kInterpolate);
  };
  std::stable_sort(indices->begin(), indices->end(),
                   [&cost](int a, int b) { return cost(a) > cost(b); });
}

int64_t OutputClock::FirstAtOrAfter(int64_t t_ns) const {
  if (t_ns <= t0_ns_) return 0;
  int64_t n = static_cast<int64_t>(
      std::ceil(static_cast<double>(t_ns - t0_ns_) * fps_ / kNanosecondsPerSecond));
  // The estimate is off by at most one either way (rounding in both directions).
  while (n > 0 && TimeNs(n - 1) >= t_ns) --n;
  while (TimeNs(n) < t_ns) ++n;
  return n;
}

void OutputClock::FramesOf(const VideoWindow& window, int64_t* begin, int64_t* end) const {
  *begin = FirstAtOrAfter(window.output_begin_ns);
  *end = window.owns_end ? FirstAtOrAfter(window.output_end_ns + 1)
                         : FirstAtOrAfter(window.output_end_ns);
  *end = std::max(*begin, *end);
}

}  // namespace evfs
