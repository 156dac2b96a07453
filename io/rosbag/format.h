// The ROS 1 bag format version 2.0 (wiki.ros.org/Bags/Format/2.0) as far as evfs checks it
// before rosbag_storage reads a file, and the two message types evfs decodes itself from their
// published definitions (ROS serialisation: little-endian, strings and arrays prefixed by a
// uint32 length):
//
//   std_msgs/Header      uint32 seq, time stamp (uint32 sec, uint32 nsec), string frame_id
//   dvs_msgs/EventArray  Header header, uint32 height, uint32 width, Event[] events, each
//                        {uint16 x, uint16 y, time ts, bool polarity} (13 bytes)
//   sensor_msgs/Image    Header header, uint32 height, uint32 width, string encoding,
//                        uint8 is_bigendian, uint32 step, uint8[] data
//
// A bag is "#ROSBAG V2.0\n" then records: uint32 header_len, header fields (uint32 len,
// "name=value"), uint32 data_len, data. The first record is the bag header (op 0x03: index_pos,
// conn_count, chunk_count); chunks (op 0x05) hold the messages (op 0x02) and connections
// (op 0x07), each chunk followed by its index data (op 0x04: offsets of its messages); at
// index_pos the connections and one chunk info (op 0x06) per chunk follow.
#ifndef EVFS_IO_ROSBAG_FORMAT_H_
#define EVFS_IO_ROSBAG_FORMAT_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "evfs/core/video.h"

namespace evfs {
namespace rosbag_format {

/// The first line of every bag of version 2.0.
constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr size_t kMagicBytes = sizeof(kMagic) - 1;

/// The datatypes evfs reads.
constexpr char kEventArrayType[] = "dvs_msgs/EventArray";
constexpr char kImageType[] = "sensor_msgs/Image";

/// Most bytes of one chunk uncompressed evfs reads (rosbag_storage allocates what the chunk
/// declares; rosbag record writes 768 KiB chunks by default).
constexpr uint32_t kMaxChunkBytes = 1u << 30;

/// One chunk of a bag and its index data, as CheckBagStructure found them.
struct BagChunk {
  size_t offset = 0;      // of the chunk record in the file
  size_t data_begin = 0;  // its data (compressed unless compression is "none") in the file
  size_t data_size = 0;
  std::string compression;  // "none", "bz2" or "lz4"
  uint32_t size = 0;        // uncompressed
  /// One index entry: a message of `connection` received at `time_ns`, at chunk byte `offset`.
  struct Entry {
    uint32_t connection;
    uint64_t time_ns;
    uint32_t offset;
  };
  std::vector<Entry> entries;
};

struct BagLayout {
  std::vector<BagChunk> chunks;  // in the order of the chunk infos
};

/// Told the byte ranges of the file a check has finished with (it may read them again later, as
/// any mapped file allows), in steps of megabytes: the reader drops their pages from memory.
using ReleaseBytes = std::function<void(size_t offset, size_t size)>;

/// Walks the records of the `size` bytes at `data` (the bag `path`, for messages) and checks
/// everything rosbag_storage relies on without checking it when it opens a bag: every record
/// and header field lies inside the file, the bag header's index position falls on a record,
/// the index holds the connections and chunk infos the header declares, every chunk info points
/// at a chunk followed by its index data, every connection named is declared and every index
/// offset lies inside its chunk. Throws InputError naming the byte offset where the file stops
/// making sense, and for an unindexed bag (index_pos 0: a recording that was cut short).
/// `release` (may be empty) is told the ranges the walk is done with.
BagLayout CheckBagStructure(const std::string& path, const uint8_t* data, size_t size,
                            const ReleaseBytes& release = {});

/// Checks the `size` bytes at `data`, `chunk` uncompressed, before rosbag_storage reads its
/// messages (it trusts the lengths it finds there): they are `chunk.size` bytes of whole records,
/// and every index entry of the chunk points at a message record. Throws InputError.
void CheckChunkRecords(const std::string& path, const BagChunk& chunk, const uint8_t* data,
                       size_t size);

/// A chunk's data uncompressed; pages the decompressor did not write are never touched, so a
/// chunk that declares more than it holds costs only what it holds.
struct ChunkBytes {
  std::unique_ptr<uint8_t[]> data;
  size_t size = 0;
};

/// The data of `chunk` of the bag whose bytes start at `file`, a bz2 or LZ4 chunk, uncompressed
/// as rosbag_storage decompresses it (at most chunk.size bytes; CheckChunkRecords checks that
/// they are exactly that many). Throws InputError naming `path` when they do not decompress.
ChunkBytes DecompressChunk(const std::string& path, const BagChunk& chunk, const uint8_t* file);

/// The header and event count of a dvs_msgs/EventArray; the events stay in the message bytes.
struct EventArray {
  int64_t stamp_ns = 0;
  uint32_t height = 0;
  uint32_t width = 0;
  uint32_t count = 0;
  const uint8_t* events = nullptr;  // `count` serialised events of kEventBytes

  static constexpr size_t kEventBytes = 13;
  /// Event `index`: its time in ns, x, y, and polarity +1 (true) or -1 (false).
  int64_t t_ns(uint32_t index) const;
  int x(uint32_t index) const;
  int y(uint32_t index) const;
  int polarity(uint32_t index) const;
};

/// Decodes the serialised message of `size` bytes at `data`; `where` names it in messages
/// ("PATH: message 12 on /dvs/events"). Throws InputError when the message is truncated, longer
/// than its fields, or holds a time with nsec >= 1e9.
EventArray DecodeEventArray(const uint8_t* data, size_t size, const std::string& where);

/// The header and pixels of a sensor_msgs/Image; the pixels stay in the message bytes.
struct ImageMessage {
  int64_t stamp_ns = 0;
  uint32_t height = 0;
  uint32_t width = 0;
  std::string encoding;
  bool is_bigendian = false;
  uint32_t step = 0;
  const uint8_t* pixels = nullptr;
  size_t pixel_bytes = 0;
};

/// As DecodeEventArray, for a sensor_msgs/Image; the encoding is not checked here.
ImageMessage DecodeImage(const uint8_t* data, size_t size, const std::string& where);

/// The image as grey values in [0, 1]: mono8 and mono16 as they are (divided by 255 or 65535),
/// rgb8, bgr8, rgba8 and bgra8 by OpenCV's grey conversion of the 8-bit pixels (as imread
/// reads a colour PNG as grey). Throws InputError for any other encoding, or a step or data
/// size that does not fit the width and height.
Image ImageToGrey(const ImageMessage& image, const std::string& where);

}  // namespace rosbag_format
}  // namespace evfs

#endif  // EVFS_IO_ROSBAG_FORMAT_H_
