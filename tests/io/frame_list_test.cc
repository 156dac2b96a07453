#include "evfs/io/frame_list.h"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

std::string TextFile(const std::string& test_name, const std::string& file_name,
                     const std::string& content) {
  const std::string path = test::ScratchDir(test_name) + "/" + file_name;
  test::WriteFile(path, content);
  return path;
}

TEST(ReadFrameListTest, ParsesTimesExactlyAndKeepsPaths) {
  const std::string path = TextFile("frames_basic", "images.txt",
                                    "# t path\r\n"
                                    "2.713576 images/frame_00000000.png\r\n"
                                    "\n"
                                    "2.752341000\timages/frame 1.png  \n"
                                    "3 images/last.png");
  const std::vector<FrameInfo> frames = ReadFrameList(path);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].t_ns, 2713576000);
  EXPECT_EQ(frames[0].path, "images/frame_00000000.png");
  EXPECT_EQ(frames[1].t_ns, 2752341000);
  EXPECT_EQ(frames[1].path, "images/frame 1.png");
  EXPECT_EQ(frames[2].t_ns, 3000000000);
  EXPECT_FALSE(frames[2].has_exposure);
}

// A file whose line 2 is `bad_line`, after a valid first line.
struct BadLineCase {
  const char* name;
  const char* bad_line;
};

// Writes each case as `file_name` and expects `read(path)` to throw `kind`, naming the file and
// line 2.
template <typename Read>
void ExpectBadLineErrors(const std::string& file_name, const std::string& first_line,
                         InputError::Kind kind, const std::vector<BadLineCase>& cases,
                         Read&& read) {
  for (const BadLineCase& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path =
        TextFile(file_name + "_" + c.name, file_name, first_line + "\n" + c.bad_line + "\n");
    test::ExpectInputError([&] { read(path); }, kind, path, 2);
  }
}

TEST(ReadFrameListTest, MalformedLinesNameFileAndLine) {
  const std::string first = "1.5 images/a.png";
  const auto read = [](const std::string& path) { ReadFrameList(path); };
  ExpectBadLineErrors("images.txt", first, InputError::Kind::kMalformed,
                      {{"no_path", "2.5"},
                       {"bad_time", "2.5x images/b.png"},
                       {"nan_time", "nan images/b.png"},
                       {"ten_digits", "2.5000000001 images/b.png"},
                       {"overflow", "99999999999 images/b.png"},
                       {"control_character", "2.5 images/\x1b[2Jb.png"},
                       {"same_path", "2.5 images/a.png"}},
                      read);
  ExpectBadLineErrors("images.txt", first, InputError::Kind::kNotMonotonic,
                      {{"same_time", "1.5 images/b.png"}, {"backwards", "1.4 images/b.png"}}, read);
  test::ExpectInputError([&] { ReadFrameList("/no/such/images.txt"); },
                         InputError::Kind::kMissingFile, "/no/such/images.txt", 0);
}

// A path that leaves the folder of images.txt is refused on its line, unless the user allowed it
// (--allow_outside_paths); ".." that stays inside is a path like any other.
TEST(ReadFrameListTest, PathsLeavingTheFolderAreRefusedUnlessAllowed) {
  const std::string first = "1.5 images/a.png";
  const auto read = [](const std::string& path) { ReadFrameList(path); };
  ExpectBadLineErrors("images.txt", first, InputError::Kind::kMalformed,
                      {{"parent", "2.5 ../../x.png"},
                       {"climbs_out", "2.5 images/../../x.png"},
                       {"absolute", "2.5 /etc/x.png"}},
                      read);
  const std::string inside =
      TextFile("frames_inside", "images.txt", first + "\n2.5 images/../images/b.png\n");
  EXPECT_EQ(ReadFrameList(inside).size(), 2u);
  const std::string outside =
      TextFile("frames_outside", "images.txt", first + "\n2.5 ../../x.png\n3.5 /abs/y.png\n");
  try {
    ReadFrameList(outside);
    ADD_FAILURE() << "a path outside the folder was read";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("--allow_outside_paths"), std::string::npos)
        << error.what();
  }
  SetFramePathsMayLeaveFolder(true);
  const std::vector<FrameInfo> frames = ReadFrameList(outside);
  SetFramePathsMayLeaveFolder(false);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2].path, "/abs/y.png");
}

// Some Windows editors start a UTF-8 file with a byte-order mark; it is no part of the first path.
TEST(ReadFrameListTest, AByteOrderMarkIsSkipped) {
  const std::string path = TextFile("frames_bom", "images.txt",
                                    "\xEF\xBB\xBF"
                                    "1.5 images/a.png\n2.5 images/b.png\n");
  const std::vector<FrameInfo> frames = ReadFrameList(path);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].t_ns, 1500000000);
  EXPECT_EQ(frames[0].path, "images/a.png");
}

TEST(ReadFrameListTest, TruncatedLastLineIsMalformed) {
  // A file cut short while it was written: the last line lacks its path and its newline.
  const std::string path =
      TextFile("frames_truncated", "images.txt", "1.5 images/a.png\n2.5 images/b.png\n3.");
  test::ExpectInputError([&] { ReadFrameList(path); }, InputError::Kind::kMalformed, path, 3);
}

