#include "evfs/io/aedat4.h"

#include <flatbuffers/flatbuffers.h>
#include <gtest/gtest.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/data_source.h"
#include "evfs/io/text_folder.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

using test::MakeRandomEvents;
using test::ScratchDir;

constexpr char kSampleFolder[] = "aedat4_dvxplorer_sample";
// A DAVIS346 recording cut by another tool than DV: its IOHeader is aligned from the flatbuffer,
// not from the size prefix, and its data table gives offsets alone (no counts, no times).
constexpr char kStreetFolder[] = "aedat4_davis346_street";
constexpr char kSampleFile[] = "sample.aedat4";
constexpr char kVersionLine[] = "#!AER-DAT4.0\r\n";
constexpr int64_t kNsPerUs = 1000;

// ---------------------------------------------------------------------------------------------
// The independent decoding (tests/io/aedat4_reference_decode.py).

// FNV-1a over every event as the script packs it: int64 t (us), uint16 x, uint16 y, uint8 p.
constexpr uint64_t kFnvOffset = 0xcbf29ce484222325ULL;
constexpr uint64_t kFnvPrime = 0x100000001b3ULL;

uint64_t Fnv1a(const uint8_t* data, size_t size, uint64_t hash = kFnvOffset) {
  for (size_t i = 0; i < size; ++i) hash = (hash ^ data[i]) * kFnvPrime;
  return hash;
}

std::string Hex64(uint64_t value) {
  char text[20];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
  return text;
}

// The figures the script prints, computed from evfs' reading.
std::map<std::string, std::string> EventFigures(const EventStream& events) {
  std::map<std::string, std::string> figures;
  int64_t positive = 0;
  int64_t sum_dt = 0;
  int64_t sum_x = 0;
  int64_t sum_y = 0;
  uint64_t hash = kFnvOffset;
  const auto describe = [&](size_t i) {
    return std::to_string(events.t_ns(i) / kNsPerUs) + " " + std::to_string(events.x(i)) + " " +
           std::to_string(events.y(i)) + " " + (events.polarity(i) > 0 ? "1" : "0");
  };
  for (size_t i = 0; i < events.size(); ++i) {
    const int64_t t_us = events.t_ns(i) / kNsPerUs;
    const uint8_t p = events.polarity(i) > 0 ? 1 : 0;
    positive += p;
    sum_dt += t_us - events.t_ns(0) / kNsPerUs;
    sum_x += events.x(i);
    sum_y += events.y(i);
    uint8_t packed[13];
    for (int b = 0; b < 8; ++b)
      packed[b] = static_cast<uint8_t>(static_cast<uint64_t>(t_us) >> (8 * b));
    packed[8] = static_cast<uint8_t>(events.x(i));
    packed[9] = static_cast<uint8_t>(events.x(i) >> 8);
    packed[10] = static_cast<uint8_t>(events.y(i));
    packed[11] = static_cast<uint8_t>(events.y(i) >> 8);
    packed[12] = p;
    hash = Fnv1a(packed, sizeof(packed), hash);
  }
  figures["sensor"] = std::to_string(events.width()) + " " + std::to_string(events.height());
  figures["events"] = std::to_string(events.size());
  figures["positive"] = std::to_string(positive);
  figures["sum_dt"] = std::to_string(sum_dt);
  figures["sum_x"] = std::to_string(sum_x);
  figures["sum_y"] = std::to_string(sum_y);
  figures["fnv1a64"] = Hex64(hash);
  if (!events.empty()) {
    figures["first"] = describe(0);
    figures["last"] = describe(events.size() - 1);
  }
  return figures;
}

// A python3 that has the script's modules, or "" (the tests needing it then skip).
std::string ReferencePython() {
  static const std::string python = [] {
    for (const char* candidate : {"/usr/bin/python3", "python3"}) {
      const std::string probe =
          std::string(candidate) + " -c 'import lz4.frame, zstandard, flatbuffers' >/dev/null 2>&1";
      if (std::system(probe.c_str()) == 0) return std::string(candidate);
    }
    return std::string();
  }();
  return python;
}

#define EVFS_REQUIRE_REFERENCE_PYTHON(variable)                                           \
  const std::string variable = ReferencePython();                                         \
  if (variable.empty()) {                                                                 \
    GTEST_SKIP() << "no python3 with the modules lz4, zstandard and flatbuffers (Debian " \
                    "python3-lz4 python3-zstandard python3-flatbuffers): skipping the "   \
                    "independent decoding";                                               \
  }

// Runs the script on `path`; its output lines as key -> rest of the line (the per-frame keys
// get their index appended: "frame 0", "pixel_sum 0").
std::map<std::string, std::string> RunReferenceDecoder(const std::string& python,
                                                       const std::string& path) {
  const std::string command =
      python + " " + EVFS_TEST_SOURCE_DIR + "/aedat4_reference_decode.py '" + path + "' 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  EXPECT_NE(pipe, nullptr);
  std::string output;
  char chunk[4096];
  for (size_t n; pipe != nullptr && (n = std::fread(chunk, 1, sizeof(chunk), pipe)) > 0;) {
    output.append(chunk, n);
  }
  const int status = pipe != nullptr ? pclose(pipe) : -1;
  EXPECT_EQ(status, 0) << "the reference decoder failed:\n" << output;
  std::map<std::string, std::string> figures;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream fields(line);
    std::string key;
    fields >> key;
    if (key == "frame" || key == "pixel_sum") {
      std::string index;
      fields >> index;
      key += " " + index;
    }
    std::string rest;
    std::getline(fields >> std::ws, rest);
    figures[key] = rest;
  }
  return figures;
}

// ---------------------------------------------------------------------------------------------
// Files built by hand: flatbuffers assembled field by field with the library's generic builder
// (slot numbers from the published schemas), not with the reader's generated code.

// One event as the format stores it (struct Event: int64, int16, int16, bool, 3 bytes padding).
struct RawEvent {
  int64_t t_us;
  int16_t x;
  int16_t y;
  uint8_t polarity;
  uint8_t padding[3];
};
static_assert(sizeof(RawEvent) == 16, "the format's event is 16 bytes");

struct RawPacketHeader {
  int32_t stream_id;
  int32_t size;
};

std::string Bytes(const flatbuffers::FlatBufferBuilder& builder) {
  return std::string(reinterpret_cast<const char*>(builder.GetBufferPointer()), builder.GetSize());
}

// Field `slot` (0-based, in schema order) of a table: its vtable offset.
constexpr flatbuffers::voffset_t Slot(int slot) {
  return static_cast<flatbuffers::voffset_t>(4 + 2 * slot);
}

std::string Le32(int32_t value) {
  std::string bytes(4, '\0');
  for (int b = 0; b < 4; ++b) bytes[b] = static_cast<char>(static_cast<uint32_t>(value) >> (8 * b));
  return bytes;
}

// How a writer puts the size in front of a flatbuffer. A builder aligns every field from the
// end of the buffer and pads its front to a whole number of the largest alignment (8 bytes
// here): DV finishes with the size prefix inside that whole (FinishSizePrefixed), other writers
// finish the flatbuffer alone and then write its size in front, so that every field lies 4 bytes
// off where DV's would, counted from the prefix.
enum class Layout { kDv, kSizeWrittenAfter };

