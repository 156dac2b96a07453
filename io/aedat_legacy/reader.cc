// Reading AEDAT 2.0 and 3.1 files: AedatLegacyDataSource (io/aedat_legacy.h).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/aedat_legacy.h"
#include "evfs/io/aedat_legacy/format.h"
#include "evfs/io/aedat_legacy/header.h"
#include "evfs/io/mapped_file.h"
#include "evfs/io/visited_events.h"

namespace evfs {
namespace aedat_legacy {
namespace {

constexpr int64_t kNanosecondsPerMicrosecond = 1000;
constexpr int64_t kMaxMicroseconds = std::numeric_limits<int64_t>::max() / 1000;

// The DAVIS sensors an AEDAT 2.0 file without a chip line may come from, smallest first: v2e
// writes no chip line, and its DAVIS240 and DAVIS346 outputs share the address layout, so the
// largest address decides.
struct SensorSize {
  int width;
  int height;
};
constexpr SensorSize kUnnamedDavisSensors[] = {{240, 180}, {346, 260}};

std::string DefaultFramePath(size_t index) {
  char name[40];
  std::snprintf(name, sizeof(name), "images/frame_%08zu.png", index);
  return name;
}

}  // namespace
}  // namespace aedat_legacy

namespace al = aedat_legacy;

bool StartsWithAedatLegacyVersionLine(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;
  std::ifstream stream(path, std::ios::binary);
  char start[sizeof(al::kVersion2Line) - 1] = {};
  stream.read(start, sizeof(start));
  return stream.gcount() == static_cast<std::streamsize>(sizeof(start)) &&
         (std::memcmp(start, al::kVersion2Line, sizeof(start)) == 0 ||
          std::memcmp(start, al::kVersion3Line, sizeof(start)) == 0);
}

class AedatLegacyDataSource::File {
 public:
  explicit File(MappedFile file)
      : file_(std::move(file)),
        data_(reinterpret_cast<const uint8_t*>(file_.data())),
        size_(file_.size()) {
    header_ = al::ParseHeader(path(), data_, size_);
    width_ = header_.width;
    height_ = header_.height;
    if (width_ > 0) size_source_ = "the header: chip " + header_.chip;
    if (header_.major_version == 2) {
      IndexVersion2();
    } else {
      IndexVersion3();
    }
  }

  const std::string& path() const { return file_.path(); }
  int width() const { return width_; }
  int height() const { return height_; }
  int major_version() const { return header_.major_version; }
  const std::string& size_source() const { return size_source_; }
  std::vector<FrameInfo>& frames() { return frames_; }
  const std::string& no_frames_reason() const { return no_frames_reason_; }
  int64_t units_decoded() const { return units_decoded_; }

  [[noreturn]] void Fail(InputError::Kind kind, const std::string& what) const {
    throw InputError(kind, path(), 0, what);
  }

  // Calls visit(t_ns, x, y, polarity) for every event with t_begin_ns <= t < t_end_ns.
  template <typename Visitor>
  void ForEachEvent(int64_t t_begin_ns, int64_t t_end_ns, Visitor&& visit) const {
    if (t_end_ns <= t_begin_ns) return;
    if (header_.major_version == 2) {
      ForEachEventVersion2(t_begin_ns, t_end_ns, visit);
    } else {
      ForEachEventVersion3(t_begin_ns, t_end_ns, visit);
    }
  }

  Image ReadImage(int index) const {
    return header_.major_version == 2 ? ReadApsFrame(aps_frames_[static_cast<size_t>(index)])
                                      : ReadFrameEvent(frame_events_[static_cast<size_t>(index)]);
  }

 private:
  // ---- AEDAT 2.0 ----

  // The records of one APS frame: every pixel's reset read, then every pixel's signal read.
  struct ApsFrame {
    size_t first_record = 0;
    size_t last_record = 0;  // inclusive
    int64_t resets = 0;
    int64_t signals = 0;
    int32_t last_reset_us = 0;
    int32_t first_signal_us = 0;
  };

