// What `evfs` may write and replace, end to end: every command that writes, against the cases
// that once deleted user files. Each test works in a sandbox folder of its own, with
// stand-ins for the home folder, the current folder and the input; no test names a real system
// path as --out.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "evfs/io/output_target.h"
#include "evfs/tests/examples/cli_test_util.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

using test::CommandResult;
using test::ExpectNoStagingLeft;
using test::ReadFile;
using test::RunEvfs;
using test::StartEvfs;
using test::WriteSyntheticFolder;

// A sandbox: a synthetic recording in data/, stand-ins for home and the current folder, and a
// user's folder of precious files.
struct Sandbox {
  explicit Sandbox(const std::string& name) : root(test::ScratchDir("output_" + name)) {
    data = WriteSyntheticFolder(root.string());
    for (const char* folder : {"home", "cwd/deeper", "thesis"})
      fs::create_directories(root / folder);
    test::WriteFile((root / "thesis/chapter1.tex").string(), "precious");
  }

  // Runs evfs in the stand-in current folder with the stand-in home folder.
  CommandResult Run(const std::string& arguments) const {
    return RunEvfs(arguments, "cd " + (root / "cwd/deeper").string() +
                                  " && HOME=" + (root / "home").string() + " ");
  }

  std::string Reconstruct(const fs::path& out) const {
    return "reconstruct --data=" + data +
           " --mode=interpolate --first=0 --last=1 --out=" + out.string();
  }

  // Every writing command, with --out=`out`.
  std::vector<std::string> AllCommands(const fs::path& out) const {
    return {Reconstruct(out), "simulate --frames=" + data + " --out=" + out.string(),
            "convert --data=" + data + " --out=" + out.string(), "demo --out=" + out.string()};
  }

  // Fails the test unless the recording and the user's files are as they were made.
  void ExpectUntouched() const {
    EXPECT_EQ(ReadFile((root / "thesis/chapter1.tex").string()), "precious");
    EXPECT_TRUE(fs::exists(fs::path(data) / "events.txt"));
    EXPECT_TRUE(fs::exists(fs::path(data) / "images.txt"));
    for (const char* folder : {"home", "cwd/deeper"}) {
      EXPECT_TRUE(fs::is_directory(root / folder)) << folder;
      EXPECT_TRUE(fs::is_empty(root / folder)) << folder;
    }
  }

  fs::path root;
  std::string data;
};

// Exit status 2, one line holding `expected`.
void ExpectRefused(const CommandResult& result, const std::string& expected) {
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_EQ(std::count(result.errors.begin(), result.errors.end(), '\n'), 1) << result.errors;
  EXPECT_NE(result.errors.find(expected), std::string::npos) << result.errors;
}

TEST(EvfsOutput, AFolderOfUnrelatedFilesIsNeverReplaced) {
  const Sandbox sandbox("unrelated");
  for (const std::string& command : sandbox.AllCommands(sandbox.root / "thesis")) {
    for (const char* overwrite : {"", " --overwrite"}) {
      SCOPED_TRACE(command + overwrite);
      ExpectRefused(sandbox.Run(command + overwrite), "holds files evfs did not write");
    }
  }
  sandbox.ExpectUntouched();
  ExpectNoStagingLeft(sandbox.root / "thesis");
}

TEST(EvfsOutput, TheInputAFolderInsideItAndOneAroundItAreRefused) {
  const Sandbox sandbox("input");
  const fs::path data = sandbox.data;
  const fs::path outer = sandbox.root / "outer";
  fs::create_directories(outer);
  fs::copy(data, outer / "recording", fs::copy_options::recursive);
  const auto expect_refused = [&sandbox](const std::string& input, const fs::path& out) {
    for (const std::string& command :
         {"reconstruct --data=" + input + " --mode=predict --first=0 --out=" + out.string(),
          "simulate --frames=" + input + " --out=" + out.string(),
          "convert --data=" + input + " --out=" + out.string()}) {
      SCOPED_TRACE(command);
      const CommandResult result = sandbox.Run(command + " --overwrite");
      EXPECT_EQ(result.exit_code, 2) << result.output;
      EXPECT_NE(result.errors.find("the input"), std::string::npos) << result.errors;
    }
  };
  for (const fs::path& out : {data, data / "images", data / "new"}) {
    expect_refused(data.string(), out);
  }
  expect_refused((outer / "recording").string(), outer);
  EXPECT_FALSE(fs::exists(data / "new"));
  EXPECT_TRUE(fs::exists(outer / "recording/events.txt"));
  sandbox.ExpectUntouched();
}