// The size-prefixed flatbuffer whose root table `root` is in `builder`.
std::string Finish(flatbuffers::FlatBufferBuilder* builder, flatbuffers::uoffset_t root,
                   const char* identifier, Layout layout) {
  const flatbuffers::Offset<flatbuffers::Table> table(root);
  if (layout == Layout::kDv) {
    builder->FinishSizePrefixed(table, identifier);
    return Bytes(*builder);
  }
  builder->Finish(table, identifier);
  return Le32(static_cast<int32_t>(builder->GetSize())) + Bytes(*builder);
}

std::string HeaderBytes(int32_t compression, int64_t data_table_position, const std::string& xml,
                        Layout layout = Layout::kDv) {
  flatbuffers::FlatBufferBuilder builder;
  builder.ForceDefaults(true);
  const auto info = builder.CreateString(xml);
  const auto start = builder.StartTable();
  builder.AddElement<int32_t>(Slot(0), compression, 0);
  builder.AddElement<int64_t>(Slot(1), data_table_position, -1);
  builder.AddOffset(Slot(2), info);
  return kVersionLine + Finish(&builder, builder.EndTable(start), "IOHE", layout);
}

std::string EventPacketBody(const std::vector<RawEvent>& events, Layout layout = Layout::kDv) {
  flatbuffers::FlatBufferBuilder builder;
  const auto elements = builder.CreateVectorOfStructs(events.data(), events.size());
  const auto start = builder.StartTable();
  builder.AddOffset(Slot(0), elements);
  return Finish(&builder, builder.EndTable(start), "EVTS", layout);
}

std::string FrameBody(int64_t t_us, int64_t exposure_begin_us, int64_t exposure_end_us,
                      int8_t format, int16_t width, int16_t height,
                      const std::vector<uint8_t>& pixels, Layout layout = Layout::kDv) {
  flatbuffers::FlatBufferBuilder builder;
  const auto pixel_vector = builder.CreateVector(pixels);
  const auto start = builder.StartTable();
  builder.AddElement<int64_t>(Slot(0), t_us, 0);
  builder.AddElement<int64_t>(Slot(3), exposure_begin_us, 0);
  builder.AddElement<int64_t>(Slot(4), exposure_end_us, 0);
  builder.AddElement<int8_t>(Slot(5), format, 0);
  builder.AddElement<int16_t>(Slot(6), width, 0);
  builder.AddElement<int16_t>(Slot(7), height, 0);
  builder.AddOffset(Slot(10), pixel_vector);
  return Finish(&builder, builder.EndTable(start), "FRME", layout);
}

struct TableEntry {
  int64_t byte_offset;
  RawPacketHeader header;
  int64_t count;
  int64_t t_first_us;
  int64_t t_last_us;
};

std::string DataTableBody(const std::vector<TableEntry>& entries, Layout layout = Layout::kDv) {
  flatbuffers::FlatBufferBuilder builder;
  std::vector<flatbuffers::Offset<flatbuffers::Table>> tables;
  for (const TableEntry& entry : entries) {
    const auto start = builder.StartTable();
    builder.AddElement<int64_t>(Slot(0), entry.byte_offset, 0);
    builder.AddStruct(Slot(1), &entry.header);
    builder.AddElement<int64_t>(Slot(2), entry.count, 0);
    builder.AddElement<int64_t>(Slot(3), entry.t_first_us, 0);
    builder.AddElement<int64_t>(Slot(4), entry.t_last_us, 0);
    tables.emplace_back(builder.EndTable(start));
  }
  const auto vector = builder.CreateVector(tables);
  const auto start = builder.StartTable();
  builder.AddOffset(Slot(0), vector);
  return Finish(&builder, builder.EndTable(start), "FTAB", layout);
}

// DV's stream description for the given streams: (id, type, sizeX, sizeY); sizeX 0 omits the
// size.
struct StreamSpec {
  int id;
  const char* type;
  int size_x;
  int size_y;
};

std::string StreamXml(const std::vector<StreamSpec>& streams) {
  std::string xml = "<dv version=\"2.0\">\n <node name=\"outInfo\" path=\"/outInfo/\">\n";
  for (const StreamSpec& s : streams) {
    xml += "  <node name=\"" + std::to_string(s.id) + "\" path=\"/outInfo/" + std::to_string(s.id) +
           "/\">\n   <attr key=\"compression\" type=\"string\">NONE</attr>\n" +
           "   <attr key=\"typeIdentifier\" type=\"string\">" + s.type + "</attr>\n" +
           "   <node name=\"info\" path=\"/outInfo/" + std::to_string(s.id) + "/info/\">\n";
    if (s.size_x > 0) {
      xml += "    <attr key=\"sizeX\" type=\"int\">" + std::to_string(s.size_x) + "</attr>\n" +
             "    <attr key=\"sizeY\" type=\"int\">" + std::to_string(s.size_y) + "</attr>\n";
    }
    xml += "    <attr key=\"tsOffset\" type=\"long\">1000</attr>\n   </node>\n  </node>\n";
  }
  return xml + " </node>\n</dv>\n";
}

std::string Packet(int32_t stream_id, const std::string& body) {
  return Le32(stream_id) + Le32(static_cast<int32_t>(body.size())) + body;
}

// The minimal recording of the hand-built tests: a 4x3 sensor, three events on stream 0, an IMU
// packet on stream 2 (skipped), a grey frame and a BGR frame on stream 5, uncompressed.
constexpr int kHandWidth = 4;
constexpr int kHandHeight = 3;
const std::vector<RawEvent> kHandEvents = {
    {100, 0, 0, 1, {}}, {100, 3, 2, 0, {}}, {250, 1, 2, 7, {}}};  // 7: any non-zero is ON

std::vector<uint8_t> HandGreyPixels() {
  std::vector<uint8_t> pixels(kHandWidth * kHandHeight);
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<uint8_t>(20 * i + 5);
  return pixels;
}

// Every pixel (blue, green, red) = (10, 200, 60).
constexpr uint8_t kBgr[3] = {10, 200, 60};

// The layout of each kind of flatbuffer in a hand-built file.
struct Layouts {
  Layout header = Layout::kDv;
  Layout events = Layout::kDv;
  Layout frames = Layout::kDv;
  Layout table = Layout::kDv;
};

std::vector<std::string> HandPackets(const Layouts& layouts) {
  std::vector<uint8_t> bgr;
  for (int i = 0; i < kHandWidth * kHandHeight; ++i) bgr.insert(bgr.end(), kBgr, kBgr + 3);
  return {Packet(0, EventPacketBody({kHandEvents[0], kHandEvents[1]}, layouts.events)),
          Packet(2, std::string(24, '\x7f')),
          Packet(5, FrameBody(200, 150, 250, 0, kHandWidth, kHandHeight, HandGreyPixels(),
                              layouts.frames)),
          Packet(0, EventPacketBody({kHandEvents[2]}, layouts.events)),
          Packet(5, FrameBody(400, 0, 0, 16, kHandWidth, kHandHeight, bgr, layouts.frames))};
}

std::string HandXml() {
  return StreamXml({{0, "EVTS", kHandWidth, kHandHeight},
                    {2, "IMUS", 0, 0},
                    {5, "FRME", kHandWidth, kHandHeight}});
}

// The hand-built file without a data table.
std::string HandBuiltFile(const Layouts& layouts = Layouts()) {
  std::string file = HeaderBytes(0, -1, HandXml(), layouts.header);
  for (const std::string& packet : HandPackets(layouts)) file += packet;
  return file;
}