  const uint8_t* Record(size_t index) const {
    return data_ + header_.data_start + index * al::kRecordBytes;
  }
  uint32_t Address(size_t index) const { return al::ReadBigEndianU32(Record(index)); }
  int32_t TimeUs(size_t index) const { return al::ReadBigEndianI32(Record(index) + 4); }
  static uint32_t RawX(uint32_t address) { return (address >> al::kXShift) & al::kXMask; }
  static uint32_t RawY(uint32_t address) { return (address >> al::kYShift) & al::kYMask; }

  std::string RecordName(size_t index) const {
    return "record " + std::to_string(index) + " (byte " +
           std::to_string(header_.data_start + index * al::kRecordBytes) + ")";
  }

  // One pass over the records: checks their times, finds the APS frames and the largest
  // address. The records stay in the mapping; nothing per event is kept.
  void IndexVersion2() {
    if (!header_.other_address_layout.empty()) {
      Fail(InputError::Kind::kMalformed,
           "AEDAT 2.0 from a " + header_.chip +
               " (the header names it): its address layout is not the DAVIS one evfs reads");
    }
    const size_t bytes = size_ - header_.data_start;
    if (bytes % al::kRecordBytes != 0) {
      Fail(InputError::Kind::kMalformed,
           std::to_string(bytes % al::kRecordBytes) +
               " bytes after the last whole 8-byte record (truncated file?)");
    }
    num_records_ = bytes / al::kRecordBytes;
    uint32_t max_x = 0, max_y = 0;
    std::vector<ApsFrame> candidates;
    bool in_frame = false;
    for (size_t i = 0; i < num_records_; ++i) {
      const uint32_t address = Address(i);
      const int32_t t_us = TimeUs(i);
      if (i > 0 && t_us < TimeUs(i - 1)) {
        Fail(InputError::Kind::kNotMonotonic, RecordName(i) + ": timestamps must not decrease (" +
                                                  std::to_string(t_us) + " us after " +
                                                  std::to_string(TimeUs(i - 1)) + " us)");
      }
      const bool aps = (address & al::kApsFlag) != 0;
      const uint32_t readout = (address >> al::kReadoutShift) & al::kReadoutMask;
      if (!aps && (address & al::kSpecialEventFlag) != 0) continue;
      if (aps && readout == al::kImuSample) continue;
      max_x = std::max(max_x, RawX(address));
      max_y = std::max(max_y, RawY(address));
      if (!aps) continue;
      if (readout == al::kCpResetRead) {
        Fail(InputError::Kind::kMalformed,
             RecordName(i) +
                 ": an APS CP-reset read (DAVIS240A/B readout), a jAER APS variant evfs does "
                 "not read");
      }
      if (readout == al::kResetRead && (!in_frame || candidates.back().signals > 0)) {
        candidates.emplace_back();
        candidates.back().first_record = i;
        in_frame = true;
      } else if (!in_frame) {  // the recording starts inside a frame's signal reads
        candidates.emplace_back();
        candidates.back().first_record = i;
        in_frame = true;
      }
      ApsFrame& frame = candidates.back();
      frame.last_record = i;
      if (readout == al::kResetRead) {
        ++frame.resets;
        frame.last_reset_us = t_us;
      } else {
        if (frame.signals == 0) frame.first_signal_us = t_us;
        ++frame.signals;
      }
    }
    SetVersion2SensorSize(max_x, max_y);
    SelectApsFrames(candidates);
  }

  void SetVersion2SensorSize(uint32_t max_x, uint32_t max_y) {
    if (width_ > 0) {
      if (max_x >= static_cast<uint32_t>(width_) || max_y >= static_cast<uint32_t>(height_)) {
        Fail(InputError::Kind::kOutOfRange,
             "an address with x " + std::to_string(max_x) + " or y " + std::to_string(max_y) +
                 " is outside the " + std::to_string(width_) + "x" + std::to_string(height_) +
                 " sensor the header names");
      }
      return;
    }
    for (const al::SensorSize& sensor : al::kUnnamedDavisSensors) {
      if (max_x < static_cast<uint32_t>(sensor.width) &&
          max_y < static_cast<uint32_t>(sensor.height)) {
        width_ = sensor.width;
        height_ = sensor.height;
        size_source_ = "the largest address (x " + std::to_string(max_x) + ", y " +
                       std::to_string(max_y) + "): the header names no chip";
        return;
      }
    }
    Fail(InputError::Kind::kOutOfRange, "the header names no chip and the largest address (x " +
                                            std::to_string(max_x) + ", y " + std::to_string(max_y) +
                                            ") fits no DAVIS240 or DAVIS346");
  }

