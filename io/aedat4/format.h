// The layout of AEDAT 4.0 files that the reader and the writer share (io/aedat4.h describes the
// format): sizes and limits, stream types, and the verification of size-prefixed flatbuffers.
#ifndef EVFS_IO_AEDAT4_FORMAT_H_
#define EVFS_IO_AEDAT4_FORMAT_H_

#include <flatbuffers/flatbuffers.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

namespace evfs {
namespace aedat4 {

inline constexpr char kVersionLine[] = "#!AER-DAT4.0\r\n";
inline constexpr size_t kVersionLineBytes = sizeof(kVersionLine) - 1;
// Every AEDAT version starts so (AEDAT 2.0 "#!AER-DAT2.0\r\n", 3.1 "#!AER-DAT3.1\r\n").
inline constexpr char kAedatPrefix[] = "#!AER-DAT";
inline constexpr size_t kAedatPrefixBytes = sizeof(kAedatPrefix) - 1;
inline constexpr size_t kSizePrefixBytes = 4;
// int32 stream id, int32 body size.
inline constexpr size_t kPacketHeaderBytes = 8;
// The smallest flatbuffer: a root offset and a table's vtable offset.
inline constexpr size_t kMinFlatbufferBytes = 8;
// The largest alignment of a field in the AEDAT 4 schemas (int64, and the Event struct).
inline constexpr size_t kFlatbufferAlignment = 8;
// Most bytes a packet body (or the data table) may decompress to: 16 M events, or a 8192x8192
// BGRA frame. DV writes packets of a few milliseconds (~100 KB), so a larger claim is a corrupt
// file or a decompression bomb; refusing it bounds what one packet can make evfs allocate.
inline constexpr size_t kMaxPacketBytes = size_t{256} << 20;
// Sensor sides: positions and frame sizes are int16 in the format.
inline constexpr int kMaxSensorSide = 32767;
// |t| in microseconds below this converts to int64 nanoseconds without overflow.
inline constexpr int64_t kMaxMicroseconds = std::numeric_limits<int64_t>::max() / 1000;
inline constexpr int64_t kNanosecondsPerMicrosecond = 1000;
// Bytes of one event in an EventPacket (fb::Event).
inline constexpr size_t kEventBytes = 16;
inline constexpr char kEventsType[] = "EVTS";
inline constexpr char kFramesType[] = "FRME";
// The writer's stream ids.
inline constexpr int32_t kEventsStreamId = 0;
inline constexpr int32_t kFramesStreamId = 1;

inline uint32_t ReadU32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 |
         static_cast<uint32_t>(p[2]) << 16 | static_cast<uint32_t>(p[3]) << 24;
}

inline int32_t ReadI32(const uint8_t* p) {
  const uint32_t value = ReadU32(p);
  int32_t result;
  std::memcpy(&result, &value, sizeof(result));
  return result;
}

inline bool StartsWith(const uint8_t* data, size_t size, const char* prefix, size_t prefix_bytes) {
  return size >= prefix_bytes && std::memcmp(data, prefix, prefix_bytes) == 0;
}

// Verifier limits for a buffer of `bytes`: every table takes at least 4 bytes, so the table
// count never limits a valid buffer (the data table holds one table per packet).
inline flatbuffers::Verifier::Options VerifierOptions(size_t bytes) {
  flatbuffers::Verifier::Options options;
  options.max_tables = static_cast<flatbuffers::uoffset_t>(bytes / 4 + 1);
  return options;
}

// Verifies the size-prefixed flatbuffer in *buffer, whose prefix the caller has checked against
// its length, as a `Table` with file identifier `identifier`; returns its root, or nullptr when
// it is not one. *buffer must start at an address aligned for kFlatbufferAlignment (a vector's
// allocation is).
//
// A flatbuffer builder writes from the end backwards and aligns every field relative to the end,
// padding the front so that the finished buffer is a whole number of its largest alignment. DV
// counts the size prefix in that whole (FlatBufferBuilder::FinishSizePrefixed); other writers
// finish the flatbuffer alone and then put its size in front, so that their fields lie 4 bytes
// off DV's relative to the prefix. The verifier checks alignment from the first byte it is given
// (and flatbuffers reads fields in place), so it is given bytes that span a whole number of
// kFlatbufferAlignment from an aligned address: the prefix and the flatbuffer when they do (DV's
// layout), else the flatbuffer alone, moved to the start of *buffer. Bytes no builder wrote (a
// length not a multiple of 4) are verified as DV's layout and refused where a field is
// misaligned.
template <typename Table>
const Table* VerifiedSizePrefixedRoot(std::vector<uint8_t>* buffer, const char* identifier) {
  if ((buffer->size() - kSizePrefixBytes) % kFlatbufferAlignment == 0) {
    buffer->erase(buffer->begin(), buffer->begin() + kSizePrefixBytes);
    flatbuffers::Verifier verifier(buffer->data(), buffer->size(), VerifierOptions(buffer->size()));
    return verifier.VerifyBuffer<Table>(identifier) ? flatbuffers::GetRoot<Table>(buffer->data())
                                                    : nullptr;
  }
  flatbuffers::Verifier verifier(buffer->data(), buffer->size(), VerifierOptions(buffer->size()));
  return verifier.VerifySizePrefixedBuffer<Table>(identifier)
             ? flatbuffers::GetSizePrefixedRoot<Table>(buffer->data())
             : nullptr;
}

}  // namespace aedat4
}  // namespace evfs

#endif  // EVFS_IO_AEDAT4_FORMAT_H_
