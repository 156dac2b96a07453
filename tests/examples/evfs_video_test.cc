// `evfs video` end to end on small synthetic recordings: the frames, their uniform timestamps,
// observed frames unchanged, --jobs not changing the output, an interrupted run resumed into
// the same output, and bad flags as one-line user errors. Each test works in a scratch folder.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "evfs/core/video.h"
#include "evfs/io/data_source.h"
#include "evfs/io/image_io.h"
#include "evfs/tests/examples/cli_test_util.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

using test::CommandResult;
using test::ReadFile;
using test::RunEvfs;
using test::StartEvfs;
using test::WriteSyntheticFolder;

// frames/NNNNNN.png
std::string FrameFileName(int n) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", n);
  return name;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream stream(text);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

// frames/, timestamps.txt and video.mp4 of two outputs hold the same bytes (video.mp4 but under
// AddressSanitizer, whose allocator the MP4 plug-in cannot have zero x264's buffers).
void ExpectSameFrames(const fs::path& a, const fs::path& b) {
  EXPECT_EQ(ReadFile(a / "timestamps.txt"), ReadFile(b / "timestamps.txt"));
#if !defined(__SANITIZE_ADDRESS__)
  EXPECT_TRUE(ReadFile(a / "video.mp4") == ReadFile(b / "video.mp4"));
#endif
  int count = 0;
  for (const auto& entry : fs::directory_iterator(a / "frames")) {
    const fs::path other = b / "frames" / entry.path().filename();
    ASSERT_TRUE(fs::exists(other)) << other;
    EXPECT_EQ(ReadFile(entry.path()), ReadFile(other)) << entry.path().filename();
    ++count;
  }
  EXPECT_EQ(count, std::distance(fs::directory_iterator(b / "frames"), fs::directory_iterator()));
  EXPECT_GT(count, 0);
}

TEST(EvfsVideo, AWholeRecordingBecomesUniformFramesWithTheObservedOnesUnchanged) {
  const fs::path root = test::ScratchDir("video_end_to_end");
  const std::string data = WriteSyntheticFolder(root.string(), 5, 5, 40, 32);
  const fs::path out = root / "out";
  const CommandResult result =
      RunEvfs("video --data=" + data + " --out=" + out.string() + " --fps=1000 --jobs=1");
  ASSERT_EQ(result.exit_code, 0) << result.output;

  // Frames 5 ms apart over 20 ms at 1000 fps: 21 output frames, 1 ms apart.
  const std::vector<std::string> stamps = Lines(ReadFile(out / "timestamps.txt"));
  ASSERT_EQ(stamps.size(), 21u);
  const auto source = DataSource::Open(data);
  const double t0_s = source->frames()[0].t_ns * 1e-9;
  for (size_t n = 0; n < stamps.size(); ++n) {
    int index = -1;
    double t_s = 0.0;
    std::istringstream(stamps[n]) >> index >> t_s;
    EXPECT_EQ(index, static_cast<int>(n));
    // Timestamps are printed with 9 decimals: exact to the nanosecond.
    EXPECT_NEAR(t_s, t0_s + n * 1e-3, 1e-9) << stamps[n];
  }
  ASSERT_EQ(std::distance(fs::directory_iterator(out / "frames"), fs::directory_iterator()), 21);

  // Output frame 5k lies on observed frame k: its pixels, exactly (8-bit frames are exact in
  // the 16-bit output).
  for (int k = 0; k < 5; ++k) {
    const Image observed = source->ReadImage(k);
    const Image written = ReadGreyImage((out / "frames" / FrameFileName(5 * k)).string());
    EXPECT_EQ((observed - written).abs().maxCoeff(), 0.0) << "observed frame " << k;
  }
  // A frame between two observed ones is a reconstruction, not a copy.
  const Image between = ReadGreyImage((out / "frames" / FrameFileName(2)).string());
  EXPECT_GT((between - source->ReadImage(0)).abs().maxCoeff(), 0.0);

  const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_EQ(summary["command"], "video");
  EXPECT_EQ(summary["output_frames"], 21);
  ASSERT_GE(summary["windows"].size(), 4u);
  for (int i = 0; i < 4; ++i) {
    const nlohmann::json& window = summary["windows"][i];
    EXPECT_EQ(window["mode"], "interpolate");
    EXPECT_EQ(window["frames"][0]["index"], i);
    EXPECT_EQ(window["frames"][1]["index"], i + 1);
    EXPECT_GT(window["events"].get<int64_t>(), 0);
    EXPECT_GE(window["latent_frames"].get<int>(), 2);
    // Ceres' own accounting: the Jacobian is evaluated at the start at least.
    EXPECT_GE(window["ceres"]["jacobian_evaluations"].get<int>(), 1);
    EXPECT_GE(window["ceres"]["time_s"]["linear_solver"].get<double>(), 0.0);
  }
  // b of the interpolations chosen on one pair of neighbouring windows (one pair per ten
  // windows, at least one): its shared frame from the outer two.
  const nlohmann::json& search = summary["log_offset_search"];
  ASSERT_EQ(search["frames"].size(), 1u) << search.dump();
  const nlohmann::json& triplet = search["frames"][0];
  EXPECT_EQ(triplet[1].get<int>(), triplet[0].get<int>() + 1);
  EXPECT_EQ(triplet[2].get<int>(), triplet[1].get<int>() + 1);
  const std::vector<double> candidates = search["candidates"].get<std::vector<double>>();
  EXPECT_NE(std::find(candidates.begin(), candidates.end(), search["chosen"].get<double>()),
            candidates.end());
  EXPECT_TRUE(summary["video"]["codec"] == "avc1" || summary["video"]["codec"] == "mp4v");
  EXPECT_GT(fs::file_size(out / "video.mp4"), 0u);
  // Nothing left beside the output: no staging folder, no work folder.
  test::ExpectNoStagingLeft(out);
}

