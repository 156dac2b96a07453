#include "evfs/io/video_writer.h"

#include <stdlib.h>

#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/plugin.h"
#include "evfs/io/image_io.h"
#include "evfs/io/mp4_encoder_plugin.h"

namespace evfs {
namespace {

// The encoder plug-in's functions, loaded once per process.
struct Mp4Plugin {
  EvfsMp4OpenFunction open = nullptr;
  EvfsMp4WriteFunction write = nullptr;
  EvfsMp4CloseFunction close = nullptr;
};

const Mp4Plugin& LoadMp4Plugin() {
  static Mp4Plugin plugin;
  static std::string error;
  static std::once_flag once;
  std::call_once(once, [] {
    std::vector<void*> functions;
    if (!LoadPlugin(EVFS_MP4_PLUGIN_FILE,
                    {EVFS_MP4_OPEN_SYMBOL, EVFS_MP4_WRITE_SYMBOL, EVFS_MP4_CLOSE_SYMBOL},
                    &functions, &error)) {
      return;
    }
    plugin.open = reinterpret_cast<EvfsMp4OpenFunction>(functions[0]);
    plugin.write = reinterpret_cast<EvfsMp4WriteFunction>(functions[1]);
    plugin.close = reinterpret_cast<EvfsMp4CloseFunction>(functions[2]);
  });
  if (plugin.open == nullptr) {
    throw Error("the MP4 encoder plug-in cannot be loaded (is evfs completely installed?): " +
                error);
  }
  return plugin;
}

}  // namespace

const char* const kMp4Codecs[2] = {"avc1", "mp4v"};

Mp4Writer::Mp4Writer(const std::string& path, double fps, int width, int height)
    : path_(path), width_(width), height_(height) {
  const Mp4Plugin& plugin = LoadMp4Plugin();
  // The same frames give the same bytes in every run (--jobs, --resume, MPI rank 0): the plug-in
  // opens x264 on one CPU, since x264 picks its thread count, which changes the stream, from
  // the CPUs it may use, and has glibc zero the memory it allocates, since x264 reads bytes it
  // never wrote (io/mp4_encoder_plugin.cc). OPENCV_FFMPEG_WRITER_OPTIONS, set to "threads;1"
  // here before, reaches no codec option in OpenCV 4.6, so it is left to the user.
  for (const char* codec : kMp4Codecs) {
    encoder_ = plugin.open(path.c_str(), codec, fps, width, height);
    if (encoder_ != nullptr) {
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

Mp4Writer::~Mp4Writer() {
  if (encoder_ != nullptr) LoadMp4Plugin().close(encoder_);
}

void Mp4Writer::WriteGrey(const Image& image) {
  bgr_.resize(static_cast<size_t>(width_) * height_ * 3);
  unsigned char* pixel = bgr_.data();
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x, pixel += 3) {
      pixel[0] = pixel[1] = pixel[2] =
          static_cast<unsigned char>(IntensityLevel(image(y, x), 255.0));
    }
  }
  WriteBgr(bgr_.data());
}

void Mp4Writer::WriteBgr(const unsigned char* pixels) {
  if (encoder_ == nullptr) throw Error("Mp4Writer: write after Close()");
  LoadMp4Plugin().write(encoder_, pixels);
}

void Mp4Writer::Close() {
  if (encoder_ != nullptr) LoadMp4Plugin().close(encoder_);
  encoder_ = nullptr;
  std::error_code error;
  if (!std::filesystem::is_regular_file(path_, error) ||
      std::filesystem::file_size(path_, error) == 0 || error) {
    throw InputError(InputError::Kind::kUnwritable, path_, 0, "the video encoder wrote nothing");
  }
}

}  // namespace evfs
