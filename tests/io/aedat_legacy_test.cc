#include "evfs/io/aedat_legacy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "evfs/io/aedat_legacy/format.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

// An AEDAT 2.0 frame holds the 10-bit ADC difference of two reads: the encoder rounds each 8-bit
// value v to round(v * 1023 / 255), so a pixel reads back within half an ADC step of v / 255.
constexpr double kAdcQuantisation = 0.5 / 1023.0 + 1e-12;
// The encoder places a frame's reset reads 1 us before its images.txt time, its signal reads
// 1 us after (tests/io/aedat_legacy_encode.py).
constexpr int64_t kEncodedHalfExposureNs = 1000;
// tests/io/aedat_legacy_encode.py shifts the v2e-layout file's events by this much, so that its
// largest address says DAVIS346.
constexpr int kV2eShiftX = 100;
constexpr int kV2eShiftY = 80;

// The files tests/io/aedat_legacy_encode.py writes from shared data folder `name`, once per run.
std::string EncodedFolder(const std::string& data_dir, const std::string& name) {
  static std::map<std::string, std::string> encoded;
  auto found = encoded.find(name);
  if (found != encoded.end()) return found->second;
  // A folder per test: ctest runs the tests of this suite in parallel processes.
  std::string test_name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::replace(test_name.begin(), test_name.end(), '/', '_');
  const std::string out = test::ScratchDir("aedat_legacy_" + name + "_" + test_name);
  const std::string command = "/usr/bin/python3 " + std::string(EVFS_TEST_SOURCE_DIR) +
                              "/aedat_legacy_encode.py " + data_dir + "/" + name + " " + out;
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  encoded[name] = out;
  return out;
}

EventStream Shifted(const EventStream& events, int width, int height, int dx, int dy) {
  EventStream shifted(width, height);
  for (size_t i = 0; i < events.size(); ++i) {
    shifted.push_back(events.t_ns(i), static_cast<uint16_t>(events.x(i) + dx),
                      static_cast<uint16_t>(events.y(i) + dy), events.polarity(i));
  }
  return shifted;
}

class AedatLegacySharedDataTest : public ::testing::TestWithParam<const char*> {};

TEST_P(AedatLegacySharedDataTest, Aedat31ReadsBackTheFolderExactly) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string dir = EncodedFolder(data_dir, GetParam());
  const auto expected = DataSource::Open(dir + "/us");
  const auto actual = DataSource::Open(dir + "/davis240.aedat3");
  const auto* legacy = dynamic_cast<const AedatLegacyDataSource*>(actual.get());
  ASSERT_NE(legacy, nullptr);
  EXPECT_EQ(legacy->major_version(), 3);
  EXPECT_EQ(legacy->sensor_size_source(), "the header: chip DAVIS240");
  EXPECT_EQ(actual->width(), expected->width());
  EXPECT_EQ(actual->height(), expected->height());
  ASSERT_EQ(actual->frames().size(), expected->frames().size());
  for (size_t i = 0; i < expected->frames().size(); ++i) {
    const FrameInfo& want = expected->frames()[i];
    const FrameInfo& got = actual->frames()[i];
    EXPECT_EQ(got.t_ns, want.t_ns) << "frame " << i;
    EXPECT_FALSE(got.has_exposure) << "frame " << i;
    EXPECT_TRUE(
        (actual->ReadImage(static_cast<int>(i)) == expected->ReadImage(static_cast<int>(i))).all())
        << "frame " << i;
  }
  EXPECT_EQ(actual->ReadAllEvents(), expected->ReadAllEvents());
}