// The same with a data table for every packet; `mutate` may change the entries first.
template <typename Mutate>
std::string HandBuiltFileWithTable(Mutate&& mutate, const Layouts& layouts = Layouts()) {
  // The same size for every position.
  const std::string probe = HeaderBytes(0, 1, HandXml(), layouts.header);
  std::string packets;
  std::vector<TableEntry> entries;
  const std::vector<std::vector<RawEvent>> event_packets = {{kHandEvents[0], kHandEvents[1]},
                                                            {kHandEvents[2]}};
  size_t event_packet = 0;
  for (const std::string& packet : HandPackets(layouts)) {
    RawPacketHeader header;
    std::memcpy(&header, packet.data(), sizeof(header));
    TableEntry entry{static_cast<int64_t>(probe.size() + packets.size() + 8), header, 1, 0, 0};
    if (header.stream_id == 0) {
      const auto& events = event_packets[event_packet++];
      entry.count = static_cast<int64_t>(events.size());
      entry.t_first_us = events.front().t_us;
      entry.t_last_us = events.back().t_us;
    }
    entries.push_back(entry);
    packets += packet;
  }
  mutate(&entries);
  return HeaderBytes(0, static_cast<int64_t>(probe.size() + packets.size()), HandXml(),
                     layouts.header) +
         packets + DataTableBody(entries, layouts.table);
}

std::string HandBuiltFileWithTable() {
  return HandBuiltFileWithTable([](std::vector<TableEntry>*) {});
}

std::unique_ptr<Aedat4DataSource> FromBytes(const std::string& bytes) {
  return Aedat4DataSource::FromMemory("test.aedat4", bytes.data(), bytes.size());
}

// Opens `bytes` and reads everything in it.
void ReadEverything(const std::string& bytes) {
  const auto source = FromBytes(bytes);
  source->ReadAllEvents();
  source->Summarize();
  for (int i = 0; i < static_cast<int>(source->frames().size()); ++i) source->ReadImage(i);
}

std::string ReadFile(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
}

// The message of the InputError `bytes` gives when opened and read whole ("" when none).
std::string ErrorOf(const std::string& bytes) {
  try {
    ReadEverything(bytes);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// ---------------------------------------------------------------------------------------------
// The real DV recording.

TEST(Aedat4RealSampleTest, AgreesWithIndependentDecoding) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_REFERENCE_PYTHON(python);
  const std::string path = data_dir + "/" + kSampleFolder + "/" + kSampleFile;
  const std::map<std::string, std::string> reference = RunReferenceDecoder(python, path);

  const Aedat4DataSource source(path);
  EXPECT_TRUE(source.indexed_by_data_table());
  EXPECT_EQ(source.compression(), Aedat4Compression::kLz4);
  EXPECT_EQ(reference.at("compression"), "1");
  EXPECT_EQ(std::to_string(source.ts_offset_us()), reference.at("ts_offset_us"));
  EXPECT_EQ(std::to_string(source.num_event_packets()), reference.at("packets"));
  EXPECT_TRUE(source.frames().empty());
  EXPECT_EQ(reference.at("frames"), "0");

  const EventStream all = source.ReadAllEvents();
  ASSERT_FALSE(all.empty());
  const std::map<std::string, std::string> mine = EventFigures(all);
  for (const char* key : {"sensor", "events", "positive", "first", "last", "sum_dt", "fnv1a64"}) {
    EXPECT_EQ(mine.at(key), reference.at(key)) << key;
  }
  const EventSummary summary = source.Summarize();
  EXPECT_EQ(std::to_string(summary.count), reference.at("events"));
  EXPECT_EQ(std::to_string(summary.positive), reference.at("positive"));
}

TEST(Aedat4RealSampleTest, WindowedReadsAgreeWithFullReadAndDecodeFewPackets) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const Aedat4DataSource source(data_dir + "/" + kSampleFolder + "/" + kSampleFile);
  const EventStream all = source.ReadAllEvents();
  ASSERT_GT(all.size(), 1000u);
  const int64_t span = all.last_t_ns() - all.first_t_ns();
  // A window of 1/200 of the recording meets at most 2 of its ~60 event packets of ~10 ms;
  // 3 allows for one more at a boundary.
  constexpr int kMaxPacketsForSmallWindow = 3;
  for (int k = 0; k < 10; ++k) {
    const int64_t begin = all.first_t_ns() + span * k / 10 + 1234;
    for (const int64_t length : {span / 200, span / 7, span}) {
      const int64_t before = source.packets_decoded();
      EXPECT_EQ(source.ReadEvents(begin, begin + length), all.Slice(begin, begin + length))
          << "window " << k << " length " << length;
      if (length == span / 200) {
        EXPECT_LE(source.packets_decoded() - before, kMaxPacketsForSmallWindow);
      }
    }
  }
  // Windows starting exactly at events (runs of equal times) and before / after everything.
  for (const size_t i : {size_t{0}, all.size() / 3, all.size() - 1}) {
    const int64_t t = all.t_ns(i);
    EXPECT_EQ(source.ReadEvents(t, t + 1), all.Slice(t, t + 1));
  }
  EXPECT_TRUE(source.ReadEvents(0, all.first_t_ns()).empty());
  EXPECT_TRUE(source.ReadEvents(all.last_t_ns() + 1, INT64_MAX).empty());
  EXPECT_TRUE(source.ReadEvents(all.last_t_ns(), all.first_t_ns()).empty());
}

TEST(Aedat4RealSampleTest, WithoutItsDataTableReadsTheSame) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string path = data_dir + "/" + kSampleFolder + "/" + kSampleFile;
  const std::string original = ReadFile(path);
  const Aedat4DataSource source(path);
  const EventStream expected = source.ReadAllEvents();
  // A recording cut short: the header's table position set to -1 (found through Flatbuffers'
  // generic table access), and the table removed.
  const size_t header_start = std::strlen(kVersionLine);
  uint32_t header_size = 0;
  std::memcpy(&header_size, original.data() + header_start, 4);
  const std::vector<uint8_t> header(original.begin() + header_start,
                                    original.begin() + header_start + 4 + header_size);
  const auto* table = flatbuffers::GetSizePrefixedRoot<flatbuffers::Table>(header.data());
  const uint8_t* position_field = table->GetAddressOf(Slot(1));
  ASSERT_NE(position_field, nullptr);
  const size_t field = header_start + static_cast<size_t>(position_field - header.data());
  const int64_t table_position = table->GetField<int64_t>(Slot(1), -1);
  ASSERT_GT(table_position, 0);
  std::string cut = original.substr(0, static_cast<size_t>(table_position));
  const int64_t none = -1;
  std::memcpy(&cut[field], &none, 8);
  const auto scanned = FromBytes(cut);
  EXPECT_FALSE(scanned->indexed_by_data_table());
  EXPECT_EQ(scanned->num_event_packets(), source.num_event_packets());
  const EventStream all = scanned->ReadAllEvents();
  EXPECT_EQ(all, expected);
  const int64_t middle = all.t_ns(all.size() / 2);
  EXPECT_EQ(scanned->ReadEvents(middle, middle + 5000000), all.Slice(middle, middle + 5000000));
}

TEST(Aedat4RealSampleTest, OpensThroughDataSourceAndIsNotEvfsOwn) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string path = data_dir + "/" + kSampleFolder + "/" + kSampleFile;
  const auto source = DataSource::Open(path);
  EXPECT_EQ(source->width(), 320);
  EXPECT_EQ(source->height(), 240);
  EXPECT_TRUE(source->has_events());
  EXPECT_FALSE(IsAedat4WrittenByEvfs(path));
}