TEST(EvfsOutput, TheCurrentAndHomeFoldersAndTheirParentsAreRefused) {
  const Sandbox sandbox("protected");
  const std::string home = (sandbox.root / "home").string();
  for (const std::string& out : {std::string("."), std::string(".."), std::string("./"),
                                 std::string("../.."), home, home + "/"}) {
    for (const std::string& command : sandbox.AllCommands(out)) {
      SCOPED_TRACE(command);
      const CommandResult result = sandbox.Run(command + " --overwrite");
      EXPECT_EQ(result.exit_code, 2) << result.output;
      EXPECT_NE(result.errors.find("which evfs never replaces"), std::string::npos)
          << result.errors;
    }
  }
  sandbox.ExpectUntouched();
  EXPECT_EQ(std::distance(fs::directory_iterator(sandbox.root / "cwd"), fs::directory_iterator()),
            1);
}

TEST(EvfsOutput, AnExistingFileIsNeverReplaced) {
  const Sandbox sandbox("file");
  const fs::path notes = sandbox.root / "notes.txt";
  const fs::path recording = sandbox.root / "recording.h5";
  test::WriteFile(notes.string(), "mine");
  test::WriteFile(recording.string(), "not even HDF5, but mine");
  for (const std::string& command : sandbox.AllCommands(notes)) {
    SCOPED_TRACE(command);
    ExpectRefused(sandbox.Run(command + " --overwrite"), "refusing --out=");
  }
  ExpectRefused(sandbox.Run("convert --data=" + sandbox.data + " --out=" + recording.string() +
                            " --overwrite"),
                "the file exists and evfs did not write it");
  EXPECT_EQ(ReadFile(notes.string()), "mine");
  EXPECT_EQ(ReadFile(recording.string()), "not even HDF5, but mine");
  ExpectNoStagingLeft(notes);
  ExpectNoStagingLeft(recording);
}

TEST(EvfsOutput, NewFoldersWithTrailingSlashesOrMissingParentsAreMade) {
  const Sandbox sandbox("new");
  const CommandResult reconstruct = sandbox.Run(sandbox.Reconstruct("../fresh/"));
  ASSERT_EQ(reconstruct.exit_code, 0) << reconstruct.output;
  const fs::path fresh = sandbox.root / "cwd/fresh";
  EXPECT_TRUE(fs::exists(fresh / "frames/000000.png"));
  EXPECT_EQ(ReadFile((fresh / kOutputMarkerFile).string()).rfind("evfs reconstruct\n", 0), 0u);
  for (const char* out : {"a/b/converted.h5", "c/d/converted", "e/f/simulated"}) {
    const std::string command = std::string(out).find("simulated") != std::string::npos
                                    ? "simulate --frames="
                                    : "convert --data=";
    const CommandResult result =
        sandbox.Run(command + sandbox.data + " --out=" + (sandbox.root / out).string());
    EXPECT_EQ(result.exit_code, 0) << out << ": " << result.output;
    EXPECT_TRUE(fs::exists(sandbox.root / out)) << out;
  }
  const CommandResult info =
      sandbox.Run("info --data=" + (sandbox.root / "a/b/converted.h5").string());
  EXPECT_EQ(info.exit_code, 0) << info.output;
}

TEST(EvfsOutput, AnEarlierOutputIsReplacedWholeAndOnlyWithOverwrite) {
  const Sandbox sandbox("replace");
  const fs::path sim = sandbox.root / "sim";
  const std::string simulate = "simulate --frames=" + sandbox.data + " --out=" + sim.string();
  ASSERT_EQ(sandbox.Run(simulate).exit_code, 0);
  // A file the user added to the output: --overwrite refuses rather than delete it.
  test::WriteFile((sim / "exposures.txt").string(), "images/frame_0.png 0 0.001\n");
  ExpectRefused(sandbox.Run(simulate), "pass --overwrite to replace it");
  ExpectRefused(sandbox.Run(simulate + " --overwrite"), "exposures.txt");
  EXPECT_TRUE(fs::exists(sim / "exposures.txt"));
  fs::remove(sim / "exposures.txt");
  ASSERT_EQ(sandbox.Run(simulate + " --overwrite").exit_code, 0);
  EXPECT_TRUE(fs::exists(sim / "events.txt"));

  // Another command's output is not replaced, even with --overwrite.
  ExpectRefused(sandbox.Run(sandbox.Reconstruct(sim) + " --overwrite"),
                "holds the output of 'evfs simulate'");

  const fs::path h5 = sandbox.root / "recording.h5";
  const std::string convert = "convert --data=" + sandbox.data + " --out=" + h5.string();
  ASSERT_EQ(sandbox.Run(convert).exit_code, 0);
  ExpectRefused(sandbox.Run(convert), "pass --overwrite");
  const CommandResult again = sandbox.Run(convert + " --overwrite");
  EXPECT_EQ(again.exit_code, 0) << again.output;
  ExpectNoStagingLeft(sim);
  ExpectNoStagingLeft(h5);
  sandbox.ExpectUntouched();
}

