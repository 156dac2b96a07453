#include "evfs/io/image_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <utility>
#include <vector>

#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

constexpr int kWidth = 37;
constexpr int kHeight = 23;
// Rounding to 16 bits moves a value by at most half a level.
constexpr double kHalf16BitLevel = 0.5 / 65535.0;

TEST(ImageIoTest, EightAndSixteenBitRoundTripsAreExact) {
  const std::string dir = test::ScratchDir("image_roundtrip");
  const Image image8 = test::MakeRandomImage(1, kWidth, kHeight, 8);
  const Image image16 = test::MakeRandomImage(2, kWidth, kHeight, 16);
  WriteGreyPng8(dir + "/a.png", image8);
  WriteGreyPng16(dir + "/b.png", image16);
  EXPECT_TRUE((ReadGreyImage(dir + "/a.png") == image8).all());
  EXPECT_TRUE((ReadGreyImage(dir + "/b.png") == image16).all());
  EXPECT_EQ(cv::imread(dir + "/a.png", cv::IMREAD_UNCHANGED).depth(), CV_8U);
  EXPECT_EQ(cv::imread(dir + "/b.png", cv::IMREAD_UNCHANGED).depth(), CV_16U);
}

TEST(ImageIoTest, LosslessWriterPicksTheBitDepth) {
  const std::string dir = test::ScratchDir("image_lossless");
  const Image image8 = test::MakeRandomImage(3, kWidth, kHeight, 8);
  const Image image16 = test::MakeRandomImage(4, kWidth, kHeight, 16);
  EXPECT_EQ(MinimalBitDepth(image8), 8);
  EXPECT_EQ(MinimalBitDepth(image16), 16);
  WriteGreyPngLossless(dir + "/a.png", image8);
  WriteGreyPngLossless(dir + "/b.png", image16);
  EXPECT_EQ(cv::imread(dir + "/a.png", cv::IMREAD_UNCHANGED).depth(), CV_8U);
  EXPECT_EQ(cv::imread(dir + "/b.png", cv::IMREAD_UNCHANGED).depth(), CV_16U);
  EXPECT_TRUE((ReadGreyImage(dir + "/b.png") == image16).all());
}

TEST(ImageIoTest, ValuesAreClampedAndRounded) {
  const std::string dir = test::ScratchDir("image_clamp");
  Image image(1, 3);
  image << -0.5, 0.3, 1.7;
  EXPECT_EQ(MinimalBitDepth(image), 16);
  WriteGreyPng16(dir + "/c.png", image);
  const Image read = ReadGreyImage(dir + "/c.png");
  EXPECT_EQ(read(0, 0), 0.0);
  EXPECT_NEAR(read(0, 1), 0.3, kHalf16BitLevel);
  EXPECT_EQ(read(0, 2), 1.0);
}

TEST(ImageIoTest, IntensityLevelRoundsAsLroundDoes) {
  // Every half level of both depths (where rounding rules differ), and values between them.
  for (const double max_level : {255.0, 65535.0}) {
    for (int64_t twice = 0; twice <= 2 * static_cast<int64_t>(max_level); ++twice) {
      for (const double nudge : {0.0, -1e-9, 1e-9}) {
        const double value = (static_cast<double>(twice) / 2.0 + nudge) / max_level;
        const double clamped = std::min(1.0, std::max(0.0, value));
        ASSERT_EQ(IntensityLevel(value, max_level), std::lround(clamped * max_level))
            << "value " << value << " at " << max_level;
      }
    }
  }
  EXPECT_EQ(IntensityLevel(-0.25, 255.0), 0);
  EXPECT_EQ(IntensityLevel(1.5, 255.0), 255);
  EXPECT_EQ(IntensityLevel(std::nan(""), 65535.0), 0);
}

TEST(ImageIoTest, ColourIsConvertedToGrey) {
  const std::string dir = test::ScratchDir("image_colour");
  cv::Mat colour(kHeight, kWidth, CV_8UC3, cv::Scalar(100, 100, 100));
  ASSERT_TRUE(cv::imwrite(dir + "/colour.png", colour));
  const Image grey = ReadGreyImage(dir + "/colour.png");
  ASSERT_EQ(grey.rows(), kHeight);
  ASSERT_EQ(grey.cols(), kWidth);
  EXPECT_EQ(grey(5, 5), 100.0 / 255.0);
}

