#include "io/aedat4.h"

#include <lz4frame.h>
#include <lz4hc.h>
#include <tinyxml2.h>
#include <zstd.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <utility>

#include "core/error.h"
#include "core/option_checker.h"
#include "io/aedat4/events_generated.h"
#include "io/aedat4/file_data_table_generated.h"
#include "io/aedat4/frame_generated.h"
#include "io/aedat4/io_header_generated.h"
#include "io/frame_list.h"
#include "io/image_io.h"
#include "io/mapped_file.h"
#include "io/message_excerpt.h"

namespace evfs {
namespace {

namespace fb = aedat4::fb;

constexpr char kVersionLine[] = "#!AER-DAT4.0\r\n";
constexpr size_t kVersionLineBytes = sizeof(kVersionLine) - 1;
// Every AEDAT version starts so (AEDAT 2.0 "#!AER-DAT2.0\r\n", 3.1 "#!AER-DAT3.1\r\n").
constexpr char kAedatPrefix[] = "#!AER-DAT";
constexpr size_t kAedatPrefixBytes = sizeof(kAedatPrefix) - 1;
constexpr size_t kSizePrefixBytes = 4;
// int32 stream id, int32 body size.
constexpr size_t kPacketHeaderBytes = 8;
// The smallest flatbuffer: a root offset and a table's vtable offset.
constexpr size_t kMinFlatbufferBytes = 8;
// Most bytes a packet body (or the data table) may decompress to: 16 M events, or a 8192x8192
// BGRA frame. DV writes packets of a few milliseconds (~100 KB), so a larger claim is a corrupt
// file or a decompression bomb; refusing it bounds what one packet can make evfs allocate.
constexpr size_t kMaxPacketBytes = size_t{256} << 20;
// Bytes a frame's flatbuffer takes besides its pixels (its fields and the size prefix) are
// fewer: the writer keeps whole frames within kMaxPacketBytes.
constexpr size_t kMaxFrameOverheadBytes = 4096;
// Most bytes of the IOHeader: the XML stream description of DV is a few KB.
constexpr size_t kMaxHeaderBytes = size_t{16} << 20;
// Decompression output starts at this many bytes (or a few times the input) and doubles.
constexpr size_t kInitialOutputBytes = size_t{64} << 10;
// Sensor sides: positions and frame sizes are int16 in the format.
constexpr int kMaxSensorSide = 32767;
// |t| in microseconds below this converts to int64 nanoseconds without overflow.
constexpr int64_t kMaxMicroseconds = std::numeric_limits<int64_t>::max() / 1000;
constexpr int64_t kNanosecondsPerMicrosecond = 1000;
// Bytes of one event in an EventPacket (fb::Event).
constexpr size_t kEventBytes = 16;
constexpr char kEventsType[] = "EVTS";
constexpr char kFramesType[] = "FRME";
// The writer's stream ids.
constexpr int32_t kEventsStreamId = 0;
constexpr int32_t kFramesStreamId = 1;
// The node the writer adds to the stream description (beside DV's "outInfo"): it marks the file
// as evfs's and keeps the frames' images.txt paths, which the format has no place for.
constexpr char kEvfsNode[] = "evfs";
constexpr char kWrittenByKey[] = "writtenBy";
constexpr char kFramePathsNode[] = "framePaths";
constexpr char kWrittenByValue[] = "evfs";

static_assert(sizeof(fb::Event) == kEventBytes, "fb::Event is the format's 16-byte event");
// Aedat4Compression and the format's values convert by a cast.
static_assert(
    static_cast<int>(Aedat4Compression::kNone) == static_cast<int>(fb::Compression::None) &&
        static_cast<int>(Aedat4Compression::kLz4) == static_cast<int>(fb::Compression::Lz4) &&
        static_cast<int>(Aedat4Compression::kLz4High) ==
            static_cast<int>(fb::Compression::Lz4High) &&
        static_cast<int>(Aedat4Compression::kZstd) == static_cast<int>(fb::Compression::Zstd) &&
        static_cast<int>(Aedat4Compression::kZstdHigh) ==
            static_cast<int>(fb::Compression::ZstdHigh),
    "Aedat4Compression follows IOHeader.compression");

uint32_t ReadU32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 |
         static_cast<uint32_t>(p[2]) << 16 | static_cast<uint32_t>(p[3]) << 24;
}

int32_t ReadI32(const uint8_t* p) {
  const uint32_t value = ReadU32(p);
  int32_t result;
  std::memcpy(&result, &value, sizeof(result));
  return result;
}

// "frame_00000012"-style default name of frame `index` in a data folder (as in text_folder.cc).
std::string DefaultFramePath(size_t index) {
  char name[40];
  std::snprintf(name, sizeof(name), "images/frame_%08zu.png", index);
  return name;
}

bool StartsWith(const uint8_t* data, size_t size, const char* prefix, size_t prefix_bytes) {
  return size >= prefix_bytes && std::memcmp(data, prefix, prefix_bytes) == 0;
}

// ---------------------------------------------------------------------------------------------
// Decompression: one LZ4 or Zstd frame per packet.

class Decompressor {
 public:
  Decompressor() = default;
  ~Decompressor() {
    if (lz4_ != nullptr) LZ4F_freeDecompressionContext(lz4_);
    if (zstd_ != nullptr) ZSTD_freeDCtx(zstd_);
  }
  Decompressor(const Decompressor&) = delete;
  Decompressor& operator=(const Decompressor&) = delete;

