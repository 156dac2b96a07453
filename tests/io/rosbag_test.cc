#include "evfs/io/rosbag.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/rosbag/format.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

// The shared folders with events.txt and images.txt (/work/shared/data/README.md).
const char* const kSharedFolders[] = {"slider_depth_70_71", "shapes_rotation_13_20",
                                      "eslnet_cups_blur"};

// mono16 pixels are v * 257 / 65535 where the folder reads v / 255: equal but for rounding.
constexpr double kMono16Rounding = 1e-12;

bool HavePythonRosbag() {
  return std::system("/usr/bin/python3 -c 'import rosbag' >/dev/null 2>&1") == 0;
}

#define EVFS_REQUIRE_PYTHON_ROSBAG()                                                         \
  if (!HavePythonRosbag()) {                                                                 \
    GTEST_SKIP() << "python3-rosbag is not installed (scripts/install-deps.sh): skipping a " \
                    "test that writes bags with tests/io/write_rosbag.py";                   \
  }

// A bag tests/io/write_rosbag.py writes from shared folder `name` with `arguments`, once per
// process and arguments, in a scratch folder of this test.
std::string WriteBag(const std::string& folder, const std::string& arguments) {
  static std::map<std::string, std::string> written;
  const std::string key = folder + " " + arguments;
  auto found = written.find(key);
  if (found != written.end()) return found->second;
  std::string test_name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::replace(test_name.begin(), test_name.end(), '/', '_');
  const std::string dir = test::ScratchDir("rosbag_" + test_name + std::to_string(written.size()));
  const std::string bag = dir + "/recording.bag";
  const std::string command = "/usr/bin/python3 " + std::string(EVFS_TEST_SOURCE_DIR) +
                              "/write_rosbag.py " + folder + " " + bag + " " + arguments;
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  written[key] = bag;
  return bag;
}

void ExpectSameFrames(const DataSource& actual, const DataSource& expected, double tolerance) {
  EXPECT_EQ(actual.width(), expected.width());
  EXPECT_EQ(actual.height(), expected.height());
  ASSERT_EQ(actual.frames().size(), expected.frames().size());
  for (int i = 0; i < static_cast<int>(expected.frames().size()); ++i) {
    // The header stamp, not the receive time (the writer receives every image 10 ms later).
    EXPECT_EQ(actual.frames()[i].t_ns, expected.frames()[i].t_ns) << "frame " << i;
    EXPECT_FALSE(actual.frames()[i].has_exposure) << "frame " << i;
    EXPECT_LE((actual.ReadImage(i) - expected.ReadImage(i)).abs().maxCoeff(), tolerance)
        << "frame " << i;
  }
}

struct SharedCase {
  const char* folder;
  const char* compression;
};

class RosbagSharedDataTest : public ::testing::TestWithParam<SharedCase> {};

// The whole recording, and windows: between the frames, and a tenth of the events anywhere.
TEST_P(RosbagSharedDataTest, ReadsBackTheFolderWholeAndByWindow) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const std::string folder = data_dir + "/" + GetParam().folder;
  const std::string bag = WriteBag(folder, std::string("--compression ") + GetParam().compression);
  const auto expected = DataSource::Open(folder);
  const RosbagDataSource actual(bag);
  EXPECT_EQ(actual.events_topic(), "/dvs/events");
  EXPECT_EQ(actual.frames_topic(), "/dvs/image_raw");
  ExpectSameFrames(actual, *expected, 0.0);
  const EventSummary summary = actual.Summarize();
  const EventStream all = expected->ReadAllEvents();
  ASSERT_GT(all.size(), 0u);
  EXPECT_EQ(actual.ReadAllEvents(), all);
  EXPECT_EQ(summary.count, static_cast<int64_t>(all.size()));
  EXPECT_EQ(summary.t_last_ns, all.last_t_ns());
  const auto& frames = expected->frames();
  for (size_t i = 0; i + 1 < frames.size(); ++i) {
    EXPECT_EQ(actual.ReadEvents(frames[i].t_ns, frames[i + 1].t_ns),
              expected->ReadEvents(frames[i].t_ns, frames[i + 1].t_ns))
        << "frames " << i << ".." << i + 1;
  }
  // A window of a tenth of the events, starting inside a run of equal times or not.
  const size_t n = all.size();
  for (const size_t start : {n / 3, n / 2 + 1}) {
    const int64_t begin_ns = all.t_ns(start), end_ns = all.t_ns(start + n / 10);
    const int64_t decoded_before = actual.messages_decoded();
    EXPECT_EQ(actual.ReadEvents(begin_ns, end_ns), all.Slice(begin_ns, end_ns));
    // 1000 events per message: the window's messages and the margin's, not the whole topic.
    const int64_t decoded = actual.messages_decoded() - decoded_before;
    if (n > 100000) {
      EXPECT_LT(decoded, static_cast<int64_t>(n / 1000 / 4));
    }
  }
  // Before the first event and after the last: nothing.
  EXPECT_EQ(actual.ReadEvents(all.t_ns(0) - 1000000000, all.t_ns(0)).size(), 0u);
  EXPECT_EQ(actual.ReadEvents(all.last_t_ns() + 1, all.last_t_ns() + 1000000000).size(), 0u);
}

