// Writing AEDAT 4.0 files: WriteAedat4 (io/aedat4.h).
#include <lz4frame.h>
#include <lz4hc.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <new>
#include <stdexcept>
#include <utility>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/io/aedat4.h"
#include "evfs/io/aedat4/events_generated.h"
#include "evfs/io/aedat4/file_data_table_generated.h"
#include "evfs/io/aedat4/format.h"
#include "evfs/io/aedat4/frame_generated.h"
#include "evfs/io/aedat4/header.h"
#include "evfs/io/image_io.h"

namespace evfs {
namespace {

namespace fb = aedat4::fb;
using aedat4::kEventBytes;
using aedat4::kEventsStreamId;
using aedat4::kFramesStreamId;
using aedat4::kMaxPacketBytes;
using aedat4::kMaxSensorSide;
using aedat4::kNanosecondsPerMicrosecond;
using aedat4::kPacketHeaderBytes;
using aedat4::kVersionLine;
using aedat4::kVersionLineBytes;

// Bytes a frame's flatbuffer takes besides its pixels (its fields and the size prefix) are
// fewer: the writer keeps whole frames within kMaxPacketBytes.
constexpr size_t kMaxFrameOverheadBytes = 4096;

// Nearest microsecond (halves away from -infinity), without overflow.
int64_t RoundToMicroseconds(int64_t t_ns) {
  int64_t quotient = t_ns / kNanosecondsPerMicrosecond;
  int64_t remainder = t_ns % kNanosecondsPerMicrosecond;
  if (remainder < 0) {
    --quotient;
    remainder += kNanosecondsPerMicrosecond;
  }
  return remainder >= kNanosecondsPerMicrosecond / 2 ? quotient + 1 : quotient;
}

class Aedat4Writer {
 public:
  Aedat4Writer(const std::string& path, Aedat4Compression compression)
      : path_(path), compression_(compression) {
    file_ = std::fopen(path.c_str(), "wb");
    if (file_ == nullptr) Fail("cannot create the file");
  }
  ~Aedat4Writer() {
    if (file_ != nullptr) std::fclose(file_);
    if (zstd_ != nullptr) ZSTD_freeCCtx(zstd_);
  }
  Aedat4Writer(const Aedat4Writer&) = delete;
  Aedat4Writer& operator=(const Aedat4Writer&) = delete;

  [[noreturn]] void Fail(const std::string& what) const {
    throw InputError(InputError::Kind::kUnwritable, path_, 0, what);
  }

  void Write(const void* data, size_t size) {
    if (size > 0 && std::fwrite(data, 1, size, file_) != size) Fail("cannot write (disk full?)");
    position_ += size;
  }

  // The version line and the IOHeader; WriteHeader again at the end, with the table's position
  // (the header keeps its size: every field is written, defaults too).
  void WriteHeader(const std::string& stream_description, int64_t data_table_position) {
    const std::vector<uint8_t> header =
        aedat4::IOHeaderBytes(compression_, data_table_position, stream_description);
    if (position_ == 0) {
      Write(kVersionLine, kVersionLineBytes);
      Write(header.data(), header.size());
      header_bytes_ = header.size();
      return;
    }
    if (header.size() != header_bytes_) {
      throw std::logic_error("AEDAT 4 header changed its size");  // a bug, not the user's
    }
    if (std::fseek(file_, static_cast<long>(kVersionLineBytes), SEEK_SET) != 0) {
      Fail("cannot write the header");
    }
    if (std::fwrite(header.data(), 1, header.size(), file_) != header.size()) {
      Fail("cannot write the header (disk full?)");
    }
  }