  // Decompresses the one frame [data, data + size) into *out; returns what is wrong, or "".
  std::string Decompress(Aedat4Compression compression, const uint8_t* data, size_t size,
                         std::vector<uint8_t>* out) {
    switch (compression) {
      case Aedat4Compression::kNone:
        if (size > kMaxPacketBytes) return TooLarge();
        out->assign(data, data + size);
        return "";
      case Aedat4Compression::kLz4:
      case Aedat4Compression::kLz4High:
        return DecompressLz4(data, size, out);
      case Aedat4Compression::kZstd:
      case Aedat4Compression::kZstdHigh:
        return DecompressZstd(data, size, out);
    }
    return "unknown compression";
  }

 private:
  // Makes room in *out beyond `produced` bytes: doubles it, up to one byte past the limit (so
  // that a frame exceeding it is seen to). False when it is already past the limit.
  static bool Grow(size_t produced, std::vector<uint8_t>* out) {
    if (produced < out->size()) return true;
    if (out->size() > kMaxPacketBytes) return false;
    out->resize(std::min(std::max(out->size() * 2, kInitialOutputBytes), kMaxPacketBytes + 1));
    return true;
  }

  static std::string TooLarge() {
    return "decompresses to more than " + std::to_string(kMaxPacketBytes >> 20) +
           " MiB (corrupt, or not a packet evfs reads)";
  }

  // Sizes *out for a frame of `size` compressed bytes that declares `content_bytes` (0: none):
  // one byte more than declared, so that the frame ends with room to spare (the decoders check
  // the declared size themselves), but no more than kMaxDeclaredRatio times the input, so that a
  // header declaring much more than its data holds does not allocate it.
  static void Start(size_t size, uint64_t content_bytes, std::vector<uint8_t>* out) {
    constexpr size_t kMaxDeclaredRatio = 256;  // LZ4 cannot exceed 255:1
    const size_t guess = content_bytes > 0
                             ? std::min(static_cast<size_t>(content_bytes) + 1,
                                        std::max(kInitialOutputBytes, kMaxDeclaredRatio * size))
                             : std::max(kInitialOutputBytes, 4 * size);
    out->resize(std::min(guess, kMaxPacketBytes + 1));
  }

  std::string DecompressLz4(const uint8_t* data, size_t size, std::vector<uint8_t>* out) {
    if (lz4_ == nullptr) {
      if (LZ4F_isError(LZ4F_createDecompressionContext(&lz4_, LZ4F_VERSION))) {
        lz4_ = nullptr;
        throw std::bad_alloc();
      }
    } else {
      LZ4F_resetDecompressionContext(lz4_);
    }
    // The frame header first: a frame declaring more than a packet may hold is refused before
    // anything is allocated for it.
    LZ4F_frameInfo_t info;
    size_t consumed = size;
    const size_t header_hint = LZ4F_getFrameInfo(lz4_, &info, data, &consumed);
    if (LZ4F_isError(header_hint)) {
      return std::string("corrupt LZ4 frame (") + LZ4F_getErrorName(header_hint) + ")";
    }
    if (info.contentSize > kMaxPacketBytes) return TooLarge();
    Start(size, info.contentSize, out);
    size_t produced = 0;
    for (;;) {
      if (!Grow(produced, out)) return TooLarge();
      size_t out_bytes = out->size() - produced;
      size_t in_bytes = size - consumed;
      const size_t hint = LZ4F_decompress(lz4_, out->data() + produced, &out_bytes, data + consumed,
                                          &in_bytes, nullptr);
      if (LZ4F_isError(hint)) {
        return std::string("corrupt LZ4 frame (") + LZ4F_getErrorName(hint) + ")";
      }
      produced += out_bytes;
      consumed += in_bytes;
      if (hint == 0) break;  // the frame is complete
      if (produced < out->size() && (consumed == size || (out_bytes == 0 && in_bytes == 0))) {
        return "truncated LZ4 frame";
      }
    }
    if (produced > kMaxPacketBytes) return TooLarge();
    if (consumed != size) {
      return std::to_string(size - consumed) + " bytes follow the LZ4 frame";
    }
    out->resize(produced);
    return "";
  }