std::vector<SharedCase> SharedCases() {
  std::vector<SharedCase> cases;
  for (const char* folder : kSharedFolders) {
    for (const char* compression : {"none", "bz2", "lz4"}) cases.push_back({folder, compression});
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Folders, RosbagSharedDataTest, ::testing::ValuesIn(SharedCases()),
                         [](const ::testing::TestParamInfo<SharedCase>& info) {
                           return std::string(info.param.folder) + "_" + info.param.compression;
                         });

TEST(RosbagTest, EveryEncodingReadsAsTheGreyFolder) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const std::string folder = data_dir + "/slider_depth_70_71";
  const std::string bag = WriteBag(folder, "--more_encodings mono16,rgb8,bgr8,rgba8,bgra8");
  const auto expected = DataSource::Open(folder);
  for (const char* encoding : {"mono16", "rgb8", "bgr8", "rgba8", "bgra8"}) {
    DataSourceOptions options;
    options.frames_topic = std::string("/camera/") + encoding + "/image_raw";
    SCOPED_TRACE(encoding);
    ExpectSameFrames(RosbagDataSource(bag, options), *expected, kMono16Rounding);
  }
}

TEST(RosbagTest, RefusesOtherEncodingsByName) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const RosbagDataSource bag(WriteBag(data_dir + "/slider_depth_70_71", "--encoding yuv422"));
  try {
    bag.ReadImage(0);
    FAIL() << "a yuv422 image was read";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'yuv422'"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(RosbagTest, TopicsAreChosenByOption) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const std::string folder = data_dir + "/slider_depth_70_71";
  const std::string path = WriteBag(folder, "--second_events_topic /dvs2/events");
  const EventStream events = DataSource::Open(folder)->ReadAllEvents();
  const RosbagDataSource first(path);
  EXPECT_EQ(first.events_topic(), "/dvs/events");
  EXPECT_NE(first.topic_choice().find("the first dvs_msgs/EventArray topic"), std::string::npos)
      << first.topic_choice();
  EXPECT_EQ(first.ReadAllEvents(), events);
  ASSERT_EQ(first.topics().size(), 3u);
  EXPECT_EQ(first.topics()[2].name, "/dvs2/events");
  EXPECT_EQ(first.topics()[2].messages, 17);

  DataSourceOptions options;
  options.events_topic = "/dvs2/events";
  const auto second = DataSource::Open(path, options);
  const EventStream flipped = second->ReadAllEvents();
  ASSERT_EQ(flipped.size(), events.size());
  for (size_t i = 0; i < events.size(); ++i) {
    ASSERT_EQ(flipped.polarity(i), -events.polarity(i)) << "event " << i;
  }
  options.events_topic = "/dvs3/events";
  EXPECT_THROW(DataSource::Open(path, options), InputError);
  options.events_topic = "";
  options.frames_topic = "/dvs/events";  // not an image topic
  EXPECT_THROW(DataSource::Open(path, options), InputError);
  // A folder has no topics to choose.
  EXPECT_THROW(DataSource::Open(folder, options), InvalidArgumentError);
}

TEST(RosbagTest, IsRecognisedByItsFirstLineWhateverItsName) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const std::string bag = WriteBag(data_dir + "/slider_depth_70_71", "--compression lz4");
  const std::string renamed = fs::path(bag).parent_path().string() + "/recording.dat";
  fs::copy_file(bag, renamed, fs::copy_options::overwrite_existing);
  EXPECT_NE(dynamic_cast<const RosbagDataSource*>(DataSource::Open(renamed).get()), nullptr);
}

