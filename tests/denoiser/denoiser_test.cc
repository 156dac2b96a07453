#include "evfs/denoiser/denoiser.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <thread>

#include "evfs/core/error.h"
#include "evfs/denoiser/sha256.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

// OpenCV runs the network in float32: on intensities in [0, 1] through two 3×3 layers with
// weights of magnitude <= 1, the rounding error stays far below this.
constexpr double kFloatTolerance = 1e-5;
// A tile and the whole frame sum the same products, possibly in another order (vectorised
// loops over rows of another length): float32 rounding of values of order 1.
constexpr double kTileTolerance = 1e-6;
// The bound for the C++ inference against the trainer's PyTorch output: the two run the
// same float32 network with other summation orders.
constexpr double kTorchTolerance = 1e-4;
constexpr double kRelativeTorchTolerance = 1e-3;

std::string DataPath(const std::string& name) {
  return (fs::path(EVFS_TEST_SOURCE_DIR) / "data" / name).string();
}

DenoiserOptions TwoConvOptions(int num_threads = 1) {
  DenoiserOptions options;
  options.weights_path = DataPath("two_conv.onnx");
  options.num_threads = num_threads;
  return options;
}

// A video of uniform random intensities in [0, 1], seeded.
Video RandomVideo(int height, int width, int num_frames, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  Video video(height, width, num_frames);
  for (int64_t i = 0; i < video.pixels_per_frame() * num_frames; ++i) {
    video.data()[i] = uniform(random);
  }
  for (int t = 0; t < num_frames; ++t) video.set_timestamp_ns(t, 1000 * t);
  return video;
}

// The network of data/make_test_networks.py, written out independently in double precision:
//   hidden_c = relu(b1_c + Σ_{dy,dx} W1[c](dy,dx) · H(y+dy, x+dx)),  c = 0, 1
//   R        = b2 + Σ_c Σ_{dy,dx} W2[c](dy,dx) · hidden_c(y+dy, x+dx)
// with zeros outside the image at each layer (ONNX Conv pads 1).
using Kernel = std::array<std::array<double, 3>, 3>;
const std::array<Kernel, 2> kFirstKernels = {
    Kernel{{{0, 1.0 / 8, 0}, {1.0 / 8, -4.0 / 8, 1.0 / 8}, {0, 1.0 / 8, 0}}},
    Kernel{{{1.0 / 8, 2.0 / 8, 1.0 / 8}, {0, 0, 0}, {-1.0 / 8, -2.0 / 8, -1.0 / 8}}}};
const std::array<double, 2> kFirstBias = {0.125, -0.25};
const std::array<Kernel, 2> kSecondKernels = {
    Kernel{{{0, 0, 0}, {0, 4.0 / 8, 0}, {0, 0, 0}}},
    Kernel{{{1.0 / 8, 0, -1.0 / 8}, {2.0 / 8, 0, -2.0 / 8}, {1.0 / 8, 0, -1.0 / 8}}}};
const double kSecondBias = -0.0625;

Image Correlate(const Image& image, const Kernel& kernel) {
  Image result = Image::Zero(image.rows(), image.cols());
  for (int y = 0; y < image.rows(); ++y) {
    for (int x = 0; x < image.cols(); ++x) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int yy = y + dy, xx = x + dx;
          if (yy < 0 || xx < 0 || yy >= image.rows() || xx >= image.cols()) continue;
          result(y, x) += kernel[dy + 1][dx + 1] * image(yy, xx);
        }
      }
    }
  }
  return result;
}

Image HandResidual(const Image& frame) {
  Image residual = Image::Constant(frame.rows(), frame.cols(), kSecondBias);
  for (int c = 0; c < 2; ++c) {
    const Image hidden = (Correlate(frame, kFirstKernels[c]) + kFirstBias[c]).max(0.0);
    residual += Correlate(hidden, kSecondKernels[c]);
  }
  return residual;
}

