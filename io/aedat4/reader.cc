// Reading AEDAT 4.0 files: Aedat4DataSource (io/aedat4.h), and recognising them.
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <utility>

#include "evfs/core/error.h"
#include "evfs/io/aedat4.h"
#include "evfs/io/aedat4/decompressor.h"
#include "evfs/io/aedat4/events_generated.h"
#include "evfs/io/aedat4/file_data_table_generated.h"
#include "evfs/io/aedat4/format.h"
#include "evfs/io/aedat4/frame_generated.h"
#include "evfs/io/aedat4/header.h"
#include "evfs/io/frame_list.h"
#include "evfs/io/image_io.h"
#include "evfs/io/mapped_file.h"

namespace evfs {
namespace {

namespace fb = aedat4::fb;
using aedat4::kAedatPrefix;
using aedat4::kAedatPrefixBytes;
using aedat4::kEventBytes;
using aedat4::kEventsType;
using aedat4::kFramesType;
using aedat4::kMaxMicroseconds;
using aedat4::kMaxPacketBytes;
using aedat4::kMinFlatbufferBytes;
using aedat4::kNanosecondsPerMicrosecond;
using aedat4::kPacketHeaderBytes;
using aedat4::kSizePrefixBytes;
using aedat4::ReadI32;
using aedat4::ReadU32;
using aedat4::VerifiedSizePrefixedRoot;

static_assert(sizeof(fb::Event) == kEventBytes, "fb::Event is the format's 16-byte event");

// "frame_00000012"-style default name of frame `index` in a data folder (as in text_folder.cc).
std::string DefaultFramePath(size_t index) {
  char name[40];
  std::snprintf(name, sizeof(name), "images/frame_%08zu.png", index);
  return name;
}

}  // namespace

bool IsAedat4Path(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".aedat4";
}

bool StartsWithAedatVersionLine(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;
  std::ifstream stream(path, std::ios::binary);
  char start[kAedatPrefixBytes] = {};
  stream.read(start, sizeof(start));
  return stream.gcount() == static_cast<std::streamsize>(sizeof(start)) &&
         std::memcmp(start, kAedatPrefix, sizeof(start)) == 0;
}

class Aedat4DataSource::File {
 public:
  explicit File(MappedFile file)
      : file_(std::move(file)),
        data_(reinterpret_cast<const uint8_t*>(file_.data())),
        size_(file_.size()) {
    header_ = aedat4::ParseHeader(path(), data_, size_);
    data_end_ =
        header_.data_table_position >= 0 ? static_cast<size_t>(header_.data_table_position) : size_;
    // The sensor size first: indexing without a data table checks the events against it.
    SetSensorSizeFromDescription();
    indexed_by_data_table_ = header_.data_table_position >= 0 && IndexFromDataTable();
    if (!indexed_by_data_table_) IndexByScanning();
    if (width_ == 0) SetSensorSizeFromFirstFrame();
    ReadFrameInfos();
  }

  const std::string& path() const { return file_.path(); }
  int width() const { return width_; }
  int height() const { return height_; }
  std::vector<FrameInfo>& frames() { return frames_; }
  const aedat4::Header& header() const { return header_; }
  bool has_events() const { return header_.events.id >= 0; }
  bool indexed_by_data_table() const { return indexed_by_data_table_; }
  int num_event_packets() const { return static_cast<int>(event_packets_.size()); }
  int64_t packets_decoded() const { return packets_decoded_; }

  [[noreturn]] void Fail(InputError::Kind kind, const std::string& what) const {
    throw InputError(kind, path(), 0, what);
  }

  // Calls visit(t_ns, x, y, polarity) for the events of packets [first, last) with
  // t_begin_ns <= t < t_end_ns, checking every event of those packets.
  template <typename Visitor>
  void ForEachEvent(size_t first, size_t last, int64_t t_begin_ns, int64_t t_end_ns,
                    Visitor&& visit) const {
    int64_t previous_t_ns = std::numeric_limits<int64_t>::min();
    for (size_t i = first; i < last; ++i) {
      DecodeEvents(event_packets_[i], &previous_t_ns,
                   [&](int64_t t_ns, int x, int y, int polarity) {
                     if (t_ns >= t_begin_ns && t_ns < t_end_ns) visit(t_ns, x, y, polarity);
                   });
    }
  }

