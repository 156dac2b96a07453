// End-to-end tests of the `evfs` tool: what users type, what they read back, exit codes.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/io/data_source.h"
#include "evfs/io/hdf5_io.h"
#include "evfs/io/image_io.h"
#include "evfs/io/text_folder.h"
#include "evfs/tests/examples/cli_test_util.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

using test::CommandResult;
using test::ExpectUserError;
using test::ReadFile;
using test::RunEvfs;
using test::WriteSyntheticFolder;

TEST(EvfsCli, InfoDescribesTheSharedSnippets) {
  EVFS_REQUIRE_SHARED_DATA(data);
  const CommandResult slider =
      RunEvfs("info --data=" + data + "/slider_depth_70_71 --first=0 --last=1");
  ASSERT_EQ(slider.exit_code, 0) << slider.output;
  EXPECT_NE(slider.output.find("240x180"), std::string::npos) << slider.output;
  EXPECT_NE(slider.output.find("events      16418"), std::string::npos) << slider.output;
  EXPECT_NE(slider.output.find("frames      2"), std::string::npos) << slider.output;
  EXPECT_NE(slider.output.find("16418 events (7353 ON, 9065 OFF) at 11264 pixels (26.1 %), "
                               "13 collision frames"),
            std::string::npos)
      << slider.output;
  EXPECT_NE(slider.output.find("brightness  frame 0 mean 0.228, frame 1 mean 0.231 (+1.1 %)"),
            std::string::npos)
      << slider.output;

  const CommandResult cups = RunEvfs("info --data=" + data + "/eslnet_cups_blur");
  ASSERT_EQ(cups.exit_code, 0) << cups.output;
  EXPECT_NE(cups.output.find("346x260"), std::string::npos);
  EXPECT_NE(cups.output.find("frames      6"), std::string::npos);
  EXPECT_NE(cups.output.find("exposure 3.312216 .. 3.416216 s (104.0 ms)"), std::string::npos)
      << cups.output;

  const CommandResult clip = RunEvfs("info --data=" + data + "/nfs_basketball_7");
  ASSERT_EQ(clip.exit_code, 0) << clip.output;
  EXPECT_NE(clip.output.find("200x200"), std::string::npos);
  EXPECT_NE(clip.output.find("frames only"), std::string::npos);
}

TEST(EvfsCli, SimulateWritesAFolderThatInfoReads) {
  EVFS_REQUIRE_SHARED_DATA(data);
  const std::string out = test::ScratchDir("simulate") + "/nfs";
  const CommandResult simulate =
      RunEvfs("simulate --frames=" + data + "/nfs_basketball_7 --out=" + out);
  ASSERT_EQ(simulate.exit_code, 0) << simulate.output;
  const CommandResult info = RunEvfs("info --data=" + out + " --first=0 --last=1");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("200x200"), std::string::npos);
  EXPECT_NE(info.output.find("frames      20"), std::string::npos);
  EXPECT_NE(info.output.find("collision frames"), std::string::npos);
}