TEST_P(AedatLegacySharedDataTest, Aedat20ReadsBackTheFolderWithinTheAdcStep) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string dir = EncodedFolder(data_dir, GetParam());
  const auto expected = DataSource::Open(dir + "/us");
  const auto actual = DataSource::Open(dir + "/davis240.aedat2");
  const auto* legacy = dynamic_cast<const AedatLegacyDataSource*>(actual.get());
  ASSERT_NE(legacy, nullptr);
  EXPECT_EQ(legacy->major_version(), 2);
  EXPECT_EQ(legacy->sensor_size_source(), "the header: chip DAVIS240");
  ASSERT_EQ(actual->frames().size(), expected->frames().size());
  for (size_t i = 0; i < expected->frames().size(); ++i) {
    const FrameInfo& want = expected->frames()[i];
    const FrameInfo& got = actual->frames()[i];
    EXPECT_EQ(got.t_ns, want.t_ns) << "frame " << i;
    EXPECT_TRUE(got.has_exposure);
    EXPECT_EQ(got.exposure_begin_ns, want.t_ns - kEncodedHalfExposureNs) << "frame " << i;
    EXPECT_EQ(got.exposure_end_ns, want.t_ns + kEncodedHalfExposureNs) << "frame " << i;
    const double error =
        (actual->ReadImage(static_cast<int>(i)) - expected->ReadImage(static_cast<int>(i)))
            .abs()
            .maxCoeff();
    EXPECT_LE(error, kAdcQuantisation) << "frame " << i;
  }
  // The special event and the IMU sample the encoder mixed in are not polarity events.
  EXPECT_EQ(actual->ReadAllEvents(), expected->ReadAllEvents());
}

TEST_P(AedatLegacySharedDataTest, V2eLayoutReadsAsDavis346) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string dir = EncodedFolder(data_dir, GetParam());
  const auto expected = DataSource::Open(dir + "/us");
  const AedatLegacyDataSource actual(dir + "/v2e346.aedat2");
  EXPECT_EQ(actual.width(), 346);
  EXPECT_EQ(actual.height(), 260);
  EXPECT_NE(actual.sensor_size_source().find("the header names no chip"), std::string::npos)
      << actual.sensor_size_source();
  EXPECT_TRUE(actual.frames().empty());
  EXPECT_EQ(actual.no_frames_reason(), "the AEDAT 2.0 file holds no APS samples");
  EXPECT_EQ(actual.ReadAllEvents(),
            Shifted(expected->ReadAllEvents(), 346, 260, kV2eShiftX, kV2eShiftY));
}