TEST(ImageIoTest, MissingOrUndecodableImageIsAnInputError) {
  const std::string dir = test::ScratchDir("image_missing");
  test::ExpectInputError([&] { ReadGreyImage(dir + "/nope.png"); }, InputError::Kind::kMissingFile,
                         dir + "/nope.png", 0);
  test::WriteFile(dir + "/garbage.png", "definitely not a png");
  test::ExpectInputError([&] { ReadGreyImage(dir + "/garbage.png"); },
                         InputError::Kind::kMissingFile, dir + "/garbage.png", 0);
}

// A PNG signature and IHDR chunk declaring `width` x `height`, then bytes that decode to
// nothing: a reader that trusts the header would allocate for the declared size first.
std::string PngHeader(uint32_t width, uint32_t height) {
  std::string bytes("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR", 16);
  for (const uint32_t side : {width, height}) {
    for (int shift = 24; shift >= 0; shift -= 8) bytes.push_back(static_cast<char>(side >> shift));
  }
  return bytes + std::string("\x08\0\0\0", 5) + std::string(64, 'x');
}

// SOI, an APP0 segment, then a baseline SOF0 declaring `width` x `height`.
std::string JpegHeader(uint16_t width, uint16_t height) {
  std::string bytes(
      "\xff\xd8\xff\xe0\0\x04"
      "ab"
      "\xff\xc0\0\x0b\x08",
      13);
  for (const uint16_t side : {height, width}) {
    bytes.push_back(static_cast<char>(side >> 8));
    bytes.push_back(static_cast<char>(side & 0xff));
  }
  return bytes + std::string(64, 'x');
}

TEST(ImageIoTest, TheDeclaredSizeIsReadFromTheHeader) {
  const std::string dir = test::ScratchDir("image_header");
  test::WriteFile(dir + "/big.png", PngHeader(20000, 30000));
  test::WriteFile(dir + "/big.jpg", JpegHeader(40000, 20000));
  ASSERT_TRUE(cv::imwrite(dir + "/real.png", cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(7))));
  ASSERT_TRUE(cv::imwrite(dir + "/real.jpg", cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(7))));
  int64_t width = 0, height = 0;
  ASSERT_TRUE(ReadImageHeaderSize(dir + "/big.png", &width, &height));
  EXPECT_EQ(width, 20000);
  EXPECT_EQ(height, 30000);
  ASSERT_TRUE(ReadImageHeaderSize(dir + "/big.jpg", &width, &height));
  EXPECT_EQ(width, 40000);
  EXPECT_EQ(height, 20000);
  for (const char* name : {"real.png", "real.jpg"}) {
    ASSERT_TRUE(ReadImageHeaderSize(dir + "/" + name, &width, &height)) << name;
    EXPECT_EQ(width, kWidth) << name;
    EXPECT_EQ(height, kHeight) << name;
  }
  test::WriteFile(dir + "/short.png", PngHeader(1, 1).substr(0, 20));
  EXPECT_FALSE(ReadImageHeaderSize(dir + "/short.png", &width, &height));
}

// Sizes beyond the cap, or other than the one expected, are refused from the header alone:
// the message names the declared size, not a failed decode.
TEST(ImageIoTest, AHugeOrMismatchedDeclaredSizeIsRefusedBeforeDecoding) {
  const std::string dir = test::ScratchDir("image_huge");
  test::WriteFile(dir + "/huge.png", PngHeader(30000, 30000));
  test::WriteFile(dir + "/huge.jpg", JpegHeader(30000, 30000));
  for (const char* name : {"huge.png", "huge.jpg"}) {
    const std::string path = dir + "/" + name;
    test::ExpectInputError([&] { ReadGreyImage(path); }, InputError::Kind::kOutOfRange, path, 0);
    try {
      ReadGreyImage(path);
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("30000x30000"), std::string::npos) << error.what();
    }
  }
  test::WriteFile(dir + "/other.png", PngHeader(kWidth + 1, kHeight));
  test::ExpectInputError([&] { ReadGreyImage(dir + "/other.png", kWidth, kHeight); },
                         InputError::Kind::kSizeMismatch, dir + "/other.png", 0);
  ASSERT_TRUE(cv::imwrite(dir + "/fits.png", cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(7))));
  EXPECT_EQ(ReadGreyImage(dir + "/fits.png", kWidth, kHeight).cols(), kWidth);
}