// Without effects the frames are written as read; with an exposure, exposures.txt is written
// and read back by info; the light sources and effects are flags with clear errors.
TEST(EvfsCli, SimulateEffectsWriteExposuresAndCheckTheirFlags) {
  EVFS_REQUIRE_SHARED_DATA(data);
  const std::string scratch = test::ScratchDir("simulate_effects");
  const std::string frames = data + "/nfs_basketball_7";
  const CommandResult plain =
      RunEvfs("simulate --frames=" + frames + " --out=" + scratch + "/plain");
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  const Image input = ReadGreyImage(frames + "/frames/frame_00000003.png");
  EXPECT_TRUE((ReadGreyImage(scratch + "/plain/frames/frame_00000003.png") == input).all());

  const CommandResult exposed =
      RunEvfs("simulate --frames=" + frames + " --out=" + scratch +
              "/exposed --exposure_s=0.01 --flicker_led_hz=500 --flicker_led_xy_px=50,60 "
              "--read_noise_dn=1");
  ASSERT_EQ(exposed.exit_code, 0) << exposed.output;
  const std::string exposures = ReadFile(scratch + "/exposed/exposures.txt");
  // Frame 1 at 4.166667 ms: its 10 ms window is cut at the first frame, t = 0.
  EXPECT_NE(exposures.find("frames/frame_00000001.png 0.000000000 0.009166667"), std::string::npos)
      << exposures;
  EXPECT_FALSE((ReadGreyImage(scratch + "/exposed/frames/frame_00000003.png") == input).all());
  const auto source = DataSource::Open(scratch + "/exposed");
  ASSERT_EQ(source->frames().size(), 20u);
  EXPECT_TRUE(source->frames()[5].has_exposure);

  for (const char* flags : {"--flicker_led_hz=500", "--flicker_led_xy_px=3,4",
                            "--mains_hz=100 --mains_depth=2", "--mains_region_px=1,2,3",
                            "--read_noise_dn=-1", "--hot_pixel_fraction=2", "--exposure_s=-1"}) {
    const CommandResult bad =
        RunEvfs("simulate --frames=" + frames + " --out=" + scratch + "/bad " + flags);
    EXPECT_EQ(bad.exit_code, 2) << flags << ": " << bad.output;
  }
}

TEST(EvfsCli, ConvertRoundTripIsByteIdentical) {
  EVFS_REQUIRE_SHARED_DATA(data);
  const std::string scratch = test::ScratchDir("convert");
  const std::string source = data + "/shapes_rotation_13_20";
  ASSERT_EQ(RunEvfs("convert --data=" + source + " --out=" + scratch + "/shapes.h5").exit_code, 0);
  ASSERT_EQ(
      RunEvfs("convert --data=" + scratch + "/shapes.h5 --out=" + scratch + "/back").exit_code, 0);
  EXPECT_EQ(ReadFile(scratch + "/back/events.txt"), ReadFile(source + "/events.txt"));
  EXPECT_EQ(ReadFile(scratch + "/back/images.txt"), ReadFile(source + "/images.txt"));
}

TEST(EvfsCli, ReconstructWritesFramesTimestampsAndSummary) {
  const std::string scratch = test::ScratchDir("reconstruct");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string out = scratch + "/out";
  const CommandResult run =
      RunEvfs("reconstruct --data=" + data +
              " --mode=interpolate --first=0 --last=2 --truth=1 --out=" + out);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string summary = ReadFile(out + "/summary.json");
  EXPECT_NE(summary.find("\"mode\": \"interpolate\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"truth\": {"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"alpha_derived\": true"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"jacobian_evaluations\": "), std::string::npos) << summary;
  const std::string timestamps = ReadFile(out + "/timestamps.txt");
  const int lines = static_cast<int>(std::count(timestamps.begin(), timestamps.end(), '\n'));
  int pngs = 0;
  for (const auto& entry : fs::directory_iterator(out + "/frames")) pngs += entry.is_regular_file();
  EXPECT_GT(lines, 2);
  EXPECT_EQ(pngs, lines);

  // Resampled to a uniform rate: 10 ms at 1 kHz gives 11 frames.
  const CommandResult resampled =
      RunEvfs("reconstruct --data=" + data +
              " --mode=interpolate --first=0 --last=2 --fps=1000 --out=" + out + "_1khz");
  ASSERT_EQ(resampled.exit_code, 0) << resampled.output;
  const std::string uniform = ReadFile(out + "_1khz/timestamps.txt");
  EXPECT_EQ(std::count(uniform.begin(), uniform.end(), '\n'), 11);
}