  // Keeps the whole global-shutter frames. A frame cut by the start or the end of the recording
  // is left out (said in no_frames_reason when no frame is left); any other incomplete frame
  // means a readout evfs does not read.
  void SelectApsFrames(const std::vector<ApsFrame>& candidates) {
    const int64_t pixels = static_cast<int64_t>(width_) * height_;
    int cut = 0;
    for (size_t i = 0; i < candidates.size(); ++i) {
      const ApsFrame& frame = candidates[i];
      if (frame.resets != pixels || frame.signals != pixels) {
        const bool at_an_end = i == 0 || i + 1 == candidates.size();
        if (at_an_end && frame.resets <= pixels && frame.signals <= pixels) {
          ++cut;
          continue;
        }
        Fail(InputError::Kind::kMalformed,
             "the APS frame from " + RecordName(frame.first_record) + " has " +
                 std::to_string(frame.resets) + " reset and " + std::to_string(frame.signals) +
                 " signal reads, expected " + std::to_string(pixels) +
                 " of each: a rolling-shutter or region-of-interest jAER APS variant evfs does "
                 "not read");
      }
      if (frame.first_signal_us < frame.last_reset_us) {
        Fail(InputError::Kind::kNotMonotonic,
             "the APS frame from " + RecordName(frame.first_record) +
                 ": its signal reads start before its reset reads end");
      }
      FrameInfo info;
      info.exposure_begin_ns = int64_t{frame.last_reset_us} * al::kNanosecondsPerMicrosecond;
      info.exposure_end_ns = int64_t{frame.first_signal_us} * al::kNanosecondsPerMicrosecond;
      info.t_ns = info.exposure_begin_ns + (info.exposure_end_ns - info.exposure_begin_ns) / 2;
      info.has_exposure = info.exposure_end_ns > info.exposure_begin_ns;
      if (!info.has_exposure) info.exposure_begin_ns = info.exposure_end_ns = 0;
      if (!frames_.empty() && info.t_ns <= frames_.back().t_ns) {
        Fail(InputError::Kind::kNotMonotonic,
             "the APS frame from " + RecordName(frame.first_record) +
                 ": frame times must increase (it is not after the frame before)");
      }
      info.path = al::DefaultFramePath(frames_.size());
      frames_.push_back(std::move(info));
      aps_frames_.push_back(frame);
    }
    if (frames_.empty()) {
      no_frames_reason_ = cut > 0 ? "the AEDAT 2.0 file holds no whole APS frame"
                                  : "the AEDAT 2.0 file holds no APS samples";
    }
  }

  // (reset - signal) / 1023 per pixel: the reset read is the dark level the signal read falls
  // from as the photodiode discharges, so their difference grows with the light (jAER's frame).
  Image ReadApsFrame(const ApsFrame& frame) const {
    Image reset = Image::Constant(height_, width_, -1);
    Image signal = Image::Constant(height_, width_, -1);
    for (size_t i = frame.first_record; i <= frame.last_record; ++i) {
      const uint32_t address = Address(i);
      if ((address & al::kApsFlag) == 0) continue;
      const uint32_t readout = (address >> al::kReadoutShift) & al::kReadoutMask;
      if (readout != al::kResetRead && readout != al::kSignalRead) continue;
      const int x = width_ - 1 - static_cast<int>(RawX(address));
      const int y = height_ - 1 - static_cast<int>(RawY(address));
      double& value = (readout == al::kResetRead ? reset : signal)(y, x);
      if (value >= 0) {
        Fail(InputError::Kind::kMalformed, RecordName(i) + ": a second " +
                                               (readout == al::kResetRead ? "reset" : "signal") +
                                               " read of pixel (" + std::to_string(x) + ", " +
                                               std::to_string(y) + ") in one APS frame");
      }
      value = static_cast<double>(address & al::kAdcMask);
    }
    return ((reset - signal) / al::kAdcMax).max(0.0).min(1.0);
  }