// A folder, a FIFO or an unreadable file where a frame should be is named as what it is, not as
// a missing file or one that does not decode.
TEST(ImageIoTest, AFolderAFifoOrAnUnreadableFileIsNamed) {
  const std::string dir = test::ScratchDir("image_not_a_file");
  std::filesystem::create_directories(dir + "/folder.png");
  ASSERT_EQ(mkfifo((dir + "/fifo.png").c_str(), 0600), 0);
  const auto message = [](const std::string& path) {
    try {
      ReadGreyImage(path);
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(dir + "/folder.png").find("a folder, not an image file"), std::string::npos)
      << message(dir + "/folder.png");
  EXPECT_NE(message(dir + "/fifo.png").find("a FIFO, socket or device"), std::string::npos)
      << message(dir + "/fifo.png");
  if (geteuid() == 0) GTEST_SKIP() << "running as root: file permissions do not stop reading";
  ASSERT_TRUE(cv::imwrite(dir + "/locked.png", cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(7))));
  std::filesystem::permissions(dir + "/locked.png", std::filesystem::perms::none);
  EXPECT_NE(message(dir + "/locked.png").find("cannot read the image file: Permission denied"),
            std::string::npos)
      << message(dir + "/locked.png");
}

TEST(ImageIoTest, UnwritableImageIsAnInputError) {
  const std::string path = test::ScratchDir("image_unwritable") + "/no/folder/a.png";
  test::ExpectInputError([&] { WriteGreyPng16(path, Image::Zero(2, 2)); },
                         InputError::Kind::kUnwritable, path, 0);
  test::ExpectInputError([&] { WriteGreyPng8(path, Image::Zero(2, 2)); },
                         InputError::Kind::kUnwritable, path, 0);
}

// Frames encoded on several threads are the files one thread writes, each under its index.
TEST(ImageIoTest, ASequenceWrittenOnThreadsIsTheOneThreadsFiles) {
  const std::string dir = test::ScratchDir("image_sequence_threads");
  Video video;
  for (int t = 0; t < 9; ++t) {
    video.AppendFrame(test::MakeRandomImage(10 + t, kWidth, kHeight, 16), 1000 * t);
  }
  WriteFrameSequence(dir + "/one", video, 1);
  WriteFrameSequence(dir + "/three", video, 3);
  for (int t = 0; t < video.num_frames(); ++t) {
    char name[32];
    std::snprintf(name, sizeof(name), "/frames/%06d.png", t);
    const std::string one = test::ReadFile(dir + "/one" + name);
    EXPECT_FALSE(one.empty()) << name;
    EXPECT_EQ(test::ReadFile(dir + "/three" + name), one) << name;
  }
  EXPECT_EQ(test::ReadFile(dir + "/three/timestamps.txt"),
            test::ReadFile(dir + "/one/timestamps.txt"));
  // A folder that cannot be made is one error, naming it.
  test::ExpectInputError([&] { WriteImageSequence(dir + "/one/timestamps.txt/x", video, 3); },
                         InputError::Kind::kUnwritable, dir + "/one/timestamps.txt/x", 0);
}

TEST(ImageIoTest, TimestampsFileHasIndexAndNineDecimals) {
  const std::string path = test::ScratchDir("image_timestamps") + "/timestamps.txt";
  WriteTimestampsTxt(path, {2713576000, 2752341001});
  EXPECT_EQ(test::ReadFile(path), "0 2.713576000\n1 2.752341001\n");
}

TEST(ImageIoTest, SharedFramesAreEightBitOfTheSensorSize) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const Image image = ReadGreyImage(data_dir + "/slider_depth_70_71/images/frame_00000000.png");
  EXPECT_EQ(image.cols(), 240);
  EXPECT_EQ(image.rows(), 180);
  EXPECT_EQ(MinimalBitDepth(image), 8);
}

// OpenCV's imread(path, IMREAD_ANYDEPTH) scaled to [0, 1]: what evfs read frames with before
// it decoded PNG files itself (io/png_codec.h), and what it must still read.
Image ReadWithOpenCv(const std::string& path) {
  const cv::Mat mat = cv::imread(path, cv::IMREAD_ANYDEPTH);
  EXPECT_FALSE(mat.empty()) << path;
  const double max_value = mat.depth() == CV_16U ? 65535.0 : 255.0;
  Image image(mat.rows, mat.cols);
  for (int y = 0; y < mat.rows; ++y) {
    for (int x = 0; x < mat.cols; ++x) {
      image(y, x) =
          (mat.depth() == CV_16U ? mat.at<uint16_t>(y, x) : mat.at<uint8_t>(y, x)) / max_value;
    }
  }
  return image;
}