// Files the user added inside an earlier output stop --overwrite of every command; the refusal
// names them, and once they are moved away the output is replaced.
TEST(EvfsOutput, OverwriteNeverDeletesWhatTheUserAddedToAnOutput) {
  const Sandbox sandbox("added");
  const fs::path out = sandbox.root / "out";
  const std::vector<std::string> commands = {
      sandbox.Reconstruct(out), "simulate --frames=" + sandbox.data + " --out=" + out.string(),
      "video --data=" + sandbox.data + " --fps=400 --out=" + out.string(),
      "demo --out=" + out.string()};
  for (const std::string& command : commands) {
    SCOPED_TRACE(command);
    fs::remove_all(out);
    const CommandResult first = sandbox.Run(command);
    ASSERT_EQ(first.exit_code, 0) << first.output;
    test::WriteFile((out / "notes.txt").string(), "mine");
    fs::create_directories(out / "my");
    test::WriteFile((out / "my/y").string(), "mine too");
    const CommandResult refused = sandbox.Run(command + " --overwrite");
    ExpectRefused(refused, "evfs did not write: my/, notes.txt");
    EXPECT_EQ(ReadFile((out / "notes.txt").string()), "mine");
    EXPECT_EQ(ReadFile((out / "my/y").string()), "mine too");
    ExpectNoStagingLeft(out);
    fs::remove(out / "notes.txt");
    fs::remove_all(out / "my");
    // No progress lines either (a sanitizer build may run past the interval).
    const CommandResult replaced = sandbox.Run(command + " --overwrite --progress_interval_s=0");
    EXPECT_EQ(replaced.exit_code, 0) << replaced.output;
    EXPECT_EQ(replaced.errors, "") << "nothing to warn about";
    ExpectNoStagingLeft(out);
  }
  sandbox.ExpectUntouched();
}

// A marker that is a link to a file naming the command is not evfs's marker.
TEST(EvfsOutput, ASymlinkedMarkerIsNamedAsOne) {
  const Sandbox sandbox("marker_link");
  const fs::path out = sandbox.root / "out";
  fs::create_directories(out);
  test::WriteFile((sandbox.root / "thesis/marker").string(), "evfs simulate\n");
  fs::create_symlink(sandbox.root / "thesis/marker", out / kOutputMarkerFile);
  ExpectRefused(
      sandbox.Run("simulate --frames=" + sandbox.data + " --out=" + out.string() + " --overwrite"),
      "is a symbolic link");
  EXPECT_TRUE(fs::is_symlink(out / kOutputMarkerFile));
  ExpectNoStagingLeft(out);
}

TEST(EvfsOutput, ABadOutFailsBeforeAnyInputIsRead) {
  const Sandbox sandbox("early");
  test::WriteFile((sandbox.root / "file").string(), "a file");
  const std::string missing = (sandbox.root / "no_such_recording").string();
  const std::string bad_out = (sandbox.root / "file/out").string();
  for (const std::string& command :
       {"reconstruct --data=" + missing + " --mode=predict --first=0 --out=" + bad_out,
        "simulate --frames=" + missing + " --out=" + bad_out,
        "convert --data=" + missing + " --out=" + bad_out,
        "reconstruct --data=" + missing +
            " --mode=predict --first=0 --out=" + (sandbox.root / "thesis").string()}) {
    SCOPED_TRACE(command);
    const CommandResult result = sandbox.Run(command);
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_EQ(result.errors.find("no_such_recording:"), std::string::npos)
        << "read the input before checking --out: " << result.errors;
  }
  sandbox.ExpectUntouched();
}