// What `evfs info` shows of it, the figures its source gives.
TEST(Aedat4StreetSampleTest, ReadsItsFramesAndEvents) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string path = data_dir + "/" + kStreetFolder + "/" + kSampleFile;
  const auto opened = DataSource::Open(path);
  const auto* source = dynamic_cast<const Aedat4DataSource*>(opened.get());
  ASSERT_NE(source, nullptr);
  EXPECT_FALSE(IsAedat4WrittenByEvfs(path));
  EXPECT_EQ(source->compression(), Aedat4Compression::kLz4);
  // Its table gives no event counts, so the packets were indexed by a pass over them.
  EXPECT_FALSE(source->indexed_by_data_table());
  EXPECT_EQ(source->width(), 346);
  EXPECT_EQ(source->height(), 260);
  ASSERT_EQ(source->frames().size(), 4u);
  // 25 frames per second, each exposed 0.5 ms around its time.
  constexpr int64_t kFramePeriodNs = 40000000;
  constexpr int64_t kHalfExposureNs = 250000;
  for (size_t k = 0; k < 4; ++k) {
    const FrameInfo& frame = source->frames()[k];
    EXPECT_EQ(frame.t_ns, source->frames()[0].t_ns + static_cast<int64_t>(k) * kFramePeriodNs);
    EXPECT_TRUE(frame.has_exposure);
    EXPECT_EQ(frame.exposure_begin_ns, frame.t_ns - kHalfExposureNs) << k;
    EXPECT_EQ(frame.exposure_end_ns, frame.t_ns + kHalfExposureNs) << k;
    const Image image = source->ReadImage(static_cast<int>(k));
    EXPECT_EQ(image.rows(), 260);
    EXPECT_EQ(image.cols(), 346);
  }
  const EventStream all = source->ReadAllEvents();
  EXPECT_EQ(all.size(), 6676u);
  EXPECT_EQ(source->Summarize().count, 6676);
  for (size_t k = 0; k + 1 < 4; ++k) {
    const int64_t begin = source->frames()[k].t_ns;
    const int64_t end = source->frames()[k + 1].t_ns;
    const EventStream between = source->ReadEvents(begin, end);
    EXPECT_FALSE(between.empty()) << k;
    EXPECT_EQ(between, all.Slice(begin, end)) << k;
  }
}

TEST(Aedat4StreetSampleTest, AgreesWithIndependentDecoding) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_REFERENCE_PYTHON(python);
  const std::string path = data_dir + "/" + kStreetFolder + "/" + kSampleFile;
  const std::map<std::string, std::string> reference = RunReferenceDecoder(python, path);

  const Aedat4DataSource source(path);
  EXPECT_EQ(reference.at("compression"), "1");
  EXPECT_EQ(std::to_string(source.ts_offset_us()), reference.at("ts_offset_us"));
  EXPECT_EQ(std::to_string(source.num_event_packets()), reference.at("packets"));
  const EventStream all = source.ReadAllEvents();
  const std::map<std::string, std::string> mine = EventFigures(all);
  for (const char* key :
       {"sensor", "events", "positive", "first", "last", "sum_dt", "sum_x", "sum_y", "fnv1a64"}) {
    EXPECT_EQ(mine.at(key), reference.at(key)) << key;
  }
  ASSERT_EQ(reference.at("frames"), std::to_string(source.frames().size()));
  for (size_t k = 0; k < source.frames().size(); ++k) {
    const FrameInfo& frame = source.frames()[k];
    const Image image = source.ReadImage(static_cast<int>(k));
    std::vector<uint8_t> pixels;
    int64_t pixel_sum = 0;
    for (Eigen::Index row = 0; row < image.rows(); ++row) {
      for (Eigen::Index column = 0; column < image.cols(); ++column) {
        pixels.push_back(static_cast<uint8_t>(std::lround(image(row, column) * 255.0)));
        pixel_sum += pixels.back();
      }
    }
    const std::string index = std::to_string(k);
    // Grey frames (format 0) of the whole sensor.
    EXPECT_EQ(reference.at("frame " + index),
              std::to_string(frame.t_ns / kNsPerUs) + " " +
                  std::to_string(frame.exposure_begin_ns / kNsPerUs) + " " +
                  std::to_string(frame.exposure_end_ns / kNsPerUs) + " 346 260 0 " +
                  Hex64(Fnv1a(pixels.data(), pixels.size())));
    EXPECT_EQ(reference.at("pixel_sum " + index), std::to_string(pixel_sum));
  }
}

// `copy` holds the recording `original` as an AEDAT 4 file can: the frames exactly (pixels,
// times, exposures, images.txt paths), the events to the microsecond.
void ExpectSameToTheMicrosecond(const DataSource& original, const DataSource& copy,
                                const std::string& name) {
  EXPECT_EQ(copy.width(), original.width()) << name;
  EXPECT_EQ(copy.height(), original.height()) << name;
  EXPECT_EQ(copy.frames(), original.frames()) << name;
  for (int i = 0; i < static_cast<int>(original.frames().size()); ++i) {
    EXPECT_TRUE((copy.ReadImage(i) == original.ReadImage(i)).all()) << name << " frame " << i;
  }
  const EventStream expected = original.ReadAllEvents();
  const EventStream read = copy.ReadAllEvents();
  ASSERT_EQ(read.size(), expected.size()) << name;
  size_t mismatches = 0;
  for (size_t i = 0; i < read.size(); ++i) {
    // The nearest microsecond, halves up (WriteAedat4); shared times are >= 0.
    const int64_t t_us = (expected.t_ns(i) + kNsPerUs / 2) / kNsPerUs;
    mismatches += read.t_ns(i) != t_us * kNsPerUs || read.x(i) != expected.x(i) ||
                  read.y(i) != expected.y(i) || read.polarity(i) != expected.polarity(i);
  }
  EXPECT_EQ(mismatches, 0u) << name;
}

// The shared folders that are recordings (events.txt beside the frames).
std::vector<std::filesystem::path> SharedRecordingFolders(const std::string& data_dir) {
  std::vector<std::filesystem::path> folders;
  for (const auto& entry : std::filesystem::directory_iterator(data_dir)) {
    if (std::filesystem::is_regular_file(entry.path() / "events.txt")) {
      folders.push_back(entry.path());
    }
  }
  std::sort(folders.begin(), folders.end());
  return folders;
}

// Every shared data folder with events, through `evfs convert` to AEDAT 4.
TEST(Aedat4RealSampleTest, SharedFoldersConvertLosslesslyToTheMicrosecond) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string scratch = ScratchDir("aedat4_shared_folders");
  const std::vector<std::filesystem::path> folders = SharedRecordingFolders(data_dir);
  EXPECT_FALSE(folders.empty());
  for (const std::filesystem::path& folder : folders) {
    const std::string name = folder.filename().string();
    const std::string path = scratch + "/" + name + ".aedat4";
    ConvertRecording(folder.string(), path);
    ExpectSameToTheMicrosecond(*DataSource::Open(folder.string()), *DataSource::Open(path), name);
  }
}