  // Index of the first event packet that may hold an event at or after t_ns, and one past the
  // last that may hold one before t_end_ns: the packets' spans are sorted and do not overlap
  // (checked when indexing).
  std::pair<size_t, size_t> PacketsOverlapping(int64_t t_begin_ns, int64_t t_end_ns) const {
    const auto first =
        std::partition_point(event_packets_.begin(), event_packets_.end(),
                             [&](const Packet& packet) { return packet.t_last_ns < t_begin_ns; });
    const auto last = std::partition_point(first, event_packets_.end(), [&](const Packet& packet) {
      return packet.t_first_ns < t_end_ns;
    });
    return {static_cast<size_t>(first - event_packets_.begin()),
            static_cast<size_t>(last - event_packets_.begin())};
  }

  size_t num_packets() const { return event_packets_.size(); }

  Image ReadImage(int index) const {
    Image image;
    DecodeFrame(frame_packets_[static_cast<size_t>(index)], nullptr, &image);
    return image;
  }

 private:
  struct Packet {
    size_t offset = 0;  // of the body, just after the packet header
    size_t size = 0;    // bytes of the (compressed) body
    int64_t count = 0;  // events in it (from the data table, or counted when indexing)
    int64_t t_first_ns = 0;
    int64_t t_last_ns = 0;
  };

  std::string PacketName(const Packet& packet, const char* type) const {
    return std::string(type) + " packet at byte " +
           std::to_string(packet.offset - kPacketHeaderBytes);
  }

  // Decompresses `packet` of stream `type` into buffer_ and verifies it as a `Table`
  // flatbuffer with file identifier `identifier`; returns its root (valid until the next read).
  template <typename Table>
  const Table* ReadPacket(const Packet& packet, const char* type, const char* identifier) const {
    return ReadFlatbuffer<Table>(data_ + packet.offset, packet.size, PacketName(packet, type),
                                 identifier);
  }

  // The same for the `size` compressed bytes at `data`, named `what` in messages.
  template <typename Table>
  const Table* ReadFlatbuffer(const uint8_t* data, size_t size, const std::string& what,
                              const char* identifier) const {
    ++packets_decoded_;
    const std::string problem = decompressor_.Decompress(header_.compression, data, size, &buffer_);
    if (!problem.empty()) Fail(InputError::Kind::kMalformed, what + ": " + problem);
    if (buffer_.size() < kSizePrefixBytes + kMinFlatbufferBytes ||
        ReadU32(buffer_.data()) != buffer_.size() - kSizePrefixBytes) {
      Fail(InputError::Kind::kMalformed,
           what + ": " + std::to_string(buffer_.size()) +
               " bytes that are not a size-prefixed flatbuffer (corrupt?)");
    }
    const Table* root = VerifiedSizePrefixedRoot<Table>(&buffer_, identifier);
    if (root == nullptr) {
      Fail(InputError::Kind::kMalformed,
           what + ": not a valid " + identifier + " flatbuffer (corrupt?)");
    }
    return root;
  }