  std::string DecompressZstd(const uint8_t* data, size_t size, std::vector<uint8_t>* out) {
    if (zstd_ == nullptr) {
      zstd_ = ZSTD_createDCtx();
      if (zstd_ == nullptr) throw std::bad_alloc();
    } else {
      ZSTD_DCtx_reset(zstd_, ZSTD_reset_session_only);
    }
    const unsigned long long content_bytes = ZSTD_getFrameContentSize(data, size);
    if (content_bytes == ZSTD_CONTENTSIZE_ERROR) return "corrupt Zstd frame (bad header)";
    const bool known = content_bytes != ZSTD_CONTENTSIZE_UNKNOWN;
    if (known && content_bytes > kMaxPacketBytes) return TooLarge();
    Start(size, known ? content_bytes : 0, out);
    ZSTD_inBuffer input = {data, size, 0};
    size_t produced = 0;
    for (;;) {
      if (!Grow(produced, out)) return TooLarge();
      ZSTD_outBuffer output = {out->data(), out->size(), produced};
      const size_t consumed_before = input.pos;
      const size_t hint = ZSTD_decompressStream(zstd_, &output, &input);
      if (ZSTD_isError(hint)) {
        return std::string("corrupt Zstd frame (") + ZSTD_getErrorName(hint) + ")";
      }
      const bool progressed = output.pos > produced || input.pos > consumed_before;
      produced = output.pos;
      if (hint == 0) break;  // the frame is complete and flushed
      if (produced < out->size() && (input.pos == input.size || !progressed)) {
        return "truncated Zstd frame";
      }
    }
    if (produced > kMaxPacketBytes) return TooLarge();
    if (input.pos != input.size) {
      return std::to_string(input.size - input.pos) + " bytes follow the Zstd frame";
    }
    out->resize(produced);
    return "";
  }

  LZ4F_dctx* lz4_ = nullptr;
  ZSTD_DCtx* zstd_ = nullptr;
};

// Verifier limits for a buffer of `bytes`: every table takes at least 4 bytes, so the table
// count never limits a valid buffer (the data table holds one table per packet).
flatbuffers::Verifier::Options VerifierOptions(size_t bytes) {
  flatbuffers::Verifier::Options options;
  options.max_tables = static_cast<flatbuffers::uoffset_t>(bytes / 4 + 1);
  return options;
}

// ---------------------------------------------------------------------------------------------
// The stream description (IOHeader.info_node).

struct StreamInfo {
  int32_t id = -1;  // -1: no such stream
  std::string type;
  int size_x = 0;  // 0: not given
  int size_y = 0;
  int64_t ts_offset_us = 0;
};

struct Header {
  Aedat4Compression compression = Aedat4Compression::kNone;
  int64_t data_table_position = -1;
  size_t data_start = 0;  // offset of the first packet
  StreamInfo events;      // the first EVTS stream, id -1 when none
  StreamInfo frames;      // the first FRME stream, id -1 when none
  bool written_by_evfs = false;
  std::vector<std::string> frame_paths;  // from the evfs node, in frame order; may be empty
};

// Parses the header of an AEDAT 4.0 file and its stream description; throws InputError.
class HeaderParser {
 public:
  HeaderParser(std::string path, const uint8_t* data, size_t size)
      : path_(std::move(path)), data_(data), size_(size) {}

  [[noreturn]] void Fail(InputError::Kind kind, const std::string& what) const {
    throw InputError(kind, path_, 0, what);
  }

