// ROS bags on the command line: `info`, `video` and `convert` on a bag written by
// tests/io/write_rosbag.py (Debian's python3-rosbag) from a shared data folder give what the
// folder gives; the topic flags; malformed bags as one-line user errors. Each test works in a
// scratch folder.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "evfs/io/data_source.h"
#include "evfs/tests/examples/cli_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;
using test::CommandResult;
using test::ReadFile;
using test::RunEvfs;

#define EVFS_REQUIRE_PYTHON_ROSBAG()                                                         \
  if (std::system("/usr/bin/python3 -c 'import rosbag' >/dev/null 2>&1") != 0) {             \
    GTEST_SKIP() << "python3-rosbag is not installed (scripts/install-deps.sh): skipping a " \
                    "test that writes bags with tests/io/write_rosbag.py";                   \
  }

// AEDAT 4 rounds times to the nearest microsecond.
constexpr int64_t kHalfMicrosecondNs = 500;

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// SCRATCH/recording.bag from shared folder `folder` with the writer's `arguments`.
std::string WriteBag(const std::string& folder, const fs::path& scratch,
                     const std::string& arguments = "") {
  fs::create_directories(scratch);
  const std::string bag = (scratch / "recording.bag").string();
  const std::string command = "/usr/bin/python3 " EVFS_SOURCE_DIR "/tests/io/write_rosbag.py " +
                              folder + " " + bag + " " + arguments;
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  return bag;
}

TEST(EvfsRosbag, InfoNamesTheTopicsAndSaysTheExposureIsUnknown) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const fs::path root = test::ScratchDir("rosbag_info");
  const std::string folder = data_dir + "/slider_depth_70_71";
  const std::string bag = WriteBag(folder, root, "--second_events_topic /dvs2/events");
  // No progress lines: info calibrates the event model, which under a sanitizer can take long
  // enough for one.
  const CommandResult result = RunEvfs("info --progress_interval_s=0 --data=" + bag);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("format      ROS bag: events from /dvs/events (the first "
                               "dvs_msgs/EventArray topic; --events_topic chooses another)"),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("/dvs2/events  dvs_msgs/EventArray  17 messages"), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find("exposure unknown"), std::string::npos) << result.output;
  // The one line on stderr says which topics evfs took.
  EXPECT_EQ(std::count(result.errors.begin(), result.errors.end(), '\n'), 1) << result.errors;
  EXPECT_NE(result.errors.find("events from /dvs/events"), std::string::npos) << result.errors;
  // The same events and frames as the folder: its info but for the lines naming the source.
  const CommandResult expected = RunEvfs("info --data=" + folder);
  for (const char* line : {"events      16418 (", "frames      2\n", "  t=2.713576 s"}) {
    EXPECT_NE(expected.output.find(line), std::string::npos) << line;
    EXPECT_NE(result.output.find(line), std::string::npos) << line;
  }

  // The second topic: every polarity flipped, so ON and OFF trade places.
  const CommandResult second = RunEvfs("info --data=" + bag + " --events_topic=/dvs2/events");
  ASSERT_EQ(second.exit_code, 0) << second.output;
  const size_t at = expected.output.find("events      16418 (");
  const std::string counts = expected.output.substr(at, expected.output.find('\n', at) - at);
  EXPECT_EQ(second.output.find(counts), std::string::npos) << counts;
}

TEST(EvfsRosbag, VideoOfABagHasTheFramesOfTheFolder) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const fs::path root = test::ScratchDir("rosbag_video");
  const std::string folder = data_dir + "/slider_depth_70_71";
  const std::string bag = WriteBag(folder, root, "--compression lz4");
  const std::string flags = " --fps=200 --jobs=1 --solver=adam --adam_iterations=5";
  const CommandResult from_folder =
      RunEvfs("video --data=" + folder + " --out=" + (root / "folder").string() + flags);
  ASSERT_EQ(from_folder.exit_code, 0) << from_folder.output;
  const CommandResult from_bag =
      RunEvfs("video --data=" + bag + " --out=" + (root / "bag").string() + flags);
  ASSERT_EQ(from_bag.exit_code, 0) << from_bag.output;
  EXPECT_EQ(ReadFile(root / "bag" / "timestamps.txt"),
            ReadFile(root / "folder" / "timestamps.txt"));
  int count = 0;
  for (const auto& entry : fs::directory_iterator(root / "folder" / "frames")) {
    const fs::path other = root / "bag" / "frames" / entry.path().filename();
    ASSERT_TRUE(fs::exists(other)) << other;
    EXPECT_EQ(ReadFile(entry.path()), ReadFile(other)) << entry.path().filename();
    ++count;
  }
  EXPECT_GT(count, 2);
}

