// Grey frames on disk: PNG in and out, and the timestamps file that goes with a frame sequence.
#ifndef EVFS_IO_IMAGE_IO_H_
#define EVFS_IO_IMAGE_IO_H_

#include <cstdint>
#include <string>
#include <vector>

#include "evfs/core/video.h"

namespace evfs {

/// Most pixels a sensor, and so a frame, may have (8192 x 8192, far beyond any event camera's
/// 1280 x 960): a declared size is allocated for (frames, per-pixel counts), so every reader
/// bounds it before it allocates.
inline constexpr int64_t kMaxSensorPixels = int64_t{1} << 26;

/// The width and height an image file declares in its header (PNG, JPEG), read without
/// decoding it. False for another format, or a header too short to hold them.
bool ReadImageHeaderSize(const std::string& path, int64_t* width, int64_t* height);

/// Reads an 8- or 16-bit image (colour is converted to grey) scaled to [0, 1]: 8-bit values are
/// divided by 255, 16-bit ones by 65535. The size its header declares is checked before any
/// pixel is decoded: more than kMaxSensorPixels is InputError(kOutOfRange), and when
/// `expected_width` and `expected_height` are not 0, another size is
/// InputError(kSizeMismatch) ("expected `expected_what`", which names the size). Throws
/// InputError(kMissingFile) when the file is missing or cannot be decoded.
Image ReadGreyImage(const std::string& path, int expected_width = 0, int expected_height = 0,
                    const std::string& expected_what = "");

/// The fewest bits per pixel (8 or 16) that hold `image` exactly as ReadGreyImage returns it:
/// 8 when every value is k / 255 for an integer k in [0, 255], else 16.
int MinimalBitDepth(const Image& image);

/// The level of `value` clamped to [0, 1] and scaled by `max_level`, rounded half away from zero
/// (std::lround's rule) without a call into libm: the conversion of every written pixel.
inline int64_t IntensityLevel(double value, double max_level) {
  const double scaled = (value > 0.0 ? (value < 1.0 ? value : 1.0) : 0.0) * max_level;
  const int64_t whole = static_cast<int64_t>(scaled);                   // the floor, as scaled >= 0
  return whole + (scaled - static_cast<double>(whole) >= 0.5 ? 1 : 0);  // the difference is exact
}

/// Writes a 16-bit grey PNG: values clamped to [0, 1], scaled by 65535 and rounded.
/// Throws InputError(kUnwritable).
void WriteGreyPng16(const std::string& path, const Image& image);

/// Writes an 8-bit grey PNG: values clamped to [0, 1], scaled by 255 and rounded.
/// Throws InputError(kUnwritable).
void WriteGreyPng8(const std::string& path, const Image& image);

/// Writes an 8-bit PNG when MinimalBitDepth(image) is 8, else a 16-bit one, so that reading
/// it back gives `image` unchanged whenever it came from an 8- or 16-bit file.
void WriteGreyPngLossless(const std::string& path, const Image& image);

/// Writes `index t_seconds` lines (0-based index, 9 decimals, exact) for a frame sequence.
/// Throws InputError(kUnwritable).
void WriteTimestampsTxt(const std::string& path, const std::vector<int64_t>& t_ns);

/// Writes every frame of `video` as `folder`/NNNNNN.png (16-bit, WriteGreyPng16; NNNNNN the
/// 0-based frame index), creating the folder when missing, the frames encoded on up to
/// `threads` threads. Throws InputError(kUnwritable).
void WriteImageSequence(const std::string& folder, const Video& video, int threads = 1);

/// Writes `video` as a frame sequence in `folder` (created when missing): frames/NNNNNN.png
/// (16-bit, WriteGreyPng16; NNNNNN the 0-based frame index) and timestamps.txt
/// (WriteTimestampsTxt), on up to `threads` threads. Throws InputError(kUnwritable).
void WriteFrameSequence(const std::string& folder, const Video& video, int threads = 1);

}  // namespace evfs

#endif  // EVFS_IO_IMAGE_IO_H_