  Header Parse() {
    if (!StartsWith(data_, size_, kVersionLine, kVersionLineBytes)) {
      if (size_ < kVersionLineBytes && size_ >= kAedatPrefixBytes &&
          std::memcmp(data_, kVersionLine, size_) == 0) {
        Fail(InputError::Kind::kMalformed, "truncated inside the version line (" +
                                               std::to_string(size_) + " of its " +
                                               std::to_string(kVersionLineBytes) + " bytes)");
      }
      if (StartsWith(data_, size_, kAedatPrefix, kAedatPrefixBytes)) {
        const size_t shown = std::min<size_t>(size_, kAedatPrefixBytes + 3);
        Fail(InputError::Kind::kMalformed,
             "version line '" +
                 MessageExcerpt(reinterpret_cast<const char*>(data_),
                                reinterpret_cast<const char*>(data_) + shown) +
                 "': only AEDAT 4.0 is supported (convert older files with DV)");
      }
      Fail(InputError::Kind::kMalformed,
           "not an AEDAT 4.0 file (expected the version line '#!AER-DAT4.0')");
    }
    if (size_ < kVersionLineBytes + kSizePrefixBytes) {
      Fail(InputError::Kind::kMalformed, "truncated after the version line (no IOHeader)");
    }
    const size_t header_bytes = ReadU32(data_ + kVersionLineBytes);
    const size_t available = size_ - kVersionLineBytes - kSizePrefixBytes;
    if (header_bytes < kMinFlatbufferBytes || header_bytes > available ||
        header_bytes > kMaxHeaderBytes) {
      Fail(InputError::Kind::kMalformed, "the IOHeader declares " + std::to_string(header_bytes) +
                                             " bytes, the file has " + std::to_string(available) +
                                             " after the version line (truncated or corrupt?)");
    }
    // Copied: flatbuffers reads scalars in place, so the buffer must be aligned.
    const uint8_t* start = data_ + kVersionLineBytes;
    const std::vector<uint8_t> buffer(start, start + kSizePrefixBytes + header_bytes);
    flatbuffers::Verifier verifier(buffer.data(), buffer.size(), VerifierOptions(buffer.size()));
    if (!fb::VerifySizePrefixedIOHeaderBuffer(verifier)) {
      Fail(InputError::Kind::kMalformed, "the IOHeader is not a valid IOHE flatbuffer (corrupt?)");
    }
    const fb::IOHeader* io_header = fb::GetSizePrefixedIOHeader(buffer.data());
    Header header;
    header.data_start = kVersionLineBytes + kSizePrefixBytes + header_bytes;
    const int compression = static_cast<int>(io_header->compression());
    if (compression < 0 || compression > static_cast<int>(fb::Compression::MAX)) {
      Fail(InputError::Kind::kMalformed,
           "unknown compression " + std::to_string(compression) +
               " in the IOHeader (expected 0 NONE, 1 LZ4, 2 LZ4_HIGH, 3 ZSTD or 4 ZSTD_HIGH)");
    }
    header.compression = static_cast<Aedat4Compression>(compression);
    header.data_table_position = io_header->data_table_position();
    if (header.data_table_position != -1 &&
        (header.data_table_position < static_cast<int64_t>(header.data_start) ||
         header.data_table_position >= static_cast<int64_t>(size_))) {
      Fail(InputError::Kind::kMalformed, "the IOHeader puts the file data table at byte " +
                                             std::to_string(header.data_table_position) +
                                             ", outside the packets [" +
                                             std::to_string(header.data_start) + ", " +
                                             std::to_string(size_) + ") (truncated or corrupt?)");
    }
    if (io_header->info_node() == nullptr) {
      Fail(InputError::Kind::kMalformed, "the IOHeader has no stream description (infoNode)");
    }
    ParseStreams(io_header->info_node()->str(), &header);
    return header;
  }

 private:
  // The <node name="NAME"> child of `parent`, or nullptr.
  static const tinyxml2::XMLElement* Node(const tinyxml2::XMLElement* parent, const char* name) {
    for (const tinyxml2::XMLElement* node = parent->FirstChildElement("node"); node != nullptr;
         node = node->NextSiblingElement("node")) {
      const char* node_name = node->Attribute("name");
      if (node_name != nullptr && std::strcmp(node_name, name) == 0) return node;
    }
    return nullptr;
  }