  template <typename Visitor>
  void ForEachEventVersion2(int64_t t_begin_ns, int64_t t_end_ns, Visitor&& visit) const {
    // Opening checked that the times never decrease, so the records are sorted by time.
    size_t low = 0, high = num_records_;
    while (low < high) {
      const size_t middle = low + (high - low) / 2;
      if (int64_t{TimeUs(middle)} * al::kNanosecondsPerMicrosecond < t_begin_ns) {
        low = middle + 1;
      } else {
        high = middle;
      }
    }
    for (size_t i = low; i < num_records_; ++i) {
      const int64_t t_ns = int64_t{TimeUs(i)} * al::kNanosecondsPerMicrosecond;
      if (t_ns >= t_end_ns) break;
      ++units_decoded_;
      const uint32_t address = Address(i);
      if ((address & (al::kApsFlag | al::kSpecialEventFlag)) != 0) continue;
      visit(t_ns, width_ - 1 - static_cast<int>(RawX(address)),
            height_ - 1 - static_cast<int>(RawY(address)),
            ((address >> al::kPolarityShift) & 1) != 0 ? 1 : -1);
    }
  }

  // ---- AEDAT 3.1 ----

  struct PolarityPacket {
    size_t body = 0;       // offset of the first event
    int64_t count = 0;     // eventNumber
    int64_t overflow = 0;  // eventTSOverflow, shifted
    int64_t t_first_ns = 0;
    int64_t t_last_ns = 0;
  };

  struct FrameEvent {
    size_t offset = 0;  // of its 36-byte header
    int channels = 1;
  };

  std::string PacketName(size_t offset) const {
    return "the packet at byte " + std::to_string(offset);
  }

  int64_t EventTimeNs(int64_t overflow, int32_t t_us, const std::string& where) const {
    if (t_us < 0) Fail(InputError::Kind::kOutOfRange, where + ": a negative time");
    const int64_t time_us = overflow | t_us;
    if (time_us > al::kMaxMicroseconds) {
      Fail(InputError::Kind::kOutOfRange, where + ": a time beyond int64 nanoseconds");
    }
    return time_us * al::kNanosecondsPerMicrosecond;
  }

