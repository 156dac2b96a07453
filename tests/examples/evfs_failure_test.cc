// How `evfs` fails, end to end: whose fault each failure is (exit status 2 for the user's, 3 for
// evfs' own bugs, 4 for a solver that failed), that each is one line saying what is wrong, and
// that a long command reports progress wherever stderr goes.
// Each test works in a scratch folder of its own.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "evfs/io/image_io.h"
#include "evfs/tests/examples/cli_test_util.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

using test::CommandResult;
using test::ExpectNoStagingLeft;
using test::ExpectUserError;
using test::RunEvfs;
using test::WriteSyntheticFolder;

// Exit statuses (core/error.h, ExitStatus).
constexpr int kSolverFailureStatus = 4;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream stream(text);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

// gflags used to print its own text and exit with status 1.
TEST(EvfsFailure, FlagsThatDoNotParseAreOneLineUserErrors) {
  const fs::path scratch = test::ScratchDir("failure_flags");
  const fs::path out = scratch / "out";
  const std::string data = WriteSyntheticFolder(scratch.string());
  const std::string reconstruct =
      "reconstruct --data=" + data + " --mode=predict --first=0 --out=" + out.string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"info --bogus=1", "evfs: unknown flag --bogus"},
      {reconstruct + " --fps=abc", "evfs: --fps=abc: expected a number"},
      {"info --first=x", "evfs: --first=x: expected a whole number"},
      {"info --first 99999999999", "evfs: --first=99999999999: expected a whole number"},
      {reconstruct + " --bounds=maybe", "evfs: --bounds=maybe: expected true or false"},
      {"info --data", "evfs: --data needs a value"},
      {"info --nodata", "evfs: unknown flag --nodata"},
      {"--flagfile=" + (scratch / "none").string() + " info", "cannot read"},
  };
  for (const auto& [arguments, expected] : cases) {
    SCOPED_TRACE(arguments);
    const CommandResult result = RunEvfs(arguments);
    ExpectUserError(result, expected, out);
    EXPECT_EQ(result.output, result.errors) << "printed on stdout too";
  }
}

// gflags ended every help flag with status 1.
TEST(EvfsFailure, HelpAskedForIsASuccess) {
  for (const char* flag : {"--help", "-help", "--helpfull", "--helpshort", "--helpon=evfs_main"}) {
    SCOPED_TRACE(flag);
    const CommandResult result = RunEvfs(flag);
    EXPECT_EQ(result.exit_code, 0);
    EXPECT_EQ(result.errors, "");
    EXPECT_NE(result.output.find("usage:"), std::string::npos) << result.output;
    EXPECT_NE(result.output.find("-progress_interval_s"), std::string::npos);
  }
  const CommandResult match = RunEvfs("--helpmatch=evfs_main");
  EXPECT_EQ(match.exit_code, 0);
  EXPECT_NE(match.output.find("-progress_interval_s"), std::string::npos) << match.output;
  const CommandResult version = RunEvfs("--version");
  EXPECT_EQ(version.exit_code, 0);
}

// Black frames with b = 1e-307 in g(x) = log(x + b): g'(0) = 1e307, and α = 100 times that
// overflows, so the event residuals' Jacobian is not finite at the start and Ceres ends with
// FAILURE. The input was accepted, so it is not the user's error (status 2) but the solver's:
// status 4, one line (Ceres' own dump is shown with --minloglevel=0 only), and no output.
TEST(EvfsFailure, CeresFailureIsASolverFailureNotAUserError) {
  const fs::path scratch = test::ScratchDir("failure_solver");
  const fs::path out = scratch / "out";
  const std::string data = WriteSyntheticFolder(scratch.string());
  for (const auto& entry : fs::directory_iterator(fs::path(data) / "images")) {
    const Image frame = ReadGreyImage(entry.path().string());
    WriteGreyPng8(entry.path().string(), Image::Zero(frame.rows(), frame.cols()));
  }
  const CommandResult result = RunEvfs("reconstruct --data=" + data +
                                       " --mode=interpolate --first=0 --last=1 --alpha=100 "
                                       "--log_offset=1e-307 --out=" +
                                       out.string());
  EXPECT_EQ(result.exit_code, kSolverFailureStatus) << result.output;
  EXPECT_EQ(Lines(result.errors).size(), 1u) << result.errors;
  EXPECT_EQ(result.errors.rfind("evfs reconstruct: the solver failed: ", 0), 0u) << result.errors;
  EXPECT_FALSE(fs::exists(out));
  ExpectNoStagingLeft(out);
}

