#include "app/video_writer.h"

#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "core/error.h"

namespace evfs {

const char* const kMp4Codecs[2] = {"avc1", "mp4v"};

Mp4Writer::Mp4Writer(const std::string& path, double fps, int width, int height)
    : path_(path), width_(width), height_(height), writer_(std::make_unique<cv::VideoWriter>()) {
  // x264 with frame threads gave different bytes for the same frames from run to run of evfs
  // (--jobs=1 against --jobs=2), so one encoder thread is asked for (OpenCV reads its FFmpeg
  // writer options from this variable; a user's own setting wins). The bytes were still seen to
  // differ between runs, so nothing relies on them: resumed and distributed runs are checked on
  // frames/ and timestamps.txt (README, `evfs video`).
  setenv("OPENCV_FFMPEG_WRITER_OPTIONS", "threads;1", /*overwrite=*/0);
  for (const char* codec : kMp4Codecs) {
    const int fourcc = cv::VideoWriter::fourcc(codec[0], codec[1], codec[2], codec[3]);
    if (writer_->open(path, cv::CAP_FFMPEG, fourcc, fps, cv::Size(width, height), true)) {
      codec_ = codec;
      return;
    }
    std::error_code ignored;
    std::filesystem::remove(path, ignored);  // what a failed open may have left
  }
  throw InputError(
      InputError::Kind::kUnwritable, path, 0,
      "OpenCV's FFmpeg back end accepts neither H.264 (avc1) nor MPEG-4 (mp4v) for a " +
          std::to_string(width) + "x" + std::to_string(height) + " video");
}

Mp4Writer::~Mp4Writer() = default;

void Mp4Writer::WriteGrey(const Image& image) {
  cv::Mat bgr(height_, width_, CV_8UC3);
  for (int y = 0; y < height_; ++y) {
    unsigned char* row = bgr.ptr<unsigned char>(y);
    for (int x = 0; x < width_; ++x) {
      const double value = std::clamp(image(y, x), 0.0, 1.0);
      const auto byte = static_cast<unsigned char>(std::lround(value * 255.0));
      row[3 * x] = row[3 * x + 1] = row[3 * x + 2] = byte;
    }
  }
  writer_->write(bgr);
}

void Mp4Writer::WriteBgr(const unsigned char* pixels) {
  const cv::Mat bgr(height_, width_, CV_8UC3, const_cast<unsigned char*>(pixels));
  writer_->write(bgr);
}

void Mp4Writer::Close() {
  writer_->release();
  std::error_code error;
  if (!std::filesystem::is_regular_file(path_, error) ||
      std::filesystem::file_size(path_, error) == 0 || error) {
    throw InputError(InputError::Kind::kUnwritable, path_, 0, "the video encoder wrote nothing");
  }
}

}  // namespace evfs
