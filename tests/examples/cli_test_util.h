// What the CLI tests share: running the `evfs` binary, reading back what it printed, checking a
// user error's shape, and a small synthetic recording to run it on.
#ifndef EVFS_TESTS_EXAMPLES_CLI_TEST_UTIL_H_
#define EVFS_TESTS_EXAMPLES_CLI_TEST_UTIL_H_

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/io/text_folder.h"

namespace evfs {
namespace test {

namespace fs = std::filesystem;

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout, then stderr
  std::string errors;  // stderr alone
};

inline std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Runs `evfs arguments` through the shell, after `shell_prefix` ("cd DIR && HOME=DIR "), and
// collects what it printed.
inline CommandResult RunEvfs(const std::string& arguments, const std::string& shell_prefix = "") {
  fs::create_directories(EVFS_TEST_TMP_DIR);
  // One file per process: ctest runs the tests of one executable side by side.
  const fs::path stderr_file =
      fs::path(EVFS_TEST_TMP_DIR) / ("stderr_" + std::to_string(::getpid()) + ".txt");
  const std::string command =
      shell_prefix + std::string(EVFS_BINARY) + " " + arguments + " 2>" + stderr_file.string();
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe)) result.output += buffer;
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.errors = ReadFile(stderr_file);
  result.output += result.errors;
  fs::remove(stderr_file);
  return result;
}

// Longest error line accepted: the paths it names plus a short explanation, even when the input
// held a megabyte line (input is quoted cut short, io/message_excerpt.h).
inline constexpr size_t kMaxErrorLineBytes = 600;

// Nothing beside `out` that its staging (".OUT.evfs-tmp-...") or aside names start with.
inline void ExpectNoStagingLeft(const fs::path& out) {
  const std::string prefix = "." + out.filename().string() + ".evfs-";
  const std::string stem_prefix = "." + out.stem().string() + ".evfs-";
  for (const auto& entry : fs::directory_iterator(out.parent_path())) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name.rfind(prefix, 0) != 0 && name.rfind(stem_prefix, 0) != 0)
        << "left behind: " << entry.path();
  }
}

// A user error: exit status 2, exactly one short line on stderr holding `expected` (the file
// and line it names, or the flag), and nothing under `out` or beside it (no staging folder).
inline void ExpectUserError(const CommandResult& result, const std::string& expected,
                            const fs::path& out) {
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_EQ(std::count(result.errors.begin(), result.errors.end(), '\n'), 1) << result.errors;
  EXPECT_EQ(result.errors.back(), '\n') << result.errors;
  EXPECT_LT(result.errors.size(), kMaxErrorLineBytes) << result.errors.substr(0, 1000);
  EXPECT_NE(result.errors.find(expected), std::string::npos) << result.errors;
  EXPECT_FALSE(fs::exists(out)) << out;
  ExpectNoStagingLeft(out);
}

// A small synthetic recording written as SCRATCH/data: `num_frames` frames `frame_step_ms` apart
// on a `width` x `height` sensor, events simulated from a 1 kHz rendering of two moving shapes.
// The defaults make 5 frames 5 ms apart at 40x32.
inline std::string WriteSyntheticFolder(const std::string& scratch, int num_frames = 5,
                                        int frame_step_ms = 5, int width = 40, int height = 32) {
  SceneOptions scene;
  scene.width = width;
  scene.height = height;
  scene.duration_s = (num_frames - 1) * frame_step_ms / 1000.0;
  scene.num_shapes = 2;
  scene.min_shape_size_px = 5.0;
  scene.max_shape_size_px = 10.0;
  const Video rendered = SceneSynthesizer(scene).RenderAtRate(1000.0);
  const EventStream events = SimulateEvents(rendered, SimulatorOptions());
  std::vector<FrameInfo> frames;
  std::vector<Image> images;
  for (int t = 0; t < rendered.num_frames(); t += frame_step_ms) {
    FrameInfo info;
    info.t_ns = rendered.timestamp_ns(t);
    info.path = "images/frame_" + std::to_string(t) + ".png";
    frames.push_back(info);
    images.push_back(rendered.frame(t));
  }
  const std::string folder = (fs::path(scratch) / "data").string();
  WriteDataFolder(folder, events, frames, images);
  return folder;
}

// Starts evfs with `arguments` in the background (the caller waits for the returned pid), its
// stdout and stderr in FOLDER/stdout.txt and FOLDER/stderr.txt.
inline pid_t StartEvfs(const std::vector<std::string>& arguments, const fs::path& folder) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  const std::string out = (folder / "stdout.txt").string();
  const std::string err = (folder / "stderr.txt").string();
  if (!freopen(out.c_str(), "w", stdout) || !freopen(err.c_str(), "w", stderr)) _exit(120);
  std::vector<char*> argv = {const_cast<char*>(EVFS_BINARY)};
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  execv(EVFS_BINARY, argv.data());
  _exit(121);
}

}  // namespace test
}  // namespace evfs

#endif  // EVFS_TESTS_EXAMPLES_CLI_TEST_UTIL_H_