TEST(EvfsCli, UserErrorsExitWithStatus2AndLeaveNoOutput) {
  const std::string scratch = test::ScratchDir("errors");
  const std::string data = WriteSyntheticFolder(scratch);
  const std::string out = scratch + "/out";
  const struct {
    std::string arguments;
    std::string expected;  // part of the one-line message
  } cases[] = {
      {"frobnicate", "unknown command"},
      {"info --data=" + scratch + "/missing", "missing"},
      {"reconstruct --data=" + data + " --mode=sideways --first=0 --out=" + out, "unknown mode"},
      {"reconstruct --data=" + data + " --mode=predict --first=9 --out=" + out, "out of range"},
      {"reconstruct --data=" + data + " --mode=interpolate --first=2 --last=1 --out=" + out,
       "must come after"},
      {"reconstruct --data=" + data + " --mode=deblur --first=1 --out=" + out, "exposure"},
      {"reconstruct --data=" + data + " --mode=predict --first=0 --spatial_tv=round --out=" + out,
       "--spatial_tv"},
      // Values that used to overflow the nanosecond timeline or resample forever.
      {"reconstruct --data=" + data + " --mode=deblur --first=1 --exposure_s=1e30 --out=" + out,
       "--exposure_s must be in [0, 3600], not 1e+30"},
      {"reconstruct --data=" + data + " --mode=predict --first=0 --fps=1e300 --out=" + out,
       "--fps would resample"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.arguments);
    ExpectUserError(RunEvfs(c.arguments), c.expected, out);
  }
}

// A tiny recording whose every line is known: two 16x12 frames 100 ms apart and ten events
// between them, on lines 1..10 of events.txt (t = 1.00, 1.01, ..., 1.09 s).
constexpr int kTinyWidth = 16;
constexpr int kTinyHeight = 12;

std::string TinyEventLines() {
  std::string lines;
  for (int i = 0; i < 10; ++i) {
    lines += "1.0" + std::to_string(i) + " " + std::to_string(i) + " " + std::to_string(i) + " " +
             (i % 2 ? "1" : "0") + "\n";
  }
  return lines;
}

fs::path WriteTinyFolder(const fs::path& folder) {
  fs::create_directories(folder / "images");
  WriteGreyPng8((folder / "images/a.png").string(),
                test::MakeRandomImage(1, kTinyWidth, kTinyHeight, 8));
  WriteGreyPng8((folder / "images/b.png").string(),
                test::MakeRandomImage(2, kTinyWidth, kTinyHeight, 8));
  test::WriteFile((folder / "images.txt").string(), "1.0 images/a.png\n1.1 images/b.png\n");
  test::WriteFile((folder / "events.txt").string(), TinyEventLines());
  return folder;
}

// `lines` with line `number` (1-based) replaced by `replacement`.
std::string ReplaceLine(const std::string& lines, int number, const std::string& replacement) {
  std::istringstream in(lines);
  std::string result;
  std::string line;
  for (int i = 1; std::getline(in, line); ++i) result += (i == number ? replacement : line) + "\n";
  return result;
}

