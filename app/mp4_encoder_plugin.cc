// The MP4 encoder plug-in (app/mp4_encoder_plugin.h): cv::VideoWriter behind a C interface.
#include "app/mp4_encoder_plugin.h"

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace {

struct Encoder {
  cv::VideoWriter writer;
  cv::Size size;
};

}  // namespace

extern "C" {

__attribute__((visibility("default"))) void* EvfsMp4Open(const char* path, const char* codec,
                                                         double fps, int width, int height) {
  auto* encoder = new Encoder{cv::VideoWriter(), cv::Size(width, height)};
  const int fourcc = cv::VideoWriter::fourcc(codec[0], codec[1], codec[2], codec[3]);
  if (!encoder->writer.open(path, cv::CAP_FFMPEG, fourcc, fps, encoder->size, true)) {
    delete encoder;
    return nullptr;
  }
  return encoder;
}

__attribute__((visibility("default"))) void EvfsMp4Write(void* encoder, const unsigned char* bgr) {
  auto* open = static_cast<Encoder*>(encoder);
  open->writer.write(cv::Mat(open->size, CV_8UC3, const_cast<unsigned char*>(bgr)));
}

__attribute__((visibility("default"))) void EvfsMp4Close(void* encoder) {
  auto* open = static_cast<Encoder*>(encoder);
  open->writer.release();
  delete open;
}

}  // extern "C"
