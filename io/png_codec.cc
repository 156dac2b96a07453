#include "evfs/io/png_codec.h"

#include <png.h>
#include <zlib.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

namespace evfs {
namespace {

constexpr size_t kMessageBytes = 256;

// libpng reports an error by longjmp back to the frame that called setjmp; the frames below
// hold no object with a destructor, so that the jump skips none. The message goes to the
// buffer given as the error pointer.
void OnPngError(png_structp png, png_const_charp message) {
  char* buffer = static_cast<char*>(png_get_error_ptr(png));
  std::snprintf(buffer, kMessageBytes, "%s", message);
  png_longjmp(png, 1);
}

void OnPngWarning(png_structp, png_const_charp) {}

bool IsBigEndian() {
  const uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 0;
}

// Where DecodeRows writes: rows allocated once the decoded size is known.
struct DecodeTarget {
  cv::Mat grey;
  std::vector<png_bytep> rows;
};

png_bytepp AllocateRows(DecodeTarget* target, png_uint_32 width, png_uint_32 height,
                        int bit_depth) noexcept {
  try {
    target->grey.create(static_cast<int>(height), static_cast<int>(width),
                        bit_depth == 16 ? CV_16UC1 : CV_8UC1);
    target->rows.resize(height);
    for (png_uint_32 y = 0; y < height; ++y)
      target->rows[y] = target->grey.ptr(static_cast<int>(y));
    return target->rows.data();
  } catch (...) {
    return nullptr;
  }
}

// The transforms of OpenCV's PNG decoder for a grey image of any depth. Errors longjmp out.
void ReadGrey(png_structp png, png_infop info, FILE* file, DecodeTarget* target) {
  png_init_io(png, file);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info);
  const png_uint_32 height = png_get_image_height(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  const int color_type = png_get_color_type(png, info);
  if (bit_depth == 16 && !IsBigEndian()) png_set_swap(png);
  png_set_strip_alpha(png);
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((color_type & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8) {
    png_set_expand_gray_1_2_4_to_8(png);
  }
  png_set_rgb_to_gray(png, 1, 0.299, 0.587);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  png_bytepp rows = AllocateRows(target, width, height, bit_depth);
  if (rows == nullptr) png_error(png, "out of memory");
  png_read_image(png, rows);
  png_read_end(png, nullptr);
}

// Grey rows, 8 or 16 bits, with OpenCV's fast settings. Errors longjmp out.
void WriteGrey(png_structp png, png_infop info, FILE* file, const cv::Mat& grey, png_bytepp rows) {
  const int bit_depth = grey.depth() == CV_16U ? 16 : 8;
  png_init_io(png, file);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  png_set_IHDR(png, info, static_cast<png_uint_32>(grey.cols), static_cast<png_uint_32>(grey.rows),
               bit_depth, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (bit_depth == 16 && !IsBigEndian()) png_set_swap(png);
  png_write_image(png, rows);
  png_write_end(png, info);
}

// The frames that call setjmp hold nothing but libpng's two structures, made before it.
bool DecodeRows(FILE* file, DecodeTarget* target, char* message) {
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, message, OnPngError, OnPngWarning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::snprintf(message, kMessageBytes, "out of memory");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  ReadGrey(png, info, file, target);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

bool EncodeRows(FILE* file, const cv::Mat& grey, png_bytepp rows, char* message) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, message, OnPngError, OnPngWarning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(message, kMessageBytes, "out of memory");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  WriteGrey(png, info, file, grey, rows);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

bool HasPngSignature(const std::string& path) {
  FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return false;
  png_byte signature[8] = {0};
  const size_t read = std::fread(signature, 1, sizeof(signature), file);
  std::fclose(file);
  return read == sizeof(signature) && png_sig_cmp(signature, 0, sizeof(signature)) == 0;
}

bool DecodePngGrey(const std::string& path, cv::Mat* grey, std::string* error) {
  FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    *error = std::strerror(errno);
    return false;
  }
  DecodeTarget target;
  char message[kMessageBytes] = {0};
  const bool decoded = DecodeRows(file, &target, message);
  std::fclose(file);
  if (!decoded) {
    *error = message;
    return false;
  }
  *grey = target.grey;
  return true;
}

bool EncodePngGrey(const std::string& path, const cv::Mat& grey, std::string* error) {
  if (grey.channels() != 1 || (grey.depth() != CV_8U && grey.depth() != CV_16U) || grey.empty()) {
    *error = "not a non-empty 8- or 16-bit grey image";
    return false;
  }
  std::vector<png_bytep> rows(grey.rows);
  for (int y = 0; y < grey.rows; ++y) rows[y] = const_cast<png_bytep>(grey.ptr(y));
  FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    *error = std::strerror(errno);
    return false;
  }
  char message[kMessageBytes] = {0};
  bool written = EncodeRows(file, grey, rows.data(), message);
  if (std::fflush(file) != 0 && written) {
    std::snprintf(message, kMessageBytes, "%s", std::strerror(errno));
    written = false;
  }
  if (std::fclose(file) != 0 && written) {
    std::snprintf(message, kMessageBytes, "%s", std::strerror(errno));
    written = false;
  }
  if (!written) {
    std::remove(path.c_str());
    *error = message;
  }
  return written;
}

}  // namespace evfs
