// End-to-end tests of the "memory and time bounded before allocation": what a hostile or
// unlucky input (a hot pixel, a binning beyond the voxel cap, a file declaring a huge sensor, a
// flag that overflows arithmetic) makes of `evfs`. Each case is small enough to run in well
// under a second, yet failed (allocated gigabytes, looped, crashed) before the fix.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "evfs/io/data_source.h"
#include "evfs/io/hdf5_io.h"
#include "evfs/io/text_folder.h"
#include "evfs/tests/examples/cli_test_util.h"
#include "evfs/tests/io/hdf5_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

using test::CommandResult;
using test::DeclareSensorResolution;
using test::ExpectUserError;
using test::ReadFile;
using test::RunEvfs;
using test::WriteSyntheticFolder;

// Every run is bounded in time: a regression that loops (a tiny --fps once did) fails the test
// instead of hanging the suite.
constexpr char kTimeLimit[] = "timeout 120 ";
// Exit status of `timeout` when it had to stop the command.
constexpr int kTimedOut = 124;

// Pixel of the synthetic folder's 40x32 sensor that the hot pixel cases make hot.
constexpr int kHotX = 1;
constexpr int kHotY = 1;

CommandResult RunLimited(const std::string& arguments) { return RunEvfs(arguments, kTimeLimit); }

// The synthetic folder of cli_test_util.h with `count` more events at (kHotX, kHotY), spread over
// its whole time span and alternating in polarity: a hot pixel in a quiet scene.
std::string WriteHotPixelFolder(const std::string& scratch, int count) {
  const std::string clean = WriteSyntheticFolder(scratch);
  const std::unique_ptr<DataSource> source = DataSource::Open(clean);
  const EventStream events = source->ReadAllEvents();
  const std::vector<FrameInfo>& frames = source->frames();
  const int64_t begin_ns = frames.front().t_ns, end_ns = frames.back().t_ns;
  std::vector<std::tuple<int64_t, uint16_t, uint16_t, int8_t>> all;
  for (size_t i = 0; i < events.size(); ++i) {
    all.emplace_back(events.t_ns(i), events.x(i), events.y(i), events.polarity(i));
  }
  for (int i = 0; i < count; ++i) {
    all.emplace_back(begin_ns + 1 + (end_ns - begin_ns - 2) * i / count, kHotX, kHotY,
                     i % 2 ? 1 : -1);
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
  EventStream hot(events.width(), events.height());
  for (const auto& [t_ns, x, y, polarity] : all) hot.push_back(t_ns, x, y, polarity);
  std::vector<Image> images;
  for (int i = 0; i < static_cast<int>(frames.size()); ++i) images.push_back(source->ReadImage(i));
  const std::string folder = (fs::path(scratch) / "hot").string();
  WriteDataFolder(folder, hot, frames, images);
  return folder;
}

// Regression: one pixel firing a thousand times made `info` and `reconstruct` bin a
// thousand collision frames of the whole sensor. Its events are left out, and both say so.
TEST(EvfsLimits, HotPixelIsLeftOutAndReported) {
  const std::string scratch = test::ScratchDir("limits_hot_pixel");
  const std::string data = WriteHotPixelFolder(scratch, 1000);
  const CommandResult info = RunLimited("info --data=" + data + " --first=0 --last=4");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("without 1 hot pixel (1000 events left out)"), std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("binning     auto: collision"), std::string::npos) << info.output;

  const std::string out = scratch + "/out";
  const CommandResult run =
      RunLimited("reconstruct --data=" + data + " --mode=predict --first=0 --last=4 --out=" + out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("hot pixels: 1, their 1000 events left out"), std::string::npos)
      << run.output;
  const std::string summary = ReadFile(out + "/summary.json");
  EXPECT_NE(summary.find("\"hot_pixels\": 1,"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"hot_pixel_events\": 1000,"), std::string::npos) << summary;

  // --hot_pixel_factor=0 keeps every event (and --flicker_min_reversals=0, since the hot pixel
  // alternates in sign): a thousand collision frames, so auto binning falls back to
  // --max_latent_frames stacked frames, decided from counts.
  const CommandResult kept = RunLimited("info --data=" + data +
                                        " --first=0 --last=4 --hot_pixel_factor=0 "
                                        "--flicker_min_reversals=0");
  ASSERT_EQ(kept.exit_code, 0) << kept.output;
  EXPECT_NE(kept.output.find("binning     auto: stacked, 48 event frames, 49 latent frames"),
            std::string::npos)
      << kept.output;
  ExpectUserError(RunLimited("info --data=" + data + " --first=0 --last=4 --hot_pixel_factor=-1"),
                  "hot_pixel_factor", scratch + "/never");
}