// Every PNG layout OpenCV writes, and a JPEG (through the decoder plug-in), read as OpenCV
// reads it: colour to the same grey, alpha dropped, 16 bits kept, 1-bit expanded.
TEST(ImageIoTest, FramesDecodeAsOpenCvDecodesThem) {
  const std::string dir = test::ScratchDir("image_like_opencv");
  cv::RNG random(7);
  struct Case {
    const char* name;
    int type;
    std::vector<int> params;
  };
  const Case cases[] = {
      {"grey8.png", CV_8UC1, {}},
      {"grey16.png", CV_16UC1, {}},
      {"bgr8.png", CV_8UC3, {}},
      {"bgr16.png", CV_16UC3, {}},
      {"bgra8.png", CV_8UC4, {}},
      {"bgra16.png", CV_16UC4, {}},
      {"bilevel.png", CV_8UC1, {cv::IMWRITE_PNG_BILEVEL, 1}},
      {"level9.png", CV_8UC3, {cv::IMWRITE_PNG_COMPRESSION, 9}},
      {"frame.jpg", CV_8UC3, {}},
      {"frame.bmp", CV_8UC1, {}},
  };
  for (const Case& c : cases) {
    cv::Mat mat(kHeight, kWidth, c.type);
    random.fill(mat, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(c.type) == CV_16U ? 65536 : 256);
    if (std::string(c.name) == "bilevel.png") mat = mat > 127;
    const std::string path = dir + "/" + c.name;
    ASSERT_TRUE(cv::imwrite(path, mat, c.params)) << c.name;
    const Image expected = ReadWithOpenCv(path);
    const Image read = ReadGreyImage(path);
    ASSERT_EQ(read.rows(), expected.rows()) << c.name;
    ASSERT_EQ(read.cols(), expected.cols()) << c.name;
    EXPECT_TRUE((read == expected).all()) << c.name;
  }
}

// What evfs writes, OpenCV reads back to the same values.
TEST(ImageIoTest, WrittenFramesReadTheSameThroughOpenCv) {
  const std::string dir = test::ScratchDir("image_written_opencv");
  const Image image8 = test::MakeRandomImage(3, kWidth, kHeight, 8);
  const Image image16 = test::MakeRandomImage(4, kWidth, kHeight, 16);
  WriteGreyPng8(dir + "/a.png", image8);
  WriteGreyPng16(dir + "/b.png", image16);
  EXPECT_TRUE((ReadWithOpenCv(dir + "/a.png") == image8).all());
  EXPECT_TRUE((ReadWithOpenCv(dir + "/b.png") == image16).all());
}

// A PNG cut short or with a broken chunk is one InputError naming the file, not a crash.
TEST(ImageIoTest, ACorruptPngIsAnInputError) {
  const std::string dir = test::ScratchDir("image_corrupt");
  WriteGreyPng16(dir + "/whole.png", test::MakeRandomImage(5, kWidth, kHeight, 16));
  const std::string whole = test::ReadFile(dir + "/whole.png");
  std::string flipped = whole;
  flipped[whole.size() / 2] = static_cast<char>(flipped[whole.size() / 2] ^ 0x55);
  for (const auto& [name, bytes] :
       {std::pair<std::string, std::string>{"cut.png", whole.substr(0, whole.size() / 2)},
        {"flipped.png", flipped}}) {
    test::WriteFile(dir + "/" + name, bytes);
    test::ExpectInputError([&] { ReadGreyImage(dir + "/" + name); }, InputError::Kind::kMissingFile,
                           dir + "/" + name, 0);
  }
}

// The shared recordings' frames read as OpenCV reads them.
TEST(ImageIoTest, SharedFramesDecodeAsOpenCvDecodesThem) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  int compared = 0;
  for (const auto& folder : std::filesystem::directory_iterator(data_dir)) {
    int in_folder = 0;
    for (const char* images : {"images", "frames"}) {
      std::error_code error;
      for (const auto& entry : std::filesystem::directory_iterator(folder.path() / images, error)) {
        if (entry.path().extension() != ".png" || in_folder >= 3) continue;
        const std::string path = entry.path().string();
        EXPECT_TRUE((ReadGreyImage(path) == ReadWithOpenCv(path)).all()) << path;
        ++in_folder;
      }
    }
    compared += in_folder;
  }
  EXPECT_GT(compared, 10);
}

}  // namespace
}  // namespace evfs
