#include "evfs/app/video_windows.h"

#include <gtest/gtest.h>

#include <vector>

#include "evfs/core/error.h"

namespace evfs {
namespace {

constexpr int64_t kMs = 1000000;  // nanoseconds per millisecond

// Frames every 40 ms from t = 1 s, sharp.
std::vector<FrameInfo> Frames(int count) {
  std::vector<FrameInfo> frames(count);
  for (int i = 0; i < count; ++i) {
    frames[i].t_ns = 1000 * kMs + i * 40 * kMs;
    frames[i].path = "images/" + std::to_string(i) + ".png";
  }
  return frames;
}

TEST(PlanVideoWindowsTest, EveryGapIsAnInterpolationWindowAndTheTailIsPredicted) {
  const std::vector<FrameInfo> frames = Frames(4);
  // Events go on 25 ms after the last frame, less than a frame gap.
  const int64_t last_event_ns = frames[3].t_ns + 25 * kMs;
  const std::vector<VideoWindow> windows =
      PlanVideoWindows(frames, true, last_event_ns, VideoWindowOptions());
  ASSERT_EQ(windows.size(), 4u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(windows[i].index, i);
    EXPECT_EQ(windows[i].kind, VideoWindowKind::kInterpolate);
    ASSERT_EQ(windows[i].frames.size(), 2u);
    EXPECT_EQ(windows[i].frames[0].index, i);
    EXPECT_EQ(windows[i].frames[1].index, i + 1);
    EXPECT_FALSE(windows[i].frames[0].blurred);
    EXPECT_EQ(windows[i].begin_ns, frames[i].t_ns);
    EXPECT_EQ(windows[i].end_ns, frames[i + 1].t_ns);
    EXPECT_EQ(windows[i].output_begin_ns, frames[i].t_ns);
    EXPECT_EQ(windows[i].output_end_ns, frames[i + 1].t_ns);
    EXPECT_FALSE(windows[i].owns_end);
  }
  const VideoWindow& tail = windows[3];
  EXPECT_EQ(tail.kind, VideoWindowKind::kPredict);
  EXPECT_EQ(tail.frames[0].index, 3);
  EXPECT_EQ(tail.begin_ns, frames[3].t_ns);
  EXPECT_EQ(tail.end_ns, last_event_ns + 1);  // the last event is read
  EXPECT_TRUE(tail.owns_end);
}

TEST(PlanVideoWindowsTest, PredictionStopsAfterOneMedianGapAndCanBeTurnedOff) {
  const std::vector<FrameInfo> frames = Frames(3);
  const int64_t last_event_ns = frames[2].t_ns + 500 * kMs;
  std::vector<VideoWindow> windows =
      PlanVideoWindows(frames, true, last_event_ns, VideoWindowOptions());
  ASSERT_EQ(windows.size(), 3u);
  EXPECT_EQ(windows.back().end_ns, frames[2].t_ns + 40 * kMs);

  VideoWindowOptions options;
  options.predict_max_s = 0.1;
  windows = PlanVideoWindows(frames, true, last_event_ns, options);
  EXPECT_EQ(windows.back().end_ns, frames[2].t_ns + 100 * kMs);

  options.predict_tail = false;
  windows = PlanVideoWindows(frames, true, last_event_ns, options);
  ASSERT_EQ(windows.size(), 2u);
  EXPECT_EQ(windows.back().kind, VideoWindowKind::kInterpolate);
  EXPECT_TRUE(windows.back().owns_end);
}

TEST(PlanVideoWindowsTest, NoTailWithoutEventsAfterTheLastFrameOrBeforeTheRecordingsEnd) {
  const std::vector<FrameInfo> frames = Frames(4);
  EXPECT_EQ(PlanVideoWindows(frames, true, frames[3].t_ns - kMs, VideoWindowOptions()).size(), 3u);
  EXPECT_EQ(PlanVideoWindows(frames, false, 0, VideoWindowOptions()).size(), 3u);
  VideoWindowOptions options;
  options.first = 1;
  options.last = 2;  // not the recording's last frame: nothing is predicted
  const std::vector<VideoWindow> windows =
      PlanVideoWindows(frames, true, frames[3].t_ns + 20 * kMs, options);
  ASSERT_EQ(windows.size(), 1u);
  EXPECT_EQ(windows[0].frames[0].index, 1);
  EXPECT_EQ(windows[0].frames[1].index, 2);
}

TEST(PlanVideoWindowsTest, FramesWithExposuresAreObservedOverThem) {
  std::vector<FrameInfo> frames = Frames(3);
  for (FrameInfo& frame : frames) {
    frame.has_exposure = true;
    frame.exposure_begin_ns = frame.t_ns - 10 * kMs;
    frame.exposure_end_ns = frame.t_ns + 10 * kMs;
  }
  VideoWindowOptions options;
  options.predict_tail = false;
  std::vector<VideoWindow> windows = PlanVideoWindows(frames, true, 0, options);
  ASSERT_EQ(windows.size(), 2u);
  EXPECT_TRUE(windows[0].frames[0].blurred);
  EXPECT_TRUE(windows[0].frames[1].blurred);
  // The scene holds both whole exposures; the output still meets at the timestamps.
  EXPECT_EQ(windows[0].begin_ns, frames[0].t_ns - 10 * kMs);
  EXPECT_EQ(windows[0].end_ns, frames[1].t_ns + 10 * kMs);
  EXPECT_EQ(windows[0].output_end_ns, frames[1].t_ns);
  EXPECT_EQ(windows[1].output_begin_ns, frames[1].t_ns);

  // A 20 ms exposure is shorter than 30 ms: sharp.
  options.min_blur_exposure_s = 0.03;
  windows = PlanVideoWindows(frames, true, 0, options);
  EXPECT_FALSE(windows[0].frames[0].blurred);
  EXPECT_EQ(windows[0].begin_ns, frames[0].t_ns);

  // A frame the data showed unblurred (sharp_frames) is observed at its timestamp; the others
  // keep their exposures, and BlurCandidateExposure still names every exposure.
  options.min_blur_exposure_s = 0.0;
  options.sharp_frames = {1};
  windows = PlanVideoWindows(frames, true, 0, options);
  EXPECT_TRUE(windows[0].frames[0].blurred);
  EXPECT_FALSE(windows[0].frames[1].blurred);
  EXPECT_FALSE(windows[1].frames[0].blurred);
  EXPECT_EQ(windows[0].end_ns, frames[1].t_ns);
  int64_t begin_ns = 0, end_ns = 0;
  EXPECT_TRUE(BlurCandidateExposure(frames[1], options, &begin_ns, &end_ns));
  EXPECT_EQ(begin_ns, frames[1].t_ns - 10 * kMs);
  EXPECT_EQ(end_ns, frames[1].t_ns + 10 * kMs);
  EXPECT_FALSE(BlurCandidateExposure(Frames(1)[0], options, &begin_ns, &end_ns));
}

TEST(PlanVideoWindowsTest, LongestWindowsGoFirstAndPredictionsBeforeEqualInterpolations) {
  std::vector<FrameInfo> frames = Frames(5);
  frames[2].t_ns += 30 * kMs;  // gap 1 -> 2: 70 ms; 2 -> 3: 10 ms
  // The tail prediction runs one median gap (40 ms), as long as the windows 0 and 3.
  const std::vector<VideoWindow> windows =
      PlanVideoWindows(frames, true, frames[4].t_ns + 100 * kMs, VideoWindowOptions());
  ASSERT_EQ(windows.size(), 5u);
  ASSERT_EQ(windows[4].kind, VideoWindowKind::kPredict);
  ASSERT_EQ(windows[4].end_ns - windows[4].begin_ns, 40 * kMs);
  std::vector<int> order = {0, 1, 2, 3, 4};
  OrderLongestFirst(windows, &order);
  EXPECT_EQ(order, (std::vector<int>{1, 4, 0, 3, 2}));
}

TEST(PlanVideoWindowsTest, SelectedFramesAreEveryStepFromFirstLessTheExcluded) {
  VideoWindowOptions options;
  options.first = 1;
  options.frame_step = 2;
  options.excluded_frames = {5};
  EXPECT_EQ(SelectedFrames(9, options), std::vector<int>({1, 3, 7}));
  options.last = 4;
  EXPECT_EQ(SelectedFrames(9, options), std::vector<int>({1, 3}));
}

TEST(PlanVideoWindowsTest, ALoneBlurredFrameIsOneDeblurWindow) {
  std::vector<FrameInfo> frames = Frames(3);
  VideoWindowOptions options;
  options.first = options.last = 1;
  options.exposure_s = 0.02;
  const std::vector<VideoWindow> windows = PlanVideoWindows(frames, true, 0, options);
  ASSERT_EQ(windows.size(), 1u);
  EXPECT_EQ(windows[0].kind, VideoWindowKind::kDeblur);
  EXPECT_EQ(windows[0].begin_ns, frames[1].t_ns - 10 * kMs);
  EXPECT_EQ(windows[0].end_ns, frames[1].t_ns + 10 * kMs);
  EXPECT_TRUE(windows[0].owns_end);

  options.exposure_s = 0.0;  // sharp and alone: nothing to do
  EXPECT_THROW(PlanVideoWindows(frames, true, 0, options), InvalidArgumentError);
}

TEST(PlanVideoWindowsTest, FrameStepWithholdsTheFramesBetweenAsTruth) {
  const std::vector<FrameInfo> frames = Frames(9);
  VideoWindowOptions options;
  options.frame_step = 4;
  const std::vector<VideoWindow> windows = PlanVideoWindows(frames, false, 0, options);
  ASSERT_EQ(windows.size(), 2u);
  EXPECT_EQ(windows[0].frames[0].index, 0);
  EXPECT_EQ(windows[0].frames[1].index, 4);
  EXPECT_EQ(windows[0].truth_frames, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(windows[1].truth_frames, (std::vector<int>{5, 6, 7}));
}

TEST(PlanVideoWindowsTest, ExcludedFramesAreSpannedByOneWindow) {
  const std::vector<FrameInfo> frames = Frames(4);
  VideoWindowOptions options;
  options.excluded_frames = {2};
  const std::vector<VideoWindow> windows = PlanVideoWindows(frames, false, 0, options);
  ASSERT_EQ(windows.size(), 2u);
  EXPECT_EQ(windows[1].frames[0].index, 1);
  EXPECT_EQ(windows[1].frames[1].index, 3);
  EXPECT_TRUE(windows[1].truth_frames.empty());
}

TEST(PlanVideoWindowsTest, BadSelectionsAreTheUsersError) {
  const std::vector<FrameInfo> frames = Frames(4);
  VideoWindowOptions options;
  options.last = 7;
  EXPECT_THROW(PlanVideoWindows(frames, false, 0, options), InvalidArgumentError);
  options.last = 1;
  options.first = 2;
  EXPECT_THROW(PlanVideoWindows(frames, false, 0, options), InvalidArgumentError);
  EXPECT_THROW(PlanVideoWindows({}, false, 0, VideoWindowOptions()), InvalidArgumentError);
  options = VideoWindowOptions();
  options.frame_step = 0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("--frame_step"), std::string::npos);
}

TEST(OutputClockTest, WindowsOwnEveryOutputFrameExactlyOnce) {
  const std::vector<FrameInfo> frames = Frames(5);
  VideoWindowOptions options;
  options.predict_tail = false;
  const std::vector<VideoWindow> windows = PlanVideoWindows(frames, false, 0, options);
  // 333 fps does not divide the 40 ms gaps: frames fall anywhere inside the windows.
  const OutputClock clock(frames[0].t_ns, 333.0);
  int64_t expected_begin = 0;
  for (const VideoWindow& window : windows) {
    int64_t begin = 0, end = 0;
    clock.FramesOf(window, &begin, &end);
    EXPECT_EQ(begin, expected_begin);
    for (int64_t n = begin; n < end; ++n) {
      EXPECT_GE(clock.TimeNs(n), window.output_begin_ns);
      EXPECT_LE(clock.TimeNs(n), window.output_end_ns);
      if (!window.owns_end) {
        EXPECT_LT(clock.TimeNs(n), window.output_end_ns);
      }
    }
    expected_begin = end;
  }
  // 160 ms at 333 fps: frames 0 … 53 (53 / 333 = 0.159 s).
  EXPECT_EQ(expected_begin, 54);
}

TEST(OutputClockTest, AFrameOnTheEndOfTheLastWindowIsWritten) {
  const std::vector<FrameInfo> frames = Frames(2);
  VideoWindowOptions options;
  options.predict_tail = false;
  const std::vector<VideoWindow> windows = PlanVideoWindows(frames, false, 0, options);
  const OutputClock clock(frames[0].t_ns, 100.0);  // 10 ms: frames at 0, 10, 20, 30, 40 ms
  int64_t begin = 0, end = 0;
  clock.FramesOf(windows[0], &begin, &end);
  EXPECT_EQ(begin, 0);
  EXPECT_EQ(end, 5);
  EXPECT_EQ(clock.TimeNs(4), frames[1].t_ns);
  EXPECT_EQ(clock.FirstAtOrAfter(frames[0].t_ns + 10 * kMs), 1);
  EXPECT_EQ(clock.FirstAtOrAfter(frames[0].t_ns + 10 * kMs + 1), 2);
}

}  // namespace
}  // namespace evfs
