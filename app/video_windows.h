// How `evfs video` cuts a recording into independent reconstruction windows, and which output
// frames of the uniform-rate video each window owns.
//
//   frames     F0        F1             F2        (last frame)   last event
//   windows    |--gap 0--|----gap 1-----|-- tail (predict) --|
//   output     [t0, t1)  [t1, t2)       [t2, t_end]
//
// Every gap between consecutive selected frames is an interpolation window. A frame whose
// exposure is known (exposures.txt, or --exposure_s) and at least `min_blur_exposure_s` long is
// observed over that exposure (the mean of the latent frames inside it, docs/design.md §1), so it
// is deblurred within each window that holds it; such a window reads the events of both frames'
// whole exposures. A sharp frame is observed at its timestamp. After the recording's last frame,
// a prediction window runs up to the last event. A single blurred frame selected alone is one
// deblur window. Windows own half-open output intervals that tile [t_first, t_end], so every
// output timestamp is written by exactly one window, whatever order the windows run in.
#ifndef EVFS_APP_VIDEO_WINDOWS_H_
#define EVFS_APP_VIDEO_WINDOWS_H_

#include <cstdint>
#include <string>
#include <vector>

#include "evfs/core/enum_names.h"
#include "evfs/io/data_source.h"

namespace evfs {

enum class VideoWindowKind { kInterpolate, kPredict, kDeblur };

inline constexpr EnumName<VideoWindowKind> kVideoWindowKindNames[] = {
    {VideoWindowKind::kInterpolate, "interpolate", "between two consecutive frames"},
    {VideoWindowKind::kPredict, "predict", "after the last frame, up to the last event"},
    {VideoWindowKind::kDeblur, "deblur", "inside one blurred exposure"},
};

/// One frame as a window observes it.
struct VideoWindowFrame {
  int index = -1;                 // images.txt line
  bool blurred = false;           // observed over [exposure_begin_ns, exposure_end_ns]
  int64_t t_ns = 0;               // its timestamp
  int64_t exposure_begin_ns = 0;  // == t_ns when sharp
  int64_t exposure_end_ns = 0;    // == t_ns when sharp
};

/// One reconstruction window of a video.
struct VideoWindow {
  int index = 0;  // 0-based position in the plan
  VideoWindowKind kind = VideoWindowKind::kInterpolate;
  /// Interpolate: the frames at both ends; predict and deblur: one frame.
  std::vector<VideoWindowFrame> frames;
  /// Frames withheld between the two observed ones (frame_step > 1): the ground truth the
  /// window is scored against (images.txt lines).
  std::vector<int> truth_frames;
  /// The scene's time span: events with begin_ns <= t < end_ns are read.
  int64_t begin_ns = 0;
  int64_t end_ns = 0;
  /// The output frames whose timestamps lie in [output_begin_ns, output_end_ns) belong to this
  /// window; with `owns_end` the end itself too (the video's last window).
  int64_t output_begin_ns = 0;
  int64_t output_end_ns = 0;
  bool owns_end = false;
};

struct VideoWindowOptions {
  int first = 0;  // images.txt line of the first frame
  int last = -1;  // images.txt line of the last frame; -1: the recording's last
  /// Predict after the recording's last frame up to the last event (only when `last` is the
  /// recording's last frame and events go on after it).
  bool predict_tail = true;
  /// Longest prediction, in seconds; 0: the median gap between the observed frames (prediction
  /// drifts with time, and beyond a frame gap nothing anchors it).
  double predict_max_s = 0.0;
  /// A frame with a known exposure at least this long is observed over its exposure (blurred);
  /// 0: every frame whose exposure is known and not empty.
  double min_blur_exposure_s = 0.0;
  /// Exposure in seconds around the timestamp for frames without one in the data; 0: none.
  double exposure_s = 0.0;
  /// Observe every frame_step-th frame from `first` and withhold the frames between them as
  /// ground truth (the "skip frame_step - 1" protocol of TimeLens); 1: observe every frame.
  int frame_step = 1;
  /// Frames left out altogether (unreadable ones, with --skip_bad_frames): windows span the gap.
  std::vector<int> excluded_frames;
  /// Frames observed at their timestamp although their exposure is known and long enough: the
  /// data shows that the exposure did not blur them (scene/exposure_blur.h).
  std::vector<int> sharp_frames;
  /// Decide from each frame and the events inside its exposure whether the exposure blurred it
  /// (RunVideo fills sharp_frames); false: every frame with a long enough exposure is blurred.
  bool blur_from_data = true;

  bool IsValid(std::string* error) const;
};

/// The exposure [*begin_ns, *end_ns] that frame `info` would be observed over as a blurred frame:
/// its known exposure, or options.exposure_s around its timestamp. True when that exposure is
/// not empty and at least options.min_blur_exposure_s long; sharp_frames is not consulted.
bool BlurCandidateExposure(const FrameInfo& info, const VideoWindowOptions& options,
                           int64_t* begin_ns, int64_t* end_ns);

/// The frames a plan observes: every frame_step-th from options.first up to options.last (or
/// the last of `frame_count`), less the excluded ones.
std::vector<int> SelectedFrames(int frame_count, const VideoWindowOptions& options);

/// Plans the windows of frames options.first … options.last of `frames` (strictly increasing
/// timestamps, as DataSource gives them). `last_event_ns` is the time of the recording's last
/// event (ignored when `has_events` is false). Throws InvalidArgumentError for a selection out
/// of range or one that leaves nothing to reconstruct.
std::vector<VideoWindow> PlanVideoWindows(const std::vector<FrameInfo>& frames, bool has_events,
                                          int64_t last_event_ns, const VideoWindowOptions& options);

/// Orders `indices` (of `windows`) longest first, so that a run does not end on one long window
/// while the other jobs sit idle: a window's cost grows with its span, and a prediction or
/// deblur, which no second frame pins, takes more iterations than an interpolation of the same
/// span. Equal windows keep their order. The order changes no window's result.
void OrderLongestFirst(const std::vector<VideoWindow>& windows, std::vector<int>* indices);

/// The uniform output timeline: frame n at t0_ns + round(n · 1e9 / fps) nanoseconds.
class OutputClock {
 public:
  OutputClock(int64_t t0_ns, double fps) : t0_ns_(t0_ns), fps_(fps) {}

  int64_t TimeNs(int64_t n) const;
  /// The first n with TimeNs(n) >= t_ns (0 for t_ns <= t0).
  int64_t FirstAtOrAfter(int64_t t_ns) const;
  /// The output frames [*begin, *end) that `window` owns.
  void FramesOf(const VideoWindow& window, int64_t* begin, int64_t* end) const;

 private:
  int64_t t0_ns_;
  double fps_;
};

}  // namespace evfs

#endif  // EVFS_APP_VIDEO_WINDOWS_H_