  template <typename Visitor>
  void DecodeEvents(const Packet& packet, int64_t* previous_t_ns, Visitor&& visit) const {
    const auto* elements =
        ReadPacket<fb::EventPacket>(packet, kEventsType, fb::EventPacketIdentifier())->elements();
    // The verifier checks a vector's length field for 4-byte alignment only; the events in it
    // are read as 8-byte aligned structs (the aedat4 fuzzer found a vector 4 bytes off). The
    // buffer itself is allocated aligned, so the address says it.
    if (elements != nullptr &&
        reinterpret_cast<uintptr_t>(elements->Data()) % alignof(fb::Event) != 0) {
      Fail(InputError::Kind::kMalformed,
           PacketName(packet, kEventsType) + ": misaligned event vector (corrupt?)");
    }
    const int64_t count = elements != nullptr ? static_cast<int64_t>(elements->size()) : 0;
    if (indexed_by_data_table() && count != packet.count) {
      Fail(InputError::Kind::kMalformed,
           PacketName(packet, kEventsType) + " holds " + std::to_string(count) +
               " events, the file data table says " + std::to_string(packet.count));
    }
    for (int64_t i = 0; i < count; ++i) {
      const fb::Event* event = elements->Get(static_cast<flatbuffers::uoffset_t>(i));
      const auto fail_event = [&](InputError::Kind kind, const std::string& what) {
        Fail(kind, PacketName(packet, kEventsType) + ", event " + std::to_string(i) + ": " + what);
      };
      const int x = event->x();
      const int y = event->y();
      if (x < 0 || x >= width_ || y < 0 || y >= height_) {
        fail_event(InputError::Kind::kOutOfRange,
                   "(" + std::to_string(x) + ", " + std::to_string(y) + ") is outside the " +
                       std::to_string(width_) + "x" + std::to_string(height_) + " sensor");
      }
      const int64_t t_us = event->timestamp();
      if (t_us > kMaxMicroseconds || t_us < -kMaxMicroseconds) {
        fail_event(InputError::Kind::kOutOfRange,
                   "time " + std::to_string(t_us) + " us is beyond int64 nanoseconds");
      }
      const int64_t t_ns = t_us * kNanosecondsPerMicrosecond;
      if (t_ns < *previous_t_ns) {
        fail_event(InputError::Kind::kNotMonotonic, "timestamps must not decrease");
      }
      if (indexed_by_data_table() && (t_ns < packet.t_first_ns || t_ns > packet.t_last_ns)) {
        fail_event(InputError::Kind::kMalformed,
                   "time " + std::to_string(t_us) +
                       " us is outside the packet's time span in the file data table");
      }
      *previous_t_ns = t_ns;
      visit(t_ns, x, y, event->polarity() ? 1 : -1);
    }
  }

  // Decodes the frame in `packet`: its times into *info and, when `image` is given, its pixels.
  void DecodeFrame(const Packet& packet, FrameInfo* info, Image* image) const {
    const fb::Frame* frame = ReadPacket<fb::Frame>(packet, kFramesType, fb::FrameIdentifier());
    const std::string name = PacketName(packet, kFramesType);
    if (info != nullptr) {
      const auto to_ns = [&](int64_t t_us, const char* what) {
        if (t_us > kMaxMicroseconds || t_us < -kMaxMicroseconds) {
          Fail(InputError::Kind::kOutOfRange,
               name + ": " + what + " " + std::to_string(t_us) + " us is beyond int64 nanoseconds");
        }
        return t_us * kNanosecondsPerMicrosecond;
      };
      info->t_ns = to_ns(frame->timestamp(), "time");
      const int64_t begin_ns = to_ns(frame->timestamp_start_of_exposure(), "exposure start");
      const int64_t end_ns = to_ns(frame->timestamp_end_of_exposure(), "exposure end");
      if (end_ns < begin_ns) {
        Fail(InputError::Kind::kOutOfRange, name + ": the exposure ends before it starts");
      }
      // A zero-length exposure is what a writer without exposure times leaves (WriteAedat4).
      info->has_exposure = end_ns > begin_ns;
      info->exposure_begin_ns = info->has_exposure ? begin_ns : 0;
      info->exposure_end_ns = info->has_exposure ? end_ns : 0;
    }
    const int size_x = frame->size_x();
    const int size_y = frame->size_y();
    if (size_x != width_ || size_y != height_ || frame->position_x() != 0 ||
        frame->position_y() != 0) {
      Fail(InputError::Kind::kSizeMismatch,
           name + ": a " + std::to_string(size_x) + "x" + std::to_string(size_y) + " frame at (" +
               std::to_string(frame->position_x()) + ", " + std::to_string(frame->position_y()) +
               "), expected the whole " + std::to_string(width_) + "x" + std::to_string(height_) +
               " sensor");
    }
    int channels = 0;
    int conversion = -1;
    switch (frame->format()) {
      case fb::FrameFormat::Gray:
        channels = 1;
        break;
      case fb::FrameFormat::Bgr:
        channels = 3;
        conversion = cv::COLOR_BGR2GRAY;
        break;
      case fb::FrameFormat::Bgra:
        channels = 4;
        conversion = cv::COLOR_BGRA2GRAY;
        break;
      default:
        Fail(InputError::Kind::kMalformed, name + ": unknown pixel format " +
                                               std::to_string(static_cast<int>(frame->format())) +
                                               " (expected 0 grey, 16 BGR or 24 BGRA)");
    }
    const size_t expected = static_cast<size_t>(width_) * height_ * channels;
    const size_t stored = frame->pixels() != nullptr ? frame->pixels()->size() : 0;
    if (stored != expected) {
      Fail(InputError::Kind::kMalformed, name + ": " + std::to_string(stored) +
                                             " bytes of pixels, expected " +
                                             std::to_string(expected));
    }
    if (image == nullptr) return;
    cv::Mat pixels(height_, width_, CV_8UC(channels),
                   const_cast<uint8_t*>(frame->pixels()->data()));
    cv::Mat grey = pixels;
    if (conversion >= 0) cv::cvtColor(pixels, grey, conversion);
    image->resize(height_, width_);
    for (int row = 0; row < height_; ++row) {
      const uint8_t* source = grey.ptr<uint8_t>(row);
      for (int column = 0; column < width_; ++column) {
        (*image)(row, column) = source[column] / 255.0;
      }
    }
  }

