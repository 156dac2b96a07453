// The C interface of the MP4 encoder plug-in (io/mp4_encoder_plugin.cc), a module that
// Mp4Writer opens with dlopen: OpenCV's videoio, with the FFmpeg and GStreamer libraries it
// loads, then costs start-up time only to the commands that write MP4 files (BENCHMARKS.md,
// "Start-up cost").
#ifndef EVFS_IO_MP4_ENCODER_PLUGIN_H_
#define EVFS_IO_MP4_ENCODER_PLUGIN_H_

extern "C" {

/// Opens `path` for `width` × `height` 8-bit BGR frames at `fps` with the FourCC `codec`
/// (e.g. "avc1") through OpenCV's FFmpeg back end; null when the back end refuses.
typedef void* (*EvfsMp4OpenFunction)(const char* path, const char* codec, double fps, int width,
                                     int height);
/// Appends one frame of width × height × 3 bytes, row-major.
typedef void (*EvfsMp4WriteFunction)(void* encoder, const unsigned char* bgr);
/// Finishes the file and frees the encoder.
typedef void (*EvfsMp4CloseFunction)(void* encoder);

}  // extern "C"

/// The module's file name and the names of its three functions.
#define EVFS_MP4_PLUGIN_FILE "libevfs_mp4_encoder.so"
#define EVFS_MP4_OPEN_SYMBOL "EvfsMp4Open"
#define EVFS_MP4_WRITE_SYMBOL "EvfsMp4Write"
#define EVFS_MP4_CLOSE_SYMBOL "EvfsMp4Close"

#endif  // EVFS_IO_MP4_ENCODER_PLUGIN_H_
