#include "evfs/io/hdf5_io.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "evfs/tests/io/hdf5_test_util.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

using test::DeclareSensorResolution;

constexpr int kWidth = 64;
constexpr int kHeight = 48;

struct Recording {
  EventStream events;
  std::vector<FrameInfo> frames;
  std::vector<Image> images;
};

// Events with nanosecond timestamps, an 8-bit and a 16-bit frame, one with an exposure.
Recording MakeRecording(uint32_t seed, int num_events) {
  Recording recording;
  recording.events = test::MakeRandomEvents(seed, num_events, kWidth, kHeight, 2713584001, 9999);
  recording.frames.resize(2);
  recording.frames[0].t_ns = 2713576000;
  recording.frames[0].path = "images/frame_00000000.png";
  recording.frames[0].has_exposure = true;
  recording.frames[0].exposure_begin_ns = 2700000001;
  recording.frames[0].exposure_end_ns = 2727152000;
  recording.frames[1].t_ns = 2752341000;
  recording.frames[1].path = "images/frame_00000001.png";
  recording.images = {test::MakeRandomImage(seed + 1, kWidth, kHeight, 8),
                      test::MakeRandomImage(seed + 2, kWidth, kHeight, 16)};
  return recording;
}

// The HDF5 type class and size of dataset `name`, to check what the writer chose.
std::pair<H5T_class_t, size_t> DatasetType(const std::string& path, const std::string& name) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t dataset = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  const hid_t type = H5Dget_type(dataset);
  const std::pair<H5T_class_t, size_t> result(H5Tget_class(type), H5Tget_size(type));
  H5Tclose(type);
  H5Dclose(dataset);
  H5Fclose(file);
  return result;
}

// Writes the scalar attribute `name` of `type` onto `object`.
void WriteScalarAttribute(hid_t object, const char* name, hid_t type, const void* value) {
  const hid_t scalar = H5Screate(H5S_SCALAR);
  const hid_t attribute = H5Acreate2(object, name, type, scalar, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attribute, type, value);
  H5Aclose(attribute);
  H5Sclose(scalar);
}

