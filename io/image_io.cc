#include "evfs/io/image_io.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <opencv2/core.hpp>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/parallel.h"
#include "evfs/core/plugin.h"
#include "evfs/io/decimal_seconds.h"
#include "evfs/io/image_decoder_plugin.h"
#include "evfs/io/png_codec.h"
#include "evfs/io/text_file_writer.h"

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
      row[x] = static_cast<Pixel>(IntensityLevel(image(y, x), max_value));
    }
  }
  return mat;
}

void WritePng(const std::string& path, const cv::Mat& mat) {
  std::string why;
  if (!EncodePngGrey(path, mat, &why)) {
    throw InputError(InputError::Kind::kUnwritable, path, 0, "cannot write the image: " + why);
  }
}

// A frame that is not a PNG file, through the image decoder plug-in; empty when it cannot be
// decoded, with the reason in `why` when the plug-in itself is missing.
cv::Mat DecodeOtherFormat(const std::string& path, std::string* why) {
  static EvfsImageDecodeFunction decode = nullptr;
  static EvfsImageFreeFunction release = nullptr;
  static std::string load_error;
  static std::once_flag once;
  std::call_once(once, [] {
    std::vector<void*> functions;
    if (LoadPlugin(EVFS_IMAGE_DECODER_PLUGIN_FILE,
                   {EVFS_IMAGE_DECODE_SYMBOL, EVFS_IMAGE_FREE_SYMBOL}, &functions, &load_error)) {
      decode = reinterpret_cast<EvfsImageDecodeFunction>(functions[0]);
      release = reinterpret_cast<EvfsImageFreeFunction>(functions[1]);
    }
  });
  if (decode == nullptr) {
    *why = "the image decoder plug-in cannot be loaded (" + load_error + ")";
    return cv::Mat();
  }
  int width = 0, height = 0, bits = 0;
  void* pixels = nullptr;
  if (decode(path.c_str(), &width, &height, &bits, &pixels) == 0) return cv::Mat();
  cv::Mat mat = cv::Mat(height, width, bits == 16 ? CV_16UC1 : CV_8UC1, pixels).clone();
  release(pixels);
  return mat;
}

// Big-endian unsigned integer of `bytes` bytes at `data`.
int64_t BigEndian(const unsigned char* data, int bytes) {
  int64_t value = 0;
  for (int i = 0; i < bytes; ++i) value = (value << 8) | data[i];
  return value;
}

// PNG: the signature, then the IHDR chunk, whose data opens with width and height (4 bytes
// each, big-endian) at bytes 16..23 of the file (PNG specification, 11.2.2).
bool PngHeaderSize(std::ifstream& file, int64_t* width, int64_t* height) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  unsigned char header[24];
  file.seekg(0);
  if (!file.read(reinterpret_cast<char*>(header), sizeof(header))) return false;
  if (std::memcmp(header, kSignature, sizeof(kSignature)) != 0) return false;
  if (std::memcmp(header + 12, "IHDR", 4) != 0) return false;
  *width = BigEndian(header + 16, 4);
  *height = BigEndian(header + 20, 4);
  return true;
}

// Most bytes of JPEG segments skipped looking for the frame header: its SOF segment comes
// before the image data, after the tables and metadata (EXIF at most 64 KiB a segment).
constexpr int64_t kMaxJpegHeaderBytes = int64_t{16} << 20;