// Few collision frames are split in time up to --min_latent_steps, and `info` says so; an
// explicit --binning=collision keeps them.
TEST(EvfsLimits, InfoReportsCollisionFramesSplitInTime) {
  const std::string scratch = test::ScratchDir("limits_split");
  const std::string data = WriteHotPixelFolder(scratch, 1000);
  const std::string window = "info --data=" + data + " --first=0 --last=1";
  const CommandResult plain = RunLimited(window + " --min_latent_steps=0");
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_NE(plain.output.find("binning     auto: collision, "), std::string::npos) << plain.output;
  const CommandResult split = RunLimited(window + " --min_latent_steps=40");
  ASSERT_EQ(split.exit_code, 0) << split.output;
  EXPECT_NE(split.output.find("binning     auto: collision split in time (--min_latent_steps), "
                              "40 event frames, 41 latent frames"),
            std::string::npos)
      << split.output;
  const CommandResult explicit_collision =
      RunLimited(window + " --min_latent_steps=40 --binning=collision");
  ASSERT_EQ(explicit_collision.exit_code, 0) << explicit_collision.output;
  EXPECT_NE(explicit_collision.output.find("binning     collision: collision, "), std::string::npos)
      << explicit_collision.output;
  ExpectUserError(RunLimited(window + " --min_latent_steps=-1"), "min_latent_steps",
                  scratch + "/never");
}

// Regression: --max_latent_voxels bounded auto binning only, after the collision
// frames were allocated; an explicit --binning beyond it was built whatever its size. It is
// now a user error in every mode and in `info`, before anything is allocated.
TEST(EvfsLimits, ExplicitBinningBeyondTheVoxelCapIsAUserError) {
  const std::string scratch = test::ScratchDir("limits_voxel_cap");
  const std::string data = WriteHotPixelFolder(scratch, 1000);
  const std::string out = scratch + "/out";
  // 40x32 = 1280 pixels; 1280 x 10 voxels hold 10 latent frames.
  const std::string cap = " --max_latent_voxels=12800 --hot_pixel_factor=0";
  for (const std::string mode :
       {"--mode=interpolate --first=0 --last=4", "--mode=predict --first=0 --last=4",
        "--mode=deblur --first=2 --exposure_s=0.02"}) {
    SCOPED_TRACE(mode);
    ExpectUserError(RunLimited("reconstruct --data=" + data + " " + mode + " --binning=collision" +
                               cap + " --out=" + out),
                    "max_latent_voxels = 12800", out);
    ExpectUserError(RunLimited("reconstruct --data=" + data + " " + mode +
                               " --binning=stacked --stacked_frames=10" + cap + " --out=" + out),
                    "max_latent_voxels = 12800", out);
    // Auto binning takes what fits: 9 stacked frames, 10 latent frames.
    const CommandResult fits = RunLimited("reconstruct --data=" + data + " " + mode + cap +
                                          " --max_iterations=1 --out=" + out);
    ASSERT_EQ(fits.exit_code, 0) << fits.output;
    EXPECT_NE(fits.output.find("9 event frames, 10 latent frames"), std::string::npos)
        << fits.output;
    fs::remove_all(out);
  }
  ExpectUserError(
      RunLimited("info --data=" + data + " --first=0 --last=4 --binning=collision" + cap),
      "max_latent_voxels = 12800", out);
  const CommandResult info = RunLimited("info --data=" + data + " --first=0 --last=4" + cap);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("binning     auto: stacked, 9 event frames, 10 latent frames "
                             "(12800 of 12800 voxels)"),
            std::string::npos)
      << info.output;
  // A cap below two latent frames of the sensor: nothing fits.
  ExpectUserError(
      RunLimited("reconstruct --data=" + data +
                 " --mode=predict --first=0 --last=4 --max_latent_voxels=2000 --out=" + out),
      "needs at least 2 latent frames", out);
}

