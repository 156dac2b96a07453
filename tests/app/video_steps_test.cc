#include "evfs/app/video_steps.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/text_folder.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;
constexpr int64_t kMs = 1000000;  // nanoseconds per millisecond
constexpr int kWidth = 8, kHeight = 6;

// A recording of `frames` frames 40 ms apart from t = 1 s, with one event every 5 ms from the
// first frame to `events_until_ns`.
std::string WriteRecording(const std::string& name, int frames, int64_t events_until_ns) {
  const std::string folder = test::ScratchDir(name) + "/data";
  std::vector<FrameInfo> infos(frames);
  std::vector<Image> images;
  for (int i = 0; i < frames; ++i) {
    infos[i].t_ns = 1000 * kMs + i * 40 * kMs;
    infos[i].path = "images/frame_" + std::to_string(i) + ".png";
    images.push_back(Image::Constant(kHeight, kWidth, (10.0 + 20.0 * i) / 255.0));
  }
  EventStream events(kWidth, kHeight);
  for (int64_t t = infos[0].t_ns; t <= events_until_ns; t += 5 * kMs) {
    events.push_back(t, 1, 2, 1);
  }
  WriteDataFolder(folder, events, infos, images);
  return folder;
}

VideoWindow Window(VideoWindowKind kind, int64_t begin_ms, int64_t end_ms) {
  VideoWindow window;
  window.kind = kind;
  window.begin_ns = window.output_begin_ns = begin_ms * kMs;
  window.end_ns = window.output_end_ns = end_ms * kMs;
  return window;
}

TEST(VideoStepsTest, UnreadableFramesAreFoundInTheSelectionOnlyAndNamedWhenRead) {
  const std::string folder = WriteRecording("video_steps_unreadable", 5, 1160 * kMs);
  std::ofstream(folder + "/images/frame_2.png", std::ios::trunc) << "not a png";
  const auto data = DataSource::Open(folder);
  EXPECT_EQ(FindUnreadableFrames(*data, VideoWindowOptions()), std::vector<int>({2}));
  VideoWindowOptions after;
  after.first = 3;
  EXPECT_TRUE(FindUnreadableFrames(*data, after).empty());
  VideoWindowOptions before;
  before.last = 1;
  EXPECT_TRUE(FindUnreadableFrames(*data, before).empty());
  try {
    ReadVideoFrame(*data, 2);
    FAIL() << "frame 2 read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("frame 2: "), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("--skip_bad_frames"), std::string::npos);
  }
}

TEST(VideoStepsTest, ThePredictionTailEndsAtTheLastEventOrIsNotPlanned) {
  // Events 20 ms past the last frame (at 1.08 s): a tail up to and including the last event.
  const auto with_tail = DataSource::Open(WriteRecording("video_steps_tail", 3, 1100 * kMs));
  std::vector<VideoWindow> windows = PlanVideo(*with_tail, VideoWindowOptions());
  ASSERT_EQ(windows.size(), 3u);
  EXPECT_EQ(windows.back().kind, VideoWindowKind::kPredict);
  EXPECT_EQ(windows.back().end_ns, 1100 * kMs + 1);
  // Events end before the last frame: nothing to predict from.
  const auto no_tail = DataSource::Open(WriteRecording("video_steps_no_tail", 3, 1060 * kMs));
  windows = PlanVideo(*no_tail, VideoWindowOptions());
  ASSERT_EQ(windows.size(), 2u);
  EXPECT_EQ(windows.back().kind, VideoWindowKind::kInterpolate);
}