TEST(EvfsVideo, WindowsWithoutEventsAreAnsweredWithoutASolve) {
  const fs::path root = test::ScratchDir("video_no_events");
  const std::string data = WriteSyntheticFolder(root.string(), 3, 5, 24, 16);
  // The same frames with an empty events.txt.
  test::WriteFile((fs::path(data) / "events.txt").string(), "");
  const fs::path out = root / "out";
  const CommandResult result =
      RunEvfs("video --data=" + data + " --out=" + out.string() + " --fps=1000 --denoise=none");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  ASSERT_EQ(summary["windows"].size(), 2u);
  for (const nlohmann::json& window : summary["windows"]) {
    EXPECT_EQ(window["events"], 0);
    EXPECT_EQ(window["solved"], false);
    EXPECT_EQ(window["iterations"], 0);
  }
}

TEST(EvfsVideo, OneJobAndTwoJobsWriteTheSameFrames) {
  const fs::path root = test::ScratchDir("video_jobs");
  const std::string data = WriteSyntheticFolder(root.string(), 7, 5, 40, 32);
  const std::string common = "video --data=" + data + " --fps=700 --preview";
  const CommandResult one = RunEvfs(common + " --jobs=1 --out=" + (root / "one").string());
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const CommandResult two = RunEvfs(common + " --jobs=2 --out=" + (root / "two").string());
  ASSERT_EQ(two.exit_code, 0) << two.output;
  ExpectSameFrames(root / "one", root / "two");
  EXPECT_GT(fs::file_size(root / "two" / "preview.mp4"), 0u);
}

