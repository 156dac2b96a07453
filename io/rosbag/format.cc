#include "evfs/io/rosbag/format.h"

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <cstring>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/message_excerpt.h"

namespace evfs {
namespace rosbag_format {
namespace {

constexpr int64_t kNanosecondsPerSecond = 1000000000;

// Record operations (the "op" header field).
constexpr uint8_t kOpMessageData = 0x02;
constexpr uint8_t kOpBagHeader = 0x03;
constexpr uint8_t kOpIndexData = 0x04;
constexpr uint8_t kOpChunk = 0x05;
constexpr uint8_t kOpChunkInfo = 0x06;
constexpr uint8_t kOpConnection = 0x07;

// The most LZ4 expands data (a run costs one byte per 255 of its length), plus room for small
// frames whose headers outweigh their data.
constexpr uint32_t kMaxLz4Expansion = 255;
constexpr uint64_t kLz4FrameSlackBytes = 1024;
constexpr size_t kIndexEntryBytes = 12;     // time (8) and offset (4)
constexpr size_t kChunkInfoEntryBytes = 8;  // connection id (4) and count (4)
// How many bytes the walk over a bag's records reads before it hands them to ReleaseBytes: a
// madvise call per record would cost more than the walk.
constexpr size_t kReleaseStepBytes = size_t{8} << 20;

uint32_t ReadU32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 |
         static_cast<uint32_t>(p[2]) << 16 | static_cast<uint32_t>(p[3]) << 24;
}

uint64_t ReadU64(const uint8_t* p) {
  return ReadU32(p) | static_cast<uint64_t>(ReadU32(p + 4)) << 32;
}

// One record of the file (or of an uncompressed chunk): where its header and data lie.
struct Record {
  size_t offset = 0;
  size_t header_begin = 0;
  size_t header_end = 0;
  size_t data_begin = 0;
  size_t data_end = 0;
  uint8_t op = 0;
};

class BagChecker {
 public:
  // `context` opens every message: "" for the file, "the chunk at byte N, uncompressed, " for
  // the bytes of a chunk.
  BagChecker(const std::string& path, const uint8_t* data, size_t size, std::string context = "",
             const ReleaseBytes* release = nullptr)
      : path_(path), data_(data), size_(size), context_(std::move(context)), release_(release) {}

  BagLayout Check() {
    if (size_ < kMagicBytes || std::memcmp(data_, kMagic, kMagicBytes) != 0) {
      Fail(0, "does not start with \"#ROSBAG V2.0\" (not a ROS 1 bag of version 2.0)");
    }
    std::vector<Record> records;
    std::map<size_t, size_t> record_at_offset;
    size_t released = 0;
    for (size_t offset = kMagicBytes; offset < size_;) {
      const Record record = ReadRecord(offset, size_, "the file");
      record_at_offset[offset] = records.size();
      records.push_back(record);
      offset = record.data_end;
      if (release_ != nullptr && offset - released >= kReleaseStepBytes) {
        (*release_)(released, offset - released);
        released = offset;
      }
    }
    if (records.empty() || records.front().op != kOpBagHeader) {
      Fail(kMagicBytes, "the first record is not the bag header (truncated file?)");
    }
    const Record& bag_header = records.front();
    const uint64_t index_pos = FieldU64(bag_header, "index_pos");
    const uint32_t conn_count = FieldU32(bag_header, "conn_count");
    const uint32_t chunk_count = FieldU32(bag_header, "chunk_count");
    if (index_pos == 0) {
      Fail(bag_header.offset,
           "an unindexed bag (index_pos 0: its recording was cut short); index it with "
           "'rosbag reindex' first");
    }
    // The index: conn_count connections, then chunk_count chunk infos.
    const auto index = record_at_offset.find(index_pos);
    if (index == record_at_offset.end()) {
      Fail(bag_header.offset, "index_pos " + std::to_string(index_pos) +
                                  " is not the start of a record (truncated file?)");
    }
    const size_t at = index->second;
    if (records.size() - at < static_cast<uint64_t>(conn_count) + chunk_count) {
      Fail(index_pos, "the index holds fewer than the " + std::to_string(conn_count) +
                          " connections and " + std::to_string(chunk_count) +
                          " chunk infos the bag header declares (truncated file?)");
    }
    std::set<uint32_t> connections;
    BagLayout layout;
    for (uint32_t i = 0; i < conn_count; ++i) {
      const Record& record = records[at + i];
      Expect(record, kOpConnection, "a connection record");
      connections.insert(FieldU32(record, "conn"));
      Field(record, "topic");
      CheckFields(record.data_begin, record.data_end);
    }
    for (uint32_t i = 0; i < chunk_count; ++i) {
      const Record& info = records[at + conn_count + i];
      Expect(info, kOpChunkInfo, "a chunk info record");
      const uint64_t chunk_pos = FieldU64(info, "chunk_pos");
      FieldU64(info, "start_time");
      FieldU64(info, "end_time");
      const uint32_t count = FieldU32(info, "count");
      if (info.data_end - info.data_begin != static_cast<uint64_t>(count) * kChunkInfoEntryBytes) {
        Fail(info.offset, "a chunk info whose data does not hold its " + std::to_string(count) +
                              " connection counts");
      }
      for (uint32_t k = 0; k < count; ++k) {
        CheckConnection(connections, ReadU32(data_ + info.data_begin + k * kChunkInfoEntryBytes),
                        info.offset);
      }
      const auto chunk_record = record_at_offset.find(chunk_pos);
      if (chunk_record == record_at_offset.end() || chunk_record->second >= at) {
        Fail(info.offset, "a chunk info points at byte " + std::to_string(chunk_pos) +
                              ", where no chunk starts");
      }
      // rosbag_storage reads `count` index data records after the chunk.
      const size_t chunk = chunk_record->second;
      if (chunk + count >= at) {
        Fail(chunk_pos, "a chunk without the index data its chunk info declares");
      }
      layout.chunks.push_back(CheckChunk(records, chunk, count, connections));
      if (release_ != nullptr) {
        (*release_)(records[chunk].offset, records[chunk + count].data_end - records[chunk].offset);
      }
    }
    return layout;
  }

