#include "io/image_io.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "io/decimal_seconds.h"
#include "io/text_file_writer.h"

namespace evfs {
namespace {

constexpr double kMax8Bit = 255.0;
constexpr double kMax16Bit = 65535.0;

template <typename Pixel>
Image ToImage(const cv::Mat& mat, double max_value) {
  Image image(mat.rows, mat.cols);
  for (int y = 0; y < mat.rows; ++y) {
    const Pixel* row = mat.ptr<Pixel>(y);
    for (int x = 0; x < mat.cols; ++x) image(y, x) = static_cast<double>(row[x]) / max_value;
  }
  return image;
}

template <typename Pixel>
cv::Mat ToMat(const Image& image, int type, double max_value) {
  cv::Mat mat(static_cast<int>(image.rows()), static_cast<int>(image.cols()), type);
  for (int y = 0; y < mat.rows; ++y) {
    Pixel* row = mat.ptr<Pixel>(y);
    for (int x = 0; x < mat.cols; ++x) {
      const double value = std::min(1.0, std::max(0.0, image(y, x)));
      row[x] = static_cast<Pixel>(std::lround(value * max_value));
    }
  }
  return mat;
}

void WritePng(const std::string& path, const cv::Mat& mat) {
  bool written = false;
  std::string why = "the encoder refused it (is the folder there, does the name end in .png?)";
  try {
    written = cv::imwrite(path, mat);
  } catch (const cv::Exception& error) {
    why = error.what();
  }
  if (!written)
    throw InputError(InputError::Kind::kUnwritable, path, 0, "cannot write the image: " + why);
}

}  // namespace

Image ReadGreyImage(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(InputError::Kind::kMissingFile, path, 0, "image file does not exist");
  }
  cv::Mat mat;
  try {
    // IMREAD_ANYDEPTH alone: grey, keeping 16 bits where the file has them.
    mat = cv::imread(path, cv::IMREAD_ANYDEPTH);
  } catch (const cv::Exception&) {
    mat.release();
  }
  if (mat.empty()) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     "cannot decode the image (expected an 8- or 16-bit PNG)");
  }
  switch (mat.depth()) {
    case CV_8U:
      return ToImage<uint8_t>(mat, kMax8Bit);
    case CV_16U:
      return ToImage<uint16_t>(mat, kMax16Bit);
    default:
      throw InputError(InputError::Kind::kMalformed, path, 0,
                       "unsupported pixel type (expected 8- or 16-bit unsigned)");
  }
}

int MinimalBitDepth(const Image& image) {
  for (Eigen::Index i = 0; i < image.size(); ++i) {
    const double value = image.data()[i];
    if (!(value >= 0.0 && value <= 1.0)) return 16;
    // Exact comparison on purpose: the same division ReadGreyImage does must give the value.
    if (static_cast<double>(std::lround(value * kMax8Bit)) / kMax8Bit != value) return 16;
  }
  return 8;
}

void WriteGreyPng16(const std::string& path, const Image& image) {
  WritePng(path, ToMat<uint16_t>(image, CV_16UC1, kMax16Bit));
}

void WriteGreyPng8(const std::string& path, const Image& image) {
  WritePng(path, ToMat<uint8_t>(image, CV_8UC1, kMax8Bit));
}

void WriteGreyPngLossless(const std::string& path, const Image& image) {
  if (MinimalBitDepth(image) == 8) {
    WriteGreyPng8(path, image);
  } else {
    WriteGreyPng16(path, image);
  }
}

void WriteTimestampsTxt(const std::string& path, const std::vector<int64_t>& t_ns) {
  TextFileWriter writer(path);
  for (size_t i = 0; i < t_ns.size(); ++i) {
    writer.Write(std::to_string(i) + ' ' + FormatDecimalSeconds(t_ns[i], kMaxFractionDigits) +
                 '\n');
  }
  writer.Close();
}

void WriteImageSequence(const std::string& folder, const Video& video) {
  const std::filesystem::path frames(folder);
  std::error_code error;
  std::filesystem::create_directories(frames, error);
  if (error) {
    throw InputError(InputError::Kind::kUnwritable, frames.string(), 0,
                     "cannot create the folder (" + error.message() + ")");
  }
  char name[32];
  for (int t = 0; t < video.num_frames(); ++t) {
    std::snprintf(name, sizeof(name), "%06d.png", t);
    WriteGreyPng16((frames / name).string(), video.frame(t));
  }
}

void WriteFrameSequence(const std::string& folder, const Video& video) {
  WriteImageSequence((std::filesystem::path(folder) / "frames").string(), video);
  WriteTimestampsTxt((std::filesystem::path(folder) / "timestamps.txt").string(),
                     video.timestamps_ns());
}

}  // namespace evfs
