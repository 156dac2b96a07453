// PNG files through libpng, the format evfs reads frames from and writes frames to. OpenCV's
// imgcodecs would do the same, but linking it (with GDAL, GDCM, libheif, Poppler and the rest
// of what Debian builds it with) cost every evfs process about 0.2 s of start-up
// (BENCHMARKS.md, "Start-up cost"); other formats go through a plug-in (image_decoder_plugin.h).
#ifndef EVFS_IO_PNG_CODEC_H_
#define EVFS_IO_PNG_CODEC_H_

#include <opencv2/core.hpp>
#include <string>

namespace evfs {

/// True when the file at `path` starts with the PNG signature.
bool HasPngSignature(const std::string& path);

/// Decodes the PNG at `path` as OpenCV's imread(path, IMREAD_ANYDEPTH) does: one grey channel
/// (colour weighted 0.299 R + 0.587 G + 0.114 B, alpha dropped, palettes and 1/2/4-bit grey
/// expanded), CV_16UC1 for 16-bit files and CV_8UC1 for the rest. False, with libpng's reason
/// in `error`, when the file cannot be read or decoded.
bool DecodePngGrey(const std::string& path, cv::Mat* grey, std::string* error);

/// Writes `grey` (CV_8UC1 or CV_16UC1) as a grey PNG with OpenCV's fast settings (SUB filter,
/// zlib level 1, RLE strategy). False, with the reason in `error`, when it cannot; a file
/// begun is then removed.
bool EncodePngGrey(const std::string& path, const cv::Mat& grey, std::string* error);

}  // namespace evfs

#endif  // EVFS_IO_PNG_CODEC_H_
