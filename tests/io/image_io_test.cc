#include "io/image_io.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "tests/io/io_test_util.h"
#include "tests/test_data.h"

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

TEST(ImageIoTest, UnwritableImageIsAnInputError) {
  const std::string path = test::ScratchDir("image_unwritable") + "/no/folder/a.png";
  test::ExpectInputError([&] { WriteGreyPng16(path, Image::Zero(2, 2)); },
                         InputError::Kind::kUnwritable, path, 0);
  test::ExpectInputError([&] { WriteGreyPng8(path, Image::Zero(2, 2)); },
                         InputError::Kind::kUnwritable, path, 0);
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

}  // namespace
}  // namespace evfs