  // The uncompressed bytes of `chunk` (this checker's data): every record inside it, and a
  // message record wherever its index data points.
  void CheckChunkRecords(const BagChunk& chunk) const {
    if (size_ != chunk.size) {
      Fail(0, "the chunk holds " + std::to_string(size_) +
                  " bytes uncompressed, its size field says " + std::to_string(chunk.size));
    }
    std::set<size_t> messages;
    for (size_t at = 0; at < size_;) {
      const Record inner = ReadRecord(at, size_, "its chunk");
      if (inner.op == kOpMessageData) {
        FieldU32(inner, "conn");
        FieldU64(inner, "time");
        messages.insert(at);
      } else if (inner.op == kOpConnection) {
        FieldU32(inner, "conn");
        Field(inner, "topic");
        CheckFields(inner.data_begin, inner.data_end);
      } else {
        Fail(at, "a record of op " + std::to_string(inner.op) + " inside a chunk");
      }
      at = inner.data_end;
    }
    for (const BagChunk::Entry& entry : chunk.entries) {
      if (messages.count(entry.offset) == 0) {
        Fail(entry.offset, "the chunk's index points here, where no message starts");
      }
    }
  }

 private:
  [[noreturn]] void Fail(size_t offset, const std::string& what) const {
    throw InputError(InputError::Kind::kMalformed, path_, 0,
                     context_ + "byte " + std::to_string(offset) + ": " + what);
  }

  // The record at `offset`, which must end by `end`.
  Record ReadRecord(size_t offset, size_t end, const char* inside) const {
    Record record;
    record.offset = offset;
    if (end - offset < 4) Fail(offset, std::string("a record cut by the end of ") + inside);
    const uint32_t header_len = ReadU32(data_ + offset);
    if (end - offset - 4 < static_cast<uint64_t>(header_len) + 4) {
      Fail(offset, "a record header of " + std::to_string(header_len) +
                       " bytes runs past the end of " + inside + " (truncated file?)");
    }
    record.header_begin = offset + 4;
    record.header_end = record.header_begin + header_len;
    const uint32_t data_len = ReadU32(data_ + record.header_end);
    record.data_begin = record.header_end + 4;
    if (end - record.data_begin < data_len) {
      Fail(offset, "a record's " + std::to_string(data_len) + " data bytes run past the end of " +
                       inside + " (truncated file?)");
    }
    record.data_end = record.data_begin + data_len;
    CheckFields(record.header_begin, record.header_end);
    const std::string op = Field(record, "op");
    if (op.size() != 1) Fail(offset, "a record whose op field is not one byte");
    record.op = static_cast<uint8_t>(op[0]);
    return record;
  }

  // Header fields: uint32 length, then "name=value".
  void CheckFields(size_t begin, size_t end) const {
    for (size_t at = begin; at < end;) {
      if (end - at < 4) Fail(at, "a header field cut by the end of its header");
      const uint32_t length = ReadU32(data_ + at);
      if (end - at - 4 < length) Fail(at, "a header field runs past the end of its header");
      if (std::memchr(data_ + at + 4, '=', length) == nullptr) {
        Fail(at, "a header field without '='");
      }
      at += 4 + length;
    }
  }

