#include "evfs/io/aedat4/header.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <limits>
#include <set>
#include <utility>

#include "evfs/core/error.h"
#include "evfs/io/aedat4/format.h"
#include "evfs/io/aedat4/io_header_generated.h"
#include "evfs/io/image_io.h"
#include "evfs/io/message_excerpt.h"

namespace evfs {
namespace aedat4 {
namespace {

// Most bytes of the IOHeader: the XML stream description of DV is a few KB.
constexpr size_t kMaxHeaderBytes = size_t{16} << 20;
// The node the writer adds to the stream description (beside DV's "outInfo"): it marks the file
// as evfs's and keeps the frames' images.txt paths, which the format has no place for.
constexpr char kEvfsNode[] = "evfs";
constexpr char kWrittenByKey[] = "writtenBy";
constexpr char kFramePathsNode[] = "framePaths";
constexpr char kWrittenByValue[] = "evfs";

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
    std::vector<uint8_t> buffer(start, start + kSizePrefixBytes + header_bytes);
    const fb::IOHeader* io_header =
        VerifiedSizePrefixedRoot<fb::IOHeader>(&buffer, fb::IOHeaderIdentifier());
    if (io_header == nullptr) {
      Fail(InputError::Kind::kMalformed, "the IOHeader is not a valid IOHE flatbuffer (corrupt?)");
    }
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

Header ParseHeader(const std::string& path, const uint8_t* data, size_t size) {
  return HeaderParser(path, data, size).Parse();
}

std::vector<uint8_t> IOHeaderBytes(Aedat4Compression compression, int64_t data_table_position,
                                   const std::string& stream_description) {
  flatbuffers::FlatBufferBuilder builder(stream_description.size() + 256);
  builder.ForceDefaults(true);
  const auto info = builder.CreateString(stream_description);
  const auto header =
      fb::CreateIOHeader(builder, static_cast<fb::Compression>(static_cast<int>(compression)),
                         data_table_position, info);
  fb::FinishSizePrefixedIOHeaderBuffer(builder, header);
  return std::vector<uint8_t>(builder.GetBufferPointer(),
                              builder.GetBufferPointer() + builder.GetSize());
}

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

}  // namespace aedat4

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

}  // namespace evfs