// The acceptance test of the AEDAT 4 round trip: every shared data folder, text → AEDAT 4 → text
// through ConvertRecording (the code of `evfs convert`), is the same recording to the microsecond,
// AEDAT 4's resolution, with its frames exact. A folder of frames only comes back as one (no
// events.txt); HDF5, whose layout holds events, refuses it with one line naming `evfs simulate`.
TEST(Aedat4RealSampleTest, SharedFoldersRoundTripTextToAedat4ToText) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string scratch = ScratchDir("aedat4_shared_round_trip");
  int with_events = 0, frames_only = 0;
  for (const auto& entry : std::filesystem::directory_iterator(data_dir)) {
    const std::filesystem::path folder = entry.path();
    const std::string name = folder.filename().string();
    if (!std::filesystem::is_regular_file(folder / "images.txt")) continue;  // not a text folder
    const std::string aedat4 = scratch + "/" + name + ".aedat4";
    const std::string back = scratch + "/" + name;
    ConvertRecording(folder.string(), aedat4);
    ConvertRecording(aedat4, back);
    const auto original = DataSource::Open(folder.string());
    const auto round_trip = DataSource::Open(back);
    ASSERT_EQ(round_trip->has_events(), original->has_events()) << name;
    if (original->has_events()) {
      ExpectSameToTheMicrosecond(*original, *round_trip, name);
      ++with_events;
    } else {
      EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(back) / "events.txt")) << name;
      // Frame times (1/240 s apart in these clips) come back to the nearest microsecond.
      ASSERT_EQ(round_trip->frames().size(), original->frames().size()) << name;
      for (size_t i = 0; i < original->frames().size(); ++i) {
        const FrameInfo& frame = original->frames()[i];
        EXPECT_EQ(round_trip->frames()[i].t_ns, (frame.t_ns + kNsPerUs / 2) / kNsPerUs * kNsPerUs)
            << name << " frame " << i;
        EXPECT_EQ(round_trip->frames()[i].path, frame.path) << name;
        EXPECT_TRUE(
            (round_trip->ReadImage(static_cast<int>(i)) == original->ReadImage(static_cast<int>(i)))
                .all())
            << name << " frame " << i;
      }
      EXPECT_THROW(ConvertRecording(folder.string(), scratch + "/" + name + ".h5"), InputError)
          << name;
      ++frames_only;
    }
  }
  std::printf("round trips: %d folders with events, %d of frames only\n", with_events, frames_only);
  EXPECT_EQ(with_events, static_cast<int>(SharedRecordingFolders(data_dir).size()));
  EXPECT_GT(with_events, 0);
  EXPECT_GT(frames_only, 0);
}

// ---------------------------------------------------------------------------------------------
// Round trips through the writer.

struct Recording {
  EventStream events;
  std::vector<FrameInfo> frames;
  std::vector<Image> images;
};

// Random 8-bit frames with and without exposures, and events on whole microseconds.
Recording MakeRecording(int width, int height, int num_events, uint32_t seed) {
  Recording recording;
  const EventStream random = MakeRandomEvents(seed, num_events, width, height, 1000000, 3000);
  recording.events = EventStream(width, height);
  for (size_t i = 0; i < random.size(); ++i) {
    recording.events.push_back(random.t_ns(i) / kNsPerUs * kNsPerUs, random.x(i), random.y(i),
                               random.polarity(i));
  }
  std::mt19937 generator(seed);
  std::uniform_int_distribution<int> value(0, 255);
  for (int k = 0; k < 3; ++k) {
    FrameInfo frame;
    frame.t_ns = 1000000 + 2000000 * k + 7000;  // between and around the events
    frame.path = "frames/cam0_" + std::to_string(k) + ".png";
    frame.has_exposure = k != 1;
    if (frame.has_exposure) {
      frame.exposure_begin_ns = frame.t_ns - 500000;
      frame.exposure_end_ns = frame.t_ns + 500000;
    }
    Image image(height, width);
    for (Eigen::Index i = 0; i < image.size(); ++i) image.data()[i] = value(generator) / 255.0;
    recording.frames.push_back(frame);
    recording.images.push_back(image);
  }
  return recording;
}

class Aedat4RoundTripTest : public ::testing::TestWithParam<Aedat4Compression> {};

TEST_P(Aedat4RoundTripTest, ReadsBackWhatWasWritten) {
  const std::string path =
      ScratchDir("aedat4_round_trip_" + std::to_string(static_cast<int>(GetParam()))) +
      "/recording.aedat4";
  const Recording recording = MakeRecording(64, 48, 5000, 7);
  Aedat4WriteOptions options;
  options.compression = GetParam();
  options.max_events_per_packet = 700;  // several packets between frames
  WriteAedat4(path, recording.events, recording.frames, recording.images, options);

  EXPECT_TRUE(IsAedat4WrittenByEvfs(path));
  const Aedat4DataSource source(path);
  EXPECT_TRUE(source.indexed_by_data_table());
  EXPECT_EQ(source.compression(), GetParam());
  EXPECT_EQ(source.num_event_packets(), 8);  // ceil(5000 / 700)
  EXPECT_EQ(source.width(), 64);
  EXPECT_EQ(source.height(), 48);
  EXPECT_EQ(source.frames(), recording.frames);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE((source.ReadImage(i) == recording.images[static_cast<size_t>(i)]).all()) << i;
  }
  const EventStream all = source.ReadAllEvents();
  EXPECT_EQ(all, recording.events);
  EXPECT_EQ(source.Summarize().count, 5000);
  for (int k = 0; k < 20; ++k) {
    const int64_t begin = recording.events.t_ns(static_cast<size_t>(k) * 250) + (k % 2);
    const int64_t end = begin + 123456 * (k + 1);
    EXPECT_EQ(source.ReadEvents(begin, end), recording.events.Slice(begin, end)) << k;
  }
  if (GetParam() == Aedat4Compression::kNone) return;
  // Compressed packets carry a checksum: one changed byte in the middle of the first packet's
  // body is an error, not a wrong event.
  std::string bytes = ReadFile(path);
  uint32_t header_bytes = 0;
  std::memcpy(&header_bytes, bytes.data() + std::strlen(kVersionLine), 4);
  const size_t first_body = std::strlen(kVersionLine) + 4 + header_bytes + 8;
  int32_t body_bytes = 0;
  std::memcpy(&body_bytes, bytes.data() + first_body - 4, 4);
  bytes[first_body + static_cast<size_t>(body_bytes) / 2] ^= 0x10;
  EXPECT_THROW(ReadEverything(bytes), InputError);
}

TEST_P(Aedat4RoundTripTest, IndependentDecoderReadsTheWriterOutput) {
  EVFS_REQUIRE_REFERENCE_PYTHON(python);
  const std::string path =
      ScratchDir("aedat4_independent_" + std::to_string(static_cast<int>(GetParam()))) +
      "/recording.aedat4";
  const Recording recording = MakeRecording(32, 24, 2000, 11);
  Aedat4WriteOptions options;
  options.compression = GetParam();
  options.max_events_per_packet = 300;
  WriteAedat4(path, recording.events, recording.frames, recording.images, options);
  const std::map<std::string, std::string> reference = RunReferenceDecoder(python, path);
  const std::map<std::string, std::string> mine = EventFigures(recording.events);
  for (const char* key : {"sensor", "events", "positive", "first", "last", "sum_dt", "fnv1a64"}) {
    EXPECT_EQ(mine.at(key), reference.at(key)) << key;
  }
  EXPECT_EQ(reference.at("frames"), "3");
  EXPECT_EQ(reference.at("table_entries"), std::to_string(7 + 3));  // ceil(2000 / 300) + frames
  for (size_t k = 0; k < 3; ++k) {
    const FrameInfo& frame = recording.frames[k];
    std::vector<uint8_t> pixels(static_cast<size_t>(recording.images[k].size()));
    for (size_t i = 0; i < pixels.size(); ++i) {
      pixels[i] = static_cast<uint8_t>(std::lround(recording.images[k].data()[i] * 255.0));
    }
    const int64_t t_us = frame.t_ns / kNsPerUs;
    const int64_t begin_us = frame.has_exposure ? frame.exposure_begin_ns / kNsPerUs : t_us;
    const int64_t end_us = frame.has_exposure ? frame.exposure_end_ns / kNsPerUs : t_us;
    EXPECT_EQ(reference.at("frame " + std::to_string(k)),
              std::to_string(t_us) + " " + std::to_string(begin_us) + " " + std::to_string(end_us) +
                  " 32 24 0 " + Hex64(Fnv1a(pixels.data(), pixels.size())));
  }
}

