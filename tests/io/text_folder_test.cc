#include "evfs/io/text_folder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "evfs/io/image_io.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

constexpr int kWidth = 40;
constexpr int kHeight = 30;

// A folder with two 8-bit frames of kWidth x kHeight and the given events.txt content.
std::string MakeFolder(const std::string& test_name, const std::string& events_txt) {
  const std::string dir = test::ScratchDir(test_name);
  std::filesystem::create_directories(dir + "/images");
  WriteGreyPng8(dir + "/images/a.png", test::MakeRandomImage(1, kWidth, kHeight, 8));
  WriteGreyPng8(dir + "/images/b.png", test::MakeRandomImage(2, kWidth, kHeight, 8));
  test::WriteFile(dir + "/images.txt", "1.0 images/a.png\n2.0 images/b.png\n");
  test::WriteFile(dir + "/events.txt", events_txt);
  return dir;
}

TEST(TextFolderDataSourceTest, ReadsFramesEventsAndSensorSize) {
  const std::string dir = MakeFolder("folder_basic", "1.5 39 29 1\n1.6 0 0 0\n");
  test::WriteFile(dir + "/exposures.txt", "images/b.png 1.9 2.1\n");
  const TextFolderDataSource source(dir);
  EXPECT_EQ(source.path(), dir);
  EXPECT_EQ(source.width(), kWidth);
  EXPECT_EQ(source.height(), kHeight);
  ASSERT_EQ(source.frames().size(), 2u);
  EXPECT_FALSE(source.frames()[0].has_exposure);
  EXPECT_TRUE(source.frames()[1].has_exposure);
  EXPECT_EQ(source.frames()[1].exposure_begin_ns, 1900000000);
  EXPECT_TRUE((source.ReadImage(1) == test::MakeRandomImage(2, kWidth, kHeight, 8)).all());
  const EventStream events = source.ReadAllEvents();
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events.width(), kWidth);
  EXPECT_EQ(source.ReadEvents(1600000000, 1700000000).size(), 1u);
  EXPECT_EQ(source.Summarize().positive, 1);
}

TEST(TextFolderDataSourceTest, EventOutsideTheFirstImageIsOutOfRange) {
  const std::string dir = MakeFolder("folder_outside", "1.5 1 1 1\n1.6 40 0 1\n");
  const TextFolderDataSource source(dir);
  test::ExpectInputError([&] { source.ReadAllEvents(); }, InputError::Kind::kOutOfRange,
                         dir + "/events.txt", 2);
}

TEST(TextFolderDataSourceTest, ImageOfAnotherSizeIsASizeMismatch) {
  const std::string dir = MakeFolder("folder_mismatch", "1.5 1 1 1\n");
  WriteGreyPng8(dir + "/images/b.png", test::MakeRandomImage(2, kWidth, kHeight + 1, 8));
  const TextFolderDataSource source(dir);
  EXPECT_NO_THROW(source.ReadImage(0));
  test::ExpectInputError([&] { source.ReadImage(1); }, InputError::Kind::kSizeMismatch,
                         "images/b.png", 0);
}

TEST(TextFolderDataSourceTest, MissingPiecesAreInputErrors) {
  const std::string dir = MakeFolder("folder_missing_image", "1.5 1 1 1\n");
  std::filesystem::remove(dir + "/images/b.png");
  const TextFolderDataSource source(dir);
  test::ExpectInputError([&] { source.ReadImage(1); }, InputError::Kind::kMissingFile,
                         "images/b.png", 0);

  const std::string no_first = MakeFolder("folder_missing_first", "1.5 1 1 1\n");
  std::filesystem::remove(no_first + "/images/a.png");
  test::ExpectInputError([&] { TextFolderDataSource s(no_first); }, InputError::Kind::kMissingFile,
                         "images/a.png", 0);

  // Frames without events.txt: a frames-only recording (a ground-truth clip to simulate
  // from). It opens; reading its events is the error, and names the file.
  const std::string no_events = MakeFolder("folder_missing_events", "");
  std::filesystem::remove(no_events + "/events.txt");
  const TextFolderDataSource frames_only(no_events);
  EXPECT_FALSE(frames_only.has_events());
  EXPECT_EQ(frames_only.Summarize().count, 0);
  EXPECT_EQ(frames_only.frames().size(), 2u);
  test::ExpectInputError([&] { frames_only.ReadEvents(0, 1000); }, InputError::Kind::kMissingFile,
                         "events.txt", 0);
  test::ExpectInputError([&] { frames_only.ReadAllEvents(); }, InputError::Kind::kMissingFile,
                         "events.txt", 0);

  // Neither events nor frames: nothing to open.
  const std::string empty = test::ScratchDir("folder_empty");
  test::WriteFile(empty + "/images.txt", "# nothing\n");
  test::ExpectInputError([&] { TextFolderDataSource s(empty); }, InputError::Kind::kMissingFile,
                         "events.txt", 0);

  test::ExpectInputError([&] { TextFolderDataSource s(no_events + "/nope"); },
                         InputError::Kind::kMissingFile, "nope", 0);
  EXPECT_THROW(source.ReadImage(2), InvalidArgumentError);
}

TEST(TextFolderDataSourceTest, FolderWithoutFramesTakesTheSizeFromTheEvents) {
  const std::string dir = test::ScratchDir("folder_no_frames");
  test::WriteFile(dir + "/events.txt", "0.1 12 3 1\n0.2 4 25 0\n");
  test::WriteFile(dir + "/images.txt", "# no frames\n");
  const TextFolderDataSource source(dir);
  EXPECT_EQ(source.width(), 13);
  EXPECT_EQ(source.height(), 26);
  EXPECT_TRUE(source.frames().empty());
  std::filesystem::remove(dir + "/images.txt");
  EXPECT_EQ(TextFolderDataSource(dir).ReadAllEvents().size(), 2u);
}

TEST(WriteDataFolderTest, WritesTheLayoutAndKeepsUsablePaths) {
  const EventStream events = test::MakeRandomEvents(5, 1000, kWidth, kHeight, 1000000000, 100000);
  std::vector<FrameInfo> frames(3);
  frames[0].t_ns = 1000000000;
  frames[0].path = "images/custom name.png";  // kept
  frames[1].t_ns = 1050000000;
  frames[1].path = "images/image000000001";  // an HDF5 dataset name: renamed
  frames[1].has_exposure = true;
  frames[1].exposure_begin_ns = 1040000000;
  frames[1].exposure_end_ns = 1060000000;
  frames[2].t_ns = 1100000000;
  frames[2].path = "../escape.png";  // outside the folder: renamed
  const std::vector<Image> images = {test::MakeRandomImage(6, kWidth, kHeight, 8),
                                     test::MakeRandomImage(7, kWidth, kHeight, 16),
                                     test::MakeRandomImage(8, kWidth, kHeight, 8)};
  const std::string dir = test::ScratchDir("folder_write") + "/out";
  WriteDataFolder(dir, events, frames, images);

  EXPECT_EQ(test::ReadFile(dir + "/images.txt"),
            "1.00 images/custom name.png\n1.05 images/frame_00000001.png\n"
            "1.10 images/frame_00000002.png\n");
  const TextFolderDataSource source(dir);
  EXPECT_EQ(source.ReadAllEvents(), events);
  ASSERT_EQ(source.frames().size(), 3u);
  EXPECT_TRUE(source.frames()[1].has_exposure);
  EXPECT_EQ(source.frames()[1].exposure_end_ns, 1060000000);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE((source.ReadImage(i) == images[i]).all()) << i;
  EXPECT_THROW(WriteDataFolder(dir, events, frames, {}), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
