// The C interface of the image decoder plug-in (io/image_decoder_plugin.cc), which
// ReadGreyImage opens with dlopen for frames that are not PNG files (JPEG, TIFF, BMP, ...):
// OpenCV's imgcodecs, with the libraries Debian builds it with, then costs start-up time only
// to the runs that read such frames (io/png_codec.h).
#ifndef EVFS_IO_IMAGE_DECODER_PLUGIN_H_
#define EVFS_IO_IMAGE_DECODER_PLUGIN_H_

extern "C" {

/// Decodes the image at `path` as OpenCV's imread(path, IMREAD_ANYDEPTH) does. On success
/// returns 1 and sets `*width`, `*height`, `*bits` (8 or 16) and `*pixels`: width × height
/// values of `bits` bits, row-major, to be released with the free function. Returns 0 when the
/// file cannot be decoded or holds another depth.
typedef int (*EvfsImageDecodeFunction)(const char* path, int* width, int* height, int* bits,
                                       void** pixels);
/// Releases the pixels of a successful decode.
typedef void (*EvfsImageFreeFunction)(void* pixels);

}  // extern "C"

/// The module's file name and the names of its two functions.
#define EVFS_IMAGE_DECODER_PLUGIN_FILE "libevfs_image_decoder.so"
#define EVFS_IMAGE_DECODE_SYMBOL "EvfsImageDecode"
#define EVFS_IMAGE_FREE_SYMBOL "EvfsImageFree"

#endif  // EVFS_IO_IMAGE_DECODER_PLUGIN_H_