INSTANTIATE_TEST_SUITE_P(EveryCompression, Aedat4RoundTripTest,
                         ::testing::Values(Aedat4Compression::kNone, Aedat4Compression::kLz4,
                                           Aedat4Compression::kLz4High, Aedat4Compression::kZstd,
                                           Aedat4Compression::kZstdHigh),
                         [](const ::testing::TestParamInfo<Aedat4Compression>& info) {
                           std::string name = Aedat4CompressionName(info.param);
                           name.erase(std::remove(name.begin(), name.end(), '_'), name.end());
                           return name;
                         });

TEST(Aedat4WriterTest, RoundsTimesToMicroseconds) {
  const std::string path = ScratchDir("aedat4_rounding") + "/r.aedat4";
  EventStream events(8, 8);
  events.push_back(1499, 1, 1, 1);   // -> 1 us
  events.push_back(1500, 2, 2, -1);  // -> 2 us (halves round up)
  events.push_back(2400, 3, 3, 1);   // -> 2 us
  WriteAedat4(path, events, {}, {});
  const EventStream read = Aedat4DataSource(path).ReadAllEvents();
  ASSERT_EQ(read.size(), 3u);
  EXPECT_EQ(read.t_ns(0), 1000);
  EXPECT_EQ(read.t_ns(1), 2000);
  EXPECT_EQ(read.t_ns(2), 2000);
  EXPECT_EQ(read.polarity(1), -1);
}

TEST(Aedat4WriterTest, RefusesWhatTheFormatCannotHold) {
  const std::string folder = ScratchDir("aedat4_refuses");
  EventStream events(4, 4);
  events.push_back(1000, 1, 1, 1);
  Image fine(4, 4);
  fine.setConstant(1000.0 / 65535.0);  // a 16-bit value
  FrameInfo frame;
  frame.t_ns = 5000;
  frame.path = "images/a.png";
  EXPECT_THROW(WriteAedat4(folder + "/a.aedat4", events, {frame}, {fine}), InvalidArgumentError);
  Image coarse(4, 4);
  coarse.setConstant(0.0);
  FrameInfo second = frame;
  second.t_ns = frame.t_ns + 400;  // the same microsecond
  second.path = "images/b.png";
  EXPECT_THROW(WriteAedat4(folder + "/b.aedat4", events, {frame, second}, {coarse, coarse}),
               InvalidArgumentError);
  Aedat4WriteOptions options;
  options.max_events_per_packet = 0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THROW(WriteAedat4(folder + "/c.aedat4", events, {}, {}, options), InvalidArgumentError);
  EXPECT_THROW(WriteAedat4(folder + "/no/such/folder/d.aedat4", events, {}, {}), InputError);
}

TEST(Aedat4WriterTest, ConvertRecordingBothWays) {
  const std::string folder = ScratchDir("aedat4_convert");
  const Recording recording = MakeRecording(20, 10, 300, 3);
  std::vector<FrameInfo> frames = recording.frames;
  for (size_t k = 0; k < frames.size(); ++k)
    frames[k].path = "images/f" + std::to_string(k) + ".png";
  WriteDataFolder(folder + "/text", recording.events, frames, recording.images);
  ConvertRecording(folder + "/text", folder + "/r.aedat4");
  // DataSource::Open knows the file by its version line too.
  std::filesystem::copy_file(folder + "/r.aedat4", folder + "/r.bin");
  EXPECT_NE(dynamic_cast<Aedat4DataSource*>(DataSource::Open(folder + "/r.bin").get()), nullptr);
  ConvertRecording(folder + "/r.aedat4", folder + "/back");
  for (const char* name : {"events.txt", "images.txt", "exposures.txt"}) {
    EXPECT_EQ(ReadFile(folder + "/back/" + name), ReadFile(folder + "/text/" + name)) << name;
  }
  const auto back = DataSource::Open(folder + "/back");
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE((back->ReadImage(k) == recording.images[static_cast<size_t>(k)]).all());
  }
}

// ---------------------------------------------------------------------------------------------
// Hand-built files.

void ExpectHandBuiltRecording(const Aedat4DataSource& source) {
  EXPECT_EQ(source.width(), kHandWidth);
  EXPECT_EQ(source.height(), kHandHeight);
  EXPECT_EQ(source.ts_offset_us(), 1000);
  EventStream expected(kHandWidth, kHandHeight);
  expected.push_back(100 * kNsPerUs, 0, 0, 1);
  expected.push_back(100 * kNsPerUs, 3, 2, -1);
  expected.push_back(250 * kNsPerUs, 1, 2, 1);
  EXPECT_EQ(source.ReadAllEvents(), expected);
  EXPECT_EQ(source.ReadEvents(101 * kNsPerUs, 251 * kNsPerUs), expected.SliceIndex(2, 3));
  ASSERT_EQ(source.frames().size(), 2u);
  const FrameInfo& grey = source.frames()[0];
  EXPECT_EQ(grey.t_ns, 200 * kNsPerUs);
  EXPECT_TRUE(grey.has_exposure);
  EXPECT_EQ(grey.exposure_begin_ns, 150 * kNsPerUs);
  EXPECT_EQ(grey.exposure_end_ns, 250 * kNsPerUs);
  EXPECT_EQ(grey.path, "images/frame_00000000.png");
  EXPECT_FALSE(source.frames()[1].has_exposure);  // written as 0 .. 0
  EXPECT_EQ(source.frames()[1].path, "images/frame_00000001.png");
  const Image image = source.ReadImage(0);
  const std::vector<uint8_t> pixels = HandGreyPixels();
  for (int row = 0; row < kHandHeight; ++row) {
    for (int column = 0; column < kHandWidth; ++column) {
      EXPECT_EQ(image(row, column), pixels[static_cast<size_t>(row * kHandWidth + column)] / 255.0);
    }
  }
  // OpenCV's BGR to grey: 0.299 R + 0.587 G + 0.114 B, rounded: 0.299*60 + 0.587*200 + 0.114*10
  // = 136.48 -> 136.
  constexpr double kGreyOfBgr = 136.0 / 255.0;
  EXPECT_TRUE((source.ReadImage(1) == kGreyOfBgr).all()) << source.ReadImage(1) * 255.0;
}

TEST(Aedat4HandBuiltTest, MinimalFileWithoutDataTable) {
  const std::string bytes = HandBuiltFile();
  const auto source = FromBytes(bytes);
  EXPECT_FALSE(source->indexed_by_data_table());
  EXPECT_EQ(source->compression(), Aedat4Compression::kNone);
  ExpectHandBuiltRecording(*source);
}

TEST(Aedat4HandBuiltTest, MinimalFileWithDataTable) {
  const std::string bytes = HandBuiltFileWithTable();
  const auto source = FromBytes(bytes);
  EXPECT_TRUE(source->indexed_by_data_table());
  EXPECT_EQ(source->num_event_packets(), 2);
  ExpectHandBuiltRecording(*source);
  EXPECT_FALSE(IsAedat4WrittenByEvfs("/nonexistent.aedat4"));
}