// Every kind of bad data file: exit status 2, one line naming the file (and line), no output.
TEST(EvfsCli, BadDataFilesAreUserErrors) {
  const fs::path scratch = test::ScratchDir("bad_files");
  const fs::path out = scratch / "out";
  const std::string events = TinyEventLines();
  const std::string megabyte(1 << 20, '9');
  const struct {
    std::string name;
    std::string file;     // relative to the folder
    std::string content;  // written over it ("" with remove: deleted)
    bool remove;
    std::string mode;  // and frame flags
    std::string expected;
  } cases[] = {
      {"field_count", "events.txt", ReplaceLine(events, 3, "1.02 2 2"), false, "predict --first=0",
       "events.txt:3: expected 4 fields"},
      {"not_a_number", "events.txt", ReplaceLine(events, 3, "1.02 two 2 1"), false,
       "predict --first=0", "events.txt:3: field 'x'"},
      {"nan", "events.txt", ReplaceLine(events, 3, "nan 2 2 1"), false, "predict --first=0",
       "events.txt:3: field 't'"},
      {"overflow", "events.txt", ReplaceLine(events, 3, "1.02 99999999999999999999 2 1"), false,
       "predict --first=0", "events.txt:3: x = 99999999999999999999 is outside"},
      {"binary", "events.txt", ReplaceLine(events, 3, std::string("\x01\xff\0\x1b[2J", 7)), false,
       "predict --first=0", "events.txt:3:"},
      {"megabyte_line", "events.txt", ReplaceLine(events, 3, "1.02 " + megabyte + " 2 1"), false,
       "predict --first=0", "events.txt:3: x = 9999"},
      {"truncated", "events.txt", events + "1.095 1", false, "predict --first=0",
       "events.txt:11: expected 4 fields"},
      {"outside_sensor", "events.txt", ReplaceLine(events, 3, "1.02 16 2 1"), false,
       "predict --first=0", "events.txt:3: x = 16 is outside the sensor"},
      {"polarity", "events.txt", ReplaceLine(events, 3, "1.02 2 2 2"), false, "predict --first=0",
       "events.txt:3: polarity must be -1, 0 or 1"},
      {"events_backwards", "events.txt", ReplaceLine(events, 3, "0.5 2 2 1"), false,
       "predict --first=0", "events.txt:3: timestamps must not decrease"},
      {"images_backwards", "images.txt", "1.0 images/a.png\n0.9 images/b.png\n", false,
       "predict --first=0", "images.txt:2: frame timestamps must increase"},
      {"images_malformed", "images.txt", "1.0 images/a.png\n1.1\n", false, "predict --first=0",
       "images.txt:2: expected 't path'"},
      {"exposures_malformed", "exposures.txt", "images/a.png 0.95 nan\n", false, "deblur --first=0",
       "exposures.txt:1: field 't_end'"},
      {"missing_events", "events.txt", "", true, "predict --first=0", "events.txt:"},
      {"missing_image", "images/b.png", "", true, "interpolate --first=0 --last=1",
       "images/b.png: image file does not exist"},
      {"unreadable_image", "images/b.png", "not a png", false, "interpolate --first=0 --last=1",
       "images/b.png: cannot decode"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path data = WriteTinyFolder(scratch / c.name);
    if (c.remove) {
      fs::remove(data / c.file);
    } else {
      test::WriteFile((data / c.file).string(), c.content);
    }
    ExpectUserError(RunEvfs("reconstruct --data=" + data.string() + " --mode=" + c.mode +
                            " --out=" + out.string()),
                    c.expected, out);
  }
}

TEST(EvfsCli, ImageOfAnotherSizeIsAUserError) {
  const fs::path scratch = test::ScratchDir("image_size");
  const fs::path data = WriteTinyFolder(scratch / "data");
  WriteGreyPng8((data / "images/b.png").string(),
                test::MakeRandomImage(3, kTinyWidth + 1, kTinyHeight, 8));
  const fs::path out = scratch / "out";
  ExpectUserError(RunEvfs("reconstruct --data=" + data.string() +
                          " --mode=interpolate --first=0 --last=1 --out=" + out.string()),
                  "images/b.png: image is 17x12, expected the sensor size 16x12", out);
}

TEST(EvfsCli, CorruptOrIncompleteHdf5IsAUserError) {
  const fs::path scratch = test::ScratchDir("bad_hdf5");
  const fs::path good = scratch / "good.h5";
  ConvertRecording(WriteTinyFolder(scratch / "data").string(), good.string());
  const fs::path out = scratch / "out";
  const auto reconstruct = [&](const fs::path& h5) {
    return RunEvfs("reconstruct --data=" + h5.string() +
                   " --mode=predict --first=0 --out=" + out.string());
  };
  ASSERT_EQ(reconstruct(good).exit_code, 0);
  fs::remove_all(out);

  const fs::path truncated = scratch / "truncated.h5";
  fs::copy_file(good, truncated);
  fs::resize_file(truncated, fs::file_size(good) / 2);
  ExpectUserError(reconstruct(truncated), truncated.string() + ":", out);

  const fs::path garbage = scratch / "garbage.h5";
  test::WriteFile(garbage.string(), std::string(4096, '\x01'));
  ExpectUserError(reconstruct(garbage), garbage.string() + ": not an HDF5 file", out);

  const fs::path no_frames = scratch / "no_frames.h5";
  WriteHdf5(no_frames.string(), EventStream(), {}, {});
  ExpectUserError(reconstruct(no_frames), no_frames.string() + " has 0 frames", out);
}

// An AEDAT 3.1 file written by an independent encoder from a folder (tests/io/
// aedat_legacy_encode.py) reconstructs to the same bytes as the folder with its event times on
// whole microseconds: every output file but summary.json, which names the input and the run's
// timings. Malformed and unreadable AEDAT 2.0/3.1 files are one-line user errors.
TEST(EvfsCli, Aedat31ReconstructsLikeItsFolderAndBadAedatIsAUserError) {
  EVFS_REQUIRE_SHARED_DATA(data);
  const fs::path scratch = test::ScratchDir("aedat_legacy_cli");
  const std::string encode = "/usr/bin/python3 " + std::string(EVFS_TEST_SOURCE_DIR) +
                             "/../io/aedat_legacy_encode.py " + data + "/slider_depth_70_71 " +
                             scratch.string();
  ASSERT_EQ(std::system(encode.c_str()), 0) << encode;
  const auto reconstruct = [&](const std::string& input, const fs::path& out) {
    return RunEvfs("reconstruct --data=" + input +
                   " --mode=interpolate --first=0 --last=1 --out=" + out.string());
  };
  ASSERT_EQ(reconstruct((scratch / "us").string(), scratch / "from_folder").exit_code, 0);
  ASSERT_EQ(reconstruct((scratch / "davis240.aedat3").string(), scratch / "from_aedat3").exit_code,
            0);
  int compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(scratch / "from_folder")) {
    const fs::path relative = fs::relative(entry.path(), scratch / "from_folder");
    if (!entry.is_regular_file() || relative == "summary.json") continue;
    EXPECT_EQ(test::ReadFile(scratch / "from_aedat3" / relative), test::ReadFile(entry.path()))
        << relative;
    ++compared;
  }
  EXPECT_GT(compared, 2);

  const fs::path out = scratch / "out";
  const fs::path truncated = scratch / "truncated.aedat3";
  fs::copy_file(scratch / "davis240.aedat3", truncated);
  fs::resize_file(truncated, fs::file_size(truncated) - 5);
  ExpectUserError(reconstruct(truncated.string(), out), truncated.string() + ": ", out);
  ExpectUserError(RunEvfs("info --data=" + truncated.string()), "(truncated file?)", out);
  const fs::path dvs128 = scratch / "dvs128.aedat";
  test::WriteFile(
      dvs128.string(),
      "#!AER-DAT2.0\r\n# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n" + std::string(8, '\0'));
  ExpectUserError(RunEvfs("convert --data=" + dvs128.string() + " --out=" + out.string()),
                  "AEDAT 2.0 from a DVS128", out);
}