  // Reads every packet header, skipping the bodies of packets that are neither polarity nor
  // frame events; of a polarity packet only its first and last event are read.
  void IndexVersion3() {
    size_t offset = header_.data_start;
    while (offset < size_) {
      if (size_ - offset < al::kPacketHeaderBytes) {
        Fail(InputError::Kind::kMalformed,
             "truncated packet header at byte " + std::to_string(offset) + " (truncated file?)");
      }
      const uint8_t* header = data_ + offset;
      const int16_t type = al::ReadLittleEndianI16(header);
      const int32_t event_size = al::ReadLittleEndianI32(header + 4);
      const int32_t overflow = al::ReadLittleEndianI32(header + 12);
      const int32_t capacity = al::ReadLittleEndianI32(header + 16);
      const int32_t number = al::ReadLittleEndianI32(header + 20);
      const size_t remaining = size_ - offset - al::kPacketHeaderBytes;
      const std::string name = PacketName(offset);
      if (event_size < 1 || capacity < 0 || number < 0 || number > capacity || overflow < 0) {
        Fail(InputError::Kind::kMalformed,
             name + ": event size " + std::to_string(event_size) + ", capacity " +
                 std::to_string(capacity) + ", number " + std::to_string(number) + ", overflow " +
                 std::to_string(overflow) + " are not a packet header (corrupt?)");
      }
      const uint64_t body_bytes = static_cast<uint64_t>(capacity) * event_size;
      if (body_bytes > remaining) {
        Fail(InputError::Kind::kMalformed, name + " declares " + std::to_string(body_bytes) +
                                               " bytes of events, " + std::to_string(remaining) +
                                               " follow (truncated file?)");
      }
      const size_t body = offset + al::kPacketHeaderBytes;
      const int64_t overflow_us = int64_t{overflow} << al::kTimestampOverflowShift;
      if (type == al::kPolarityEventType && number > 0) {
        if (event_size != static_cast<int32_t>(al::kPolarityEventBytes)) {
          Fail(InputError::Kind::kMalformed,
               name + ": polarity events of " + std::to_string(event_size) + " bytes, expected 8");
        }
        PolarityPacket packet;
        packet.body = body;
        packet.count = number;
        packet.overflow = overflow_us;
        packet.t_first_ns =
            EventTimeNs(overflow_us, al::ReadLittleEndianI32(data_ + body + 4), name);
        packet.t_last_ns = EventTimeNs(
            overflow_us,
            al::ReadLittleEndianI32(data_ + body + (number - 1) * al::kPolarityEventBytes + 4),
            name);
        if (packet.t_last_ns < packet.t_first_ns ||
            (!polarity_packets_.empty() &&
             packet.t_first_ns < polarity_packets_.back().t_last_ns)) {
          Fail(InputError::Kind::kNotMonotonic, name + ": timestamps must not decrease");
        }
        polarity_packets_.push_back(packet);
      } else if (type == al::kFrameEventType) {
        for (int32_t k = 0; k < number; ++k) {
          IndexFrameEvent(body + static_cast<size_t>(k) * event_size, event_size, overflow_us,
                          name + ", frame event " + std::to_string(k));
        }
      }
      offset = body + body_bytes;
    }
    if (width_ == 0) SetVersion3SensorSize();
    for (size_t i = 0; i < frame_events_.size(); ++i) CheckFrameSize(i);
    if (frames_.empty()) no_frames_reason_ = "the AEDAT 3.1 file holds no frame events";
  }

  void IndexFrameEvent(size_t offset, int32_t event_size, int64_t overflow_us,
                       const std::string& name) {
    if (event_size < static_cast<int32_t>(al::kFrameHeaderBytes)) {
      Fail(InputError::Kind::kMalformed, name + ": frame events of " + std::to_string(event_size) +
                                             " bytes, shorter than their 36-byte header");
    }
    const uint8_t* event = data_ + offset;
    const uint32_t info = al::ReadLittleEndianU32(event);
    if ((info & 1) == 0) return;  // not valid: a slot the camera did not fill
    const int channels = static_cast<int>((info >> 1) & 0x7);
    const int roi_region = static_cast<int>((info >> 8) & 0x7f);
    if (channels != 1 && channels != 3 && channels != 4) {
      Fail(InputError::Kind::kMalformed,
           name + ": " + std::to_string(channels) + " colour channels (expected 1, 3 or 4)");
    }
    if (roi_region != 0) {
      Fail(InputError::Kind::kMalformed, name + ": a frame of region of interest " +
                                             std::to_string(roi_region) +
                                             ", a layout evfs does not read");
    }
    const int64_t length_x = al::ReadLittleEndianI32(event + 20);
    const int64_t length_y = al::ReadLittleEndianI32(event + 24);
    if (length_x < 1 || length_y < 1 ||
        length_x * length_y * channels * 2 >
            event_size - static_cast<int64_t>(al::kFrameHeaderBytes)) {
      Fail(InputError::Kind::kMalformed, name + ": a " + std::to_string(length_x) + "x" +
                                             std::to_string(length_y) + " frame does not fit its " +
                                             std::to_string(event_size) + "-byte event");
    }
    FrameInfo frame;
    const int64_t begin_ns =
        EventTimeNs(overflow_us, al::ReadLittleEndianI32(event + 12), name + " exposure start");
    const int64_t end_ns =
        EventTimeNs(overflow_us, al::ReadLittleEndianI32(event + 16), name + " exposure end");
    if (end_ns < begin_ns) {
      Fail(InputError::Kind::kOutOfRange, name + ": the exposure ends before it starts");
    }
    frame.t_ns = begin_ns + (end_ns - begin_ns) / 2;
    frame.has_exposure = end_ns > begin_ns;
    frame.exposure_begin_ns = frame.has_exposure ? begin_ns : 0;
    frame.exposure_end_ns = frame.has_exposure ? end_ns : 0;
    if (!frames_.empty() && frame.t_ns <= frames_.back().t_ns) {
      Fail(InputError::Kind::kNotMonotonic,
           name + ": frame times must increase (it is not after the frame before)");
    }
    frame.path = al::DefaultFramePath(frames_.size());
    frames_.push_back(std::move(frame));
    frame_events_.push_back({offset, channels});
  }