  // The text of <attr key="KEY"> in `node`, or nullptr when it has none.
  static const char* Attr(const tinyxml2::XMLElement* node, const char* key) {
    if (node == nullptr) return nullptr;
    for (const tinyxml2::XMLElement* attr = node->FirstChildElement("attr"); attr != nullptr;
         attr = attr->NextSiblingElement("attr")) {
      const char* attr_key = attr->Attribute("key");
      if (attr_key != nullptr && std::strcmp(attr_key, key) == 0) {
        return attr->GetText() != nullptr ? attr->GetText() : "";
      }
    }
    return nullptr;
  }

  int64_t ParseInteger(const char* text, const std::string& what, int64_t min, int64_t max) const {
    std::string trimmed(text);
    const auto not_space = [](unsigned char c) { return !std::isspace(c); };
    trimmed.erase(trimmed.begin(), std::find_if(trimmed.begin(), trimmed.end(), not_space));
    trimmed.erase(std::find_if(trimmed.rbegin(), trimmed.rend(), not_space).base(), trimmed.end());
    int64_t value = 0;
    const char* end = trimmed.data() + trimmed.size();
    const auto result = std::from_chars(trimmed.data(), end, value);
    if (trimmed.empty() || result.ec != std::errc() || result.ptr != end || value < min ||
        value > max) {
      Fail(InputError::Kind::kMalformed, "stream description: " + what + " is '" +
                                             MessageExcerpt(text) + "', expected an integer in [" +
                                             std::to_string(min) + ", " + std::to_string(max) +
                                             "]");
    }
    return value;
  }

  void ParseStreams(const std::string& xml, Header* header) const {
    tinyxml2::XMLDocument document;
    if (document.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
      Fail(InputError::Kind::kMalformed,
           std::string("the stream description in the IOHeader is not XML (") +
               document.ErrorName() + " at line " + std::to_string(document.ErrorLineNum()) + ")");
    }
    const tinyxml2::XMLElement* root = document.RootElement();
    const tinyxml2::XMLElement* out_info =
        root != nullptr && std::strcmp(root->Name(), "dv") == 0 ? Node(root, "outInfo") : nullptr;
    if (out_info == nullptr) {
      Fail(InputError::Kind::kMalformed,
           "the stream description in the IOHeader has no <dv><node name=\"outInfo\">");
    }
    std::set<int64_t> ids;
    for (const tinyxml2::XMLElement* node = out_info->FirstChildElement("node"); node != nullptr;
         node = node->NextSiblingElement("node")) {
      const char* name = node->Attribute("name");
      const int64_t id = ParseInteger(name != nullptr ? name : "", "a stream id", 0,
                                      std::numeric_limits<int32_t>::max());
      if (!ids.insert(id).second) {
        Fail(InputError::Kind::kMalformed,
             "stream description: stream " + std::to_string(id) + " is described twice");
      }
      const char* type = Attr(node, "typeIdentifier");
      StreamInfo* stream = nullptr;
      if (type != nullptr && std::strcmp(type, kEventsType) == 0) stream = &header->events;
      if (type != nullptr && std::strcmp(type, kFramesType) == 0) stream = &header->frames;
      // The first stream of each type is read; later ones (another camera) are skipped, as are
      // IMU, trigger and any other streams.
      if (stream == nullptr || (stream->id >= 0 && stream->id < id)) continue;
      *stream = StreamInfo();
      stream->id = static_cast<int32_t>(id);
      stream->type = type;
      const std::string where = "stream " + std::to_string(id) + " (" + type + ") ";
      const tinyxml2::XMLElement* info = Node(node, "info");
      const char* size_x = Attr(info, "sizeX");
      const char* size_y = Attr(info, "sizeY");
      if ((size_x == nullptr) != (size_y == nullptr)) {
        Fail(InputError::Kind::kMalformed,
             "stream description: " + where + "gives only one of sizeX and sizeY");
      }
      if (size_x != nullptr) {
        const int64_t width = ParseInteger(size_x, where + "sizeX", 1, kMaxSensorSide);
        const int64_t height = ParseInteger(size_y, where + "sizeY", 1, kMaxSensorSide);
        if (width * height > kMaxSensorPixels) {
          Fail(InputError::Kind::kOutOfRange,
               "stream description: " + where + "declares a " + std::to_string(width) + "x" +
                   std::to_string(height) + " sensor: more than the " +
                   std::to_string(kMaxSensorPixels) + " pixels (8192x8192) evfs reads");
        }
        stream->size_x = static_cast<int>(width);
        stream->size_y = static_cast<int>(height);
      }
      const char* ts_offset = Attr(info, "tsOffset");
      if (ts_offset != nullptr) {
        stream->ts_offset_us =
            ParseInteger(ts_offset, where + "tsOffset", -kMaxMicroseconds, kMaxMicroseconds);
      }
    }
    if (header->events.id < 0 && header->frames.id < 0) {
      Fail(InputError::Kind::kMalformed,
           "the file has neither an EVTS (events) nor an FRME (frames) stream");
    }
    if (header->events.id >= 0 && header->events.size_x == 0) {
      Fail(InputError::Kind::kMalformed, "stream description: the EVTS stream " +
                                             std::to_string(header->events.id) +
                                             " gives no sensor size (sizeX, sizeY)");
    }
    const tinyxml2::XMLElement* evfs = Node(root, kEvfsNode);
    const char* written_by = Attr(evfs, kWrittenByKey);
    header->written_by_evfs =
        written_by != nullptr &&
        std::strncmp(written_by, kWrittenByValue, sizeof(kWrittenByValue) - 1) == 0;
    const tinyxml2::XMLElement* paths = evfs != nullptr ? Node(evfs, kFramePathsNode) : nullptr;
    for (size_t i = 0; paths != nullptr; ++i) {
      const char* frame_path = Attr(paths, std::to_string(i).c_str());
      if (frame_path == nullptr) break;
      header->frame_paths.push_back(frame_path);
    }
  }