  // Compresses the flatbuffer in `builder` and writes it as a packet of `stream_id`, recording
  // it in the data table.
  void WritePacket(int32_t stream_id, const flatbuffers::FlatBufferBuilder& builder, int64_t count,
                   int64_t t_first_us, int64_t t_last_us) {
    const std::vector<uint8_t> body = Compress(builder.GetBufferPointer(), builder.GetSize());
    if (body.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
      throw InvalidArgumentError("AEDAT 4: a packet of " + std::to_string(body.size()) +
                                 " bytes does not fit the format's int32 size");
    }
    const int32_t size = static_cast<int32_t>(body.size());
    const uint8_t packet_header[kPacketHeaderBytes] = {static_cast<uint8_t>(stream_id),
                                                       static_cast<uint8_t>(stream_id >> 8),
                                                       static_cast<uint8_t>(stream_id >> 16),
                                                       static_cast<uint8_t>(stream_id >> 24),
                                                       static_cast<uint8_t>(size),
                                                       static_cast<uint8_t>(size >> 8),
                                                       static_cast<uint8_t>(size >> 16),
                                                       static_cast<uint8_t>(size >> 24)};
    Write(packet_header, sizeof(packet_header));
    table_.push_back({static_cast<int64_t>(position_), fb::PacketHeader(stream_id, size), count,
                      t_first_us, t_last_us});
    Write(body.data(), body.size());
  }

  // Writes the data table; returns its position.
  int64_t WriteDataTable() {
    flatbuffers::FlatBufferBuilder builder(table_.size() * 64 + 64);
    std::vector<flatbuffers::Offset<fb::FileDataDefinition>> entries;
    entries.reserve(table_.size());
    for (const Entry& entry : table_) {
      entries.push_back(fb::CreateFileDataDefinition(builder, entry.byte_offset, &entry.header,
                                                     entry.count, entry.t_first_us,
                                                     entry.t_last_us));
    }
    fb::FinishSizePrefixedFileDataTableBuffer(
        builder, fb::CreateFileDataTable(builder, builder.CreateVector(entries)));
    const int64_t position = static_cast<int64_t>(position_);
    const std::vector<uint8_t> body = Compress(builder.GetBufferPointer(), builder.GetSize());
    Write(body.data(), body.size());
    return position;
  }

  void Close() {
    const int status = std::fclose(file_);
    file_ = nullptr;
    if (status != 0) Fail("cannot write (disk full?)");
  }

 private:
  struct Entry {
    int64_t byte_offset;
    fb::PacketHeader header;
    int64_t count;
    int64_t t_first_us;
    int64_t t_last_us;
  };

  std::vector<uint8_t> Compress(const uint8_t* data, size_t size) {
    std::vector<uint8_t> out;
    switch (compression_) {
      case Aedat4Compression::kNone:
        out.assign(data, data + size);
        break;
      case Aedat4Compression::kLz4:
      case Aedat4Compression::kLz4High: {
        LZ4F_preferences_t preferences;
        std::memset(&preferences, 0, sizeof(preferences));
        preferences.frameInfo.contentSize = size;
        // A checksum per packet, so that a reader sees a corrupt byte instead of a wrong event.
        preferences.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
        preferences.compressionLevel =
            compression_ == Aedat4Compression::kLz4High ? LZ4HC_CLEVEL_DEFAULT : 0;
        out.resize(LZ4F_compressFrameBound(size, &preferences));
        const size_t written = LZ4F_compressFrame(out.data(), out.size(), data, size, &preferences);
        if (LZ4F_isError(written)) {
          throw std::runtime_error(std::string("LZ4 compression failed: ") +
                                   LZ4F_getErrorName(written));
        }
        out.resize(written);
        break;
      }
      case Aedat4Compression::kZstd:
      case Aedat4Compression::kZstdHigh: {
        // Level 19 for "high": DV's choice is not documented; 19 is zstd's highest ordinary one.
        constexpr int kZstdHighLevel = 19;
        if (zstd_ == nullptr) {
          zstd_ = ZSTD_createCCtx();
          if (zstd_ == nullptr) throw std::bad_alloc();
          ZSTD_CCtx_setParameter(
              zstd_, ZSTD_c_compressionLevel,
              compression_ == Aedat4Compression::kZstdHigh ? kZstdHighLevel : ZSTD_CLEVEL_DEFAULT);
          ZSTD_CCtx_setParameter(zstd_, ZSTD_c_checksumFlag, 1);  // as for LZ4 above
        }
        out.resize(ZSTD_compressBound(size));
        const size_t written = ZSTD_compress2(zstd_, out.data(), out.size(), data, size);
        if (ZSTD_isError(written)) {
          throw std::runtime_error(std::string("Zstd compression failed: ") +
                                   ZSTD_getErrorName(written));
        }
        out.resize(written);
        break;
      }
    }
    return out;
  }

