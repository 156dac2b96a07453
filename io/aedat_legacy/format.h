// The byte layouts of AEDAT 2.0 (jAER) and AEDAT 3.1 (cAER), as iniVation documents them
// ("AEDAT file formats") and jAER's DavisBaseCamera and libcaer's polarity.h/frame.h read them.
//
// AEDAT 2.0 record, 8 bytes big-endian: uint32 address, int32 timestamp (us). DAVIS address:
//   bit 31       1: an APS (or IMU) sample, 0: a DVS event
//   bits 22..30  y, counted from the bottom row (jAER's origin is the lower left)
//   bits 12..21  x, counted from the right column
//   bit 11       DVS: polarity (1 ON); APS: readout type high bit
//   bit 10       DVS: a special (external input) event; APS: readout type low bit
//   bits 0..9    APS: the 10-bit ADC value
// APS readout type (bits 10..11): 0 reset read, 1 signal read, 2 CP reset read (DAVIS240A/B),
// 3 an IMU sample.
//
// AEDAT 3.1 packet header, 28 bytes little-endian: int16 eventType, int16 eventSource,
// int32 eventSize, int32 eventTSOffset, int32 eventTSOverflow, int32 eventCapacity,
// int32 eventNumber, int32 eventValid; then eventCapacity * eventSize bytes of events, of which
// the first eventNumber are filled. A time is (eventTSOverflow << 31) | the event's int32 time.
//   Polarity event (type 1, 8 bytes): uint32 data (bit 0 valid, bit 1 polarity, bits 2..16 y,
//     bits 17..31 x; origin top left), int32 timestamp.
//   Frame event (type 2): uint32 info (bit 0 valid, bits 1..3 colour channels, bits 4..7 colour
//     filter, bits 8..14 ROI region), int32 ts start of frame, end of frame, start of exposure,
//     end of exposure, int32 lengthX, lengthY, positionX, positionY, then lengthX * lengthY *
//     channels uint16 pixels, row by row from the top, the ADC value left-aligned in 16 bits.
#ifndef EVFS_IO_AEDAT_LEGACY_FORMAT_H_
#define EVFS_IO_AEDAT_LEGACY_FORMAT_H_

#include <cstddef>
#include <cstdint>

namespace evfs {
namespace aedat_legacy {

inline constexpr char kVersion2Line[] = "#!AER-DAT2.0";
inline constexpr char kVersion3Line[] = "#!AER-DAT3.1";
inline constexpr char kEndOfHeader3[] = "#!END-HEADER\r\n";

// AEDAT 2.0.
inline constexpr size_t kRecordBytes = 8;
inline constexpr uint32_t kApsFlag = 1u << 31;
inline constexpr int kYShift = 22;
inline constexpr uint32_t kYMask = 0x1ff;
inline constexpr int kXShift = 12;
inline constexpr uint32_t kXMask = 0x3ff;
inline constexpr int kPolarityShift = 11;
inline constexpr uint32_t kSpecialEventFlag = 1u << 10;
inline constexpr int kReadoutShift = 10;
inline constexpr uint32_t kReadoutMask = 0x3;
inline constexpr uint32_t kAdcMask = 0x3ff;
inline constexpr double kAdcMax = 1023.0;
enum ApsReadout : uint32_t { kResetRead = 0, kSignalRead = 1, kCpResetRead = 2, kImuSample = 3 };

inline uint32_t ReadBigEndianU32(const uint8_t* p) {
  return (static_cast<uint32_t>(p[0]) << 24) | (static_cast<uint32_t>(p[1]) << 16) |
         (static_cast<uint32_t>(p[2]) << 8) | static_cast<uint32_t>(p[3]);
}

inline int32_t ReadBigEndianI32(const uint8_t* p) {
  return static_cast<int32_t>(ReadBigEndianU32(p));
}

// AEDAT 3.1.
inline constexpr size_t kPacketHeaderBytes = 28;
inline constexpr int16_t kPolarityEventType = 1;
inline constexpr int16_t kFrameEventType = 2;
inline constexpr size_t kPolarityEventBytes = 8;
inline constexpr size_t kFrameHeaderBytes = 36;
inline constexpr int kTimestampOverflowShift = 31;

inline uint32_t ReadLittleEndianU32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | (static_cast<uint32_t>(p[1]) << 8) |
         (static_cast<uint32_t>(p[2]) << 16) | (static_cast<uint32_t>(p[3]) << 24);
}

inline int32_t ReadLittleEndianI32(const uint8_t* p) {
  return static_cast<int32_t>(ReadLittleEndianU32(p));
}

inline int16_t ReadLittleEndianI16(const uint8_t* p) {
  return static_cast<int16_t>(static_cast<uint16_t>(p[0]) | (static_cast<uint16_t>(p[1]) << 8));
}

}  // namespace aedat_legacy
}  // namespace evfs

#endif  // EVFS_IO_AEDAT_LEGACY_FORMAT_H_