  // Without a chip in the header: the first frame's size, else the largest event address.
  void SetVersion3SensorSize() {
    if (!frame_events_.empty()) {
      const uint8_t* event = data_ + frame_events_.front().offset;
      width_ = al::ReadLittleEndianI32(event + 20);
      height_ = al::ReadLittleEndianI32(event + 24);
      size_source_ = "the first frame: the header names no chip";
      return;
    }
    int max_x = -1, max_y = -1;
    width_ = height_ = std::numeric_limits<int>::max();
    ForEachEventVersion3(std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max(),
                         [&](int64_t, int x, int y, int) {
                           max_x = std::max(max_x, x);
                           max_y = std::max(max_y, y);
                         });
    units_decoded_ = 0;
    width_ = max_x + 1;
    height_ = max_y + 1;
    if (width_ == 0) {
      Fail(InputError::Kind::kMalformed,
           "no sensor size: the header names no chip and the file holds no events or frames");
    }
    size_source_ = "the largest event address: the header names no chip";
  }

  void CheckFrameSize(size_t index) const {
    const uint8_t* event = data_ + frame_events_[index].offset;
    const int length_x = al::ReadLittleEndianI32(event + 20);
    const int length_y = al::ReadLittleEndianI32(event + 24);
    const int position_x = al::ReadLittleEndianI32(event + 28);
    const int position_y = al::ReadLittleEndianI32(event + 32);
    if (length_x != width_ || length_y != height_ || position_x != 0 || position_y != 0) {
      Fail(InputError::Kind::kSizeMismatch,
           "frame " + std::to_string(index) + ": a " + std::to_string(length_x) + "x" +
               std::to_string(length_y) + " frame at (" + std::to_string(position_x) + ", " +
               std::to_string(position_y) + "), expected the whole " + std::to_string(width_) +
               "x" + std::to_string(height_) + " sensor");
    }
  }

  Image ReadFrameEvent(const FrameEvent& frame) const {
    const uint8_t* pixels = data_ + frame.offset + al::kFrameHeaderBytes;
    cv::Mat colour(height_, width_, CV_16UC(frame.channels));
    for (int row = 0; row < height_; ++row) {
      uint16_t* target = colour.ptr<uint16_t>(row);
      for (int i = 0; i < width_ * frame.channels; ++i) {
        const uint8_t* p = pixels + 2 * (static_cast<size_t>(row) * width_ * frame.channels + i);
        target[i] = static_cast<uint16_t>(p[0] | (p[1] << 8));
      }
    }
    cv::Mat grey = colour;
    if (frame.channels == 3) cv::cvtColor(colour, grey, cv::COLOR_RGB2GRAY);
    if (frame.channels == 4) cv::cvtColor(colour, grey, cv::COLOR_RGBA2GRAY);
    Image image(height_, width_);
    for (int row = 0; row < height_; ++row) {
      const uint16_t* source = grey.ptr<uint16_t>(row);
      for (int column = 0; column < width_; ++column) image(row, column) = source[column] / 65535.0;
    }
    return image;
  }