TEST(DenoiserOptionsTest, Validity) {
  std::string error;
  DenoiserOptions options = TwoConvOptions();
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.weights_path.clear();
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("weights"), std::string::npos) << error;
  options = TwoConvOptions();
  options.tile_size_px = 2;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("tile_size_px"), std::string::npos) << error;
  options = TwoConvOptions();
  options.num_threads = -1;
  EXPECT_FALSE(options.IsValid(&error));
  options = TwoConvOptions();
  options.margin_px = -2;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THROW(Denoiser{options}, InvalidArgumentError);
}

TEST(DenoiserTest, MatchesTheHandComputedNetwork) {
  const Denoiser denoiser(TwoConvOptions());
  EXPECT_EQ(denoiser.receptive_radius_px(), 2);
  EXPECT_EQ(denoiser.margin_px(), 2);
  const Video video = RandomVideo(37, 53, 3, 7);
  DenoiseStats stats;
  const Video denoised = denoiser.Apply(video, {}, &stats);
  ASSERT_EQ(denoised.num_frames(), 3);
  EXPECT_EQ(denoised.timestamps_ns(), video.timestamps_ns());
  EXPECT_EQ(stats.frames, 3);
  EXPECT_EQ(stats.pixels_changed, 3 * 37 * 53);
  for (int t = 0; t < 3; ++t) {
    const Image expected = Image(video.frame(t)) - HandResidual(video.frame(t));
    const double error = (Image(denoised.frame(t)) - expected).abs().maxCoeff();
    EXPECT_LT(error, kFloatTolerance) << "frame " << t;
  }
}

// two_scale.onnx of data/make_test_networks.py in double precision, on the frame padded at the
// bottom and right to even sides by repeating its last row and column (the inference contract):
//   coarse_c(i, j) = relu(b1_c + Σ_{dy,dx} W1[c](dy,dx) · P(2i+dy, 2j+dx)),  c = 0, 1
//   R(y, x)        = P(y, x) + bu + Σ_c U[c](y mod 2, x mod 2) · coarse_c(y/2, x/2)
// cropped back to the frame.
using UpKernel = std::array<std::array<double, 2>, 2>;
const std::array<UpKernel, 2> kUpKernels = {UpKernel{{{1.0 / 8, 2.0 / 8}, {3.0 / 8, 4.0 / 8}}},
                                            UpKernel{{{-2.0 / 8, 1.0 / 8}, {0, -1.0 / 8}}}};
const double kUpBias = 0.25;

Image HandTwoScaleResidual(const Image& frame) {
  const int rows = frame.rows() + frame.rows() % 2, cols = frame.cols() + frame.cols() % 2;
  Image padded(rows, cols);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      padded(y, x) = frame(std::min<int>(y, frame.rows() - 1), std::min<int>(x, frame.cols() - 1));
    }
  }
  Image residual = padded + kUpBias;
  for (int c = 0; c < 2; ++c) {
    const Image fine = (Correlate(padded, kFirstKernels[c]) + kFirstBias[c]).max(0.0);
    for (int y = 0; y < rows; ++y) {
      for (int x = 0; x < cols; ++x) {
        const double coarse = fine(y / 2 * 2, x / 2 * 2);  // stride 2: the even pixels
        residual(y, x) += kUpKernels[c][y % 2][x % 2] * coarse;
      }
    }
  }
  return residual.topLeftCorner(frame.rows(), frame.cols());
}

DenoiserOptions TwoScaleOptions() {
  DenoiserOptions options;
  options.weights_path = DataPath("two_scale.onnx");
  options.num_threads = 2;
  return options;
}

// A network with a half-resolution middle (as the shipped one): its geometry is derived from
// its layers, and frames of odd sides are padded as the contract says.
TEST(DenoiserTest, TwoScaleNetworkMatchesTheHandComputation) {
  const Denoiser denoiser(TwoScaleOptions());
  EXPECT_EQ(denoiser.receptive_radius_px(), 2);
  EXPECT_EQ(denoiser.input_multiple_px(), 2);
  for (const auto& [height, width] : {std::pair{36, 52}, std::pair{37, 53}, std::pair{1, 1}}) {
    const Video video = RandomVideo(height, width, 2, 5);
    const Video denoised = denoiser.Apply(video);
    for (int t = 0; t < 2; ++t) {
      const Image expected = Image(video.frame(t)) - HandTwoScaleResidual(Image(video.frame(t)));
      const double error = (Image(denoised.frame(t)) - expected).abs().maxCoeff();
      EXPECT_LT(error, kFloatTolerance) << height << "x" << width << " frame " << t;
    }
  }
}