// Regression: a sensor_resolution of 65535x65535 made `info --first --last` allocate
// for 4 G pixels (bad_alloc, or the machine's memory). It is a one-line user error now, and so
// is a declared size the frames do not have.
TEST(EvfsLimits, HugeDeclaredSensorIsAUserError) {
  const std::string scratch = test::ScratchDir("limits_sensor_size");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string h5 = scratch + "/data.h5";
  ASSERT_EQ(RunLimited("convert --data=" + data + " --out=" + h5).exit_code, 0);
  DeclareSensorResolution(h5, 65535, 65535);
  for (const std::string window : {"", " --first=0 --last=1"}) {
    ExpectUserError(RunLimited("info --data=" + h5 + window), "65535x65535 sensor",
                    scratch + "/never");
  }
  ExpectUserError(RunLimited("reconstruct --data=" + h5 +
                             " --mode=predict --first=0 --out=" + scratch + "/out"),
                  "65535x65535 sensor", scratch + "/out");
  DeclareSensorResolution(h5, 4096, 4096);
  ExpectUserError(RunLimited("info --data=" + h5 + " --first=0 --last=1"),
                  "the sensor is 4096x4096", scratch + "/never");
}

// Regression: --fps below ~1e-10 made the resampling's int64 arithmetic wrap, and it
// looped forever, allocating. A rate below one frame per window gives the first frame alone.
TEST(EvfsLimits, TinyFpsGivesOneFrame) {
  const std::string scratch = test::ScratchDir("limits_fps");
  const std::string data = WriteSyntheticFolder(scratch);
  for (const std::string fps : {"1e-12", "1e-300"}) {
    SCOPED_TRACE(fps);
    const std::string out = scratch + "/out_" + fps;
    const CommandResult run = RunLimited(
        "reconstruct --data=" + data +
        " --mode=predict --first=0 --last=1 --solver=copy --fps=" + fps + " --out=" + out);
    ASSERT_NE(run.exit_code, kTimedOut) << "looped";
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const std::string timestamps = ReadFile(out + "/timestamps.txt");
    EXPECT_EQ(std::count(timestamps.begin(), timestamps.end(), '\n'), 1) << timestamps;
  }
  ExpectUserError(
      RunLimited("reconstruct --data=" + data +
                 " --mode=predict --first=0 --last=1 --fps=1e300 --out=" + scratch + "/out"),
      "--fps", scratch + "/out");
}

// --max_time_s bounds the whole solve: a schedule of a million Adam steps ends near the budget
// with the answer it has, and the solve line and summary.json say why (Levenberg-Marquardt and
// L-BFGS converge on this small scene first; tests/solver holds them to a deadline). The budget
// is 1 s and the test fails only when the run reaches the 120 s limit: no timing noise decides.
TEST(EvfsLimits, MaxTimeBoundsEveryIterativeSolve) {
  const std::string scratch = test::ScratchDir("limits_max_time");
  const std::string data = WriteSyntheticFolder(scratch);
  for (const std::string solver : {"adam", "adam_smooth"}) {
    SCOPED_TRACE(solver);
    const std::string out = scratch + "/out_" + solver;
    const CommandResult run = RunLimited(
        "reconstruct --data=" + data + " --mode=interpolate --first=0 --last=4 --solver=" + solver +
        " --adam_iterations=1000000 --max_iterations=1000000 --function_tolerance=0 " +
        "--max_time_s=1 --out=" + out);
    ASSERT_NE(run.exit_code, kTimedOut) << "the budget was ignored";
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("stopped early (time limit --max_time_s reached)"), std::string::npos)
        << run.output;
    EXPECT_NE(ReadFile(out + "/summary.json").find("\"stopped_early\""), std::string::npos);
  }
}