TEST(Aedat4HandBuiltTest, FramesOnly) {
  const std::string bytes =
      HeaderBytes(0, -1, StreamXml({{3, "FRME", 0, 0}})) +
      Packet(3, FrameBody(7, 0, 0, 0, kHandWidth, kHandHeight, HandGreyPixels()));
  const auto source = FromBytes(bytes);
  EXPECT_FALSE(source->has_events());
  EXPECT_EQ(source->width(), kHandWidth);  // from the frame: the stream gives no size
  EXPECT_EQ(source->Summarize().count, 0);
  EXPECT_THROW(source->ReadAllEvents(), InputError);
  EXPECT_EQ(source->frames().size(), 1u);
}

// Every flatbuffer of a file, aligned from its size prefix (DV) or from itself (other writers),
// in every combination.
TEST(Aedat4HandBuiltTest, FlatbuffersAlignedFromTheirSizePrefixOrFromThemselves) {
  // The two layouts differ where the test needs them to: DV's flatbuffer with its prefix is a
  // whole number of 8 bytes, the other's flatbuffer alone is.
  const size_t prefix_at = std::strlen(kVersionLine);
  ASSERT_EQ((HeaderBytes(0, -1, HandXml(), Layout::kDv).size() - prefix_at) % 8, 0u);
  ASSERT_EQ((HeaderBytes(0, -1, HandXml(), Layout::kSizeWrittenAfter).size() - prefix_at - 4) % 8,
            0u);
  for (int combination = 0; combination < 16; ++combination) {
    const auto layout = [&](int bit) {
      return (combination >> bit & 1) != 0 ? Layout::kSizeWrittenAfter : Layout::kDv;
    };
    Layouts layouts;
    layouts.header = layout(0);
    layouts.events = layout(1);
    layouts.frames = layout(2);
    layouts.table = layout(3);
    SCOPED_TRACE("combination " + std::to_string(combination));
    const std::string scanned_bytes = HandBuiltFile(layouts);
    const auto scanned = FromBytes(scanned_bytes);
    EXPECT_FALSE(scanned->indexed_by_data_table());
    ExpectHandBuiltRecording(*scanned);
    const std::string indexed_bytes =
        HandBuiltFileWithTable([](std::vector<TableEntry>*) {}, layouts);
    const auto indexed = FromBytes(indexed_bytes);
    EXPECT_TRUE(indexed->indexed_by_data_table());
    ExpectHandBuiltRecording(*indexed);
  }
}

// A data table of offsets alone, as tools that cut recordings write it: the packets are indexed
// by a pass over them, which stops at the table.
TEST(Aedat4HandBuiltTest, DataTableWithoutCountsIsNotUsedAsAnIndex) {
  const std::string bytes = HandBuiltFileWithTable([](std::vector<TableEntry>* entries) {
    for (TableEntry& entry : *entries) entry = {entry.byte_offset, entry.header, 0, 0, 0};
  });
  const auto source = FromBytes(bytes);
  EXPECT_FALSE(source->indexed_by_data_table());
  EXPECT_EQ(source->num_event_packets(), 2);
  ExpectHandBuiltRecording(*source);
}

// ---------------------------------------------------------------------------------------------
// Malformed files: one InputError each, naming what is wrong.