  template <typename Visitor>
  void ForEachEventVersion3(int64_t t_begin_ns, int64_t t_end_ns, Visitor&& visit) const {
    const auto first = std::partition_point(
        polarity_packets_.begin(), polarity_packets_.end(),
        [&](const PolarityPacket& packet) { return packet.t_last_ns < t_begin_ns; });
    int64_t previous_t_ns = std::numeric_limits<int64_t>::min();
    for (auto packet = first; packet != polarity_packets_.end(); ++packet) {
      if (packet->t_first_ns >= t_end_ns) break;
      ++units_decoded_;
      const std::string name = PacketName(packet->body - al::kPacketHeaderBytes);
      for (int64_t k = 0; k < packet->count; ++k) {
        const uint8_t* event = data_ + packet->body + k * al::kPolarityEventBytes;
        const uint32_t bits = al::ReadLittleEndianU32(event);
        if ((bits & 1) == 0) continue;  // not valid: filtered out by the camera's software
        const int64_t t_ns =
            EventTimeNs(packet->overflow, al::ReadLittleEndianI32(event + 4), name);
        if (t_ns < previous_t_ns || t_ns < packet->t_first_ns || t_ns > packet->t_last_ns) {
          Fail(InputError::Kind::kNotMonotonic,
               name + ", event " + std::to_string(k) + ": timestamps must not decrease");
        }
        previous_t_ns = t_ns;
        const int x = static_cast<int>(bits >> 17);
        const int y = static_cast<int>((bits >> 2) & 0x7fff);
        if (x >= width_ || y >= height_) {
          Fail(InputError::Kind::kOutOfRange,
               name + ", event " + std::to_string(k) + ": (" + std::to_string(x) + ", " +
                   std::to_string(y) + ") is outside the " + std::to_string(width_) + "x" +
                   std::to_string(height_) + " sensor (" + size_source_ + ")");
        }
        if (t_ns >= t_begin_ns && t_ns < t_end_ns) visit(t_ns, x, y, (bits & 2) != 0 ? 1 : -1);
      }
    }
  }

  MappedFile file_;
  const uint8_t* data_;
  size_t size_;
  al::Header header_;
  int width_ = 0;
  int height_ = 0;
  std::string size_source_;
  std::vector<FrameInfo> frames_;
  std::string no_frames_reason_;
  size_t num_records_ = 0;                        // AEDAT 2.0
  std::vector<ApsFrame> aps_frames_;              // AEDAT 2.0, one per frame
  std::vector<PolarityPacket> polarity_packets_;  // AEDAT 3.1, sorted by time
  std::vector<FrameEvent> frame_events_;          // AEDAT 3.1, one per frame
  mutable int64_t units_decoded_ = 0;
};

AedatLegacyDataSource::AedatLegacyDataSource(const std::string& path)
    : AedatLegacyDataSource(std::make_unique<File>(MappedFile(path))) {}

std::unique_ptr<AedatLegacyDataSource> AedatLegacyDataSource::FromMemory(const std::string& path,
                                                                         const char* data,
                                                                         size_t size) {
  return std::unique_ptr<AedatLegacyDataSource>(
      new AedatLegacyDataSource(std::make_unique<File>(MappedFile::FromMemory(path, data, size))));
}

AedatLegacyDataSource::AedatLegacyDataSource(std::unique_ptr<File> file)
    : DataSource(file->path(), file->width(), file->height(), std::move(file->frames())),
      file_(std::move(file)) {
  no_frames_reason_ = file_->no_frames_reason();
}

AedatLegacyDataSource::~AedatLegacyDataSource() = default;

int AedatLegacyDataSource::major_version() const { return file_->major_version(); }

const std::string& AedatLegacyDataSource::sensor_size_source() const {
  return file_->size_source();
}

int64_t AedatLegacyDataSource::units_decoded() const { return file_->units_decoded(); }

Image AedatLegacyDataSource::ReadImage(int index) const {
  CheckFrameIndex(index);
  return file_->ReadImage(index);
}

EventStream AedatLegacyDataSource::ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const {
  return CollectVisitedEvents(
      width_, height_, [&](auto&& visit) { file_->ForEachEvent(t_begin_ns, t_end_ns, visit); });
}

EventStream AedatLegacyDataSource::ReadAllEvents() const {
  return ReadEvents(kAllEventsBeginNs, kAllEventsEndNs);
}

EventSummary AedatLegacyDataSource::Summarize() const {
  return SummarizeVisitedEvents(
      [&](auto&& visit) { file_->ForEachEvent(kAllEventsBeginNs, kAllEventsEndNs, visit); });
}

}  // namespace evfs