  // Checks that `packet` (from the data table) lies among the packets and that a packet header
  // of `stream_id` and its size stands in front of it.
  void CheckTableEntry(size_t index, int64_t byte_offset, int32_t stream_id, int32_t size) const {
    const std::string where = "file data table entry " + std::to_string(index) + ": ";
    if (size < 0 || byte_offset < static_cast<int64_t>(header_.data_start + kPacketHeaderBytes) ||
        byte_offset > static_cast<int64_t>(data_end_) ||
        static_cast<int64_t>(size) > static_cast<int64_t>(data_end_) - byte_offset) {
      Fail(InputError::Kind::kMalformed,
           where + "a packet of " + std::to_string(size) + " bytes at byte " +
               std::to_string(byte_offset) + " is outside the packets [" +
               std::to_string(header_.data_start) + ", " + std::to_string(data_end_) + ")");
    }
    const uint8_t* packet_header = data_ + byte_offset - kPacketHeaderBytes;
    if (ReadI32(packet_header) != stream_id || ReadI32(packet_header + 4) != size) {
      Fail(InputError::Kind::kMalformed,
           where + "no packet of stream " + std::to_string(stream_id) + " with " +
               std::to_string(size) + " bytes starts at byte " + std::to_string(byte_offset));
    }
  }

  // Indexes the packets from the data table; false (indexing nothing) when the table does not
  // give the element count of every event packet. A count of 0 says nothing: DV writes no empty
  // packets, and tools that cut or rewrite recordings write tables of offsets alone, without
  // counts and times, which other readers, walking the packets, never look at.
  bool IndexFromDataTable() {
    const size_t position = static_cast<size_t>(header_.data_table_position);
    const auto* table =
        ReadFlatbuffer<fb::FileDataTable>(data_ + position, size_ - position, "the file data table",
                                          fb::FileDataTableIdentifier())
            ->table();
    const size_t entries = table != nullptr ? table->size() : 0;
    for (size_t i = 0; i < entries; ++i) {
      const fb::FileDataDefinition* entry = table->Get(static_cast<flatbuffers::uoffset_t>(i));
      const fb::PacketHeader* info = entry->packet_info();
      if (info == nullptr) {
        Fail(InputError::Kind::kMalformed,
             "file data table entry " + std::to_string(i) + " has no packet header");
      }
      const int32_t stream = info->stream_id();
      if (stream != header_.events.id && stream != header_.frames.id) continue;
      CheckTableEntry(i, entry->byte_offset(), stream, info->size());
      Packet packet;
      packet.offset = static_cast<size_t>(entry->byte_offset());
      packet.size = static_cast<size_t>(info->size());
      if (stream == header_.frames.id) {
        frame_packets_.push_back(packet);
        continue;
      }
      packet.count = entry->num_elements();
      if (packet.count == 0) {
        event_packets_.clear();
        frame_packets_.clear();
        return false;
      }
      const std::string where = "file data table entry " + std::to_string(i) + ": ";
      if (packet.count < 0 || packet.count > static_cast<int64_t>(kMaxPacketBytes / kEventBytes)) {
        Fail(InputError::Kind::kMalformed,
             where + "a packet of " + std::to_string(packet.count) + " events");
      }
      const int64_t t_first_us = entry->timestamp_start();
      const int64_t t_last_us = entry->timestamp_end();
      if (t_first_us > t_last_us || t_first_us < -kMaxMicroseconds ||
          t_last_us > kMaxMicroseconds) {
        Fail(InputError::Kind::kMalformed, where + "the time span [" + std::to_string(t_first_us) +
                                               ", " + std::to_string(t_last_us) +
                                               "] us is not one");
      }
      packet.t_first_ns = t_first_us * kNanosecondsPerMicrosecond;
      packet.t_last_ns = t_last_us * kNanosecondsPerMicrosecond;
      if (!event_packets_.empty() && packet.offset <= event_packets_.back().offset) {
        Fail(InputError::Kind::kMalformed,
             where + "EVTS packets listed out of file order (or twice)");
      }
      if (!event_packets_.empty() && packet.t_first_ns < event_packets_.back().t_last_ns) {
        Fail(InputError::Kind::kNotMonotonic,
             where + "the EVTS packet starts before the one before it ends");
      }
      event_packets_.push_back(packet);
    }
    return true;
  }