// A window reads what the whole stream holds between its ends, decoding only its part.
TEST_P(AedatLegacySharedDataTest, WindowedReadsDecodeOnlyTheWindow) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const std::string dir = EncodedFolder(data_dir, GetParam());
  for (const char* name : {"davis240.aedat2", "davis240.aedat3"}) {
    const AedatLegacyDataSource source(dir + "/" + name);
    const EventStream all = source.ReadAllEvents();
    const int64_t decoded_all = source.units_decoded();
    const int64_t begin_ns = all.t_ns(all.size() / 2);
    const int64_t end_ns = all.t_ns(all.size() / 2 + all.size() / 20) + 1;
    EventStream expected(all.width(), all.height());
    for (size_t i = 0; i < all.size(); ++i) {
      if (all.t_ns(i) >= begin_ns && all.t_ns(i) < end_ns) {
        expected.push_back(all.t_ns(i), all.x(i), all.y(i), all.polarity(i));
      }
    }
    const EventStream window = source.ReadEvents(begin_ns, end_ns);
    EXPECT_EQ(window, expected) << name;
    // A twentieth of the events, plus the two AEDAT 3.1 packets a window may straddle.
    EXPECT_LE(source.units_decoded() - decoded_all, decoded_all / 4 + 2) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(SharedFolders, AedatLegacySharedDataTest,
                         ::testing::Values("slider_depth_70_71", "shapes_rotation_13_20"));

// ---- Hand-built files: layouts evfs refuses by name, malformed and truncated files ----

std::string BigEndianRecord(uint32_t address, int32_t t_us) {
  std::string record(8, '\0');
  for (int i = 0; i < 4; ++i) {
    record[i] = static_cast<char>(address >> (24 - 8 * i));
    record[4 + i] = static_cast<char>(static_cast<uint32_t>(t_us) >> (24 - 8 * i));
  }
  return record;
}

std::string LittleEndian(uint32_t value, int bytes = 4) {
  std::string text;
  for (int i = 0; i < bytes; ++i) text += static_cast<char>(value >> (8 * i));
  return text;
}

std::string PacketHeader(int16_t type, int32_t size, int32_t capacity, int32_t number) {
  return LittleEndian(static_cast<uint16_t>(type), 2) + LittleEndian(1, 2) + LittleEndian(size) +
         LittleEndian(4) + LittleEndian(0) + LittleEndian(capacity) + LittleEndian(number) +
         LittleEndian(number);
}

const std::string kDavis240Header2 =
    "#!AER-DAT2.0\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n";
const std::string kDavis240Header3 = "#!AER-DAT3.1\r\n#Source 1: DAVIS240C\r\n#!END-HEADER\r\n";

// The address of an APS read of pixel (x, y) counted from the top left of a DAVIS240.
uint32_t ApsAddress(int x, int y, uint32_t readout, uint32_t adc) {
  return aedat_legacy::kApsFlag | (static_cast<uint32_t>(179 - y) << 22) |
         (static_cast<uint32_t>(239 - x) << 12) | (readout << 10) | adc;
}

// Runs the reader on `bytes` and expects an InputError of `kind` whose message holds `what`.
void ExpectRefused(const std::string& bytes, InputError::Kind kind, const std::string& what) {
  const std::string name = "hand_built.aedat";
  const InputError error = test::CatchInputError(
      [&] { AedatLegacyDataSource::FromMemory(name, bytes.data(), bytes.size())->Summarize(); });
  EXPECT_EQ(static_cast<int>(error.kind()), static_cast<int>(kind)) << error.what();
  EXPECT_NE(std::string(error.what()).find(what), std::string::npos) << error.what();
  test::ExpectShortPrintableMessage(error);
}

TEST(AedatLegacyTest, HandBuiltEventsDecodeToTheDocumentedLayouts) {
  // AEDAT 2.0, DAVIS240: raw x 239 - x, raw y 179 - y, polarity bit 11.
  const std::string v2 = kDavis240Header2 + BigEndianRecord((179u << 22) | (239u << 12), 5) +
                         BigEndianRecord((0u << 22) | (0u << 12) | (1u << 11), 7);
  const auto source2 = AedatLegacyDataSource::FromMemory("a.aedat", v2.data(), v2.size());
  EventStream expected(240, 180);
  expected.push_back(5000, 0, 0, -1);
  expected.push_back(7000, 239, 179, 1);
  EXPECT_EQ(source2->ReadAllEvents(), expected);
  // AEDAT 3.1: valid bit 0, polarity bit 1, y bits 2..16, x bits 17..31; time with overflow.
  const std::string v3 = kDavis240Header3 + PacketHeader(1, 8, 2, 2) +
                         LittleEndian((239u << 17) | (179u << 2) | 2u | 1u) + LittleEndian(5) +
                         LittleEndian((0u << 17) | (0u << 2) | 1u) + LittleEndian(7);
  const auto source3 = AedatLegacyDataSource::FromMemory("a.aedat", v3.data(), v3.size());
  EventStream expected3(240, 180);
  expected3.push_back(5000, 239, 179, 1);
  expected3.push_back(7000, 0, 0, -1);
  EXPECT_EQ(source3->ReadAllEvents(), expected3);
}

TEST(AedatLegacyTest, LayoutsEvfsDoesNotReadAreRefusedByName) {
  ExpectRefused(
      "#!AER-DAT2.0\r\n# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n" + BigEndianRecord(0, 1),
      InputError::Kind::kMalformed, "AEDAT 2.0 from a DVS128 (the header names it)");
  // The fuzzer's finding: a chip line of control bytes and 200 more is not quoted whole.
  ExpectRefused("#!AER-DAT2.0\r\n#\x01\x02 tmpdiff128" + std::string(200, '\x7f') + "\n",
                InputError::Kind::kMalformed, "AEDAT 2.0 from a tmpdiff128");
  ExpectRefused(kDavis240Header2 + BigEndianRecord(ApsAddress(0, 0, 2, 100), 1),
                InputError::Kind::kMalformed, "CP-reset read (DAVIS240A/B readout)");
  // Rolling shutter: each row's reset reads followed by its signal reads.
  std::string rolling = kDavis240Header2;
  for (int frame = 0; frame < 2; ++frame) {
    for (int y = 0; y < 180; ++y) {
      for (uint32_t readout : {0u, 1u}) {
        for (int x = 0; x < 240; ++x)
          rolling += BigEndianRecord(ApsAddress(x, y, readout, 9), 1000 * frame + y);
      }
    }
  }
  ExpectRefused(rolling, InputError::Kind::kMalformed, "rolling-shutter or region-of-interest");
  std::string roi_frame = PacketHeader(2, 36 + 2, 1, 1) + LittleEndian(1u | (1u << 1) | (3u << 8));
  for (int32_t field : {1, 1, 1, 1, 1, 1, 0, 0}) roi_frame += LittleEndian(field);
  ExpectRefused(kDavis240Header3 + roi_frame + std::string(2, '\0'), InputError::Kind::kMalformed,
                "region of interest 3");
}

TEST(AedatLegacyTest, MalformedAndTruncatedFilesAreInputErrors) {
  const std::string v2 = kDavis240Header2 + BigEndianRecord(0, 1) + BigEndianRecord(0, 2);
  ExpectRefused(v2.substr(0, v2.size() - 3), InputError::Kind::kMalformed, "truncated file?");
  ExpectRefused(kDavis240Header2 + BigEndianRecord(0, 2) + BigEndianRecord(0, 1),
                InputError::Kind::kNotMonotonic, "timestamps must not decrease");
  ExpectRefused("#!AER-DAT2.0\r\n" + BigEndianRecord(1000u << 12, 1), InputError::Kind::kOutOfRange,
                "fits no DAVIS240 or DAVIS346");
  ExpectRefused("#!AER-DAT3.1\r\n#Source 1: DAVIS240C\r\n", InputError::Kind::kMalformed,
                "'#!END-HEADER'");
  ExpectRefused("#!AER-DAT2.0\r\n# cut", InputError::Kind::kMalformed, "without its line end");
  ExpectRefused("#!AER-DAT1.0\r\n", InputError::Kind::kMalformed, "'#!AER-DAT2.0'");
  const std::string v3 =
      kDavis240Header3 + PacketHeader(1, 8, 1, 1) + LittleEndian((1u << 17) | 1u) + LittleEndian(5);
  ExpectRefused(v3.substr(0, v3.size() - 1), InputError::Kind::kMalformed, "truncated file?");
  ExpectRefused(v3.substr(0, kDavis240Header3.size() + 10), InputError::Kind::kMalformed,
                "truncated packet header");
  ExpectRefused(kDavis240Header3 + PacketHeader(1, 0, 1, 1), InputError::Kind::kMalformed,
                "are not a packet header");
  ExpectRefused(kDavis240Header3 + PacketHeader(1, 8, 1, 1) + LittleEndian((240u << 17) | 1u) +
                    LittleEndian(5),
                InputError::Kind::kOutOfRange, "outside the 240x180 sensor");
  ExpectRefused(kDavis240Header3 + PacketHeader(1, 8, 2, 2) + LittleEndian(1u) + LittleEndian(5) +
                    LittleEndian(1u) + LittleEndian(4),
                InputError::Kind::kNotMonotonic, "timestamps must not decrease");
  ExpectRefused(kDavis240Header3 + PacketHeader(2, 36, 1, 1) + LittleEndian(1u | (1u << 1)) +
                    std::string(32, '\0'),
                InputError::Kind::kMalformed, "does not fit its 36-byte event");
}

TEST(AedatLegacyTest, OpenDispatchesOnTheVersionLine) {
  const std::string dir = test::ScratchDir("aedat_legacy_dispatch");
  test::WriteFile(dir + "/old.dat", kDavis240Header2 + BigEndianRecord(0, 1));
  test::WriteFile(dir + "/old3.aedat", kDavis240Header3);
  EXPECT_NE(dynamic_cast<AedatLegacyDataSource*>(DataSource::Open(dir + "/old.dat").get()),
            nullptr);
  EXPECT_NE(dynamic_cast<AedatLegacyDataSource*>(DataSource::Open(dir + "/old3.aedat").get()),
            nullptr);
}

}  // namespace
}  // namespace evfs