// Two files the HDF5 fuzzer found on which libhdf5 1.10 itself dies of a segmentation fault
// (in H5AC_protect's block read, and in H5Aexists). The CLI runs HDF5 commands in a child
// process (runtime/crash_guard.h), so they end as a user error, not as a crash. Whether libhdf5
// dies or reads garbage past the corruption depends on what its heap held (one CI run in many
// read an exposure that ends before it starts instead): either way, one line naming the file.
TEST(EvfsCli, Hdf5FileThatCrashesLibhdf5IsAUserError) {
  // Under AddressSanitizer the crash must stay a signal, not become a sanitizer report.
  const char* asan = std::getenv("ASAN_OPTIONS");
  const std::string asan_options = std::string(asan ? asan : "") + ":handle_segv=0";
  setenv("ASAN_OPTIONS", asan_options.c_str(), 1);
  const fs::path scratch = test::ScratchDir("libhdf5_crash");
  const fs::path out = scratch / "out";
  for (const char* name : {"fuzz_libhdf5_segv_cache_read.h5", "fuzz_libhdf5_segv_attribute.h5"}) {
    const std::string h5 = std::string(EVFS_TEST_SOURCE_DIR) + "/data/" + name;
    const std::string expected = h5 + ": ";
    ExpectUserError(RunEvfs("info --data=" + h5), expected, out);
    ExpectUserError(RunEvfs("reconstruct --data=" + h5 +
                            " --mode=interpolate --first=0 --last=1 --out=" + out.string()),
                    expected, out);
    ExpectUserError(RunEvfs("convert --data=" + h5 + " --out=" + out.string()), expected, out);
  }
}