  std::string path_;
  const uint8_t* data_;
  size_t size_;
};

}  // namespace

const char* Aedat4CompressionName(Aedat4Compression compression) {
  switch (compression) {
    case Aedat4Compression::kNone:
      return "NONE";
    case Aedat4Compression::kLz4:
      return "LZ4";
    case Aedat4Compression::kLz4High:
      return "LZ4_HIGH";
    case Aedat4Compression::kZstd:
      return "ZSTD";
    case Aedat4Compression::kZstdHigh:
      return "ZSTD_HIGH";
  }
  return "?";
}

bool Aedat4WriteOptions::IsValid(std::string* error) const {
  constexpr int kMaxEventsPerPacket = 1 << 20;  // 16 MB decompressed, within kMaxPacketBytes
  OptionChecker check;
  check.Require(max_events_per_packet >= 1 && max_events_per_packet <= kMaxEventsPerPacket,
                "max_events_per_packet", "in [1, " + std::to_string(kMaxEventsPerPacket) + "]");
  return check.Passed(error);
}

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

// ---------------------------------------------------------------------------------------------
// Reading.

class Aedat4DataSource::File {
 public:
  explicit File(MappedFile file)
      : file_(std::move(file)),
        data_(reinterpret_cast<const uint8_t*>(file_.data())),
        size_(file_.size()) {
    header_ = HeaderParser(path(), data_, size_).Parse();
    data_end_ =
        header_.data_table_position >= 0 ? static_cast<size_t>(header_.data_table_position) : size_;
    // The sensor size first: indexing without a data table checks the events against it.
    SetSensorSizeFromDescription();
    if (header_.data_table_position >= 0) {
      IndexFromDataTable();
    } else {
      IndexByScanning();
    }
    if (width_ == 0) SetSensorSizeFromFirstFrame();
    ReadFrameInfos();
  }

  const std::string& path() const { return file_.path(); }
  int width() const { return width_; }
  int height() const { return height_; }
  std::vector<FrameInfo>& frames() { return frames_; }
  const Header& header() const { return header_; }
  bool has_events() const { return header_.events.id >= 0; }
  bool indexed_by_data_table() const { return header_.data_table_position >= 0; }
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

  // Decompresses `packet` into buffer_ and checks it is a size-prefixed flatbuffer.
  const std::vector<uint8_t>& ReadBody(const Packet& packet, const char* type) const {
    return ReadFlatbuffer(data_ + packet.offset, packet.size, PacketName(packet, type));
  }

  const std::vector<uint8_t>& ReadFlatbuffer(const uint8_t* data, size_t size,
                                             const std::string& what) const {
    ++packets_decoded_;
    const std::string problem = decompressor_.Decompress(header_.compression, data, size, &buffer_);
    if (!problem.empty()) Fail(InputError::Kind::kMalformed, what + ": " + problem);
    if (buffer_.size() < kSizePrefixBytes + kMinFlatbufferBytes ||
        ReadU32(buffer_.data()) != buffer_.size() - kSizePrefixBytes) {
      Fail(InputError::Kind::kMalformed,
           what + ": " + std::to_string(buffer_.size()) +
               " bytes that are not a size-prefixed flatbuffer (corrupt?)");
    }
    return buffer_;
  }