// Writes /events/{ts,xs,ys,ps} with the given file types, the way other tools do.
template <typename T, typename P>
void WriteRawEvents(const std::string& path, const std::vector<T>& ts, hid_t ts_type,
                    const std::vector<uint16_t>& xs, const std::vector<uint16_t>& ys,
                    const std::vector<P>& ps, hid_t ps_type, const char* ts_unit) {
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const hid_t group = H5Gcreate2(file, "events", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  const hsize_t n = ts.size();
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const auto write = [&](const char* name, hid_t type, const void* data) {
    const hid_t dataset =
        H5Dcreate2(group, name, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(dataset, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    if (ts_unit != nullptr && std::string(name) == "ts") {
      const hid_t string_type = H5Tcopy(H5T_C_S1);
      H5Tset_size(string_type, H5T_VARIABLE);
      WriteScalarAttribute(dataset, "ts_unit", string_type, &ts_unit);
      H5Tclose(string_type);
    }
    H5Dclose(dataset);
  };
  write("ts", ts_type, ts.data());
  write("xs", H5T_NATIVE_UINT16, xs.data());
  write("ys", H5T_NATIVE_UINT16, ys.data());
  write("ps", ps_type, ps.data());
  H5Sclose(space);
  H5Gclose(group);
  H5Fclose(file);
}

TEST(Hdf5IoTest, RoundTripIsLossless) {
  const Recording recording = MakeRecording(1, 5000);
  const std::string path = test::ScratchDir("h5_roundtrip") + "/recording.h5";
  WriteHdf5(path, recording.events, recording.frames, recording.images);

  const Hdf5DataSource source(path);
  EXPECT_EQ(source.width(), kWidth);
  EXPECT_EQ(source.height(), kHeight);
  EXPECT_EQ(source.num_events(), 5000);
  EXPECT_EQ(source.ReadAllEvents(), recording.events);
  EXPECT_EQ(source.frames(), recording.frames);
  for (int i = 0; i < 2; ++i) EXPECT_TRUE((source.ReadImage(i) == recording.images[i]).all()) << i;
  EXPECT_EQ(DatasetType(path, "images/image000000000"), std::make_pair(H5T_INTEGER, size_t{1}));
  EXPECT_EQ(DatasetType(path, "images/image000000001"), std::make_pair(H5T_INTEGER, size_t{2}));
  EXPECT_EQ(DatasetType(path, "events/ts"), std::make_pair(H5T_FLOAT, size_t{8}));
}

TEST(Hdf5IoTest, WindowedReadEqualsSlicingTheFullRead) {
  const EventStream events = test::MakeRandomEvents(8, 200000, kWidth, kHeight, 1000000000, 20000);
  const std::string path = test::ScratchDir("h5_window") + "/events.h5";
  WriteHdf5(path, events, {}, {});
  const Hdf5DataSource source(path);
  const EventStream all = source.ReadAllEvents();
  ASSERT_EQ(all, events);
  const int64_t first = all.first_t_ns();
  const int64_t last = all.last_t_ns();
  const std::vector<std::pair<int64_t, int64_t>> windows = {
      {first, last + 1},          {0, first},
      {last, last + 1},           {last + 1, last + 100},
      {all.t_ns(5), all.t_ns(5)}, {all.t_ns(1000) + 1, all.t_ns(123456)},
  };
  for (const auto& window : windows) {
    EXPECT_EQ(source.ReadEvents(window.first, window.second),
              all.Slice(window.first, window.second));
  }
  EXPECT_EQ(source.LowerBound(all.t_ns(777)), static_cast<int64_t>(all.LowerBound(all.t_ns(777))));
  const EventSummary summary = source.Summarize();
  EXPECT_EQ(summary.count, 200000);
  EXPECT_EQ(summary.positive, static_cast<int64_t>(events.CountPositive()));
  EXPECT_EQ(summary.t_first_ns, first);
  EXPECT_EQ(summary.t_last_ns, last);
}

TEST(Hdf5IoTest, WindowedReadKeepsWholeRunsOfEqualTimestamps) {
  const std::string path = test::ScratchDir("h5_runs") + "/events.h5";
  test::ExpectWindowsKeepWholeRuns(
      kWidth, kHeight, [&](const EventStream& events) { WriteHdf5(path, events, {}, {}); },
      [&](int64_t t_begin_ns, int64_t t_end_ns) {
        return Hdf5DataSource(path).ReadEvents(t_begin_ns, t_end_ns);
      });
}

TEST(Hdf5IoTest, TimesBeyondExactDoublesAreStoredAsIntegerNanoseconds) {
  EventStream events(kWidth, kHeight);
  events.push_back(4000000000000000001, 1, 2, 1);  // ~127 years: float64 seconds would round
  events.push_back(4000000000000000002, 3, 4, -1);
  const std::string path = test::ScratchDir("h5_int_ns") + "/events.h5";
  WriteHdf5(path, events, {}, {});
  EXPECT_EQ(DatasetType(path, "events/ts").first, H5T_INTEGER);
  EXPECT_EQ(Hdf5DataSource(path).ReadAllEvents(), events);
}

TEST(Hdf5IoTest, ReadsFilesOfOtherTools) {
  const std::string dir = test::ScratchDir("h5_other_tools");
  const std::vector<uint16_t> xs = {1, 5, 9};
  const std::vector<uint16_t> ys = {2, 6, 7};
  const std::vector<int8_t> minus_one_one = {-1, 1, -1};
  // Integer microseconds (no unit attribute), nanoseconds with ts_unit, and float seconds with
  // h5py-style bool polarity.
  WriteRawEvents(dir + "/us.h5", std::vector<int64_t>{10, 20, 20}, H5T_NATIVE_INT64, xs, ys,
                 minus_one_one, H5T_NATIVE_INT8, nullptr);
  WriteRawEvents(dir + "/ns.h5", std::vector<int64_t>{10, 20, 20}, H5T_NATIVE_INT64, xs, ys,
                 std::vector<uint8_t>{0, 1, 0}, H5T_NATIVE_UINT8, "ns");
  const hid_t bool_type = H5Tenum_create(H5T_NATIVE_INT8);
  const int8_t false_value = 0;
  const int8_t true_value = 1;
  H5Tenum_insert(bool_type, "FALSE", &false_value);
  H5Tenum_insert(bool_type, "TRUE", &true_value);
  WriteRawEvents(dir + "/bool.h5", std::vector<double>{0.5, 0.75, 1.000000001}, H5T_NATIVE_DOUBLE,
                 xs, ys, std::vector<int8_t>{0, 1, 0}, bool_type, nullptr);
  H5Tclose(bool_type);

  const auto expected = [&](std::vector<int64_t> t_ns) {
    EventStream events(10, 8);  // no sensor_resolution, no frames: largest coordinate + 1
    for (int i = 0; i < 3; ++i) events.push_back(t_ns[i], xs[i], ys[i], i == 1 ? 1 : -1);
    return events;
  };
  EXPECT_EQ(Hdf5DataSource(dir + "/us.h5").ReadAllEvents(), expected({10000, 20000, 20000}));
  EXPECT_EQ(Hdf5DataSource(dir + "/ns.h5").ReadAllEvents(), expected({10, 20, 20}));
  EXPECT_EQ(Hdf5DataSource(dir + "/bool.h5").ReadAllEvents(),
            expected({500000000, 750000000, 1000000001}));
}

TEST(Hdf5IoTest, InvalidEventsAreInputErrors) {
  const std::string dir = test::ScratchDir("h5_invalid_events");
  const std::vector<uint16_t> xs = {1, 5, 9};
  const std::vector<uint16_t> ys = {2, 6, 7};
  WriteRawEvents(dir + "/polarity.h5", std::vector<double>{0.1, 0.2, 0.3}, H5T_NATIVE_DOUBLE, xs,
                 ys, std::vector<int8_t>{0, 2, 1}, H5T_NATIVE_INT8, nullptr);
  WriteRawEvents(dir + "/backwards.h5", std::vector<double>{0.1, 0.3, 0.2}, H5T_NATIVE_DOUBLE, xs,
                 ys, std::vector<int8_t>{0, 1, 1}, H5T_NATIVE_INT8, nullptr);
  WriteRawEvents(dir + "/unit.h5", std::vector<int64_t>{1, 2, 3}, H5T_NATIVE_INT64, xs, ys,
                 std::vector<int8_t>{0, 1, 1}, H5T_NATIVE_INT8, "fortnights");
  test::ExpectInputError([&] { Hdf5DataSource source(dir + "/polarity.h5"); },
                         InputError::Kind::kOutOfRange, "events/ps[1]", 0);
  test::ExpectInputError([&] { Hdf5DataSource source(dir + "/backwards.h5"); },
                         InputError::Kind::kNotMonotonic, "events/ts[2]", 0);
  test::ExpectInputError([&] { Hdf5DataSource source(dir + "/unit.h5"); },
                         InputError::Kind::kMalformed, "ts_unit", 0);

  // Coordinates outside sensor_resolution.
  EventStream events(kWidth, kHeight);
  events.push_back(1000, kWidth - 1, 0, 1);
  events.push_back(2000, kWidth, 0, 1);
  WriteHdf5(dir + "/outside.h5", events, {}, {});
  const Hdf5DataSource source(dir + "/outside.h5");
  test::ExpectInputError([&] { source.ReadAllEvents(); }, InputError::Kind::kOutOfRange,
                         "events/xs[1]", 0);
  EXPECT_EQ(source.ReadEvents(0, 1500).size(), 1u);
}

herr_t CountHdf5Errors(hid_t, void* count) {
  ++*static_cast<int*>(count);
  return 0;
}

// libhdf5's automatic error printing belongs to the process: evfs silences it only while it
// calls libhdf5 itself, and puts back whatever handler was installed before.
TEST(Hdf5IoTest, Hdf5ErrorPrintingIsSilencedOnlyWhileEvfsCallsLibhdf5) {
  const std::string dir = test::ScratchDir("h5_error_scope");
  const std::string garbage = dir + "/garbage.h5";
  test::WriteFile(garbage, std::string(4096, 'x'));
  H5E_auto2_t saved = nullptr;
  void* saved_data = nullptr;
  ASSERT_GE(H5Eget_auto2(H5E_DEFAULT, &saved, &saved_data), 0);
  int errors = 0;
  ASSERT_GE(H5Eset_auto2(H5E_DEFAULT, CountHdf5Errors, &errors), 0);

  // evfs' own failing calls report nothing through the handler...
  test::ExpectInputError([&] { Hdf5DataSource source(garbage); }, InputError::Kind::kMalformed,
                         garbage, 0);
  EXPECT_FALSE(IsHdf5WrittenByEvfs(garbage));
  const std::string unwritable = dir + "/no/such/folder/out.h5";
  test::ExpectInputError([&] { WriteHdf5(unwritable, EventStream(), {}, {}); },
                         InputError::Kind::kUnwritable, unwritable, 0);
  EXPECT_EQ(errors, 0);
  // ...and leave it installed, so that a failing call of the process's own is still reported.
  H5E_auto2_t current = nullptr;
  void* current_data = nullptr;
  ASSERT_GE(H5Eget_auto2(H5E_DEFAULT, &current, &current_data), 0);
  EXPECT_EQ(current, &CountHdf5Errors);
  EXPECT_EQ(current_data, &errors);
  EXPECT_LT(H5Fopen(garbage.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), 0);
  EXPECT_GT(errors, 0);
  H5Eset_auto2(H5E_DEFAULT, saved, saved_data);
}

// Reading marks the thread as inside libhdf5 only while it is (core/input_library.h).
TEST(Hdf5IoTest, ReadingMarksLibhdf5OnlyWhileItRuns) {
  EXPECT_EQ(InputLibraryOfThisThread(), nullptr);
  // Reading leaves no mark behind, on success or failure.
  const std::string dir = test::ScratchDir("h5_marks");
  const Recording recording = MakeRecording(3, 1000);
  WriteHdf5(dir + "/good.h5", recording.events, recording.frames, recording.images);
  {
    const Hdf5DataSource source(dir + "/good.h5");
    EXPECT_EQ(source.ReadAllEvents().size(), recording.events.size());
    EXPECT_EQ(InputLibraryOfThisThread(), nullptr);
    EXPECT_EQ(LastInputLibrary(), &kLibhdf5);
  }
  test::WriteFile(dir + "/garbage.h5", std::string(4096, 'x'));
  EXPECT_THROW(Hdf5DataSource source(dir + "/garbage.h5"), InputError);
  EXPECT_EQ(InputLibraryOfThisThread(), nullptr);
}

// A folder (or FIFO) named like an HDF5 file exists: saying it does not would mislead.
TEST(Hdf5IoTest, FolderNamedLikeAnHdf5FileIsNotAMissingFile) {
  const std::string dir = test::ScratchDir("h5_folder");
  const std::string folder = dir + "/recording.h5";
  std::filesystem::create_directories(folder);
  const InputError error = test::CatchInputError([&] { Hdf5DataSource source(folder); });
  EXPECT_EQ(error.kind(), InputError::Kind::kMalformed);
  EXPECT_NE(std::string(error.what()).find("not a regular file"), std::string::npos)
      << error.what();
}

TEST(Hdf5IoTest, CorruptOrIncompleteFilesAreInputErrors) {
  const std::string dir = test::ScratchDir("h5_corrupt");
  const Recording recording = MakeRecording(2, 100000);
  const std::string good = dir + "/good.h5";
  WriteHdf5(good, recording.events, recording.frames, recording.images);

  const std::string truncated = dir + "/truncated.h5";
  std::filesystem::copy_file(good, truncated);
  std::filesystem::resize_file(truncated, std::filesystem::file_size(good) / 2);
  test::ExpectInputError([&] { Hdf5DataSource source(truncated); }, InputError::Kind::kMalformed,
                         truncated, 0);

  const std::string garbage = dir + "/garbage.h5";
  test::WriteFile(garbage, std::string(4096, 'x'));
  test::ExpectInputError([&] { Hdf5DataSource source(garbage); }, InputError::Kind::kMalformed,
                         garbage, 0);

  const std::string missing_dataset = dir + "/missing_dataset.h5";
  std::filesystem::copy_file(good, missing_dataset);
  const hid_t file = H5Fopen(missing_dataset.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  ASSERT_GE(H5Ldelete(file, "events/ps", H5P_DEFAULT), 0);
  H5Fclose(file);
  const InputError error = test::CatchInputError([&] { Hdf5DataSource source(missing_dataset); });
  EXPECT_EQ(error.kind(), InputError::Kind::kMalformed);
  EXPECT_NE(std::string(error.what()).find("events/ps"), std::string::npos) << error.what();

  test::ExpectInputError([&] { Hdf5DataSource source(dir + "/nope.h5"); },
                         InputError::Kind::kMissingFile, dir + "/nope.h5", 0);
}

// A dataset created but never (or only partly) written reads as fill values; the reader must
// call that an incomplete file, not zeros (a 7 KB file could otherwise claim a 65536x65536 frame).
TEST(Hdf5IoTest, DeclaredButUnwrittenDataIsAnInputError) {
  const std::string dir = test::ScratchDir("h5_unwritten");
  const Recording recording = MakeRecording(6, 100);
  // Replaces dataset `name` of a fresh copy of the recording by one of `dims` and `type`, chunked
  // by `chunk`, of which only the first chunk is written when `write_first_chunk`.
  const auto recreated = [&](const std::string& file_name, const std::string& name,
                             std::vector<hsize_t> dims, std::vector<hsize_t> chunk, hid_t type,
                             bool write_first_chunk) {
    const std::string path = dir + "/" + file_name;
    WriteHdf5(path, recording.events, recording.frames, recording.images);
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    EXPECT_GE(H5Ldelete(file, name.c_str(), H5P_DEFAULT), 0);
    const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
    const hid_t properties = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(properties, static_cast<int>(chunk.size()), chunk.data());
    const hid_t dataset =
        H5Dcreate2(file, name.c_str(), type, space, H5P_DEFAULT, properties, H5P_DEFAULT);
    if (write_first_chunk) {
      const std::vector<hsize_t> origin(dims.size(), 0);
      H5Sselect_hyperslab(space, H5S_SELECT_SET, origin.data(), nullptr, chunk.data(), nullptr);
      const hid_t memory = H5Screate_simple(static_cast<int>(chunk.size()), chunk.data(), nullptr);
      const std::vector<uint8_t> zeros(1 << 16, 0);
      H5Dwrite(dataset, H5T_NATIVE_UINT8, memory, space, H5P_DEFAULT, zeros.data());
      H5Sclose(memory);
    }
    const double timestamp = 3.0;
    WriteScalarAttribute(dataset, "timestamp", H5T_NATIVE_DOUBLE, &timestamp);
    H5Dclose(dataset);
    H5Pclose(properties);
    H5Sclose(space);
    H5Fclose(file);
    return test::CatchInputError([&] { Hdf5DataSource source(path); });
  };
  const struct {
    const char* file_name;
    InputError error;
    const char* message_part;
  } cases[] = {
      {"events.h5", recreated("events.h5", "events/ps", {100}, {50}, H5T_STD_I8LE, false),
       "events/ps declares 100 1-byte values but the file stores 0 bytes"},
      {"image.h5",
       recreated("image.h5", "images/image000000001", {65536, 65536}, {256, 256}, H5T_STD_U8LE,
                 false),
       "images/image000000001 declares 65536x65536 1-byte values but the file stores 0 bytes"},
      {"partial.h5",
       recreated("partial.h5", "images/image000000001", {kHeight, kWidth}, {kHeight / 2, kWidth},
                 H5T_STD_U8LE, true),
       "images/image000000001 declares 48x64 1-byte values but the file stores 1536 bytes"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file_name);
    EXPECT_EQ(c.error.kind(), InputError::Kind::kMalformed);
    EXPECT_NE(std::string(c.error.what()).find(c.message_part), std::string::npos)
        << c.error.what();
  }
}

// Image names and paths end up in messages and file names, so they must be printable text.
TEST(Hdf5IoTest, UnprintableImageNamesAndPathsAreMalformed) {
  const std::string dir = test::ScratchDir("h5_names");
  Recording recording = MakeRecording(5, 10);
  recording.frames[1].path = "images/\x1b[2Jb.png";
  WriteHdf5(dir + "/path.h5", recording.events, recording.frames, recording.images);
  const InputError path_error =
      test::CatchInputError([&] { Hdf5DataSource source(dir + "/path.h5"); });
  EXPECT_EQ(path_error.kind(), InputError::Kind::kMalformed);
  EXPECT_NE(std::string(path_error.what()).find("images/\\x1b[2Jb.png' holds a control"),
            std::string::npos)
      << path_error.what();

  const Recording good = MakeRecording(5, 10);
  const auto renamed = [&](const std::string& name, const std::string& new_name) {
    const std::string path = dir + "/" + name + ".h5";
    WriteHdf5(path, good.events, good.frames, good.images);
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    EXPECT_GE(H5Lmove(file, "images/image000000001", file, ("images/" + new_name).c_str(),
                      H5P_DEFAULT, H5P_DEFAULT),
              0);
    H5Fclose(file);
    return test::CatchInputError([&] { Hdf5DataSource source(path); });
  };
  const InputError control = renamed("control", "image\x01");
  EXPECT_EQ(control.kind(), InputError::Kind::kMalformed);
  EXPECT_NE(std::string(control.what()).find("images/image\\x01: expected a printable"),
            std::string::npos)
      << control.what();
  const InputError long_name = renamed("long_name", std::string(1000, 'n'));
  EXPECT_EQ(long_name.kind(), InputError::Kind::kMalformed);
  EXPECT_NE(std::string(long_name.what()).find("(1000 bytes): expected a printable"),
            std::string::npos)
      << long_name.what();
}

TEST(Hdf5IoTest, ImageOfAnotherSizeThanTheSensorIsAnInputError) {
  Recording recording = MakeRecording(3, 10);
  recording.images[1] = test::MakeRandomImage(4, kWidth + 1, kHeight, 8);
  const std::string path = test::ScratchDir("h5_size") + "/recording.h5";
  WriteHdf5(path, recording.events, recording.frames, recording.images);
  // Found when the file opens, before any frame is read.
  test::ExpectInputError([&] { Hdf5DataSource source(path); }, InputError::Kind::kSizeMismatch,
                         "images/image000000001", 0);
}

// A compressed dataset may declare any extent (its stored size says nothing about it). One of
// 2^32 + 48 rows once passed as the 48-row sensor's image (the extent was cast to int) and
// H5Dread wrote past the image: it must be an error, whether it is the first image (which sets
// the sensor size) or a later one.
TEST(Hdf5IoTest, ImageExtentBeyondIntIsAnInputError) {
  const std::string dir = test::ScratchDir("h5_huge_extent");
  const Recording recording = MakeRecording(7, 10);
  const auto with_huge_image = [&](const std::string& file_name, const std::string& name) {
    const std::string path = dir + "/" + file_name;
    WriteHdf5(path, recording.events, recording.frames, recording.images);
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    EXPECT_GE(H5Ldelete(file, name.c_str(), H5P_DEFAULT), 0);
    const hsize_t dims[2] = {(hsize_t{1} << 32) + kHeight, kWidth};
    const hsize_t chunk[2] = {kHeight, kWidth};
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t properties = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(properties, 2, chunk);
    H5Pset_deflate(properties, 1);
    const hid_t dataset =
        H5Dcreate2(file, name.c_str(), H5T_STD_U8LE, space, H5P_DEFAULT, properties, H5P_DEFAULT);
    const hsize_t origin[2] = {0, 0};
    H5Sselect_hyperslab(space, H5S_SELECT_SET, origin, nullptr, chunk, nullptr);
    const hid_t memory = H5Screate_simple(2, chunk, nullptr);
    const std::vector<uint8_t> zeros(kHeight * kWidth, 0);
    H5Dwrite(dataset, H5T_NATIVE_UINT8, memory, space, H5P_DEFAULT, zeros.data());
    const double timestamp = name.back() == '0' ? 2.0 : 3.0;
    WriteScalarAttribute(dataset, "timestamp", H5T_NATIVE_DOUBLE, &timestamp);
    H5Sclose(memory);
    H5Dclose(dataset);
    H5Pclose(properties);
    H5Sclose(space);
    H5Fclose(file);
    return path;
  };
  // With the sensor size in the file, every image is checked against it when the file opens.
  const std::string first = with_huge_image("first.h5", "images/image000000000");
  test::ExpectInputError([&] { Hdf5DataSource source(first); }, InputError::Kind::kSizeMismatch,
                         "images/image000000000 is 64x4294967344", 0);
  // Without, the first image sets it.
  const std::string unsized = with_huge_image("unsized.h5", "images/image000000000");
  const hid_t file = H5Fopen(unsized.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  EXPECT_GE(H5Adelete(file, "sensor_resolution"), 0);
  H5Fclose(file);
  test::ExpectInputError([&] { Hdf5DataSource source(unsized); }, InputError::Kind::kMalformed,
                         "each side must be 1 to 65536 pixels", 0);
  const std::string later = with_huge_image("later.h5", "images/image000000001");
  test::ExpectInputError([&] { Hdf5DataSource source(later); }, InputError::Kind::kSizeMismatch,
                         "images/image000000001 is 64x4294967344", 0);
}

// Regression: a sensor_resolution of 65535x65535 over 64x48 frames was trusted until
// a frame was read, and `evfs info --first` allocated for its 4 G pixels first (bad_alloc).
// Declared sizes are checked against the frames and bounded when the file opens.
TEST(Hdf5IoTest, DeclaredSensorSizeIsCheckedBeforeAllocating) {
  const std::string dir = test::ScratchDir("h5_declared_size");
  const Recording recording = MakeRecording(5, 100);
  const std::string framed = dir + "/framed.h5";
  WriteHdf5(framed, recording.events, recording.frames, recording.images);
  DeclareSensorResolution(framed, 65535, 65535);
  test::ExpectInputError([&] { Hdf5DataSource source(framed); }, InputError::Kind::kOutOfRange,
                         "65535x65535 sensor", 0);
  // Sides beyond what any reader takes are named as such, not as a non-positive size.
  DeclareSensorResolution(framed, 100000, 100000);
  test::ExpectInputError([&] { Hdf5DataSource source(framed); }, InputError::Kind::kOutOfRange,
                         "declares a 100000x100000 sensor: beyond the 65536 pixels a side", 0);
  // Within the bound, the frames must still have the declared size.
  DeclareSensorResolution(framed, 4096, 8192);
  test::ExpectInputError([&] { Hdf5DataSource source(framed); }, InputError::Kind::kSizeMismatch,
                         "the sensor is 8192x4096", 0);
  // Without frames, too: a size beyond any sensor is refused.
  const std::string huge = dir + "/huge.h5";
  WriteHdf5(huge, recording.events, {}, {});
  DeclareSensorResolution(huge, 65535, 65535);
  test::ExpectInputError([&] { Hdf5DataSource source(huge); }, InputError::Kind::kOutOfRange,
                         "65535x65535 sensor", 0);
  // A declared sensor larger than the events need, within the bound, is a sensor.
  const std::string larger = dir + "/larger.h5";
  WriteHdf5(larger, recording.events, {}, {});
  DeclareSensorResolution(larger, 4096, 8192);
  const Hdf5DataSource source(larger);
  EXPECT_EQ(source.width(), 8192);
  EXPECT_EQ(source.height(), 4096);
  EXPECT_EQ(source.ReadAllEvents().size(), recording.events.size());
}

// The file the HDF5 fuzzer found it with: a contiguous image whose type reads as 0 bytes (so no
// stored size could be checked) and whose extent wraps onto 12x16 in 32 bits.
TEST(Hdf5IoTest, FuzzerFindingImageExtentWrapsIntIsAnInputError) {
  const std::string path =
      std::string(EVFS_TEST_SOURCE_DIR) + "/data/fuzz_image_extent_wraps_int.h5";
  test::ExpectInputError([&] { Hdf5DataSource source(path); }, InputError::Kind::kMalformed,
                         "unreadable type of images/image000000001", 0);
}

// The file the HDF5 fuzzer found it with: events/xs holds 16-bit integers at bit offset 1 of a
// 2-byte type, which libhdf5 converted differently depending on where a read started (event 20
// read as x = 32768 in the whole file and as x = 0 from event 19 on).
TEST(Hdf5IoTest, FuzzerFindingIntegerBitsBeyondTheirTypeIsAnInputError) {
  const std::string path =
      std::string(EVFS_TEST_SOURCE_DIR) + "/data/fuzz_integer_bits_beyond_type.h5";
  test::ExpectInputError([&] { Hdf5DataSource source(path); }, InputError::Kind::kMalformed,
                         "corrupt type of events/xs: 16 bits at bit offset 1 do not fit in 2 "
                         "bytes",
                         0);
}

TEST(Hdf5IoTest, UnwritablePathIsAnInputError) {
  const std::string path = test::ScratchDir("h5_unwritable") + "/no/folder/out.h5";
  test::ExpectInputError([&] { WriteHdf5(path, EventStream(), {}, {}); },
                         InputError::Kind::kUnwritable, path, 0);
  EXPECT_THROW(WriteHdf5(path, EventStream(), std::vector<FrameInfo>(1), {}), InvalidArgumentError);
}

}  // namespace
}  // namespace evfs