  // Indexes the packets by a pass over them, up to the data table (or the end of the file).
  void IndexByScanning() {
    int64_t previous_t_ns = std::numeric_limits<int64_t>::min();
    size_t offset = header_.data_start;
    while (offset < data_end_) {
      if (data_end_ - offset < kPacketHeaderBytes) {
        Fail(InputError::Kind::kMalformed,
             "truncated packet header at byte " + std::to_string(offset) + " (truncated file?)");
      }
      const int32_t stream = ReadI32(data_ + offset);
      const int32_t size = ReadI32(data_ + offset + 4);
      const size_t remaining = data_end_ - offset - kPacketHeaderBytes;
      if (size < 0 || static_cast<size_t>(size) > remaining) {
        Fail(InputError::Kind::kMalformed,
             "the packet at byte " + std::to_string(offset) + " (stream " + std::to_string(stream) +
                 ") declares " + std::to_string(size) + " bytes, " + std::to_string(remaining) +
                 " follow (truncated file?)");
      }
      Packet packet;
      packet.offset = offset + kPacketHeaderBytes;
      packet.size = static_cast<size_t>(size);
      offset = packet.offset + packet.size;
      if (stream == header_.frames.id) {
        frame_packets_.push_back(packet);
      } else if (stream == header_.events.id) {
        bool any = false;
        DecodeEvents(packet, &previous_t_ns, [&](int64_t t_ns, int, int, int) {
          if (!any) packet.t_first_ns = t_ns;
          any = true;
          packet.t_last_ns = t_ns;
          ++packet.count;
        });
        if (any) event_packets_.push_back(packet);
      }
    }
  }

  // The sensor: the events stream's size, else the frames stream's (else, later, the first
  // frame's: SetSensorSizeFromFirstFrame).
  void SetSensorSizeFromDescription() {
    const aedat4::StreamInfo& events = header_.events;
    const aedat4::StreamInfo& frames = header_.frames;
    if (events.id >= 0 && frames.id >= 0 && frames.size_x > 0 &&
        (frames.size_x != events.size_x || frames.size_y != events.size_y)) {
      Fail(InputError::Kind::kSizeMismatch,
           "stream description: the frames are " + std::to_string(frames.size_x) + "x" +
               std::to_string(frames.size_y) + ", the events " + std::to_string(events.size_x) +
               "x" + std::to_string(events.size_y));
    }
    if (events.id >= 0) {
      width_ = events.size_x;
      height_ = events.size_y;
    } else if (frames.size_x > 0) {
      width_ = frames.size_x;
      height_ = frames.size_y;
    }
  }

  void SetSensorSizeFromFirstFrame() {
    if (!frame_packets_.empty()) {
      const fb::Frame* frame =
          ReadPacket<fb::Frame>(frame_packets_.front(), kFramesType, fb::FrameIdentifier());
      width_ = frame->size_x();
      height_ = frame->size_y();
      if (width_ < 1 || height_ < 1) {
        Fail(InputError::Kind::kMalformed, "the first frame is " + std::to_string(width_) + "x" +
                                               std::to_string(height_) + " pixels");
      }
    } else {
      Fail(InputError::Kind::kMalformed,
           "no sensor size: the FRME stream gives none and holds no frames");
    }
  }