// The staging folder of --out=`out` once it holds `frame`, or "" after `timeout`.
fs::path WaitForStagedFrame(const fs::path& out, const std::string& frame,
                            std::chrono::seconds timeout) {
  const std::string prefix = "." + out.filename().string() + ".evfs-tmp-";
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    for (const auto& entry : fs::directory_iterator(out.parent_path())) {
      if (entry.path().filename().string().rfind(prefix, 0) == 0 &&
          fs::exists(entry.path() / "frames" / frame)) {
        return entry.path();
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return "";
}

// A signal while evfs writes frames (thousands of them, at --fps=1000000) over an earlier
// output: evfs dies of that signal, its staging folder is gone and the earlier output is whole.
void ExpectSignalLeavesTheEarlierOutput(int signal_number, bool hdf5) {
  const Sandbox sandbox("signal_" + std::to_string(signal_number) + (hdf5 ? "_h5" : ""));
  std::string data = sandbox.data;
  if (hdf5) {
    data = (sandbox.root / "recording.h5").string();
    ASSERT_EQ(RunEvfs("convert --data=" + sandbox.data + " --out=" + data).exit_code, 0);
  }
  const fs::path out = sandbox.root / "out";
  const std::vector<std::string> arguments = {"reconstruct",        "--data=" + data,
                                              "--mode=interpolate", "--first=0",
                                              "--last=1",           "--out=" + out.string()};
  const CommandResult earlier = sandbox.Run(sandbox.Reconstruct(out));
  ASSERT_EQ(earlier.exit_code, 0) << earlier.output;
  const std::string earlier_summary = ReadFile((out / "summary.json").string());

  std::vector<std::string> long_job = arguments;
  long_job.push_back("--fps=1000000");
  long_job.push_back("--overwrite");
  const pid_t pid = StartEvfs(long_job, sandbox.root);
  ASSERT_GT(pid, 0);
  const fs::path staging = WaitForStagedFrame(out, "000100.png", std::chrono::seconds(60));
  ASSERT_FALSE(staging.empty()) << "evfs never wrote frames";
  ASSERT_EQ(kill(pid, signal_number), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  const std::string errors = ReadFile((sandbox.root / "stderr.txt").string());
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status) << ": " << errors;
  EXPECT_EQ(WTERMSIG(status), signal_number);
  EXPECT_NE(errors.find("the unfinished output was removed"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(staging)) << staging;
  ExpectNoStagingLeft(out);
  EXPECT_EQ(ReadFile((out / "summary.json").string()), earlier_summary);
  EXPECT_FALSE(fs::exists(out / "frames/000100.png")) << "new frames mixed into the old output";
  sandbox.ExpectUntouched();
}

TEST(EvfsOutput, SigintWhileWritingFramesKeepsTheEarlierOutput) {
  ExpectSignalLeavesTheEarlierOutput(SIGINT, false);
}

TEST(EvfsOutput, SigtermWhileWritingFramesKeepsTheEarlierOutput) {
  ExpectSignalLeavesTheEarlierOutput(SIGTERM, false);
}

TEST(EvfsOutput, SighupWhileWritingFramesKeepsTheEarlierOutput) {
  ExpectSignalLeavesTheEarlierOutput(SIGHUP, false);
}

TEST(EvfsOutput, SigtermWhileWritingFramesFromHdf5KeepsTheEarlierOutput) {
  ExpectSignalLeavesTheEarlierOutput(SIGTERM, true);
}

// SIGKILL of the main process leaves its staging folder (nothing can clean up); the next run
// on that output removes it, since its marker shows it to be evfs's, and says so.
TEST(EvfsOutput, AStagingFolderLeftBySigkillIsRemovedByTheNextRun) {
  const Sandbox sandbox("sigkill");
  const fs::path out = sandbox.root / "out";
  ASSERT_EQ(sandbox.Run(sandbox.Reconstruct(out)).exit_code, 0);
  const pid_t pid =
      StartEvfs({"reconstruct", "--data=" + sandbox.data, "--mode=interpolate", "--first=0",
                 "--last=1", "--fps=1000000", "--overwrite", "--out=" + out.string()},
                sandbox.root);
  ASSERT_GT(pid, 0);
  const fs::path staging = WaitForStagedFrame(out, "000100.png", std::chrono::seconds(60));
  ASSERT_FALSE(staging.empty()) << "evfs never wrote frames";
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  // The worker, whose id the staging name carries, dies with its parent.
  const std::string name = staging.filename().string();
  const size_t digits = name.rfind(".evfs-tmp-") + std::string(".evfs-tmp-").size();
  const pid_t worker = static_cast<pid_t>(std::stol(name.substr(digits)));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (kill(worker, 0) == 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(fs::exists(staging)) << "nothing left: the test proves nothing";

  const CommandResult next = sandbox.Run(sandbox.Reconstruct(out) + " --overwrite");
  EXPECT_EQ(next.exit_code, 0) << next.output;
  EXPECT_NE(next.errors.find("removed " + staging.string()), std::string::npos) << next.errors;
  EXPECT_FALSE(fs::exists(staging));
  ExpectNoStagingLeft(out);
  sandbox.ExpectUntouched();
}

}  // namespace
}  // namespace evfs