  // The value of field `name` of `record`'s header; fails when there is none.
  std::string Field(const Record& record, const std::string& name) const {
    for (size_t at = record.header_begin; at < record.header_end;) {
      const uint32_t length = ReadU32(data_ + at);
      const char* field = reinterpret_cast<const char*>(data_ + at + 4);
      if (length > name.size() && std::memcmp(field, name.data(), name.size()) == 0 &&
          field[name.size()] == '=') {
        return std::string(field + name.size() + 1, length - name.size() - 1);
      }
      at += 4 + length;
    }
    Fail(record.offset, "a record without the header field '" + name + "'");
  }

  uint32_t FieldU32(const Record& record, const std::string& name) const {
    const std::string value = Field(record, name);
    if (value.size() != 4) Fail(record.offset, "header field '" + name + "' is not 4 bytes");
    return ReadU32(reinterpret_cast<const uint8_t*>(value.data()));
  }

  uint64_t FieldU64(const Record& record, const std::string& name) const {
    const std::string value = Field(record, name);
    if (value.size() != 8) Fail(record.offset, "header field '" + name + "' is not 8 bytes");
    return ReadU64(reinterpret_cast<const uint8_t*>(value.data()));
  }

  void Expect(const Record& record, uint8_t op, const char* what) const {
    if (record.op != op) Fail(record.offset, std::string("expected ") + what + " in the index");
  }

  void CheckConnection(const std::set<uint32_t>& connections, uint32_t id, size_t offset) const {
    if (connections.count(id) == 0) {
      Fail(offset, "connection " + std::to_string(id) + " is not among the bag's connections");
    }
  }

  // The chunk records[chunk] and the `count` index data records after it. Its records are
  // checked when it is first read (CheckChunkRecords): a compressed one only decompressed shows
  // them.
  BagChunk CheckChunk(const std::vector<Record>& records, size_t chunk, uint32_t count,
                      const std::set<uint32_t>& connections) const {
    const Record& record = records[chunk];
    if (record.op != kOpChunk) {
      Fail(record.offset, "a chunk info points at a record that is no chunk");
    }
    BagChunk layout;
    layout.offset = record.offset;
    layout.data_begin = record.data_begin;
    layout.data_size = record.data_end - record.data_begin;
    layout.compression = Field(record, "compression");
    layout.size = FieldU32(record, "size");
    if (layout.compression == "none" && layout.data_size != layout.size) {
      Fail(record.offset, "an uncompressed chunk whose size field differs from its data");
    }
    if (layout.compression != "none" && layout.compression != "bz2" &&
        layout.compression != "lz4") {
      Fail(record.offset, "a chunk compressed with '" + MessageExcerpt(layout.compression) +
                              "' (rosbag_storage reads none, bz2 and lz4)");
    }
    // An LZ4 match of n bytes costs at least one byte per 255 of its length, so no LZ4 data
    // expands more than 255-fold: a larger declared size is a lie that would cost its memory.
    if (layout.compression == "lz4" &&
        layout.size > uint64_t{kMaxLz4Expansion} * layout.data_size + kLz4FrameSlackBytes) {
      Fail(record.offset, "an LZ4 chunk of " + std::to_string(layout.data_size) +
                              " bytes declares " + std::to_string(layout.size) +
                              " uncompressed, more than LZ4 expands to");
    }
    if (layout.size > kMaxChunkBytes) {
      Fail(record.offset, "a chunk of " + std::to_string(layout.size) + " bytes, more than the " +
                              std::to_string(kMaxChunkBytes) + " evfs reads");
    }
    for (uint32_t i = 1; i <= count; ++i) {
      const Record& index = records[chunk + i];
      if (index.op != kOpIndexData) Fail(index.offset, "expected index data after a chunk");
      if (FieldU32(index, "ver") != 1) Fail(index.offset, "index data of a version other than 1");
      const uint32_t connection = FieldU32(index, "conn");
      CheckConnection(connections, connection, index.offset);
      const uint32_t entries = FieldU32(index, "count");
      if (index.data_end - index.data_begin != static_cast<uint64_t>(entries) * kIndexEntryBytes) {
        Fail(index.offset,
             "index data whose size does not hold its " + std::to_string(entries) + " entries");
      }
      for (uint32_t k = 0; k < entries; ++k) {
        const uint8_t* entry = data_ + index.data_begin + k * kIndexEntryBytes;
        const uint32_t sec = ReadU32(entry), nsec = ReadU32(entry + 4);
        if (nsec >= kNanosecondsPerSecond) {
          Fail(index.offset, "index entry " + std::to_string(k) + ": a time with nsec >= 1e9");
        }
        const uint32_t offset = ReadU32(entry + 8);
        if (offset >= layout.size) {
          Fail(index.offset, "index entry " + std::to_string(k) + " points at chunk byte " +
                                 std::to_string(offset) + ", past the chunk's end");
        }
        layout.entries.push_back(
            {connection, uint64_t{sec} * kNanosecondsPerSecond + nsec, offset});
      }
    }
    return layout;
  }

