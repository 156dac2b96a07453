#include "evfs/io/data_source.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "evfs/io/hdf5_io.h"
#include "evfs/io/text_folder.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

constexpr int kWidth = 50;
constexpr int kHeight = 20;

// Every frame and event of a source, for comparing two sources.
void ExpectSameRecording(const DataSource& expected, const DataSource& actual) {
  EXPECT_EQ(actual.width(), expected.width());
  EXPECT_EQ(actual.height(), expected.height());
  ASSERT_EQ(actual.frames(), expected.frames());
  for (int i = 0; i < static_cast<int>(expected.frames().size()); ++i) {
    EXPECT_TRUE((actual.ReadImage(i) == expected.ReadImage(i)).all()) << "frame " << i;
  }
  EXPECT_EQ(actual.ReadAllEvents(), expected.ReadAllEvents());
}

TEST(DataSourceTest, OpenDispatchesOnFolderOrExtension) {
  const std::string dir = test::ScratchDir("open_dispatch");
  const EventStream events = test::MakeRandomEvents(1, 100, kWidth, kHeight, 0, 1000);
  WriteDataFolder(dir + "/folder", events, {}, {});
  WriteHdf5(dir + "/file.H5", events, {}, {});
  EXPECT_NE(dynamic_cast<TextFolderDataSource*>(DataSource::Open(dir + "/folder").get()), nullptr);
  EXPECT_NE(dynamic_cast<Hdf5DataSource*>(DataSource::Open(dir + "/file.H5").get()), nullptr);
  EXPECT_TRUE(IsHdf5Path("a/b.hdf5"));
  EXPECT_FALSE(IsHdf5Path("a/b.h5/c"));

  test::ExpectInputError([&] { DataSource::Open(dir + "/nothing"); },
                         InputError::Kind::kMissingFile, dir + "/nothing", 0);
  test::WriteFile(dir + "/events.txt", "0.1 1 1 1\n");
  test::ExpectInputError([&] { DataSource::Open(dir + "/events.txt"); },
                         InputError::Kind::kMalformed, dir + "/events.txt", 0);
}

// text -> HDF5 -> text keeps events to the nanosecond, frames with their bit depth, timestamps,
// exposures and paths; the events.txt comes back byte-identical.
TEST(DataSourceTest, SyntheticConversionRoundTripIsLossless) {
  const std::string dir = test::ScratchDir("convert_synthetic");
  const EventStream events = test::MakeRandomEvents(2, 30000, kWidth, kHeight, 713584001, 3000);
  std::vector<FrameInfo> frames(3);
  for (int i = 0; i < 3; ++i) {
    frames[i].t_ns = 700000000 + 20000001 * i;
    frames[i].path = "images/frame_0000000" + std::to_string(i) + ".png";
  }
  frames[2].has_exposure = true;
  frames[2].exposure_begin_ns = 735000000;
  frames[2].exposure_end_ns = 745000002;
  const std::vector<Image> images = {test::MakeRandomImage(3, kWidth, kHeight, 8),
                                     test::MakeRandomImage(4, kWidth, kHeight, 16),
                                     test::MakeRandomImage(5, kWidth, kHeight, 8)};
  WriteDataFolder(dir + "/original", events, frames, images);
  ConvertRecording(dir + "/original", dir + "/converted.h5");
  ConvertRecording(dir + "/converted.h5", dir + "/back");

  const auto original = DataSource::Open(dir + "/original");
  ExpectSameRecording(*original, *DataSource::Open(dir + "/converted.h5"));
  ExpectSameRecording(*original, *DataSource::Open(dir + "/back"));
  EXPECT_EQ(test::ReadFile(dir + "/back/events.txt"), test::ReadFile(dir + "/original/events.txt"));
  EXPECT_EQ(test::ReadFile(dir + "/back/images.txt"), test::ReadFile(dir + "/original/images.txt"));
}

struct SharedSnippet {
  const char* folder;
  int width;
  int height;
  int64_t events;
  size_t frames;
  bool exposures;
};

const SharedSnippet kSnippets[] = {
    {"slider_depth_70_71", 240, 180, 16418, 2, false},
    {"eslnet_cups_blur", 346, 260, 413963, 6, true},
    {"shapes_rotation_13_20", 240, 180, 108406, 5, false},
};

TEST(DataSourceTest, SharedDataHasTheDocumentedContents) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  for (const SharedSnippet& snippet : kSnippets) {
    SCOPED_TRACE(snippet.folder);
    const auto source = DataSource::Open(data_dir + "/" + snippet.folder);
    EXPECT_EQ(source->width(), snippet.width);
    EXPECT_EQ(source->height(), snippet.height);
    ASSERT_EQ(source->frames().size(), snippet.frames);
    for (const FrameInfo& frame : source->frames())
      EXPECT_EQ(frame.has_exposure, snippet.exposures);
    const EventSummary summary = source->Summarize();
    EXPECT_EQ(summary.count, snippet.events);
    EXPECT_GT(summary.positive, 0);
    EXPECT_LT(summary.positive, summary.count);
    EXPECT_LT(summary.t_first_ns, summary.t_last_ns);
    EXPECT_EQ(source->ReadImage(0).cols(), snippet.width);
  }
  const auto slider = DataSource::Open(data_dir + "/slider_depth_70_71");
  EXPECT_EQ(slider->frames()[0].t_ns, 2713576000);
  EXPECT_EQ(slider->ReadAllEvents().t_ns(0), 2713584001);
  const auto cups = DataSource::Open(data_dir + "/eslnet_cups_blur");
  EXPECT_EQ(cups->frames()[0].exposure_begin_ns, 3312216000);
  EXPECT_EQ(cups->frames()[0].exposure_end_ns, 3416216000);
}

TEST(DataSourceTest, SharedDataConversionRoundTripIsByteIdentical) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  for (const SharedSnippet& snippet : kSnippets) {
    SCOPED_TRACE(snippet.folder);
    const std::string original = data_dir + "/" + snippet.folder;
    const std::string dir = test::ScratchDir(std::string("convert_shared_") + snippet.folder);
    ConvertRecording(original, dir + "/converted.h5");
    ConvertRecording(dir + "/converted.h5", dir + "/back");
    const auto source = DataSource::Open(original);
    ExpectSameRecording(*source, *DataSource::Open(dir + "/converted.h5"));
    ExpectSameRecording(*source, *DataSource::Open(dir + "/back"));
    EXPECT_TRUE(test::ReadFile(dir + "/back/events.txt") ==
                test::ReadFile(original + "/events.txt"));
    EXPECT_EQ(test::ReadFile(dir + "/back/images.txt"), test::ReadFile(original + "/images.txt"));
  }
}

TEST(DataSourceTest, SharedDataWindowsMatchInBothFormats) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string original = data_dir + "/shapes_rotation_13_20";
  const std::string h5 = test::ScratchDir("windows_shared") + "/shapes.h5";
  ConvertRecording(original, h5);
  const auto text = DataSource::Open(original);
  const auto hdf5 = DataSource::Open(h5);
  const std::vector<FrameInfo>& frames = text->frames();
  for (size_t i = 0; i + 1 < frames.size(); ++i) {
    const EventStream window = text->ReadEvents(frames[i].t_ns, frames[i + 1].t_ns);
    EXPECT_FALSE(window.empty());
    EXPECT_EQ(window, text->ReadAllEvents().Slice(frames[i].t_ns, frames[i + 1].t_ns));
    EXPECT_EQ(hdf5->ReadEvents(frames[i].t_ns, frames[i + 1].t_ns), window);
  }
}

}  // namespace
}  // namespace evfs