void ExpectError(const std::string& bytes, const std::string& part) {
  const std::string message = ErrorOf(bytes);
  EXPECT_NE(message.find(part), std::string::npos) << "message: '" << message << "'";
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(Aedat4MalformedTest, HeaderProblems) {
  ExpectError("", "not an AEDAT 4.0 file");
  ExpectError("#!AER-DAT2.0\r\n#Start\r\n", "only AEDAT 4.0 is supported");
  ExpectError(kVersionLine, "truncated after the version line");
  // Cut inside the version line: truncated, not another AEDAT version.
  ExpectError(std::string(kVersionLine, 13), "truncated inside the version line (13 of its 14");
  ExpectError(std::string(kVersionLine) + Le32(1 << 30) + "xxxx", "IOHeader declares");
  ExpectError(std::string(kVersionLine) + Le32(12) + std::string(12, '\0'), "not a valid IOHE");
  ExpectError(HeaderBytes(9, -1, HandXml()), "unknown compression 9");
  ExpectError(HeaderBytes(0, 1 << 20, HandXml()), "data table at byte");
  ExpectError(HeaderBytes(0, -1, "<dv><node name=\"outInfo\">"), "not XML");
  ExpectError(HeaderBytes(0, -1, "<dv/>"), "outInfo");
  ExpectError(HeaderBytes(0, -1, StreamXml({{0, "IMUS", 0, 0}})), "neither an EVTS");
  ExpectError(HeaderBytes(0, -1, StreamXml({{0, "EVTS", 0, 0}})), "gives no sensor size");
  ExpectError(HeaderBytes(0, -1, StreamXml({{0, "EVTS", 40000, 2}})), "sizeX");
  ExpectError(HeaderBytes(0, -1, StreamXml({{0, "EVTS", 30000, 30000}})),
              "declares a 30000x30000 sensor: more than the 67108864 pixels");
  ExpectError(HeaderBytes(0, -1, StreamXml({{0, "EVTS", 4, 3}, {0, "FRME", 4, 3}})),
              "described twice");
  ExpectError(HeaderBytes(0, -1, StreamXml({{0, "EVTS", 4, 3}, {1, "FRME", 5, 3}})),
              "the frames are 5x3");
}

TEST(Aedat4MalformedTest, PacketProblems) {
  const std::string header = HeaderBytes(0, -1, HandXml());
  ExpectError(header + "abc", "truncated packet header");
  ExpectError(header + Le32(0) + Le32(100) + "short", "declares 100 bytes");
  ExpectError(header + Le32(0) + Le32(-5), "declares -5 bytes");
  ExpectError(header + Packet(0, "not a flatbuffer at all"), "not a size-prefixed flatbuffer");
  std::string wrong_kind = FrameBody(1, 0, 0, 0, kHandWidth, kHandHeight, HandGreyPixels());
  ExpectError(header + Packet(0, wrong_kind), "not a valid EVTS flatbuffer");
  ExpectError(header + Packet(0, EventPacketBody({{5, 4, 0, 1, {}}})), "outside the 4x3 sensor");
  ExpectError(header + Packet(0, EventPacketBody({{5, 0, -1, 1, {}}})), "outside the 4x3 sensor");
  ExpectError(header + Packet(0, EventPacketBody({{5, 0, 0, 1, {}}, {4, 0, 0, 1, {}}})),
              "must not decrease");
  ExpectError(header + Packet(0, EventPacketBody({{5, 0, 0, 1, {}}})) +
                  Packet(0, EventPacketBody({{4, 0, 0, 1, {}}})),
              "must not decrease");
  ExpectError(header + Packet(0, EventPacketBody({{INT64_MAX, 0, 0, 1, {}}})),
              "beyond int64 nanoseconds");
  ExpectError(header + Packet(5, FrameBody(1, 0, 0, 0, 4, 2, std::vector<uint8_t>(8))),
              "expected the whole 4x3 sensor");
  ExpectError(header + Packet(5, FrameBody(1, 0, 0, 3, 4, 3, std::vector<uint8_t>(12))),
              "unknown pixel format 3");
  ExpectError(header + Packet(5, FrameBody(1, 0, 0, 0, 4, 3, std::vector<uint8_t>(11))),
              "11 bytes of pixels, expected 12");
  ExpectError(header + Packet(5, FrameBody(1, 9, 8, 0, 4, 3, std::vector<uint8_t>(12))),
              "exposure ends before it starts");
  ExpectError(header + Packet(5, FrameBody(2, 0, 0, 0, 4, 3, std::vector<uint8_t>(12))) +
                  Packet(5, FrameBody(2, 0, 0, 0, 4, 3, std::vector<uint8_t>(12))),
              "frame times must increase");
}

TEST(Aedat4MalformedTest, CompressedPacketProblems) {
  const std::string xml = HandXml();
  const std::string body = EventPacketBody(kHandEvents);
  std::string compressed(ZSTD_compressBound(body.size()), '\0');
  compressed.resize(ZSTD_compress(&compressed[0], compressed.size(), body.data(), body.size(), 3));
  EXPECT_EQ(FromBytes(HeaderBytes(3, -1, xml) + Packet(0, compressed))->ReadAllEvents().size(), 3u);
  ExpectError(HeaderBytes(3, -1, xml) + Packet(0, compressed.substr(0, compressed.size() - 3)),
              "truncated Zstd frame");
  ExpectError(HeaderBytes(3, -1, xml) + Packet(0, compressed + "zz"), "bytes follow the Zstd");
  ExpectError(HeaderBytes(3, -1, xml) + Packet(0, "garbage!"), "corrupt Zstd frame");
  ExpectError(HeaderBytes(1, -1, xml) + Packet(0, "garbage!"), "corrupt LZ4 frame");
  // A frame that declares 300 MiB is refused from its header, before anything is allocated.
  ZSTD_CCtx* context = ZSTD_createCCtx();
  ASSERT_FALSE(ZSTD_isError(ZSTD_CCtx_setPledgedSrcSize(context, 300ULL << 20)));
  const std::vector<char> zeros(1024, 0);
  std::vector<char> out(ZSTD_CStreamOutSize());
  ZSTD_inBuffer input = {zeros.data(), zeros.size(), 0};
  ZSTD_outBuffer output = {out.data(), out.size(), 0};
  ASSERT_FALSE(ZSTD_isError(ZSTD_compressStream2(context, &output, &input, ZSTD_e_flush)));
  ZSTD_freeCCtx(context);
  ExpectError(HeaderBytes(3, -1, xml) + Packet(0, std::string(out.data(), output.pos)),
              "more than 256 MiB");
}

TEST(Aedat4MalformedTest, DecompressionBombIsRefused) {
  // 257 MiB of zeros in a few KB of Zstd: beyond the 256 MiB a packet may hold.
  ZSTD_CCtx* context = ZSTD_createCCtx();
  const std::vector<char> zeros(1 << 20, 0);
  std::string compressed;
  std::vector<char> out(ZSTD_CStreamOutSize());
  for (int mib = 0; mib <= 257; ++mib) {
    ZSTD_inBuffer input = {zeros.data(), mib < 257 ? zeros.size() : 0, 0};
    const ZSTD_EndDirective mode = mib < 257 ? ZSTD_e_continue : ZSTD_e_end;
    for (bool done = false; !done;) {
      ZSTD_outBuffer output = {out.data(), out.size(), 0};
      const size_t remaining = ZSTD_compressStream2(context, &output, &input, mode);
      ASSERT_FALSE(ZSTD_isError(remaining));
      compressed.append(out.data(), output.pos);
      done = mode == ZSTD_e_end ? remaining == 0 : input.pos == input.size;
    }
  }
  ZSTD_freeCCtx(context);
  ASSERT_LT(compressed.size(), 100000u);
  ExpectError(HeaderBytes(3, -1, HandXml()) + Packet(0, compressed), "more than 256 MiB");
}

TEST(Aedat4MalformedTest, DataTableProblems) {
  // An entry pointing where its packet is not.
  ExpectError(HandBuiltFileWithTable(
                  [](std::vector<TableEntry>* entries) { (*entries)[0].byte_offset += 4; }),
              "no packet of stream 0");
  ExpectError(HandBuiltFileWithTable(
                  [](std::vector<TableEntry>* entries) { (*entries)[3].byte_offset = 1 << 30; }),
              "outside the packets");
  ExpectError(
      HandBuiltFileWithTable([](std::vector<TableEntry>* entries) { (*entries)[0].count = 5; }),
      "holds 2 events, the file data table says 5");
  ExpectError(HandBuiltFileWithTable(
                  [](std::vector<TableEntry>* entries) { (*entries)[0].t_last_us = 99; }),
              "time span [100, 99]");
  ExpectError(HandBuiltFileWithTable(
                  [](std::vector<TableEntry>* entries) { (*entries)[3].t_first_us = 50; }),
              "starts before the one before it ends");
  ExpectError(HandBuiltFileWithTable([](std::vector<TableEntry>* entries) {
                (*entries)[3].t_first_us = 251;
                (*entries)[3].t_last_us = 260;
              }),
              "outside the packet's time span");
  ExpectError(HandBuiltFileWithTable([](std::vector<TableEntry>* entries) {
                (*entries)[3] = (*entries)[0];
                (*entries)[3].t_first_us = (*entries)[3].t_last_us;
              }),
              "out of file order (or twice)");
  std::string cut = HandBuiltFileWithTable();
  cut.resize(cut.size() - 6);
  ExpectError(cut, "file data table");
}

// Regression tests: inputs the aedat4 fuzzer found (tests/io/data/fuzz_aedat4_*).

// An EventPacket whose event vector starts 4 bytes off the 8-byte alignment of its structs: the
// Flatbuffers verifier accepts it (it checks the length field's alignment), and reading the
// events was undefined behaviour (UBSan: misaligned member call).
TEST(Aedat4FuzzRegressionTest, MisalignedEventVectorIsAnInputError) {
  const std::string bytes =
      ReadFile(std::string(EVFS_TEST_SOURCE_DIR) + "/data/fuzz_aedat4_misaligned_events.aedat4");
  ASSERT_FALSE(bytes.empty());
  ExpectError(bytes, "misaligned event vector");
}

TEST(Aedat4MalformedTest, EveryTruncationIsAnInputError) {
  const std::string path = ScratchDir("aedat4_truncated") + "/t.aedat4";
  const Recording recording = MakeRecording(16, 8, 400, 5);
  Aedat4WriteOptions options;
  options.max_events_per_packet = 100;
  WriteAedat4(path, recording.events, recording.frames, recording.images, options);
  const std::string bytes = ReadFile(path);
  for (size_t size = 0; size < bytes.size(); size += 1 + size / 16) {
    EXPECT_THROW(ReadEverything(bytes.substr(0, size)), InputError) << "cut at " << size;
  }
}

TEST(Aedat4MalformedTest, CorruptBytesGiveResultsOrInputErrors) {
  // Every byte of a small file changed in turn: each either reads or is an InputError (under
  // AddressSanitizer, any read out of bounds would abort).
  const std::string bytes = HandBuiltFileWithTable();
  int errors = 0;
  for (size_t i = 0; i < bytes.size(); ++i) {
    for (const unsigned char flip : {0x01, 0x80, 0xff}) {
      std::string corrupt = bytes;
      corrupt[i] = static_cast<char>(static_cast<unsigned char>(corrupt[i]) ^ flip);
      try {
        ReadEverything(corrupt);
      } catch (const InputError& error) {
        EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos);
        ++errors;
      }
    }
  }
  EXPECT_GT(errors, 0);
}

}  // namespace
}  // namespace evfs
