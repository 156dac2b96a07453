// libFuzzer target: evfs' own ROS 1 bag code in memory (io/rosbag/format.h), without
// rosbag_storage, so that it runs several times as many inputs a second as rosbag_fuzzer (the
// whole reader, a rosbag::Bag and its queries per input). An input that starts as a bag goes
// through CheckBagStructure (the ranges it hands back must lie in the input), then every chunk
// through DecompressChunk and CheckChunkRecords, and every message record an index entry points
// at through both decoders; any other input is decoded as one dvs_msgs/EventArray and as one
// sensor_msgs/Image. Every input must give a result or an evfs::Error whose message is one short
// line, and what a check accepts must hold what it promises (the records and events lie inside
// the bytes; an image has its size).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "evfs/core/error.h"
#include "evfs/io/rosbag/format.h"
#include "evfs/tests/fuzz/fuzz_util.h"

namespace evfs {
namespace fuzzing {
namespace {

namespace rf = rosbag_format;

// The path the messages name; no file is written.
constexpr char kPath[] = "recording.bag";

uint32_t U32At(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 |
         static_cast<uint32_t>(p[2]) << 16 | static_cast<uint32_t>(p[3]) << 24;
}

void DecodeMessage(const uint8_t* data, size_t size) {
  try {
    const rf::EventArray array = rf::DecodeEventArray(data, size, kPath);
    Require(array.events + size_t{array.count} * rf::EventArray::kEventBytes <= data + size &&
                array.events >= data,
            "events outside the message");
    int64_t sum = 0;
    for (uint32_t i = 0; i < array.count; ++i) {
      Require(array.t_ns(i) >= 0, "an event time before 0");
      sum += array.x(i) + array.y(i) + array.polarity(i);
    }
    Require(sum >= -static_cast<int64_t>(array.count), "a polarity other than +1 or -1");
  } catch (const Error& error) {
    CheckMessage(error, kPath);
  }
  try {
    const rf::ImageMessage image = rf::DecodeImage(data, size, kPath);
    Require(image.pixels >= data && image.pixels + image.pixel_bytes <= data + size,
            "pixels outside the message");
    const Image grey = rf::ImageToGrey(image, kPath);
    Require(grey.rows() == static_cast<int>(image.height) &&
                grey.cols() == static_cast<int>(image.width),
            "a grey image of another size than the message's");
  } catch (const Error& error) {
    CheckMessage(error, kPath);
  }
}

// The message records of a checked chunk's `bytes` that its index entries point at.
void DecodeChunkMessages(const rf::BagChunk& chunk, const uint8_t* bytes, size_t size) {
  for (const rf::BagChunk::Entry& entry : chunk.entries) {
    // CheckChunkRecords promised a whole message record at each entry.
    Require(size_t{entry.offset} + 4 <= size, "an index entry past the chunk");
    const size_t header_len = U32At(bytes + entry.offset);
    const size_t data_len_at = size_t{entry.offset} + 4 + header_len;
    Require(data_len_at + 4 <= size, "a record header past the chunk");
    const size_t data_len = U32At(bytes + data_len_at);
    Require(data_len_at + 4 + data_len <= size, "a record's data past the chunk");
    DecodeMessage(bytes + data_len_at + 4, data_len);
  }
}

void FuzzBag(const uint8_t* data, size_t size) {
  try {
    const rf::BagLayout layout =
        rf::CheckBagStructure(kPath, data, size, [size](size_t offset, size_t length) {
          Require(offset <= size && length <= size - offset, "a released range past the file");
        });
    for (const rf::BagChunk& chunk : layout.chunks) {
      Require(chunk.data_begin + chunk.data_size <= size, "a chunk past the file");
      if (chunk.compression == "none") {
        rf::CheckChunkRecords(kPath, chunk, data + chunk.data_begin, chunk.data_size);
        DecodeChunkMessages(chunk, data + chunk.data_begin, chunk.data_size);
      } else {
        const rf::ChunkBytes bytes = rf::DecompressChunk(kPath, chunk, data);
        Require(bytes.size <= chunk.size, "a chunk larger than it declares");
        rf::CheckChunkRecords(kPath, chunk, bytes.data.get(), bytes.size);
        DecodeChunkMessages(chunk, bytes.data.get(), bytes.size);
      }
    }
  } catch (const Error& error) {
    CheckMessage(error, kPath);
  }
}

}  // namespace
}  // namespace fuzzing
}  // namespace evfs

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace rf = evfs::rosbag_format;
  if (size >= rf::kMagicBytes && std::memcmp(data, rf::kMagic, rf::kMagicBytes) == 0) {
    evfs::fuzzing::FuzzBag(data, size);
  } else {
    evfs::fuzzing::DecodeMessage(data, size);
  }
  return 0;
}