// Tiles of a strided network start on its sampling grid: with odd tile sizes and odd frame
// sides they still give the whole frame's values.
TEST(DenoiserTest, TwoScaleTilesMatchTheWholeFrame) {
  const Video video = RandomVideo(71, 89, 2, 13);
  const Video whole = Denoiser(TwoScaleOptions()).Apply(video);
  DenoiseRegion region;
  region.pixels.assign(video.pixels_per_frame(), 0);
  for (int y = 60; y < 71; ++y) {
    for (int x = 75; x < 89; ++x) region.pixels[y * 89 + x] = 1;  // the bottom-right corner
  }
  for (int y = 21; y < 34; ++y) {
    for (int x = 13; x < 30; ++x) region.pixels[y * 89 + x] = 1;
  }
  for (const int tile : {8, 9, 11}) {
    DenoiserOptions options = TwoScaleOptions();
    options.tile_size_px = tile;
    DenoiseStats stats;
    const Video denoised = Denoiser(options).Apply(video, region, &stats);
    EXPECT_GT(stats.tiles, 2) << "tile " << tile;
    for (int t = 0; t < 2; ++t) {
      for (int64_t p = 0; p < video.pixels_per_frame(); ++p) {
        const double expected = region.pixels[p] ? whole.frame_data(t)[p] : video.frame_data(t)[p];
        ASSERT_NEAR(denoised.frame_data(t)[p], expected, kTileTolerance)
            << "tile " << tile << " frame " << t << " pixel " << p;
      }
    }
  }
}

// A block of active pixels spanning several rows of tiles is run as one rectangle (one network
// call per frame, one margin around it), not as a run per row of tiles.
TEST(DenoiserTest, ABlockOfTilesIsOneNetworkRun) {
  const Video video = RandomVideo(70, 90, 2, 17);
  DenoiserOptions options = TwoConvOptions();
  options.tile_size_px = 8;
  DenoiseRegion region;
  region.pixels.assign(video.pixels_per_frame(), 0);
  for (int y = 17; y < 39; ++y) {
    for (int x = 25; x < 44; ++x) region.pixels[y * 90 + x] = 1;  // tiles 2-4 × 3-5
  }
  DenoiseStats stats;
  const Video denoised = Denoiser(options).Apply(video, region, &stats);
  EXPECT_EQ(stats.tiles, 2);
  // Tiles of columns 24-48 and rows 16-40, with the 2-pixel margin.
  EXPECT_EQ(stats.network_pixels, 2 * (24 + 4) * (24 + 4));
  const Video whole = Denoiser(TwoConvOptions()).Apply(video);
  for (int t = 0; t < 2; ++t) {
    for (int64_t p = 0; p < video.pixels_per_frame(); ++p) {
      const double expected = region.pixels[p] ? whole.frame_data(t)[p] : video.frame_data(t)[p];
      ASSERT_NEAR(denoised.frame_data(t)[p], expected, kTileTolerance) << "pixel " << p;
    }
  }
}