  void ReadFrameInfos() {
    // The images.txt paths an evfs file keeps, when they fit these frames (else the default
    // names of a data folder).
    std::vector<std::string> paths = header_.frame_paths;
    const std::set<std::string> unique(paths.begin(), paths.end());
    const bool paths_fit = paths.size() == frame_packets_.size() && unique.size() == paths.size() &&
                           std::all_of(paths.begin(), paths.end(), [](const std::string& p) {
                             return !p.empty() && ImagePathProblem(p).empty();
                           });
    for (size_t i = 0; i < frame_packets_.size(); ++i) {
      FrameInfo frame;
      DecodeFrame(frame_packets_[i], &frame, nullptr);
      frame.path = paths_fit ? paths[i] : DefaultFramePath(i);
      if (!frames_.empty() && frame.t_ns <= frames_.back().t_ns) {
        Fail(InputError::Kind::kNotMonotonic,
             PacketName(frame_packets_[i], kFramesType) +
                 ": frame times must increase (it is not after the frame before)");
      }
      frames_.push_back(std::move(frame));
    }
  }

  MappedFile file_;
  const uint8_t* data_;
  size_t size_;
  aedat4::Header header_;
  size_t data_end_ = 0;  // packets end here: at the data table, or at the end of the file
  bool indexed_by_data_table_ = false;
  int width_ = 0;
  int height_ = 0;
  std::vector<Packet> event_packets_;  // sorted by time, spans not overlapping
  std::vector<Packet> frame_packets_;  // in file order
  std::vector<FrameInfo> frames_;
  mutable aedat4::Decompressor decompressor_;
  mutable std::vector<uint8_t> buffer_;  // the last decompressed packet
  mutable int64_t packets_decoded_ = 0;
};

Aedat4DataSource::Aedat4DataSource(const std::string& path)
    : Aedat4DataSource(std::make_unique<File>(MappedFile(path))) {}

std::unique_ptr<Aedat4DataSource> Aedat4DataSource::FromMemory(const std::string& path,
                                                               const char* data, size_t size) {
  return std::unique_ptr<Aedat4DataSource>(
      new Aedat4DataSource(std::make_unique<File>(MappedFile::FromMemory(path, data, size))));
}

Aedat4DataSource::Aedat4DataSource(std::unique_ptr<File> file)
    : DataSource(file->path(), file->width(), file->height(), std::move(file->frames())),
      file_(std::move(file)) {}

Aedat4DataSource::~Aedat4DataSource() = default;

bool Aedat4DataSource::has_events() const { return file_->has_events(); }

Aedat4Compression Aedat4DataSource::compression() const { return file_->header().compression; }

int64_t Aedat4DataSource::ts_offset_us() const {
  const aedat4::Header& header = file_->header();
  return header.events.id >= 0 ? header.events.ts_offset_us : header.frames.ts_offset_us;
}

bool Aedat4DataSource::indexed_by_data_table() const { return file_->indexed_by_data_table(); }

int Aedat4DataSource::num_event_packets() const { return file_->num_event_packets(); }

int64_t Aedat4DataSource::packets_decoded() const { return file_->packets_decoded(); }

Image Aedat4DataSource::ReadImage(int index) const {
  CheckFrameIndex(index);
  return file_->ReadImage(index);
}

EventStream Aedat4DataSource::ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const {
  if (!has_events()) {
    throw InputError(InputError::Kind::kMissingFile, path_, 0,
                     "the recording has no events (no EVTS stream)");
  }
  EventStream events(width_, height_);
  if (t_end_ns <= t_begin_ns) return events;
  const auto [first, last] = file_->PacketsOverlapping(t_begin_ns, t_end_ns);
  file_->ForEachEvent(first, last, t_begin_ns, t_end_ns,
                      [&](int64_t t_ns, int x, int y, int polarity) {
                        events.push_back(t_ns, static_cast<uint16_t>(x), static_cast<uint16_t>(y),
                                         static_cast<int8_t>(polarity));
                      });
  return events;
}

EventStream Aedat4DataSource::ReadAllEvents() const {
  return ReadEvents(std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max());
}

EventSummary Aedat4DataSource::Summarize() const {
  EventSummary summary;
  if (!has_events()) return summary;
  file_->ForEachEvent(
      0, file_->num_packets(), std::numeric_limits<int64_t>::min(),
      std::numeric_limits<int64_t>::max(),
      [&](int64_t t_ns, int x, int y, int polarity) { summary.Add(t_ns, x, y, polarity); });
  return summary;
}

bool IsAedat4WrittenByEvfs(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;
  try {
    const MappedFile file(path);
    return aedat4::ParseHeader(path, reinterpret_cast<const uint8_t*>(file.data()), file.size())
        .written_by_evfs;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace evfs
