// End-to-end tests of the `evfs` tool: what users type, what they read back, exit codes.
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "events/scene_synthesizer.h"
#include "events/simulator.h"
#include "io/text_folder.h"
#include "tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

CommandResult RunEvfs(const std::string& arguments) {
  const std::string command = std::string(EVFS_BINARY) + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (fgets(buffer, sizeof(buffer), pipe)) result.output += buffer;
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A small synthetic recording written as a data folder: 5 frames 5 ms apart, events simulated
// from a 1 kHz rendering.
std::string WriteSyntheticFolder(const std::string& scratch) {
  SceneOptions scene;
  scene.width = 40;
  scene.height = 32;
  scene.duration_s = 0.02;
  scene.num_shapes = 2;
  scene.min_shape_size_px = 5.0;
  scene.max_shape_size_px = 10.0;
  const Video rendered = SceneSynthesizer(scene).RenderAtRate(1000.0);
  const EventStream events = SimulateEvents(rendered, SimulatorOptions());
  std::vector<FrameInfo> frames;
  std::vector<Image> images;
  for (int t = 0; t < rendered.num_frames(); t += 5) {
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

TEST(EvfsCli, InfoDescribesTheSharedSnippets) {
  EVFS_REQUIRE_SHARED_DATA(data);
  const CommandResult slider =
      RunEvfs("info --data=" + data + "/slider_depth_70_71 --first=0 --last=1");
  ASSERT_EQ(slider.exit_code, 0) << slider.output;
  EXPECT_NE(slider.output.find("240x180"), std::string::npos) << slider.output;
  EXPECT_NE(slider.output.find("events      16418"), std::string::npos) << slider.output;
  EXPECT_NE(slider.output.find("frames      2"), std::string::npos) << slider.output;
  EXPECT_NE(slider.output.find("16418 events, 13 collision frames"), std::string::npos)
      << slider.output;

  const CommandResult cups = RunEvfs("info --data=" + data + "/eslnet_cups_blur");
  ASSERT_EQ(cups.exit_code, 0) << cups.output;
  EXPECT_NE(cups.output.find("346x260"), std::string::npos);
  EXPECT_NE(cups.output.find("frames      6"), std::string::npos);
  EXPECT_NE(cups.output.find("exposure 3.312216 .. 3.416216 s (104.0 ms)"), std::string::npos)
      << cups.output;

  const CommandResult clip = RunEvfs("info --data=" + data + "/nfs_basketball_7");
  ASSERT_EQ(clip.exit_code, 0) << clip.output;
  EXPECT_NE(clip.output.find("200x200"), std::string::npos);
  EXPECT_NE(clip.output.find("frames only"), std::string::npos);
}

TEST(EvfsCli, SimulateWritesAFolderThatInfoReads) {
  EVFS_REQUIRE_SHARED_DATA(data);
  const std::string out = testing::ScratchDir("simulate") + "/nfs";
  const CommandResult simulate =
      RunEvfs("simulate --frames=" + data + "/nfs_basketball_7 --out=" + out);
  ASSERT_EQ(simulate.exit_code, 0) << simulate.output;
  const CommandResult info = RunEvfs("info --data=" + out + " --first=0 --last=1");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("200x200"), std::string::npos);
  EXPECT_NE(info.output.find("frames      20"), std::string::npos);
  EXPECT_NE(info.output.find("collision frames"), std::string::npos);
}

TEST(EvfsCli, ConvertRoundTripIsByteIdentical) {
  EVFS_REQUIRE_SHARED_DATA(data);
  const std::string scratch = testing::ScratchDir("convert");
  const std::string source = data + "/shapes_rotation_13_20";
  ASSERT_EQ(RunEvfs("convert --data=" + source + " --out=" + scratch + "/shapes.h5").exit_code, 0);
  ASSERT_EQ(RunEvfs("convert --data=" + scratch + "/shapes.h5 --out=" + scratch + "/back").exit_code,
            0);
  EXPECT_EQ(ReadFile(scratch + "/back/events.txt"), ReadFile(source + "/events.txt"));
  EXPECT_EQ(ReadFile(scratch + "/back/images.txt"), ReadFile(source + "/images.txt"));
}

TEST(EvfsCli, ReconstructWritesFramesTimestampsAndSummary) {
  const std::string scratch = testing::ScratchDir("reconstruct");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string out = scratch + "/out";
  const CommandResult run = RunEvfs("reconstruct --data=" + data +
                                    " --mode=interpolate --first=0 --last=2 --truth=1 --out=" + out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string summary = ReadFile(out + "/summary.json");
  EXPECT_NE(summary.find("\"mode\": \"interpolate\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"truth\": {"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"alpha_derived\": true"), std::string::npos) << summary;
  const std::string timestamps = ReadFile(out + "/timestamps.txt");
  const int lines = static_cast<int>(std::count(timestamps.begin(), timestamps.end(), '\n'));
  int pngs = 0;
  for (const auto& entry : fs::directory_iterator(out + "/frames")) pngs += entry.is_regular_file();
  EXPECT_GT(lines, 2);
  EXPECT_EQ(pngs, lines);

  // Resampled to a uniform rate: 10 ms at 1 kHz gives 11 frames.
  const CommandResult resampled = RunEvfs("reconstruct --data=" + data +
                                          " --mode=interpolate --first=0 --last=2 --fps=1000 --out=" +
                                          out + "_1khz");
  ASSERT_EQ(resampled.exit_code, 0) << resampled.output;
  const std::string uniform = ReadFile(out + "_1khz/timestamps.txt");
  EXPECT_EQ(std::count(uniform.begin(), uniform.end(), '\n'), 11);
}

TEST(EvfsCli, UserErrorsExitWithStatus2AndLeaveNoOutput) {
  const std::string scratch = testing::ScratchDir("errors");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string out = scratch + "/out";
  const struct {
    std::string arguments;
    std::string expected;  // part of the one-line message
  } cases[] = {
      {"frobnicate", "unknown command"},
      {"info --data=" + scratch + "/missing", "missing"},
      {"reconstruct --data=" + data + " --mode=sideways --first=0 --out=" + out, "unknown mode"},
      {"reconstruct --data=" + data + " --mode=predict --first=9 --out=" + out, "out of range"},
      {"reconstruct --data=" + data + " --mode=interpolate --first=2 --last=1 --out=" + out,
       "must come after"},
      {"reconstruct --data=" + data + " --mode=deblur --first=1 --out=" + out, "exposure"},
      {"reconstruct --data=" + data + " --mode=predict --first=0 --spatial_tv=round --out=" + out,
       "--spatial_tv"},
  };
  for (const auto& c : cases) {
    const CommandResult result = RunEvfs(c.arguments);
    EXPECT_EQ(result.exit_code, 2) << c.arguments << "\n" << result.output;
    EXPECT_NE(result.output.find(c.expected), std::string::npos) << c.arguments << "\n"
                                                                 << result.output;
    EXPECT_FALSE(fs::exists(out)) << c.arguments;
  }
}

}  // namespace
}  // namespace evfs