// --fps is bounded by the memory its resampled frames take, not only by their count: the cups
// deblur (346x260) at 20 kHz would hold 3 GB, and is refused before anything is solved.
TEST(EvfsLimits, FpsBeyondTheOutputMemoryIsAUserError) {
  EVFS_REQUIRE_SHARED_DATA(data);
  const std::string scratch = test::ScratchDir("limits_fps_memory");
  const std::string cups = data + "/eslnet_cups_blur";
  ExpectUserError(RunLimited("reconstruct --data=" + cups +
                             " --mode=deblur --first=1 --fps=20000 --out=" + scratch + "/r"),
                  "--fps=20000 would resample the 0.104 s window to 2080 frames of 346x260",
                  scratch + "/r");
  ExpectUserError(RunLimited("video --data=" + cups + " --fps=20000 --out=" + scratch + "/v"),
                  "lower --fps", scratch + "/v");
}

// --jobs beyond the windows is lowered, and said so, rather than starting idle threads.
TEST(EvfsLimits, VideoJobsBeyondTheWindowsAreLowered) {
  const std::string scratch = test::ScratchDir("limits_jobs");
  const std::string data = WriteSyntheticFolder(scratch);
  const CommandResult run =
      RunLimited("video --data=" + data + " --jobs=4096 --fps=400 --out=" + scratch + "/out");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.errors.find("--jobs=4096 lowered to"), std::string::npos) << run.errors;
}

// Regression: --activity_radius_px of 2^31 - 239 or more overflowed int in the
// dilation of the activity mask (SIGSEGV). Any radius beyond the sensor solves every pixel.
TEST(EvfsLimits, HugeActivityRadiusSolvesEveryPixel) {
  const std::string scratch = test::ScratchDir("limits_radius");
  const std::string data = WriteSyntheticFolder(scratch);
  for (const std::string radius : {"2147483409", "2147483647"}) {
    SCOPED_TRACE(radius);
    const std::string out = scratch + "/out_" + radius;
    const CommandResult run = RunLimited("reconstruct --data=" + data +
                                         " --mode=predict --first=0 --last=1 --max_iterations=2"
                                         " --activity_radius_px=" +
                                         radius + " --out=" + out);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const std::string summary = ReadFile(out + "/summary.json");
    EXPECT_NE(summary.find("\"active\": 1280,"), std::string::npos) << summary;
    EXPECT_NE(summary.find("\"skipped\": 0,"), std::string::npos) << summary;
  }
}

// Regression: simulate --noise_rate_hz=1e12 drew noise events until memory ran out
// (bad_alloc, exit 1). The expected count is known before drawing: a one-line user error.
TEST(EvfsLimits, NoiseBeyondTheEventBudgetIsAUserError) {
  const std::string scratch = test::ScratchDir("limits_noise");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string out = scratch + "/simulated";
  ExpectUserError(RunLimited("simulate --frames=" + data + " --noise_rate_hz=1e12 --out=" + out),
                  "max_events", out);
  const CommandResult noisy =
      RunLimited("simulate --frames=" + data + " --noise_rate_hz=100 --out=" + out);
  EXPECT_EQ(noisy.exit_code, 0) << noisy.output;
}

}  // namespace
}  // namespace evfs