  std::string path_;
  Aedat4Compression compression_;
  std::FILE* file_ = nullptr;
  size_t position_ = 0;
  size_t header_bytes_ = 0;
  std::vector<Entry> table_;
  ZSTD_CCtx* zstd_ = nullptr;  // made on the first Zstd packet
};

}  // namespace

bool Aedat4WriteOptions::IsValid(std::string* error) const {
  constexpr int kMaxEventsPerPacket = 1 << 20;  // 16 MB decompressed, within kMaxPacketBytes
  OptionChecker check;
  check.Require(max_events_per_packet >= 1 && max_events_per_packet <= kMaxEventsPerPacket,
                "max_events_per_packet", "in [1, " + std::to_string(kMaxEventsPerPacket) + "]");
  return check.Passed(error);
}

void WriteAedat4(const std::string& path, const EventStream& events,
                 const std::vector<FrameInfo>& frames, const std::vector<Image>& images,
                 const Aedat4WriteOptions& options) {
  std::string problem;
  if (!options.IsValid(&problem)) throw InvalidArgumentError("WriteAedat4: " + problem);
  if (frames.size() != images.size()) {
    throw InvalidArgumentError("WriteAedat4: " + std::to_string(frames.size()) + " frames but " +
                               std::to_string(images.size()) + " images");
  }
  if (!options.with_events && !events.empty()) {
    throw InvalidArgumentError("WriteAedat4: a file without an event stream cannot hold " +
                               std::to_string(events.size()) + " events");
  }
  int width = events.width();
  int height = events.height();
  if ((width <= 0 || height <= 0) && !images.empty()) {
    width = static_cast<int>(images.front().cols());
    height = static_cast<int>(images.front().rows());
  }
  if (width < 1 || height < 1 || width > kMaxSensorSide || height > kMaxSensorSide) {
    throw InvalidArgumentError("AEDAT 4: the sensor is " + std::to_string(width) + "x" +
                               std::to_string(height) + ", the format takes sides of 1 to " +
                               std::to_string(kMaxSensorSide) + " pixels");
  }
  for (size_t i = 0; i < events.size(); ++i) {
    if (events.x(i) >= width || events.y(i) >= height) {
      throw InvalidArgumentError("AEDAT 4: event " + std::to_string(i) + " at (" +
                                 std::to_string(events.x(i)) + ", " + std::to_string(events.y(i)) +
                                 ") is outside the " + std::to_string(width) + "x" +
                                 std::to_string(height) + " sensor");
    }
  }
  // Frames: 8-bit pixels of the sensor's size, times distinct in microseconds.
  std::vector<int64_t> frame_t_us(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const std::string name = "frame " + std::to_string(i) + " (" + frames[i].path + ")";
    if (images[i].cols() != width || images[i].rows() != height) {
      throw InvalidArgumentError("AEDAT 4: " + name + " is " + std::to_string(images[i].cols()) +
                                 "x" + std::to_string(images[i].rows()) + ", the sensor " +
                                 std::to_string(width) + "x" + std::to_string(height));
    }
    if (static_cast<size_t>(width) * height > kMaxPacketBytes - kMaxFrameOverheadBytes) {
      throw InvalidArgumentError("AEDAT 4: " + name + " is too large for one packet");
    }
    if (MinimalBitDepth(images[i]) != 8) {
      throw InvalidArgumentError("AEDAT 4 frames hold 8-bit pixels, " + name +
                                 " has finer values (write .h5 or a data folder instead)");
    }
    frame_t_us[i] = RoundToMicroseconds(frames[i].t_ns);
    if (i > 0 && frame_t_us[i] <= frame_t_us[i - 1]) {
      throw InvalidArgumentError("AEDAT 4 keeps microseconds: " + name +
                                 " is not 1 us after the frame before");
    }
    if (frames[i].has_exposure && RoundToMicroseconds(frames[i].exposure_end_ns) <=
                                      RoundToMicroseconds(frames[i].exposure_begin_ns)) {
      throw InvalidArgumentError("AEDAT 4 keeps microseconds: the exposure of " + name +
                                 " is shorter than 1 us");
    }
  }

  Aedat4Writer writer(path, options.compression);
  const std::string description = aedat4::StreamDescription(
      width, height, options.with_events, !frames.empty(), options.compression, frames);
  writer.WriteHeader(description, /*data_table_position=*/-1);

  const size_t chunk = static_cast<size_t>(options.max_events_per_packet);
  size_t next_event = 0;
  size_t next_frame = 0;
  std::vector<fb::Event> packet_events;
  packet_events.reserve(std::min(chunk, events.size()));
  // Packets in time order across the two streams, as DV records them.
  while (next_event < events.size() || next_frame < frames.size()) {
    const bool frame_next =
        next_frame < frames.size() &&
        (next_event == events.size() ||
         frame_t_us[next_frame] <= RoundToMicroseconds(events.t_ns(next_event)));
    if (frame_next) {
      const FrameInfo& frame = frames[next_frame];
      const Image& image = images[next_frame];
      std::vector<uint8_t> pixels(static_cast<size_t>(image.size()));
      for (Eigen::Index k = 0; k < image.size(); ++k) {
        pixels[static_cast<size_t>(k)] = static_cast<uint8_t>(std::lround(image.data()[k] * 255.0));
      }
      const int64_t t_us = frame_t_us[next_frame];
      const int64_t begin_us =
          frame.has_exposure ? RoundToMicroseconds(frame.exposure_begin_ns) : t_us;
      const int64_t end_us = frame.has_exposure ? RoundToMicroseconds(frame.exposure_end_ns) : t_us;
      flatbuffers::FlatBufferBuilder builder(pixels.size() + 256);
      const auto pixel_vector = builder.CreateVector(pixels);
      const auto root = fb::CreateFrame(builder, t_us, begin_us, end_us, begin_us, end_us,
                                        fb::FrameFormat::Gray, static_cast<int16_t>(width),
                                        static_cast<int16_t>(height), 0, 0, pixel_vector);
      fb::FinishSizePrefixedFrameBuffer(builder, root);
      writer.WritePacket(kFramesStreamId, builder, 1, t_us, t_us);
      ++next_frame;
      continue;
    }
    const size_t end = std::min(events.size(), next_event + chunk);
    packet_events.clear();
    for (size_t i = next_event; i < end; ++i) {
      packet_events.emplace_back(RoundToMicroseconds(events.t_ns(i)),
                                 static_cast<int16_t>(events.x(i)),
                                 static_cast<int16_t>(events.y(i)), events.polarity(i) > 0);
    }
    flatbuffers::FlatBufferBuilder builder(packet_events.size() * kEventBytes + 256);
    const auto root = fb::CreateEventPacket(builder, builder.CreateVectorOfStructs(packet_events));
    fb::FinishSizePrefixedEventPacketBuffer(builder, root);
    writer.WritePacket(kEventsStreamId, builder, static_cast<int64_t>(packet_events.size()),
                       packet_events.front().timestamp(), packet_events.back().timestamp());
    next_event = end;
  }
  const int64_t table_position = writer.WriteDataTable();
  writer.WriteHeader(description, table_position);
  writer.Close();
}

}  // namespace evfs
