// The work folder of `evfs video` (app/video_work_folder.h): what it may delete is only what evfs
// wrote there. Every test works inside its own scratch folder under the build tree, with
// stand-ins for what a user keeps beside an output.
#include "evfs/app/video_work_folder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "evfs/core/error.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

void Write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

std::string Read(const fs::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// A work folder as a finished run leaves it: the marker, a frame, a confidence map, a record.
fs::path MakeFinishedWorkFolder(const fs::path& root) {
  const fs::path work = VideoWorkFolder((root / "out").string());
  PrepareVideoWorkFolder(work, "settings", /*resume=*/false);
  Write(work / "frames" / "000000.png", "frame");
  Write(work / "confidence" / "000000.png", "sigma");
  Write(work / "windows" / "000000.json", "{\"index\": 0}");
  return work;
}

TEST(VideoWorkFolder, IsAHiddenSiblingOfTheOutputNeverTheOutputOrItsParent) {
  EXPECT_EQ(VideoWorkFolder("/data/run/out"), "/data/run/.out.evfs-video-work");
  EXPECT_EQ(VideoWorkFolder("/data/run/out/"), "/data/run/.out.evfs-video-work");
  EXPECT_EQ(VideoWorkFolder("/data/run/./out"), "/data/run/.out.evfs-video-work");
}

TEST(VideoWorkFolder, AFinishedRunsFolderIsRemovedWhole) {
  const fs::path root = test::ScratchDir("work_folder_whole");
  Write(root / "keep.txt", "beside the output");
  const fs::path work = MakeFinishedWorkFolder(root);
  ASSERT_TRUE(IsVideoWorkFolder(work));
  RemoveVideoWorkFolder((root / "out").string());
  EXPECT_FALSE(fs::exists(work));
  EXPECT_EQ(Read(root / "keep.txt"), "beside the output");
}

TEST(VideoWorkFolder, WhatTheUserPutInsideStaysWithItsFolders) {
  const fs::path root = test::ScratchDir("work_folder_user_file");
  const fs::path work = MakeFinishedWorkFolder(root);
  Write(work / "frames" / "notes.txt", "precious");
  ClearVideoWorkFolder(work);
  EXPECT_EQ(Read(work / "frames" / "notes.txt"), "precious");
  EXPECT_FALSE(fs::exists(work / "frames" / "000000.png"));
  EXPECT_FALSE(fs::exists(work / "confidence"));  // emptied: evfs' own
  EXPECT_FALSE(fs::exists(work / "windows"));
}

TEST(VideoWorkFolder, AFolderEvfsDidNotMarkIsNeverTouched) {
  const fs::path root = test::ScratchDir("work_folder_unmarked");
  // Shaped like a work folder, without the marker: a user's folder.
  const fs::path work = VideoWorkFolder((root / "out").string());
  Write(work / "frames" / "000000.png", "the user's frame");
  EXPECT_FALSE(IsVideoWorkFolder(work));
  ClearVideoWorkFolder(work);
  RemoveVideoWorkFolder((root / "out").string());
  EXPECT_EQ(Read(work / "frames" / "000000.png"), "the user's frame");
  EXPECT_THROW(PrepareVideoWorkFolder(work, "settings", false), InvalidArgumentError);
  EXPECT_THROW(PrepareVideoWorkFolder(work, "settings", true), InvalidArgumentError);
  EXPECT_EQ(Read(work / "frames" / "000000.png"), "the user's frame");
}

TEST(VideoWorkFolder, ALinkAtItsPathIsNeverFollowed) {
  const fs::path root = test::ScratchDir("work_folder_link");
  // The link points to a marked work folder elsewhere: still not this run's to delete.
  fs::create_directory(root / "elsewhere");
  const fs::path elsewhere = MakeFinishedWorkFolder(root / "elsewhere");
  const fs::path work = VideoWorkFolder((root / "out").string());
  fs::create_directory_symlink(elsewhere, work);
  EXPECT_FALSE(IsVideoWorkFolder(work));
  RemoveVideoWorkFolder((root / "out").string());
  EXPECT_THROW(PrepareVideoWorkFolder(work, "settings", false), InvalidArgumentError);
  EXPECT_TRUE(fs::is_symlink(work));
  EXPECT_EQ(Read(elsewhere / "frames" / "000000.png"), "frame");
}

TEST(VideoWorkFolder, ARunWithoutResumeReplacesOnlyAnOwnFolder) {
  const fs::path root = test::ScratchDir("work_folder_replace");
  const fs::path work = MakeFinishedWorkFolder(root);
  // Without --resume the earlier run's windows go; the folder is made again, empty.
  EXPECT_TRUE(PrepareVideoWorkFolder(work, "other settings", false).empty());
  EXPECT_TRUE(IsVideoWorkFolder(work));
  EXPECT_FALSE(fs::exists(work / "frames" / "000000.png"));
  EXPECT_FALSE(fs::exists(work / "windows" / "000000.json"));
  // With a file of the user's inside, it is refused and nothing is removed.
  Write(work / "frames" / "000001.png", "frame");
  Write(work / "notes.txt", "precious");
  EXPECT_THROW(PrepareVideoWorkFolder(work, "other settings", false), InvalidArgumentError);
  EXPECT_EQ(Read(work / "notes.txt"), "precious");
  EXPECT_EQ(Read(work / "frames" / "000001.png"), "frame");
}

TEST(VideoWorkFolder, ResumeReturnsTheRecordsOfTheSameSettingsOnly) {
  const fs::path root = test::ScratchDir("work_folder_resume");
  const fs::path work = VideoWorkFolder((root / "out").string());
  PrepareVideoWorkFolder(work, "settings", false);
  Write(work / "windows" / "000003.json", "{\"index\": 3}");
  Write(work / "windows" / "000004.json", "not json");  // solved again
  const auto records = PrepareVideoWorkFolder(work, "settings", true);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records.begin()->first, 3);
  EXPECT_THROW(PrepareVideoWorkFolder(work, "other settings", true), InvalidArgumentError);
  EXPECT_TRUE(fs::exists(work / "windows" / "000003.json"));
}

}  // namespace
}  // namespace evfs