// Starts `evfs arguments` (whose --out is root/out) and stops it with SIGINT once it has
// finished window `window_file` (e.g. "000002.json"), as a user interrupting a long run;
// fails the test if the run ends before.
void InterruptAfterWindow(const std::vector<std::string>& arguments, const fs::path& root,
                          const std::string& window_file) {
  const pid_t pid = StartEvfs(arguments, root);
  ASSERT_GT(pid, 0);
  const fs::path window = root / ".out.evfs-video-work" / "windows" / window_file;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!fs::exists(window) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(fs::exists(window)) << "no window finished: " << ReadFile(root / "stderr.txt");
  ASSERT_EQ(kill(pid, SIGINT), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run ended before the signal: make it longer";
}

TEST(EvfsVideo, AnInterruptedRunResumesIntoTheSameOutput) {
  const fs::path root = test::ScratchDir("video_resume");
  // 30 windows, solved one at a time: the run is stopped after its first windows.
  const std::string data = WriteSyntheticFolder(root.string(), 31, 4, 64, 48);
  const std::vector<std::string> arguments = {"video", "--data=" + data, "--fps=500", "--jobs=1",
                                              "--threads=1"};
  std::vector<std::string> reference = arguments;
  reference.push_back("--out=" + (root / "reference").string());
  const pid_t reference_pid = StartEvfs(reference, root);
  int status = 0;
  ASSERT_EQ(waitpid(reference_pid, &status, 0), reference_pid);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << ReadFile(root / "stderr.txt");

  const fs::path out = root / "out";
  std::vector<std::string> interrupted = arguments;
  interrupted.push_back("--out=" + out.string());
  InterruptAfterWindow(interrupted, root, "000002.json");
  if (HasFatalFailure()) return;
  const fs::path work = root / ".out.evfs-video-work";
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::exists(work / ".evfs-video-work"));

  const std::string resume_flags = " --fps=500 --jobs=1 --threads=1 --resume";
  const CommandResult resumed =
      RunEvfs("video --data=" + data + " --out=" + out.string() + resume_flags);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_GE(summary["run"]["windows_resumed"].get<int>(), 3);
  EXPECT_LT(summary["run"]["windows_resumed"].get<int>(), 30);
  ExpectSameFrames(root / "reference", out);
  EXPECT_FALSE(fs::exists(work));
}

// The recording is edited in place (polarities flipped in its first third) between the
// interrupted run and --resume: the finished windows that read changed events are solved again,
// said on stderr, and the output is that of a fresh run on the edited recording.
TEST(EvfsVideo, ResumeRecomputesTheWindowsWhoseRecordingChanged) {
  const fs::path root = test::ScratchDir("video_resume_changed");
  const std::string data = WriteSyntheticFolder(root.string(), 31, 4, 64, 48);
  const std::vector<std::string> arguments = {"video", "--data=" + data, "--fps=500", "--jobs=1",
                                              "--threads=1"};
  const fs::path out = root / "out";
  std::vector<std::string> interrupted = arguments;
  interrupted.push_back("--out=" + out.string());
  InterruptAfterWindow(interrupted, root, "000002.json");
  if (HasFatalFailure()) return;
  const fs::path work = root / ".out.evfs-video-work";

  // The stale frames: those the interrupted run wrote from the recording as it was.
  std::vector<std::pair<fs::path, std::string>> stale;
  for (const auto& entry : fs::directory_iterator(work / "frames")) {
    if (entry.path().extension() == ".png" && entry.path().stem().extension().empty()) {
      stale.emplace_back(entry.path().filename(), ReadFile(entry.path()));
    }
  }
  const fs::path events_path = fs::path(data) / "events.txt";
  const std::vector<std::string> lines = Lines(ReadFile(events_path));
  std::string edited;
  for (size_t i = 0; i < lines.size(); ++i) {
    std::string line = lines[i];
    if (i < lines.size() / 3 && !line.empty()) {
      char& polarity = line.back();
      polarity = polarity == '1' ? '0' : '1';
      if (line.size() >= 2 && line[line.size() - 2] == '-') line.erase(line.size() - 2, 1);
    }
    edited += line + "\n";
  }
  test::WriteFile(events_path.string(), edited);

  const CommandResult resumed = RunEvfs("video --data=" + data + " --out=" + out.string() +
                                        " --fps=500 --jobs=1 --threads=1 --resume");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.errors.find("the recording changed since the interrupted run"),
            std::string::npos)
      << resumed.errors;
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_GE(summary["run"]["windows_changed"].get<int>(), 1);

  const CommandResult fresh =
      RunEvfs("video --data=" + data + " --out=" + (root / "fresh").string() +
              " --fps=500 --jobs=1 --threads=1");
  ASSERT_EQ(fresh.exit_code, 0) << fresh.output;
  ExpectSameFrames(root / "fresh", out);
  int changed_frames = 0;
  for (const auto& [name, bytes] : stale)
    changed_frames += ReadFile(out / "frames" / name) != bytes;
  EXPECT_GT(changed_frames, 0);
}