// Flags whose values reached Ceres, or the solve, before anything named them: each is one line
// naming the flag, before any work.
TEST(EvfsFailure, BadSolverAndFrameFlagsNameTheFlag) {
  const fs::path scratch = test::ScratchDir("failure_flags");
  const fs::path out = scratch / "out";
  const std::string data = WriteSyntheticFolder(scratch.string());
  const std::string reconstruct =
      "reconstruct --data=" + data + " --mode=interpolate --first=0 --last=1 --out=" + out.string();
  ExpectUserError(RunEvfs(reconstruct + " --alpha=1e308"), "--alpha must be <= 1000000, not 1e+308",
                  out);
  ExpectUserError(RunEvfs(reconstruct + " --threads=0"), "--threads must be in [1, 4096], not 0",
                  out);
  ExpectUserError(
      RunEvfs("reconstruct --data=" + data + " --mode=predict --first=-5 --out=" + out.string()),
      "--first must be -1, or >= 0, not -5", out);
  const std::string video = "video --data=" + data + " --out=" + out.string();
  ExpectUserError(RunEvfs(video + " --first=-5"), "--first must be -1, or >= 0, not -5", out);
  const CommandResult slow = RunEvfs(video + " --fps=1e-3");
  ExpectUserError(slow, "--fps must be 0 (derived) or at least 1 frame per second", out);
  EXPECT_EQ(slow.output.find("windows"), std::string::npos) << "solved first: " << slow.output;
}

// Only a window's events are read to solve it, but a text recording is parsed whole once by every
// command, so that info, reconstruct and video accept and refuse the same events.txt.
TEST(EvfsFailure, MalformedEventLineOutsideTheWindowIsRefusedByEveryCommand) {
  const fs::path scratch = test::ScratchDir("failure_line_outside_window");
  const fs::path out = scratch / "out";
  const fs::path data = WriteSyntheticFolder(scratch.string());
  std::ofstream(data / "events.txt", std::ios::app) << "1.5 3 4 x\n";  // after every frame
  const std::string expected = (data / "events.txt").string() + ":";
  for (const std::string& command :
       {"info --data=" + data.string(),
        "reconstruct --data=" + data.string() +
            " --mode=interpolate --first=0 --last=1 --out=" + out.string(),
        "video --data=" + data.string() + " --out=" + out.string()}) {
    const CommandResult result = RunEvfs(command);
    ExpectUserError(result, expected, out);
    EXPECT_NE(result.errors.find("field 'p'"), std::string::npos)
        << command << ": " << result.errors;
  }
}

