// Encoding frame sequences as MP4 files through OpenCV's VideoWriter (the FFmpeg back end of
// Debian's OpenCV), for `evfs video`. The encoder lives in a plug-in opened on first use
// (io/mp4_encoder_plugin.h), so that the other commands do not load videoio.
#ifndef EVFS_IO_VIDEO_WRITER_H_
#define EVFS_IO_VIDEO_WRITER_H_

#include <string>
#include <vector>

#include "evfs/core/video.h"

namespace evfs {

/// The codecs tried, best first, as FourCC strings: H.264 ("avc1", which plays in browsers and
/// every common player), then MPEG-4 Part 2 ("mp4v", which FFmpeg always has).
extern const char* const kMp4Codecs[2];

/// One MP4 file written frame by frame. The file is complete once Close() returned.
class Mp4Writer {
 public:
  /// Opens `path` for `width` × `height` colour frames at `fps` with the first codec of
  /// kMp4Codecs that the FFmpeg back end accepts. Throws InputError(kUnwritable) when none does,
  /// and Error when the encoder plug-in (an incomplete installation) cannot be loaded.
  Mp4Writer(const std::string& path, double fps, int width, int height);
  ~Mp4Writer();
  Mp4Writer(const Mp4Writer&) = delete;
  Mp4Writer& operator=(const Mp4Writer&) = delete;

  /// The FourCC in use ("avc1" or "mp4v").
  const std::string& codec() const { return codec_; }

  /// Appends a grey frame (values in [0, 1], clamped).
  void WriteGrey(const Image& image);
  /// Appends 8-bit BGR pixels, row-major, width × height × 3 bytes.
  void WriteBgr(const unsigned char* pixels);
  /// Finishes the file. Throws InputError(kUnwritable) when it cannot be finished.
  void Close();

 private:
  std::string path_;
  int width_, height_;
  std::string codec_;
  void* encoder_ = nullptr;         // the plug-in's, until Close()
  std::vector<unsigned char> bgr_;  // WriteGrey's frame
};

}  // namespace evfs

#endif  // EVFS_IO_VIDEO_WRITER_H_