#ifdef EVFS_MPIRUN
// mpirun -np 2: rank 0 hands the windows to rank 1 and writes; the frames are those of one
// process.
TEST(EvfsVideo, TwoMpiRanksWriteTheSameFramesAsOneProcess) {
  const fs::path root = test::ScratchDir("video_mpi");
  const std::string data = WriteSyntheticFolder(root.string(), 7, 5, 40, 32);
  const std::string common = "video --data=" + data + " --fps=700 --jobs=1 --threads=1";
  const CommandResult single = RunEvfs(common + " --out=" + (root / "single").string());
  ASSERT_EQ(single.exit_code, 0) << single.output;
  const CommandResult ranks =
      RunEvfs(common + " --out=" + (root / "ranks").string(),
              std::string(EVFS_MPIRUN) + " --allow-run-as-root --oversubscribe -np 2 ");
  ASSERT_EQ(ranks.exit_code, 0) << ranks.output;
  ExpectSameFrames(root / "single", root / "ranks");
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(root / "ranks" / "summary.json"));
  EXPECT_EQ(summary["windows"].size(), 6u);  // 7 frames: 6 gaps, no events after the last
  EXPECT_FALSE(fs::exists(root / ".ranks.evfs-video-work"));
}
#endif

TEST(EvfsVideo, ResumeWithOtherSettingsIsRefused) {
  const fs::path root = test::ScratchDir("video_resume_settings");
  const std::string data = WriteSyntheticFolder(root.string(), 3, 5, 24, 16);
  // An interrupted run's work folder, as evfs leaves it.
  const fs::path work = root / ".out.evfs-video-work";
  fs::create_directories(work / "windows");
  fs::create_directories(work / "frames");
  test::WriteFile((work / ".evfs-video-work").string(),
                  "evfs video work folder\nsettings of another run");
  const fs::path out = root / "out";
  const CommandResult result =
      RunEvfs("video --data=" + data + " --out=" + out.string() + " --resume");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_EQ(std::count(result.errors.begin(), result.errors.end(), '\n'), 1) << result.errors;
  EXPECT_NE(result.errors.find("other settings"), std::string::npos) << result.errors;
  EXPECT_FALSE(fs::exists(out));
  // Kept: the run it belongs to can still be resumed with its own settings.
  EXPECT_TRUE(fs::exists(work / ".evfs-video-work"));
}

// --event_model=FILE.json is part of the settings by its bytes, not its path: a calibration
// file rewritten in place between the interrupted run and --resume refuses the resume; with
// its first bytes back, the same run resumes.
TEST(EvfsVideo, ResumeNoticesACalibrationFileChangedInPlace) {
  const fs::path root = test::ScratchDir("video_resume_model_file");
  fs::remove_all(root);
  const std::string data = WriteSyntheticFolder(root.string(), 31, 4, 64, 48);
  const fs::path model = root / "model.json";
  const auto write_model = [&model](double threshold_on) {
    test::WriteFile(model.string(),
                    "{\"evfs_calibration\": 1, \"log_offset\": {\"value\": 0.1}, "
                    "\"threshold_on\": {\"value\": " +
                        std::to_string(threshold_on) + "}, \"threshold_off\": {\"value\": 0.2}}\n");
  };
  write_model(0.2);
  const fs::path out = root / "out";
  const std::vector<std::string> arguments = {
      "video",    "--data=" + data, "--out=" + out.string(),          "--fps=500",
      "--jobs=1", "--threads=1",    "--event_model=" + model.string()};
  InterruptAfterWindow(arguments, root, "000000.json");
  if (HasFatalFailure()) return;

  const std::string resume =
      "video --data=" + data + " --out=" + out.string() +
      " --fps=500 --jobs=1 --threads=1 --resume --event_model=" + model.string();
  write_model(0.3);  // same path, other thresholds
  const CommandResult refused = RunEvfs(resume);
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.errors.find("other settings"), std::string::npos) << refused.errors;
  EXPECT_FALSE(fs::exists(out));

  write_model(0.2);
  const CommandResult resumed = RunEvfs(resume);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_GE(summary["run"]["windows_resumed"].get<int>(), 1);
}