TEST(EvfsCli, UnwritableOutputIsAUserError) {
  const fs::path scratch = test::ScratchDir("unwritable");
  const fs::path data = WriteTinyFolder(scratch / "data");
  test::WriteFile((scratch / "file").string(), "a file, not a folder");
  const fs::path out = scratch / "file" / "out";
  const CommandResult result = RunEvfs("reconstruct --data=" + data.string() +
                                       " --mode=predict --first=0 --out=" + out.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_EQ(std::count(result.errors.begin(), result.errors.end(), '\n'), 1) << result.errors;
  EXPECT_NE(result.errors.find(out.string() + ": cannot create the output: "), std::string::npos)
      << result.errors;
  const CommandResult convert =
      RunEvfs("convert --data=" + data.string() + " --out=" + (scratch / "file/x.h5").string());
  EXPECT_EQ(convert.exit_code, 2) << convert.output;
  EXPECT_NE(convert.errors.find("file/x.h5: cannot create the output: "), std::string::npos)
      << convert.errors;
}

TEST(EvfsCli, ConvertAndSimulateLeaveNothingBehindOnBadInput) {
  const fs::path scratch = test::ScratchDir("convert_bad");
  const fs::path data = WriteTinyFolder(scratch / "data");
  test::WriteFile((data / "events.txt").string(), ReplaceLine(TinyEventLines(), 9, "1.08 1"));
  for (const char* out_name : {"out.h5", "out"}) {
    SCOPED_TRACE(out_name);
    const fs::path out = scratch / out_name;
    ExpectUserError(RunEvfs("convert --data=" + data.string() + " --out=" + out.string()),
                    "events.txt:9: expected 4 fields", out);
  }
  fs::remove(data / "images/a.png");
  ExpectUserError(
      RunEvfs("simulate --frames=" + data.string() + " --out=" + (scratch / "sim").string()),
      "images/a.png: image file does not exist", scratch / "sim");
}

// CRLF, comments, blank lines, -1/1 polarity and last lines without a newline are valid.
TEST(EvfsCli, OdditiesOfRealFilesAreAccepted) {
  const fs::path scratch = test::ScratchDir("oddities");
  const fs::path data = WriteTinyFolder(scratch / "data");
  std::string odd = "# t x y p\r\n\r\n";
  std::istringstream lines(TinyEventLines());
  for (std::string line; std::getline(lines, line);) {
    if (line.back() == '0') line = line.substr(0, line.size() - 1) + "-1";
    odd += line + "\r\n";
  }
  odd.resize(odd.size() - 2);  // no newline after the last event
  test::WriteFile((data / "events.txt").string(), odd);
  test::WriteFile((data / "images.txt").string(),
                  "# t path\r\n1.0 images/a.png\r\n\n1.1 images/b.png");
  const fs::path out = scratch / "out";
  const CommandResult run = RunEvfs("reconstruct --data=" + data.string() +
                                    " --mode=interpolate --first=0 --last=1 --out=" + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(ReadFile(out / "summary.json").find("\"events\": 10,"), std::string::npos);
}

// A window without events is answered with the initialisation (here a copy of the frame).
TEST(EvfsCli, WindowWithoutEventsGivesTheInitialisation) {
  const fs::path scratch = test::ScratchDir("no_events");
  const fs::path data = WriteTinyFolder(scratch / "data");
  test::WriteFile((data / "events.txt").string(), "# no events\n");
  const fs::path out = scratch / "out";
  const CommandResult run = RunEvfs("reconstruct --data=" + data.string() +
                                    " --mode=predict --first=0 --out=" + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(ReadFile(out / "summary.json").find("\"solved\": false"), std::string::npos);
  const Image first = ReadGreyImage((data / "images/a.png").string());
  for (const auto& entry : fs::directory_iterator(out / "frames")) {
    // An 8-bit frame written as 16 bits comes back exactly (k/255 = 257k/65535).
    EXPECT_TRUE((ReadGreyImage(entry.path().string()) == first).all()) << entry.path();
  }
}

}  // namespace
}  // namespace evfs
