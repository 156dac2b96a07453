#include "app/video_writer.h"

#include <dlfcn.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "app/mp4_encoder_plugin.h"
#include "core/error.h"

namespace evfs {
namespace {

// The encoder plug-in's functions, loaded once per process.
struct Mp4Plugin {
  EvfsMp4OpenFunction open = nullptr;
  EvfsMp4WriteFunction write = nullptr;
  EvfsMp4CloseFunction close = nullptr;
};

// Where the plug-in is looked for: $EVFS_PLUGIN_DIR, next to the binary that holds this code
// and in the lib/evfs/ of its installation, the configured install folder, then where the build
// tree made it.
std::vector<std::filesystem::path> PluginCandidates() {
  std::vector<std::filesystem::path> candidates;
  if (const char* dir = getenv("EVFS_PLUGIN_DIR"); dir != nullptr && *dir != '\0') {
    candidates.push_back(std::filesystem::path(dir) / EVFS_MP4_PLUGIN_FILE);
  }
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&PluginCandidates), &info) != 0 && info.dli_fname) {
    const std::filesystem::path binary = std::filesystem::weakly_canonical(info.dli_fname);
    candidates.push_back(binary.parent_path() / EVFS_MP4_PLUGIN_FILE);
    candidates.push_back(binary.parent_path().parent_path() / EVFS_PLUGIN_INSTALL_SUBDIR /
                         EVFS_MP4_PLUGIN_FILE);
  }
  candidates.push_back(std::filesystem::path(EVFS_PLUGIN_INSTALL_DIR) / EVFS_MP4_PLUGIN_FILE);
  candidates.push_back(std::filesystem::path(EVFS_PLUGIN_BUILD_DIR) / EVFS_MP4_PLUGIN_FILE);
  return candidates;
}

const Mp4Plugin& LoadMp4Plugin() {
  static Mp4Plugin plugin;
  static std::string error;
  static std::once_flag once;
  std::call_once(once, [] {
    for (const std::filesystem::path& candidate : PluginCandidates()) {
      std::error_code ignored;
      if (!std::filesystem::is_regular_file(candidate, ignored)) continue;
      void* module = dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (module == nullptr) {
        const char* why = dlerror();
        error = why != nullptr ? why : candidate.string();
        continue;
      }
      plugin.open = reinterpret_cast<EvfsMp4OpenFunction>(dlsym(module, EVFS_MP4_OPEN_SYMBOL));
      plugin.write = reinterpret_cast<EvfsMp4WriteFunction>(dlsym(module, EVFS_MP4_WRITE_SYMBOL));
      plugin.close = reinterpret_cast<EvfsMp4CloseFunction>(dlsym(module, EVFS_MP4_CLOSE_SYMBOL));
      if (plugin.open && plugin.write && plugin.close) return;
      error = candidate.string() + " lacks the encoder's functions";
      plugin = Mp4Plugin();
    }
    if (error.empty())
      error = "no " EVFS_MP4_PLUGIN_FILE " next to evfs or in " EVFS_PLUGIN_INSTALL_DIR;
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
  // never wrote (app/mp4_encoder_plugin.cc). OPENCV_FFMPEG_WRITER_OPTIONS, set to "threads;1"
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
      const double value = std::clamp(image(y, x), 0.0, 1.0);
      pixel[0] = pixel[1] = pixel[2] = static_cast<unsigned char>(std::lround(value * 255.0));
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