TEST(EvfsVideo, AWorkFolderPathEvfsDidNotMarkIsNeverTouched) {
  const fs::path root = test::ScratchDir("video_foreign_work");
  const std::string data = WriteSyntheticFolder(root.string(), 3, 5, 24, 16);
  const fs::path work = root / ".out.evfs-video-work";
  fs::create_directories(work);
  test::WriteFile((work / "notes.txt").string(), "precious");
  const fs::path out = root / "out";
  const CommandResult result = RunEvfs("video --data=" + data + " --out=" + out.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.errors.find("not an evfs video work folder"), std::string::npos)
      << result.errors;
  EXPECT_EQ(ReadFile(work / "notes.txt"), "precious");
  EXPECT_FALSE(fs::exists(out));
}

// A file the user put into an evfs work folder is neither discarded (a run without --resume
// replaces the folder) nor mixed into a resumed run.
TEST(EvfsVideo, WhatTheUserPutInAWorkFolderIsKept) {
  const fs::path root = test::ScratchDir("video_work_added");
  const std::string data = WriteSyntheticFolder(root.string(), 3, 5, 24, 16);
  const fs::path work = root / ".out.evfs-video-work";
  fs::create_directories(work / "frames");
  test::WriteFile((work / ".evfs-video-work").string(), "evfs video work folder\nold settings");
  test::WriteFile((work / "frames/000000.png").string(), "an old frame");
  test::WriteFile((work / "frames/notes.txt").string(), "precious");
  const fs::path out = root / "out";
  for (const char* resume : {"", " --resume"}) {
    SCOPED_TRACE(resume);
    const CommandResult result =
        RunEvfs("video --data=" + data + " --out=" + out.string() + resume);
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_EQ(std::count(result.errors.begin(), result.errors.end(), '\n'), 1) << result.errors;
    EXPECT_NE(result.errors.find("evfs did not write: frames/notes.txt"), std::string::npos)
        << result.errors;
    EXPECT_EQ(ReadFile(work / "frames/notes.txt"), "precious");
    EXPECT_FALSE(fs::exists(out));
  }
  fs::remove(work / "frames/notes.txt");
  const CommandResult result = RunEvfs("video --data=" + data + " --out=" + out.string());
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_FALSE(fs::exists(work));
}

TEST(EvfsVideo, BadFlagsAreOneLineUserErrors) {
  const fs::path root = test::ScratchDir("video_bad_flags");
  const std::string data = WriteSyntheticFolder(root.string(), 3, 5, 24, 16);
  const fs::path out = root / "out";
  const std::string base = "video --data=" + data + " --out=" + out.string();
  test::ExpectUserError(RunEvfs(base + " --frame_step=0"), "--frame_step", out);
  test::ExpectUserError(RunEvfs(base + " --jobs=-1"), "--jobs", out);
  test::ExpectUserError(RunEvfs(base + " --fps=-5"), "--fps", out);
  test::ExpectUserError(RunEvfs(base + " --first=1 --last=9"), "3 frames", out);
  test::ExpectUserError(RunEvfs("video --data=" + data), "--out", out);
  test::ExpectUserError(RunEvfs(base + " --jobs=two"), "--jobs", out);
}

TEST(EvfsVideo, AnUnreadableFrameIsNamedOrSkipped) {
  const fs::path root = test::ScratchDir("video_bad_frame");
  const std::string data = WriteSyntheticFolder(root.string(), 4, 5, 24, 16);
  const auto source = DataSource::Open(data);
  const std::string broken = source->frames()[2].path;
  test::WriteFile((fs::path(data) / broken).string(), "not a png");
  const fs::path out = root / "out";
  const std::string base = "video --data=" + data + " --out=" + out.string() + " --fps=1000";
  test::ExpectUserError(RunEvfs(base), "frame 2", out);
  const CommandResult skipped = RunEvfs(base + " --skip_bad_frames");
  ASSERT_EQ(skipped.exit_code, 0) << skipped.output;
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(out / "summary.json"));
  EXPECT_EQ(summary["skipped_frames"], nlohmann::json::array({2}));
  EXPECT_EQ(summary["windows"][1]["frames"][1]["index"], 3);  // across the gap
}

}  // namespace
}  // namespace evfs