  template <typename Visitor>
  void DecodeEvents(const Packet& packet, int64_t* previous_t_ns, Visitor&& visit) const {
    const std::vector<uint8_t>& body = ReadBody(packet, kEventsType);
    flatbuffers::Verifier verifier(body.data(), body.size(), VerifierOptions(body.size()));
    if (!fb::VerifySizePrefixedEventPacketBuffer(verifier)) {
      Fail(InputError::Kind::kMalformed,
           PacketName(packet, kEventsType) + ": not a valid EVTS flatbuffer (corrupt?)");
    }
    const auto* elements = fb::GetSizePrefixedEventPacket(body.data())->elements();
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
    const std::vector<uint8_t>& body = ReadBody(packet, kFramesType);
    const std::string name = PacketName(packet, kFramesType);
    flatbuffers::Verifier verifier(body.data(), body.size(), VerifierOptions(body.size()));
    if (!fb::VerifySizePrefixedFrameBuffer(verifier)) {
      Fail(InputError::Kind::kMalformed, name + ": not a valid FRME flatbuffer (corrupt?)");
    }
    const fb::Frame* frame = fb::GetSizePrefixedFrame(body.data());
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

  void IndexFromDataTable() {
    const size_t position = static_cast<size_t>(header_.data_table_position);
    const std::vector<uint8_t>& body =
        ReadFlatbuffer(data_ + position, size_ - position, "the file data table");
    flatbuffers::Verifier verifier(body.data(), body.size(), VerifierOptions(body.size()));
    if (!fb::VerifySizePrefixedFileDataTableBuffer(verifier)) {
      Fail(InputError::Kind::kMalformed,
           "the file data table is not a valid FTAB flatbuffer (corrupt?)");
    }
    const auto* table = fb::GetSizePrefixedFileDataTable(body.data())->table();
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
      if (packet.count == 0) continue;  // nothing to read
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
  }

  void IndexByScanning() {
    int64_t previous_t_ns = std::numeric_limits<int64_t>::min();
    size_t offset = header_.data_start;
    while (offset < size_) {
      if (size_ - offset < kPacketHeaderBytes) {
        Fail(InputError::Kind::kMalformed,
             "truncated packet header at byte " + std::to_string(offset) + " (truncated file?)");
      }
      const int32_t stream = ReadI32(data_ + offset);
      const int32_t size = ReadI32(data_ + offset + 4);
      const size_t remaining = size_ - offset - kPacketHeaderBytes;
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
    const StreamInfo& events = header_.events;
    const StreamInfo& frames = header_.frames;
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
      const std::vector<uint8_t>& body = ReadBody(frame_packets_.front(), kFramesType);
      flatbuffers::Verifier verifier(body.data(), body.size(), VerifierOptions(body.size()));
      if (!fb::VerifySizePrefixedFrameBuffer(verifier)) {
        Fail(InputError::Kind::kMalformed, PacketName(frame_packets_.front(), kFramesType) +
                                               ": not a valid FRME flatbuffer (corrupt?)");
      }
      const fb::Frame* frame = fb::GetSizePrefixedFrame(body.data());
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
  Header header_;
  size_t data_end_ = 0;  // packets end here: at the data table, or at the end of the file
  int width_ = 0;
  int height_ = 0;
  std::vector<Packet> event_packets_;  // sorted by time, spans not overlapping
  std::vector<Packet> frame_packets_;  // in file order
  std::vector<FrameInfo> frames_;
  mutable Decompressor decompressor_;
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
  const Header& header = file_->header();
  return header.events.id >= 0 ? header.events.ts_offset_us : header.frames.ts_offset_us;
}

bool Aedat4DataSource::indexed_by_data_table() const { return file_->indexed_by_data_table(); }

int Aedat4DataSource::num_event_packets() const { return file_->num_event_packets(); }

int64_t Aedat4DataSource::packets_decoded() const { return file_->packets_decoded(); }

Image Aedat4DataSource::ReadImage(int index) const {
  if (index < 0 || index >= static_cast<int>(frames_.size())) {
    throw InvalidArgumentError("frame index " + std::to_string(index) + " is outside [0, " +
                               std::to_string(frames_.size()) + ")");
  }
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
    return HeaderParser(path, reinterpret_cast<const uint8_t*>(file.data()), file.size())
        .Parse()
        .written_by_evfs;
  } catch (const InputError&) {
    return false;
  }
}

// ---------------------------------------------------------------------------------------------
// Writing.

namespace {

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
    flatbuffers::FlatBufferBuilder builder(stream_description.size() + 256);
    builder.ForceDefaults(true);
    const auto info = builder.CreateString(stream_description);
    const auto header =
        fb::CreateIOHeader(builder, static_cast<fb::Compression>(static_cast<int>(compression_)),
                           data_table_position, info);
    fb::FinishSizePrefixedIOHeaderBuffer(builder, header);
    if (position_ == 0) {
      Write(kVersionLine, kVersionLineBytes);
      Write(builder.GetBufferPointer(), builder.GetSize());
      header_bytes_ = builder.GetSize();
      return;
    }
    if (builder.GetSize() != header_bytes_) {
      throw std::logic_error("AEDAT 4 header changed its size");  // a bug, not the user's
    }
    if (std::fseek(file_, static_cast<long>(kVersionLineBytes), SEEK_SET) != 0) {
      Fail("cannot write the header");
    }
    if (std::fwrite(builder.GetBufferPointer(), 1, builder.GetSize(), file_) != builder.GetSize()) {
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

// The XML stream description DV writes (see the IOHeader of a DV recording), plus the evfs node.
std::string StreamDescription(int width, int height, bool with_events, bool with_frames,
                              Aedat4Compression compression, const std::vector<FrameInfo>& frames) {
  tinyxml2::XMLDocument document;
  const auto add_node = [&](tinyxml2::XMLElement* parent, const std::string& name,
                            const std::string& path) {
    tinyxml2::XMLElement* node = document.NewElement("node");
    node->SetAttribute("name", name.c_str());
    node->SetAttribute("path", path.c_str());
    parent->InsertEndChild(node);
    return node;
  };
  const auto add_attr = [&](tinyxml2::XMLElement* node, const std::string& key, const char* type,
                            const std::string& value) {
    tinyxml2::XMLElement* attr = document.NewElement("attr");
    attr->SetAttribute("key", key.c_str());
    attr->SetAttribute("type", type);
    attr->SetText(value.c_str());
    node->InsertEndChild(attr);
  };
  tinyxml2::XMLElement* root = document.NewElement("dv");
  root->SetAttribute("version", "2.0");
  document.InsertEndChild(root);
  tinyxml2::XMLElement* out_info = add_node(root, "outInfo", "/outInfo/");
  const auto add_stream = [&](int32_t id, const char* type, const char* output,
                              const char* description) {
    const std::string path = "/outInfo/" + std::to_string(id) + "/";
    tinyxml2::XMLElement* stream = add_node(out_info, std::to_string(id), path);
    add_attr(stream, "compression", "string", Aedat4CompressionName(compression));
    add_attr(stream, "originalModuleName", "string", "evfs");
    add_attr(stream, "originalOutputName", "string", output);
    add_attr(stream, "typeDescription", "string", description);
    add_attr(stream, "typeIdentifier", "string", type);
    tinyxml2::XMLElement* info = add_node(stream, "info", path + "info/");
    add_attr(info, "sizeX", "int", std::to_string(width));
    add_attr(info, "sizeY", "int", std::to_string(height));
    add_attr(info, "source", "string", "evfs");
    // The stored times are the recording's own; nothing was added to them.
    add_attr(info, "tsOffset", "long", "0");
  };
  if (with_events) {
    add_stream(kEventsStreamId, kEventsType, "events", "Array of events (polarity ON/OFF).");
  }
  if (with_frames) {
    add_stream(kFramesStreamId, kFramesType, "frames", "Standard frame (8-bit image).");
  }
  tinyxml2::XMLElement* evfs = add_node(root, kEvfsNode, "/evfs/");
  add_attr(evfs, kWrittenByKey, "string", kWrittenByValue);
  if (with_frames) {
    tinyxml2::XMLElement* paths = add_node(evfs, kFramePathsNode, "/evfs/framePaths/");
    for (size_t i = 0; i < frames.size(); ++i) {
      add_attr(paths, std::to_string(i), "string", frames[i].path);
    }
  }
  tinyxml2::XMLPrinter printer;
  document.Print(&printer);
  return printer.CStr();
}

}  // namespace

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
  const std::string description = StreamDescription(width, height, options.with_events,
                                                    !frames.empty(), options.compression, frames);
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