// A frame cut into tiles (context = receptive radius) gives the whole frame's values at the
// selected pixels and leaves every other pixel bit-identical.
TEST(DenoiserTest, TilesMatchTheWholeFrameAndSkippedPixelsAreUntouched) {
  const Video video = RandomVideo(70, 90, 2, 11);
  const Video whole = Denoiser(TwoConvOptions()).Apply(video);

  DenoiserOptions options = TwoConvOptions();
  options.tile_size_px = 8;
  const Denoiser tiled(options);
  DenoiseRegion region;
  region.pixels.assign(video.pixels_per_frame(), 0);
  // Two blobs, one touching the image border, and a lone pixel on a tile's corner.
  for (int y = 0; y < 12; ++y) {
    for (int x = 70; x < 90; ++x) region.pixels[y * 90 + x] = 1;
  }
  for (int y = 30; y < 45; ++y) {
    for (int x = 20; x < 33; ++x) region.pixels[y * 90 + x] = 1;
  }
  region.pixels[56 * 90 + 47] = 1;
  DenoiseStats stats;
  const Video denoised = tiled.Apply(video, region, &stats);
  EXPECT_GT(stats.tiles, 2);
  EXPECT_LT(stats.network_pixels, 2 * video.pixels_per_frame());
  int64_t changed = 0;
  for (int t = 0; t < 2; ++t) {
    for (int64_t p = 0; p < video.pixels_per_frame(); ++p) {
      const double value = denoised.frame_data(t)[p];
      if (region.pixels[p]) {
        EXPECT_NEAR(value, whole.frame_data(t)[p], kTileTolerance) << "t " << t << " p " << p;
        changed += value != video.frame_data(t)[p];
      } else {
        ASSERT_EQ(std::memcmp(&value, &video.frame_data(t)[p], sizeof(double)), 0)
            << "skipped pixel " << p << " of frame " << t << " changed";
      }
    }
  }
  EXPECT_EQ(stats.pixels_changed, 2 * (12 * 20 + 15 * 13 + 1));
  EXPECT_GT(changed, stats.pixels_changed / 2);
}

TEST(DenoiserTest, UnselectedFramesAreBitIdentical) {
  const Video video = RandomVideo(20, 30, 4, 3);
  DenoiseRegion region;
  region.frames = {0, 1, 0, 1};
  DenoiseStats stats;
  const Video denoised = Denoiser(TwoConvOptions()).Apply(video, region, &stats);
  EXPECT_EQ(stats.frames, 2);
  for (const int t : {0, 2}) {
    EXPECT_EQ(std::memcmp(denoised.frame_data(t), video.frame_data(t),
                          sizeof(double) * video.pixels_per_frame()),
              0);
  }
  for (const int t : {1, 3}) {
    EXPECT_GT((Image(denoised.frame(t)) - Image(video.frame(t))).abs().maxCoeff(), 0.01);
  }
  region.frames.clear();
  region.pixels.assign(video.pixels_per_frame(), 0);
  const Video untouched = Denoiser(TwoConvOptions()).Apply(video, region, &stats);
  EXPECT_EQ(stats.tiles, 0);
  EXPECT_EQ(std::memcmp(untouched.data(), video.data(),
                        sizeof(double) * video.pixels_per_frame() * video.num_frames()),
            0);
}

TEST(DenoiserTest, ThreadsGiveTheSameResult) {
  DenoiserOptions options = TwoConvOptions(1);
  options.tile_size_px = 16;
  const Video video = RandomVideo(64, 80, 5, 5);
  const Video one = Denoiser(options).Apply(video);
  options.num_threads = 3;
  const Video three = Denoiser(options).Apply(video);
  EXPECT_EQ(std::memcmp(one.data(), three.data(),
                        sizeof(double) * video.pixels_per_frame() * video.num_frames()),
            0);
}

TEST(DenoiserTest, CallsFromSeveralThreadsShareTheNetworks) {
  // Four callers at once on one denoiser with two network copies (as evfs video's windows):
  // every call gives what it gives alone.
  DenoiserOptions options = TwoConvOptions(1);
  options.tile_size_px = 16;
  options.num_threads = 2;
  const Denoiser denoiser(options);
  std::vector<Video> videos, alone, together(4);
  for (int i = 0; i < 4; ++i) {
    videos.push_back(RandomVideo(48, 64, 6, 10 + i));
    alone.push_back(denoiser.Apply(videos.back()));
  }
  std::vector<std::thread> callers;
  for (int i = 0; i < 4; ++i) {
    callers.emplace_back([&, i] { together[i] = denoiser.Apply(videos[i]); });
  }
  for (std::thread& caller : callers) caller.join();
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(std::memcmp(alone[i].data(), together[i].data(),
                          sizeof(double) * videos[i].pixels_per_frame() * videos[i].num_frames()),
              0)
        << "caller " << i;
  }
}