// JPEG: the segments after SOI up to a start-of-frame marker (SOF0..SOF15 but DHT, JPG and
// DAC), whose data holds precision, height and width (ITU T.81, B.2.2).
bool JpegHeaderSize(std::ifstream& file, int64_t* width, int64_t* height) {
  unsigned char soi[2];
  file.seekg(0);
  if (!file.read(reinterpret_cast<char*>(soi), 2) || soi[0] != 0xFF || soi[1] != 0xD8) {
    return false;
  }
  while (file.tellg() < kMaxJpegHeaderBytes) {
    unsigned char marker[2];
    if (!file.read(reinterpret_cast<char*>(marker), 2) || marker[0] != 0xFF) return false;
    if (marker[1] == 0xFF) {  // fill byte
      file.seekg(-1, std::ios::cur);
      continue;
    }
    unsigned char length_bytes[2];
    if (!file.read(reinterpret_cast<char*>(length_bytes), 2)) return false;
    const int64_t length = BigEndian(length_bytes, 2);
    if (length < 2) return false;
    const unsigned char code = marker[1];
    if (code >= 0xC0 && code <= 0xCF && code != 0xC4 && code != 0xC8 && code != 0xCC) {
      unsigned char frame[5];
      if (!file.read(reinterpret_cast<char*>(frame), 5)) return false;
      *height = BigEndian(frame + 1, 2);
      *width = BigEndian(frame + 3, 2);
      return true;
    }
    file.seekg(length - 2, std::ios::cur);
  }
  return false;
}

}  // namespace

bool ReadImageHeaderSize(const std::string& path, int64_t* width, int64_t* height) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return false;
  if (PngHeaderSize(file, width, height)) return true;
  file.clear();
  return JpegHeaderSize(file, width, height);
}

Image ReadGreyImage(const std::string& path, int expected_width, int expected_height,
                    const std::string& expected_what) {
  // What stands at the path is named: a folder, a FIFO or a file without read permission is
  // not a missing file, and none of them an undecodable one.
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (!std::filesystem::exists(status)) {
    throw InputError(InputError::Kind::kMissingFile, path, 0, "image file does not exist");
  }
  if (std::filesystem::is_directory(status)) {
    throw InputError(InputError::Kind::kMissingFile, path, 0, "a folder, not an image file");
  }
  if (!std::filesystem::is_regular_file(status)) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     "a FIFO, socket or device, not an image file");
  }
  if (::access(path.c_str(), R_OK) != 0) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     std::string("cannot read the image file: ") + std::strerror(errno));
  }
  const auto size_text = [](int64_t width, int64_t height) {
    return std::to_string(width) + "x" + std::to_string(height);
  };
  // The declared size first: decoding allocates for it, whatever the file's own size.
  int64_t width = 0, height = 0;
  if (ReadImageHeaderSize(path, &width, &height)) {
    if (expected_width > 0 && expected_height > 0 &&
        (width != expected_width || height != expected_height)) {
      throw InputError(
          InputError::Kind::kSizeMismatch, path, 0,
          "image is " + size_text(width, height) + ", expected " +
              (expected_what.empty() ? size_text(expected_width, expected_height) : expected_what));
    }
    if (width * height > kMaxSensorPixels) {
      throw InputError(InputError::Kind::kOutOfRange, path, 0,
                       "image is " + size_text(width, height) + ": more than the " +
                           std::to_string(kMaxSensorPixels) + " pixels (8192x8192) evfs reads");
    }
  }
  cv::Mat mat;
  std::string why;
  if (HasPngSignature(path)) {
    if (!DecodePngGrey(path, &mat, &why)) mat.release();
  } else {
    mat = DecodeOtherFormat(path, &why);
  }
  if (mat.empty()) {
    throw InputError(InputError::Kind::kMissingFile, path, 0,
                     "cannot decode the image (expected an 8- or 16-bit PNG" +
                         (why.empty() ? std::string(")") : std::string("): ") + why));
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

void WriteImageSequence(const std::string& folder, const Video& video, int threads) {
  const std::filesystem::path frames(folder);
  std::error_code error;
  std::filesystem::create_directories(frames, error);
  if (error) {
    throw InputError(InputError::Kind::kUnwritable, frames.string(), 0,
                     "cannot create the folder (" + error.message() + ")");
  }
  ParallelForEach(video.num_frames(), threads, [&](int t) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", t);
    WriteGreyPng16((frames / name).string(), video.frame(t));
  });
}

void WriteFrameSequence(const std::string& folder, const Video& video, int threads) {
  WriteImageSequence((std::filesystem::path(folder) / "frames").string(), video, threads);
  WriteTimestampsTxt((std::filesystem::path(folder) / "timestamps.txt").string(),
                     video.timestamps_ns());
}

}  // namespace evfs