  const std::string& path_;
  const uint8_t* data_;
  size_t size_;
  std::string context_;
  const ReleaseBytes* release_;  // may be null
};

// Reads a serialised message field by field, failing on a short message.
class MessageReader {
 public:
  MessageReader(const uint8_t* data, size_t size, const std::string& where)
      : data_(data), size_(size), where_(where) {}

  const uint8_t* Take(size_t bytes) {
    if (size_ - at_ < bytes) Fail("the message ends inside a field (truncated?)");
    const uint8_t* p = data_ + at_;
    at_ += bytes;
    return p;
  }
  uint8_t U8() { return *Take(1); }
  uint32_t U32() { return ReadU32(Take(4)); }
  int64_t Time() {
    const uint32_t sec = U32();
    const uint32_t nsec = U32();
    if (nsec >= kNanosecondsPerSecond) Fail("a time with " + std::to_string(nsec) + " ns");
    return int64_t{sec} * kNanosecondsPerSecond + nsec;
  }
  std::string String() {
    const uint32_t length = U32();
    const uint8_t* p = Take(length);
    return std::string(reinterpret_cast<const char*>(p), length);
  }
  // std_msgs/Header: the stamp.
  int64_t Header() {
    U32();  // seq
    const int64_t stamp_ns = Time();
    Take(U32());  // frame_id
    return stamp_ns;
  }
  void ExpectEnd() {
    if (at_ != size_) Fail(std::to_string(size_ - at_) + " bytes after the message's last field");
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw InputError(InputError::Kind::kMalformed, where_, 0, what);
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
  const std::string& where_;
};

}  // namespace

BagLayout CheckBagStructure(const std::string& path, const uint8_t* data, size_t size,
                            const ReleaseBytes& release) {
  return BagChecker(path, data, size, "", release ? &release : nullptr).Check();
}

void CheckChunkRecords(const std::string& path, const BagChunk& chunk, const uint8_t* data,
                       size_t size) {
  BagChecker(path, data, size,
             "the chunk at byte " + std::to_string(chunk.offset) + ", uncompressed, ")
      .CheckChunkRecords(chunk);
}

ChunkBytes DecompressChunk(const std::string& path, const BagChunk& chunk, const uint8_t* file) {
  ChunkBytes out;
  // Not value-initialised: a declared size the data does not fill stays unmapped.
  out.data.reset(new uint8_t[chunk.size]);
  char* input = const_cast<char*>(reinterpret_cast<const char*>(file + chunk.data_begin));
  unsigned int length = chunk.size;
  char* output = reinterpret_cast<char*>(out.data.get());
  const bool ok =
      chunk.compression == "bz2"
          ? BZ2_bzBuffToBuffDecompress(output, &length, input,
                                       static_cast<unsigned int>(chunk.data_size), 0, 0) == BZ_OK
          : roslz4_buffToBuffDecompress(input, static_cast<unsigned int>(chunk.data_size), output,
                                        &length) == ROSLZ4_OK;
  if (!ok) {
    throw InputError(InputError::Kind::kMalformed, path, 0,
                     "byte " + std::to_string(chunk.offset) + ": a " + chunk.compression +
                         " chunk that does not decompress (corrupt?)");
  }
  out.size = length;
  return out;
}

int64_t EventArray::t_ns(uint32_t index) const {
  const uint8_t* event = events + size_t{index} * kEventBytes;
  return int64_t{ReadU32(event + 4)} * kNanosecondsPerSecond + ReadU32(event + 8);
}

int EventArray::x(uint32_t index) const {
  const uint8_t* event = events + size_t{index} * kEventBytes;
  return event[0] | event[1] << 8;
}

int EventArray::y(uint32_t index) const {
  const uint8_t* event = events + size_t{index} * kEventBytes;
  return event[2] | event[3] << 8;
}

int EventArray::polarity(uint32_t index) const {
  return events[size_t{index} * kEventBytes + 12] != 0 ? 1 : -1;
}

EventArray DecodeEventArray(const uint8_t* data, size_t size, const std::string& where) {
  MessageReader reader(data, size, where);
  EventArray array;
  array.stamp_ns = reader.Header();
  array.height = reader.U32();
  array.width = reader.U32();
  array.count = reader.U32();
  if ((size / EventArray::kEventBytes) < array.count) {
    reader.Fail("an array of " + std::to_string(array.count) + " events in a " +
                std::to_string(size) + "-byte message (truncated?)");
  }
  array.events = reader.Take(size_t{array.count} * EventArray::kEventBytes);
  reader.ExpectEnd();
  for (uint32_t i = 0; i < array.count; ++i) {
    if (ReadU32(array.events + size_t{i} * EventArray::kEventBytes + 8) >= kNanosecondsPerSecond) {
      reader.Fail("event " + std::to_string(i) + ": a time with nsec >= 1e9");
    }
  }
  return array;
}

ImageMessage DecodeImage(const uint8_t* data, size_t size, const std::string& where) {
  MessageReader reader(data, size, where);
  ImageMessage image;
  image.stamp_ns = reader.Header();
  image.height = reader.U32();
  image.width = reader.U32();
  image.encoding = reader.String();
  image.is_bigendian = reader.U8() != 0;
  image.step = reader.U32();
  image.pixel_bytes = reader.U32();
  image.pixels = reader.Take(image.pixel_bytes);
  reader.ExpectEnd();
  return image;
}

Image ImageToGrey(const ImageMessage& image, const std::string& where) {
  struct Encoding {
    const char* name;
    int channels;
    int bytes_per_channel;
    int to_grey;  // cv::COLOR_... or -1 for grey already
  };
  static const Encoding kEncodings[] = {
      {"mono8", 1, 1, -1},
      {"mono16", 1, 2, -1},
      {"rgb8", 3, 1, cv::COLOR_RGB2GRAY},
      {"bgr8", 3, 1, cv::COLOR_BGR2GRAY},
      {"rgba8", 4, 1, cv::COLOR_RGBA2GRAY},
      {"bgra8", 4, 1, cv::COLOR_BGRA2GRAY},
  };
  const Encoding* encoding = nullptr;
  for (const Encoding& candidate : kEncodings) {
    if (image.encoding == candidate.name) encoding = &candidate;
  }
  if (encoding == nullptr) {
    throw InputError(InputError::Kind::kMalformed, where, 0,
                     "image encoding '" + MessageExcerpt(image.encoding) +
                         "' (evfs reads mono8, mono16, rgb8, bgr8, rgba8 and bgra8)");
  }
  const uint64_t row_bytes =
      uint64_t{image.width} * encoding->channels * encoding->bytes_per_channel;
  if (image.width == 0 || image.height == 0 || image.width > 65535 || image.height > 65535 ||
      image.step < row_bytes ||
      image.pixel_bytes < uint64_t{image.step} * (image.height - 1) + row_bytes) {
    throw InputError(InputError::Kind::kMalformed, where, 0,
                     "a " + std::to_string(image.width) + "x" + std::to_string(image.height) + " " +
                         MessageExcerpt(image.encoding) + " image with step " +
                         std::to_string(image.step) + " and " + std::to_string(image.pixel_bytes) +
                         " bytes of data, which do not fit");
  }
  const int rows = static_cast<int>(image.height);
  const int cols = static_cast<int>(image.width);
  Image grey(rows, cols);
  if (encoding->bytes_per_channel == 2) {
    for (int row = 0; row < rows; ++row) {
      const uint8_t* p = image.pixels + size_t{image.step} * row;
      for (int col = 0; col < cols; ++col) {
        const int high = image.is_bigendian ? p[2 * col] : p[2 * col + 1];
        const int low = image.is_bigendian ? p[2 * col + 1] : p[2 * col];
        grey(row, col) = (high << 8 | low) / 65535.0;
      }
    }
    return grey;
  }
  const cv::Mat pixels(rows, cols, CV_8UC(encoding->channels), const_cast<uint8_t*>(image.pixels),
                       image.step);
  cv::Mat grey8 = pixels;
  if (encoding->to_grey >= 0) cv::cvtColor(pixels, grey8, encoding->to_grey);
  for (int row = 0; row < rows; ++row) {
    const uint8_t* p = grey8.ptr<uint8_t>(row);
    for (int col = 0; col < cols; ++col) grey(row, col) = p[col] / 255.0;
  }
  return grey;
}

}  // namespace rosbag_format
}  // namespace evfs