// events.txt or images.txt that exists but is no regular file used to read as "this folder
// holds frames only" (or, for images.txt, as no frames at all).
TEST(EvfsFailure, DataFileThatIsNoRegularFileIsNamedAsSuch) {
  const fs::path scratch = test::ScratchDir("failure_not_a_file");
  const fs::path out = scratch / "out";
  const fs::path data = WriteSyntheticFolder(scratch.string());
  const std::string reconstruct =
      "reconstruct --data=" + data.string() + " --mode=predict --first=0 --out=" + out.string();

  const fs::path events_txt = data / "events.txt";
  const fs::path events_aside = scratch / "events.txt";
  fs::rename(events_txt, events_aside);
  fs::create_directory(events_txt);
  const std::string folder_message =
      events_txt.string() + ": a folder, not a file of events ('t x y p' lines)";
  ExpectUserError(RunEvfs("info --data=" + data.string()), folder_message, out);
  ExpectUserError(RunEvfs(reconstruct), folder_message, out);

  fs::remove(events_txt);
  ASSERT_EQ(mkfifo(events_txt.c_str(), 0600), 0);
  const std::string fifo_message =
      events_txt.string() + ": a FIFO, socket or device, not a file of events";
  ExpectUserError(RunEvfs("info --data=" + data.string()), fifo_message, out);
  ExpectUserError(RunEvfs(reconstruct), fifo_message, out);
  fs::remove(events_txt);
  fs::rename(events_aside, events_txt);

  const fs::path images_txt = data / "images.txt";
  fs::remove(images_txt);
  fs::create_directory(images_txt);
  ExpectUserError(RunEvfs("info --data=" + data.string()),
                  images_txt.string() + ": a folder, not a file of frames ('t path' lines)", out);
}

// A frame path in images.txt that leaves the recording's folder is refused on its line, for
// every command that reads frames, unless --allow_outside_paths is given.
TEST(EvfsFailure, FramePathsOutsideTheRecordingNeedAFlag) {
  const fs::path scratch = test::ScratchDir("failure_outside_paths");
  const fs::path out = scratch / "out";
  const fs::path data = WriteSyntheticFolder(scratch.string());
  const fs::path images_txt = data / "images.txt";
  std::string list = test::ReadFile(images_txt);
  const std::string first = "images/frame_0.png";
  fs::copy_file(data / first, scratch / "outside.png");
  for (const std::string& outside :
       {std::string("../outside.png"), (scratch / "outside.png").string()}) {
    SCOPED_TRACE(outside);
    std::string changed = list;
    changed.replace(changed.find(first), first.size(), outside);
    test::WriteFile(images_txt.string(), changed);
    for (const std::string& command :
         {"info --data=" + data.string(),
          "reconstruct --data=" + data.string() + " --mode=predict --first=0 --out=" + out.string(),
          "convert --data=" + data.string() + " --out=" + out.string()}) {
      SCOPED_TRACE(command);
      ExpectUserError(RunEvfs(command), images_txt.string() + ":1", out);
      const CommandResult allowed = RunEvfs(command + " --allow_outside_paths");
      EXPECT_EQ(allowed.exit_code, 0) << allowed.output;
      fs::remove_all(out);
    }
  }
  test::WriteFile(images_txt.string(), list);
}

// A folder without images.txt is events alone: `info` describes it (status 0) and says why it
// lists no frame; reading a frame says the same instead of "has 0 frames (0..-1)".
TEST(EvfsFailure, MissingFrameListIsNamed) {
  const fs::path scratch = test::ScratchDir("failure_no_frames");
  const fs::path out = scratch / "out";
  const fs::path data = WriteSyntheticFolder(scratch.string());
  const fs::path images_txt = data / "images.txt";
  fs::remove(images_txt);
  const std::string reason = "(there is no " + images_txt.string() + ")";

  const CommandResult info = RunEvfs("info --data=" + data.string());
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("frames      0 " + reason), std::string::npos) << info.output;
  ExpectUserError(RunEvfs("info --data=" + data.string() + " --first=0"),
                  data.string() + " has 0 frames " + reason, out);
  ExpectUserError(RunEvfs("reconstruct --data=" + data.string() +
                          " --mode=predict --first=0 --out=" + out.string()),
                  data.string() + " has 0 frames " + reason, out);

  // The same recording as HDF5: it has no /images group.
  const fs::path h5 = scratch / "events_only.h5";
  ASSERT_EQ(RunEvfs("convert --data=" + data.string() + " --out=" + h5.string()).exit_code, 0);
  ExpectUserError(RunEvfs("reconstruct --data=" + h5.string() +
                          " --mode=predict --first=0 --out=" + out.string()),
                  h5.string() + " has 0 frames (", out);
}