TEST(VideoStepsTest, ExposuresAreTestedOnlyWhenAskedAndKnown) {
  const auto data = DataSource::Open(WriteRecording("video_steps_exposures", 3, 1080 * kMs));
  VideoWindowOptions options;
  EXPECT_TRUE(TestExposures(*data, options).empty());  // no frame has an exposure
  options.exposure_s = 0.01;
  const auto tests = TestExposures(*data, options);
  ASSERT_EQ(tests.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(tests[i].first, i);
  options.blur_from_data = false;
  EXPECT_TRUE(TestExposures(*data, options).empty());
}

TEST(VideoStepsTest, TheDerivedRateUpsamplesTheInterpolationWindowsFrameRate) {
  // Two 50 ms gaps (20 frames per second) and a 30 ms tail, which does not count.
  const std::vector<VideoWindow> windows = {Window(VideoWindowKind::kInterpolate, 0, 50),
                                            Window(VideoWindowKind::kInterpolate, 50, 100),
                                            Window(VideoWindowKind::kPredict, 100, 130)};
  EXPECT_DOUBLE_EQ(VideoOutputFps(0.0, windows), kDefaultUpsampling * 20.0);
  EXPECT_DOUBLE_EQ(VideoOutputFps(123.0, windows), 123.0);
  // A lone prediction: its own span is the frame interval.
  EXPECT_DOUBLE_EQ(VideoOutputFps(0.0, {Window(VideoWindowKind::kPredict, 0, 25)}),
                   kDefaultUpsampling * 40.0);
  // A very long window still makes at least one frame per second.
  EXPECT_DOUBLE_EQ(VideoOutputFps(0.0, {Window(VideoWindowKind::kInterpolate, 0, 3600000)}), 1.0);
}

TEST(VideoStepsTest, OutputFramesAreCountedAndRunawayRatesRefused) {
  std::vector<VideoWindow> windows = {Window(VideoWindowKind::kInterpolate, 0, 50),
                                      Window(VideoWindowKind::kInterpolate, 50, 100)};
  windows.back().index = 1;
  windows.back().owns_end = true;
  const OutputClock clock(0, 200.0);
  // 5 ms steps over [0, 100 ms], the end included.
  EXPECT_EQ(CheckVideoOutput(windows, clock, 200.0, kWidth, kHeight), 21);
  const OutputClock runaway(0, 1e9);
  EXPECT_THROW(CheckVideoOutput(windows, runaway, 1e9, kWidth, kHeight), InvalidArgumentError);
}

TEST(VideoStepsTest, TheFingerprintChangesWithWhatDecidesTheOutputOnly) {
  const std::vector<VideoWindow> windows = {Window(VideoWindowKind::kInterpolate, 0, 50)};
  const OutputClock clock(0, 200.0);
  const std::string base = WorkFolderFingerprint("rec", 200.0, "a=1", windows, clock);
  EXPECT_EQ(base, WorkFolderFingerprint("./rec", 200.0, "a=1", windows, clock));
  EXPECT_EQ(base, WorkFolderFingerprint((fs::current_path() / "rec").string(), 200.0, "a=1",
                                        windows, clock));
  EXPECT_NE(base, WorkFolderFingerprint("other", 200.0, "a=1", windows, clock));
  EXPECT_NE(base, WorkFolderFingerprint("rec", 250.0, "a=1", windows, OutputClock(0, 250.0)));
  EXPECT_NE(base, WorkFolderFingerprint("rec", 200.0, "a=2", windows, clock));
  std::vector<VideoWindow> blurred = windows;
  blurred[0].frames.resize(1);
  blurred[0].frames[0].blurred = true;
  std::vector<VideoWindow> sharp = blurred;
  sharp[0].frames[0].blurred = false;
  EXPECT_NE(WorkFolderFingerprint("rec", 200.0, "a=1", blurred, clock),
            WorkFolderFingerprint("rec", 200.0, "a=1", sharp, clock));
}

TEST(VideoStepsTest, JobsAreCappedByCoresAndWindowsAndThreadsShareTheCores) {
  // 0 jobs: one per core, each with one thread.
  VideoSchedule schedule = ScheduleVideo(0, 0, 100, 4, 1000, 0);
  EXPECT_EQ(schedule.jobs, 4);
  EXPECT_EQ(schedule.threads_per_window, 1);
  EXPECT_TRUE(schedule.lowered_because.empty());
  // Fewer windows than cores: the cores go to the windows' threads, and nothing was asked.
  schedule = ScheduleVideo(0, 0, 2, 4, 1000, 0);
  EXPECT_EQ(schedule.jobs, 2);
  EXPECT_EQ(schedule.threads_per_window, 2);
  EXPECT_TRUE(schedule.lowered_because.empty());
  // Asked for more than the machine runs: lowered, with the reason.
  schedule = ScheduleVideo(100, 0, 1000, 2, 1000, 0);
  EXPECT_EQ(schedule.jobs, 2 * kMaxJobsPerCore);
  EXPECT_EQ(schedule.threads_per_window, 1);
  EXPECT_NE(schedule.lowered_because.find("per hardware thread"), std::string::npos);
  // Threads asked for are kept.
  schedule = ScheduleVideo(2, 3, 10, 4, 1000, 0);
  EXPECT_EQ(schedule.jobs, 2);
  EXPECT_EQ(schedule.threads_per_window, 3);
}

TEST(VideoStepsTest, TruthScoresAreAveragedAndTheWorstKept) {
  VideoResult result;
  SummarizeTruth({}, &result);
  EXPECT_EQ(result.truth_frames, 0);
  EXPECT_EQ(result.mean_psnr, 0.0);
  EXPECT_EQ(result.worst_ssim, 0.0);

  VideoTruthScore a, b;
  a.psnr = 30.0;
  a.ssim = 0.9;
  a.blend_psnr = 28.0;
  a.blend_ssim = 0.8;
  a.has_within_sigma = true;
  a.within_sigma = 0.6;
  b.psnr = 20.0;
  b.ssim = 0.95;
  b.blend_psnr = 24.0;
  b.blend_ssim = 0.7;
  SummarizeTruth({a, b}, &result);
  EXPECT_EQ(result.truth_frames, 2);
  EXPECT_DOUBLE_EQ(result.mean_psnr, 25.0);
  EXPECT_DOUBLE_EQ(result.worst_psnr, 20.0);
  EXPECT_DOUBLE_EQ(result.mean_ssim, 0.925);
  EXPECT_DOUBLE_EQ(result.worst_ssim, 0.9);
  EXPECT_DOUBLE_EQ(result.mean_blend_psnr, 26.0);
  EXPECT_DOUBLE_EQ(result.mean_blend_ssim, 0.75);
  // Only the frames that have a confidence share count toward its mean.
  EXPECT_DOUBLE_EQ(result.mean_within_sigma, 0.6);
}

}  // namespace
}  // namespace evfs