TEST(DenoiserTest, RegionOfTheWrongSizeIsAnError) {
  const Denoiser denoiser(TwoConvOptions());
  const Video video = RandomVideo(10, 12, 2, 1);
  DenoiseRegion region;
  region.pixels.assign(10 * 11, 1);
  EXPECT_THROW(denoiser.Apply(video, region), InvalidArgumentError);
  region.pixels.clear();
  region.frames.assign(3, 1);
  EXPECT_THROW(denoiser.Apply(video, region), InvalidArgumentError);
}

TEST(DenoiserTest, RecordsTheWeightsSha256) {
  const std::string path = DataPath("two_conv.onnx");
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const Denoiser denoiser(TwoConvOptions());
  EXPECT_EQ(denoiser.weights_path(), path);
  EXPECT_EQ(denoiser.weights_sha256(), Sha256Hex(bytes));
}

// The shipped weights against the trainer: tools/train_denoiser/train.py writes a small input
// and PyTorch's residual R for it (PFM, float32) together with models/evfs_denoiser.onnx.
TEST(DenoiserTest, ShippedWeightsMatchTheTrainersPyTorchOutput) {
  const fs::path source = fs::path(EVFS_TEST_SOURCE_DIR);
  const std::string weights = (source / ".." / ".." / "models" / "evfs_denoiser.onnx").string();
  const std::string input_path = DataPath("reference_input.pfm");
  const std::string output_path = DataPath("reference_output.pfm");
  if (!fs::exists(weights) || !fs::exists(input_path) || !fs::exists(output_path)) {
    GTEST_SKIP() << "models/evfs_denoiser.onnx or tests/denoiser/data/reference_*.pfm missing "
                    "(make train-denoiser writes them)";
  }
  const cv::Mat input = cv::imread(input_path, cv::IMREAD_UNCHANGED);
  const cv::Mat expected = cv::imread(output_path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(input.type(), CV_32FC1);
  ASSERT_EQ(expected.type(), CV_32FC1);
  ASSERT_EQ(input.size(), expected.size());
  Video video(input.rows, input.cols, 1);
  for (int y = 0; y < input.rows; ++y) {
    for (int x = 0; x < input.cols; ++x) video.at(0, y, x) = input.at<float>(y, x);
  }
  DenoiserOptions options;
  options.weights_path = weights;
  options.num_threads = 1;
  const Video denoised = Denoiser(options).Apply(video);
  double max_error = 0.0, max_residual = 0.0;
  for (int y = 0; y < input.rows; ++y) {
    for (int x = 0; x < input.cols; ++x) {
      const double residual = video.at(0, y, x) - denoised.at(0, y, x);
      max_error = std::max(max_error, std::abs(residual - expected.at<float>(y, x)));
      max_residual = std::max(max_residual, std::abs(double{expected.at<float>(y, x)}));
    }
  }
  // Weights whose residual is tiny everywhere would pass 1e-4 whatever C++ computed: the bound
  // is also held relative to the largest residual (float32 keeps ~1e-6 of it).
  ASSERT_GT(max_residual, 0.0);
  EXPECT_LT(max_error, std::min(kTorchTolerance, kRelativeTorchTolerance * max_residual))
      << "largest |R| " << max_residual;
}

// Loading `path` fails with an InputError naming it, in one line.
void ExpectBadWeights(const std::string& path, const std::string& expected_words) {
  DenoiserOptions options = TwoConvOptions();
  options.weights_path = path;
  try {
    Denoiser denoiser(options);
    ADD_FAILURE() << path << " loaded";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_EQ(error.file(), path);
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(expected_words), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

void WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

TEST(DenoiserTest, BadWeightsFilesAreUserErrors) {
  const std::string dir = test::ScratchDir("bad_weights");
  ExpectBadWeights(dir + "/missing.onnx", "not found");
  ExpectBadWeights(dir, "not a folder");
  WriteFile(dir + "/empty.onnx", "");
  ExpectBadWeights(dir + "/empty.onnx", "empty");
  WriteFile(dir + "/text.onnx", "this is not a network\n");
  ExpectBadWeights(dir + "/text.onnx", "not an ONNX network");
  std::ifstream in(DataPath("two_conv.onnx"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  WriteFile(dir + "/truncated.onnx", bytes.substr(0, bytes.size() / 2));
  ExpectBadWeights(dir + "/truncated.onnx", "not an ONNX network");
  ExpectBadWeights(DataPath("two_channels.onnx"), "1x1xHxW");
  ExpectBadWeights(DataPath("three_inputs.onnx"), "1x1xHxW");
}

TEST(DenoiserTest, UnreadableWeightsAreUserErrors) {
  if (geteuid() == 0) GTEST_SKIP() << "running as root: file permissions do not stop reading";
  const std::string dir = test::ScratchDir("unreadable_weights");
  const std::string path = dir + "/locked.onnx";
  fs::copy_file(DataPath("two_conv.onnx"), path);
  fs::permissions(path, fs::perms::none);
  ExpectBadWeights(path, "cannot be read");
}

// The gate's weight σ²/(σ²+τ²) at σ = 1e6 τ differs from 1 by 1e-12; the correction between two
// videos in [0, 1] is at most 1, so the gated value lies within that of the correction.
constexpr double kLargeSigmaTolerance = 1e-11;

TEST(GateCorrectionTest, ZeroSigmaKeepsTheInputBitForBit) {
  const Video input = RandomVideo(9, 13, 3, 1);
  const Video corrected = RandomVideo(9, 13, 3, 2);
  const Video sigma(9, 13, 3);  // zero everywhere
  const Video gated = GateCorrection(input, corrected, sigma, 0.01);
  ASSERT_EQ(gated.num_frames(), input.num_frames());
  EXPECT_EQ(0, std::memcmp(gated.data(), input.data(),
                           sizeof(double) * input.pixels_per_frame() * input.num_frames()));
}

TEST(GateCorrectionTest, LargeSigmaTakesTheCorrection) {
  const double tau = 0.02;
  const Video input = RandomVideo(9, 13, 3, 3);
  const Video corrected = RandomVideo(9, 13, 3, 4);
  Video sigma(9, 13, 3);
  for (int64_t i = 0; i < sigma.pixels_per_frame() * 3; ++i) sigma.data()[i] = 1e6 * tau;
  const Video gated = GateCorrection(input, corrected, sigma, tau);
  for (int64_t i = 0; i < input.pixels_per_frame() * 3; ++i) {
    ASSERT_NEAR(gated.data()[i], corrected.data()[i], kLargeSigmaTolerance) << "value " << i;
  }
}

TEST(GateCorrectionTest, WeightIsTheWienerGainPerPixel) {
  const double tau = 0.05;
  const Video input = RandomVideo(4, 5, 2, 5);
  const Video corrected = RandomVideo(4, 5, 2, 6);
  Video sigma = RandomVideo(4, 5, 2, 7);
  sigma.data()[3] = tau;  // half the correction, by hand
  const Video gated = GateCorrection(input, corrected, sigma, tau);
  EXPECT_DOUBLE_EQ(gated.data()[3], 0.5 * (input.data()[3] + corrected.data()[3]));
  for (int64_t i = 0; i < input.pixels_per_frame() * 2; ++i) {
    const double s2 = sigma.data()[i] * sigma.data()[i];
    const double expected =
        input.data()[i] + s2 / (s2 + tau * tau) * (corrected.data()[i] - input.data()[i]);
    EXPECT_DOUBLE_EQ(gated.data()[i], expected) << "value " << i;
  }
}

TEST(GateCorrectionTest, BadTauOrSizesAreErrors) {
  const Video video = RandomVideo(4, 5, 2, 8);
  EXPECT_THROW(GateCorrection(video, video, video, 0.0), InvalidArgumentError);
  EXPECT_THROW(GateCorrection(video, video, video, -1.0), InvalidArgumentError);
  EXPECT_THROW(GateCorrection(video, video, video, std::nan("")), InvalidArgumentError);
  EXPECT_THROW(GateCorrection(video, RandomVideo(4, 5, 3, 9), video, 0.1), InvalidArgumentError);
  EXPECT_THROW(GateCorrection(video, video, RandomVideo(5, 4, 2, 9), 0.1), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