// Progress lines (runtime/progress.h) look like
//   evfs reconstruct: 0.0 s elapsed             (before the job names its first stage)
//   evfs reconstruct: build and solve, 0.1 s elapsed
//   evfs reconstruct: solve, iteration 3 (cost 1.234567e-01), 0.2 s elapsed
// (std::regex would do, but GCC 12 warns inside <regex> under -O2 with the sanitizers, and CI
// builds those with -Werror.)
bool AllOf(const std::string& text, const char* characters) {
  return !text.empty() && text.find_first_not_of(characters) == std::string::npos;
}

bool IsProgressLine(const std::string& line) {
  const std::string prefix = "evfs reconstruct: ", suffix = " s elapsed";
  if (line.size() < prefix.size() + suffix.size() || line.rfind(prefix, 0) != 0 ||
      line.compare(line.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return false;
  }
  const std::string body = line.substr(prefix.size(), line.size() - prefix.size() - suffix.size());
  const size_t comma = body.rfind(", ");
  const std::string seconds = comma == std::string::npos ? body : body.substr(comma + 2);
  const size_t point = seconds.find('.');
  if (point == std::string::npos || point + 2 != seconds.size() ||
      !AllOf(seconds.substr(0, point), "0123456789") ||
      !AllOf(seconds.substr(point + 1), "0123456789")) {
    return false;
  }
  if (comma == std::string::npos) return true;
  const std::string head = body.substr(0, comma);
  const size_t iteration = head.find(", iteration ");
  const std::string stage = head.substr(0, iteration);
  const std::vector<std::string> stages = {"read",  "bin",     "build", "build and solve",
                                           "solve", "denoise", "write"};
  if (std::find(stages.begin(), stages.end(), stage) == stages.end()) return false;
  if (iteration == std::string::npos) return true;
  const std::string rest = head.substr(iteration + std::string(", iteration ").size());
  const size_t cost = rest.find(" (cost ");
  return cost != std::string::npos && AllOf(rest.substr(0, cost), "0123456789") &&
         rest.back() == ')' &&
         AllOf(rest.substr(cost + 7, rest.size() - cost - 8), "-+.e0123456789");
}

// stderr is a file here, not a terminal: a command running longer than the interval still
// says what it does, on a line of its own every interval.
TEST(EvfsFailure, ProgressIsPrintedOffATerminal) {
  const fs::path scratch = test::ScratchDir("failure_progress");
  const std::string data = WriteSyntheticFolder(scratch.string());
  // An interval far below the job's length (a fork, a read, a build and a solve: well over
  // 10 ms), so that several lines come.
  const CommandResult result =
      RunEvfs("reconstruct --data=" + data + " --mode=interpolate --first=0 --last=2 --out=" +
              (scratch / "out").string() + " --progress_interval_s=0.002");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::vector<std::string> lines = Lines(result.errors);
  ASSERT_GE(lines.size(), 1u) << result.errors;
  for (const std::string& line : lines) {
    EXPECT_TRUE(IsProgressLine(line)) << line;
  }
}

TEST(EvfsFailure, QuickCommandsPrintNoProgress) {
  const fs::path scratch = test::ScratchDir("failure_quick");
  const std::string data = WriteSyntheticFolder(scratch.string());
  const CommandResult result =
      RunEvfs("reconstruct --data=" + data +
              " --mode=predict --first=0 --out=" + (scratch / "out").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.errors, "");
  // --progress keeps its line per iteration.
  const CommandResult every =
      RunEvfs("reconstruct --data=" + data +
              " --mode=predict --first=0 --progress --out=" + (scratch / "out2").string());
  ASSERT_EQ(every.exit_code, 0) << every.output;
  EXPECT_EQ(every.errors.rfind("iter    0  cost ", 0), 0u) << every.errors;
}

}  // namespace
}  // namespace evfs