TEST(RosbagTest, AnUnindexedBagIsRefusedWithTheRemedy) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const std::string bag = WriteBag(data_dir + "/slider_depth_70_71", "--unindexed");
  try {
    RosbagDataSource source(bag);
    FAIL() << "an unindexed bag was opened";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("rosbag reindex"), std::string::npos) << error.what();
  }
}

// Every truncation of a bag and random bytes after its first line are an InputError of one
// line, never a crash (rosbag_storage trusts what a file declares; CheckBagStructure does not).
TEST(RosbagTest, TruncatedAndCorruptBagsAreInputErrors) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  for (const char* compression : {"none", "lz4"}) {
    const std::string bag =
        WriteBag(data_dir + "/slider_depth_70_71", std::string("--compression ") + compression);
    std::ifstream in(bag, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string broken = fs::path(bag).parent_path().string() + "/broken.bag";
    std::mt19937 random(7);
    std::vector<std::string> variants;
    for (const size_t length : {size_t{0}, size_t{5}, size_t{13}, size_t{100}, size_t{4200},
                                bytes.size() / 2, bytes.size() - 1}) {
      variants.push_back(bytes.substr(0, length));
    }
    std::string garbage = rosbag_format::kMagic;
    for (int i = 0; i < 5000; ++i) garbage += static_cast<char>(random() & 0xff);
    variants.push_back(garbage);
    for (size_t i = 0; i < variants.size(); ++i) {
      test::WriteFile(broken, variants[i]);
      try {
        const RosbagDataSource source(broken);
        source.ReadAllEvents();
        ADD_FAILURE() << compression << " variant " << i << " opened";
      } catch (const InputError& error) {
        EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos) << error.what();
      }
    }
  }
}

// A regression test from rosbag_fuzzer: a control byte in a field the message quotes (here the
// chunk's compression) is written as \xNN, so the message stays one printable line.
TEST(RosbagTest, MessagesQuoteTheFileWithoutControlBytes) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const std::string bag = WriteBag(data_dir + "/slider_depth_70_71", "--compression lz4");
  std::ifstream in(bag, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = bytes.find("compression=lz4");
  ASSERT_NE(at, std::string::npos);
  bytes[at + std::string("compression=lz").size()] = '\x01';
  const std::string broken = fs::path(bag).parent_path().string() + "/control.bag";
  test::WriteFile(broken, bytes);
  try {
    RosbagDataSource source(broken);
    FAIL() << "a chunk compressed with 'lz\\x01' was read";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'lz\\x01'"), std::string::npos) << message;
    EXPECT_TRUE(std::none_of(message.begin(), message.end(), [](char c) {
      return static_cast<unsigned char>(c) < 0x20;
    })) << message;
  }
}

// The structure check tells the reader which bytes it is done with (their pages then leave
// memory): ranges inside the file, covering every chunk, and the same layout as without it.
TEST(RosbagTest, TheStructureCheckHandsBackEveryChunkItRead) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const std::string bag = WriteBag(data_dir + "/eslnet_cups_blur", "--compression none");
  std::ifstream in(bag, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
  std::vector<std::pair<size_t, size_t>> released;
  const rosbag_format::BagLayout layout = rosbag_format::CheckBagStructure(
      bag, data, bytes.size(),
      [&](size_t offset, size_t size) { released.emplace_back(offset, size); });
  EXPECT_EQ(layout.chunks.size(),
            rosbag_format::CheckBagStructure(bag, data, bytes.size()).chunks.size());
  ASSERT_GT(layout.chunks.size(), 1u) << "a bag of one chunk tests little here";
  for (const auto& [offset, size] : released) {
    EXPECT_LE(offset + size, bytes.size()) << offset << " + " << size;
  }
  for (const rosbag_format::BagChunk& chunk : layout.chunks) {
    EXPECT_TRUE(std::any_of(released.begin(), released.end(),
                            [&](const auto& range) {
                              return range.first <= chunk.offset &&
                                     chunk.data_begin + chunk.data_size <=
                                         range.first + range.second;
                            }))
        << "the chunk at byte " << chunk.offset;
  }
}

}  // namespace
}  // namespace evfs