TEST(ReadFrameListTest, MegabyteLinesAndBinaryGarbageGiveShortMessages) {
  constexpr size_t kMegabyte = 1 << 20;
  std::string garbage;
  for (int i = 0; i < 4096; ++i) garbage += static_cast<char>(i % 256 == '\n' ? 0 : i % 256);
  const struct {
    const char* name;
    std::string bad_line;
  } cases[] = {
      {"long_time", std::string(kMegabyte, '7') + "x images/b.png"},
      {"long_path", "2.5 images/" + std::string(kMegabyte, 'b') + ".png"},
      {"one_word", std::string(kMegabyte, 'w')},
      {"garbage", garbage},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = TextFile(std::string("frames_") + c.name, "images.txt",
                                      "1.5 images/a.png\n" + c.bad_line + "\n");
    test::ExpectInputError([&] { ReadFrameList(path); }, InputError::Kind::kMalformed, path, 2);
    test::ExpectShortPrintableMessage(test::CatchInputError([&] { ReadFrameList(path); }));
  }
}

TEST(ReadFrameListTest, StreamsInMemoryReadLikeTheFile) {
  const std::string images = "# t path\r\n1.5 images/a.png\n2.5 images/b.png";
  std::istringstream images_stream(images);
  std::vector<FrameInfo> frames = ReadFrameList(images_stream, "memory/images.txt");
  EXPECT_EQ(frames, ReadFrameList(TextFile("frames_stream", "images.txt", images)));
  std::istringstream exposures("images/b.png 2.4 2.6\n");
  ReadExposures(exposures, "memory/exposures.txt", &frames);
  EXPECT_TRUE(frames[1].has_exposure);
  std::istringstream bad("1.5 images/a.png\n1.5 images/b.png\n");
  test::ExpectInputError([&] { ReadFrameList(bad, "memory/images.txt"); },
                         InputError::Kind::kNotMonotonic, "memory/images.txt", 2);
}

TEST(ReadExposuresTest, MatchesByPath) {
  std::vector<FrameInfo> frames(2);
  frames[0].t_ns = 3364216000;
  frames[0].path = "images/frame_00000000.png";
  frames[1].t_ns = 3486557000;
  frames[1].path = "images/frame 1.png";
  const std::string path = TextFile("exposures_basic", "exposures.txt",
                                    "# image t_exposure_start t_exposure_end\n"
                                    "images/frame 1.png 3.434558 3.538557\r\n");
  ReadExposures(path, &frames);
  EXPECT_FALSE(frames[0].has_exposure);
  EXPECT_TRUE(frames[1].has_exposure);
  EXPECT_EQ(frames[1].exposure_begin_ns, 3434558000);
  EXPECT_EQ(frames[1].exposure_end_ns, 3538557000);
}

TEST(ReadExposuresTest, RejectsUnknownPathsAndEmptyExposures) {
  // Line 1 is a valid exposure, so that a second one for the same image is an error too.
  const std::string first = "images/a.png 1.0 2.0";
  const auto read = [](const std::string& path) {
    std::vector<FrameInfo> frames(2);
    frames[0].t_ns = 1500000000;
    frames[0].path = "images/a.png";
    frames[1].t_ns = 2500000000;
    frames[1].path = "images/b.png";
    ReadExposures(path, &frames);
  };
  ExpectBadLineErrors("exposures.txt", first, InputError::Kind::kMalformed,
                      {{"unknown_path", "images/other.png 1.0 2.0"},
                       {"two_fields", "images/b.png 2.0"},
                       {"bad_number", "images/b.png 1.0 two"},
                       {"nan", "images/b.png nan 2.0"},
                       {"twice", "images/a.png 1.0 2.0"}},
                      read);
  ExpectBadLineErrors(
      "exposures.txt", first, InputError::Kind::kOutOfRange,
      {{"end_before_start", "images/b.png 2.0 1.0"}, {"zero_length", "images/b.png 2.0 2.0"}},
      read);
}

TEST(WriteFrameListTest, RoundTripsWithTheFewestDigits) {
  std::vector<FrameInfo> frames(2);
  frames[0].t_ns = 600891000;
  frames[0].path = "images/frame_00000013.png";
  frames[0].has_exposure = true;
  frames[0].exposure_begin_ns = 550000000;
  frames[0].exposure_end_ns = 651782000;
  frames[1].t_ns = 644956000;
  frames[1].path = "images/frame_00000014.png";
  const std::string dir = test::ScratchDir("frames_write");
  WriteFrameList(dir + "/images.txt", frames);
  WriteExposures(dir + "/exposures.txt", frames);
  EXPECT_EQ(test::ReadFile(dir + "/images.txt"),
            "0.600891 images/frame_00000013.png\n0.644956 images/frame_00000014.png\n");
  std::vector<FrameInfo> read = ReadFrameList(dir + "/images.txt");
  ReadExposures(dir + "/exposures.txt", &read);
  EXPECT_EQ(read, frames);
}

TEST(WriteFrameListTest, SharedImagesTxtRewritesByteIdentically) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  for (const char* folder : {"slider_depth_70_71", "shapes_rotation_13_20", "eslnet_cups_blur"}) {
    SCOPED_TRACE(folder);
    const std::string images_txt = data_dir + "/" + folder + "/images.txt";
    const std::string rewritten =
        test::ScratchDir(std::string("frames_shared_") + folder) + "/i.txt";
    WriteFrameList(rewritten, ReadFrameList(images_txt));
    EXPECT_EQ(test::ReadFile(rewritten), test::ReadFile(images_txt));
  }
}

}  // namespace
}  // namespace evfs