TEST(EvfsRosbag, ConvertWritesTheFolderHdf5AndAedat4Recordings) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const fs::path root = test::ScratchDir("rosbag_convert");
  const std::string folder = data_dir + "/shapes_rotation_13_20";
  const std::string bag = WriteBag(folder, root, "--compression bz2");
  const auto expected = DataSource::Open(folder);
  for (const char* name : {"out", "out.h5", "out.aedat4"}) {
    const fs::path out = root / name;
    const CommandResult result = RunEvfs("convert --data=" + bag + " --out=" + out.string());
    ASSERT_EQ(result.exit_code, 0) << result.output;
    const auto converted = DataSource::Open(out.string());
    const EventStream events = converted->ReadAllEvents();
    const EventStream want = expected->ReadAllEvents();
    ASSERT_EQ(events.size(), want.size()) << name;
    // AEDAT 4 keeps times to the microsecond; the folder and HDF5 to the nanosecond.
    const int64_t tolerance_ns = fs::path(name).extension() == ".aedat4" ? kHalfMicrosecondNs : 0;
    for (size_t i = 0; i < want.size(); ++i) {
      ASSERT_LE(std::abs(events.t_ns(i) - want.t_ns(i)), tolerance_ns) << name << " event " << i;
      ASSERT_EQ(events.x(i), want.x(i)) << name << " event " << i;
      ASSERT_EQ(events.y(i), want.y(i)) << name << " event " << i;
      ASSERT_EQ(events.polarity(i), want.polarity(i)) << name << " event " << i;
    }
    ASSERT_EQ(converted->frames().size(), expected->frames().size()) << name;
    for (int i = 0; i < static_cast<int>(expected->frames().size()); ++i) {
      EXPECT_EQ(converted->frames()[i].t_ns, expected->frames()[i].t_ns) << name << " " << i;
      EXPECT_TRUE((converted->ReadImage(i) == expected->ReadImage(i)).all()) << name << " " << i;
    }
  }
}

TEST(EvfsRosbag, MalformedBagsAndBadTopicsAreOneLineUserErrors) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  EVFS_REQUIRE_PYTHON_ROSBAG();
  const fs::path root = test::ScratchDir("rosbag_errors");
  const std::string folder = data_dir + "/slider_depth_70_71";
  const std::string bag = WriteBag(folder, root);
  const fs::path out = root / "out";
  test::ExpectUserError(RunEvfs("info --data=" + bag + " --events_topic=/nope"),
                        "--events_topic=/nope: no such topic", out);
  test::ExpectUserError(RunEvfs("info --data=" + bag + " --frames_topic=/dvs/events"),
                        "expected sensor_msgs/Image", out);
  test::ExpectUserError(RunEvfs("info --data=" + folder + " --events_topic=/dvs/events"),
                        "apply to ROS bags", out);

  const std::string bytes = ReadFile(bag);
  const fs::path broken = root / "broken.bag";
  for (const size_t length : {size_t{20}, bytes.size() / 3, bytes.size() - 10}) {
    WriteBytes(broken, bytes.substr(0, length));
    test::ExpectUserError(RunEvfs("video --data=" + broken.string() + " --out=" + out.string()),
                          broken.string(), out);
  }
  WriteBytes(broken, "#ROSBAG V2.0\n" + std::string(3000, '\x7f'));
  test::ExpectUserError(RunEvfs("info --data=" + broken.string()), broken.string(), out);
  const std::string unindexed = WriteBag(folder, root / "unindexed", "--unindexed");
  test::ExpectUserError(RunEvfs("info --data=" + unindexed), "rosbag reindex", out);
}

}  // namespace
}  // namespace evfs
