// The image decoder plug-in (io/image_decoder_plugin.h): OpenCV's imread behind a C interface.
#include "evfs/io/image_decoder_plugin.h"

#include <cstdlib>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

extern "C" __attribute__((visibility("default"))) int EvfsImageDecode(const char* path, int* width,
                                                                      int* height, int* bits,
                                                                      void** pixels) {
  try {
    const cv::Mat mat = cv::imread(path, cv::IMREAD_ANYDEPTH);
    if (mat.empty() || mat.channels() != 1 || (mat.depth() != CV_8U && mat.depth() != CV_16U)) {
      return 0;
    }
    const size_t row_bytes = mat.elemSize() * static_cast<size_t>(mat.cols);
    void* copy = std::malloc(row_bytes * static_cast<size_t>(mat.rows));
    if (copy == nullptr) return 0;
    for (int y = 0; y < mat.rows; ++y) {
      std::memcpy(static_cast<unsigned char*>(copy) + row_bytes * y, mat.ptr(y), row_bytes);
    }
    *width = mat.cols;
    *height = mat.rows;
    *bits = mat.depth() == CV_16U ? 16 : 8;
    *pixels = copy;
    return 1;
  } catch (...) {
    return 0;
  }
}

extern "C" __attribute__((visibility("default"))) void EvfsImageFree(void* pixels) {
  std::free(pixels);
}
