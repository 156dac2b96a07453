// The header of an AEDAT 4.0 file: after the version line, the IOHeader flatbuffer
// (io_header.fbs) with the compression, the position of the file data table and the XML
// description of the streams. Parsed for the reader, built for the writer.
#ifndef EVFS_IO_AEDAT4_HEADER_H_
#define EVFS_IO_AEDAT4_HEADER_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "evfs/io/aedat4.h"
#include "evfs/io/data_source.h"

namespace evfs {
namespace aedat4 {

// One stream of the description.
struct StreamInfo {
  int32_t id = -1;  // -1: no such stream
  std::string type;
  int size_x = 0;  // 0: not given
  int size_y = 0;
  int64_t ts_offset_us = 0;
};

// What the header says, and where the packets start.
struct Header {
  Aedat4Compression compression = Aedat4Compression::kNone;
  int64_t data_table_position = -1;
  size_t data_start = 0;  // offset of the first packet
  StreamInfo events;      // the first EVTS stream, id -1 when none
  StreamInfo frames;      // the first FRME stream, id -1 when none
  bool written_by_evfs = false;
  std::vector<std::string> frame_paths;  // from the evfs node, in frame order; may be empty
};

// Parses the version line, the IOHeader and its stream description at the start of the `size`
// bytes at `data`, the file `path`; throws InputError naming `path`.
Header ParseHeader(const std::string& path, const uint8_t* data, size_t size);

// The IOHeader as a size-prefixed flatbuffer (the bytes after the version line), every field
// written, defaults too, so that its size does not depend on `data_table_position`.
std::vector<uint8_t> IOHeaderBytes(Aedat4Compression compression, int64_t data_table_position,
                                   const std::string& stream_description);

// The XML stream description DV writes (see the IOHeader of a DV recording), plus the evfs node
// that marks the file as evfs's and keeps the images.txt paths of `frames`.
std::string StreamDescription(int width, int height, bool with_events, bool with_frames,
                              Aedat4Compression compression, const std::vector<FrameInfo>& frames);

}  // namespace aedat4
}  // namespace evfs

#endif  // EVFS_IO_AEDAT4_HEADER_H_
