// evfs calibrate end to end: the model file it writes, --event_model reading it back, and the
// recordings it refuses (one line, exit status 2). Each test works in a scratch folder of its
// own.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "evfs/tests/examples/cli_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

using test::CommandResult;
using test::ExpectUserError;
using test::RunEvfs;
using test::WriteSyntheticFolder;

// A recording with enough moving texture for a calibration: 9 frames 5 ms apart at 64x48.
std::string WriteRecording(const fs::path& scratch) {
  return WriteSyntheticFolder(scratch.string(), /*num_frames=*/9, /*frame_step_ms=*/5,
                              /*width=*/64, /*height=*/48);
}

TEST(EvfsCalibrate, WritesTheModelAndReconstructReadsItBack) {
  const fs::path scratch = test::ScratchDir("calibrate_model");
  fs::remove_all(scratch);
  const std::string data = WriteRecording(scratch);
  const fs::path model = scratch / "model.json";
  const CommandResult calibrated = RunEvfs("calibrate --data=" + data + " --out=" + model.string());
  ASSERT_EQ(calibrated.exit_code, 0) << calibrated.output;
  EXPECT_NE(calibrated.output.find("C_on"), std::string::npos) << calibrated.output;
  EXPECT_NE(calibrated.output.find("±"), std::string::npos) << calibrated.output;

  std::ifstream file(model);
  const nlohmann::json json = nlohmann::json::parse(file);
  for (const char* key : {"log_offset", "threshold_on", "threshold_off"}) {
    ASSERT_TRUE(json.contains(key)) << key;
    EXPECT_TRUE(json[key]["estimated"].get<bool>()) << key;
    EXPECT_GT(json[key]["value"].get<double>(), 0.0) << key;
    EXPECT_GT(json[key]["standard_error"].get<double>(), 0.0) << key;
    EXPECT_GT(json[key]["pixels"].get<int>(), 0) << key;
    EXPECT_EQ(json[key]["pairs"].get<int>(), 8) << key;
  }
  // The default simulator's sensor: thresholds 0.2 (b = 0.001 is beyond what 8-bit frames of
  // a scene in [0.05, 0.95] can tell, so only the thresholds are held to it).
  constexpr double kThresholdTolerance = 0.05;
  EXPECT_NEAR(json["threshold_on"]["value"].get<double>(), 0.2, kThresholdTolerance);
  EXPECT_NEAR(json["threshold_off"]["value"].get<double>(), 0.2, kThresholdTolerance);

  const fs::path out = scratch / "out";
  const CommandResult reconstructed =
      RunEvfs("reconstruct --data=" + data + " --mode=interpolate --first=2 --last=4 --out=" +
              out.string() + " --event_model=" + model.string());
  ASSERT_EQ(reconstructed.exit_code, 0) << reconstructed.output;
  // The model the file gives: α from the ON threshold, not derived from the window.
  std::ifstream summary_file(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_FALSE(summary["model"]["alpha_derived"].get<bool>());
  EXPECT_NEAR(summary["model"]["alpha"].get<double>(),
              1.0 / json["threshold_on"]["value"].get<double>(), 1e-6);
  EXPECT_NEAR(
      summary["model"]["off_alpha_ratio"].get<double>(),
      json["threshold_on"]["value"].get<double>() / json["threshold_off"]["value"].get<double>(),
      1e-6);

  // A second run may replace the file only with --overwrite.
  EXPECT_EQ(RunEvfs("calibrate --data=" + data + " --out=" + model.string()).exit_code, 2);
  EXPECT_EQ(
      RunEvfs("calibrate --data=" + data + " --out=" + model.string() + " --overwrite").exit_code,
      0);
}

TEST(EvfsCalibrate, RecordingsThatCannotTellAreOneLineUserErrors) {
  const fs::path scratch = test::ScratchDir("calibrate_refused");
  fs::remove_all(scratch);
  const std::string data = WriteRecording(scratch);
  const fs::path model = scratch / "model.json";
  // One frame.
  ExpectUserError(
      RunEvfs("calibrate --data=" + data + " --first=3 --last=3 --out=" + model.string()),
      "two frames", model);
  // No events.
  const fs::path quiet = scratch / "quiet";
  fs::create_directories(quiet);
  fs::copy(data, quiet / "data", fs::copy_options::recursive);
  std::ofstream(quiet / "data" / "events.txt", std::ios::trunc).close();
  ExpectUserError(
      RunEvfs("calibrate --data=" + (quiet / "data").string() + " --out=" + model.string()),
      "no events", model);
  // Not a .json file.
  ExpectUserError(
      RunEvfs("calibrate --data=" + data + " --out=" + (scratch / "model.txt").string()), ".json",
      scratch / "model.txt");
}

TEST(EvfsCalibrate, AMissingOrMalformedModelFileIsAUserError) {
  const fs::path scratch = test::ScratchDir("calibrate_bad_file");
  fs::remove_all(scratch);
  const std::string data = WriteRecording(scratch);
  const fs::path out = scratch / "out";
  ExpectUserError(RunEvfs("reconstruct --data=" + data + " --mode=interpolate --first=2 " +
                          "--last=4 --out=" + out.string() +
                          " --event_model=" + (scratch / "none.json").string()),
                  "none.json", out);
  std::ofstream(scratch / "bad.json") << "{\"log_offset\": 1}";
  ExpectUserError(RunEvfs("reconstruct --data=" + data + " --mode=interpolate --first=2 " +
                          "--last=4 --out=" + out.string() +
                          " --event_model=" + (scratch / "bad.json").string()),
                  "bad.json", out);
}

// evfs info ends with the calibration: each value with its standard error, on no more than the
// first few frames of the selection (and says so), or one line saying why it cannot tell.
TEST(EvfsCalibrate, InfoPrintsTheEventModelOfTheFirstFrames) {
  const fs::path scratch = test::ScratchDir("calibrate_info");
  fs::remove_all(scratch);
  const std::string data = WriteRecording(scratch);
  const CommandResult whole = RunEvfs("info --data=" + data);
  ASSERT_EQ(whole.exit_code, 0) << whole.output;
  // 9 frames: calibrated on the first kInfoCalibrationFrames (3) of them only.
  EXPECT_NE(whole.output.find("event model (as evfs calibrate) on frames 0 to 2, the first 3 of "
                              "the selection"),
            std::string::npos)
      << whole.output;
  for (const char* name : {"b (log offset)", "C_on", "threshold spread", "background rate"}) {
    EXPECT_NE(whole.output.find(name), std::string::npos) << name << "\n" << whole.output;
  }
  // The same thresholds as `evfs calibrate` on those frames.
  const fs::path model = scratch / "model.json";
  ASSERT_EQ(
      RunEvfs("calibrate --data=" + data + " --first=0 --last=2 --out=" + model.string()).exit_code,
      0);
  std::ifstream file(model);
  const nlohmann::json json = nlohmann::json::parse(file);
  char on_line[64];
  std::snprintf(on_line, sizeof(on_line), "%-22s %.4g ± ",
                json["thresholds_tied"].get<bool>() ? "C_on = C_off (tied)" : "C_on (ON threshold)",
                json["threshold_on"]["value"].get<double>());
  EXPECT_NE(whole.output.find(on_line), std::string::npos) << on_line << "\n" << whole.output;

  // A window of two frames is calibrated whole, without the note.
  const CommandResult window = RunEvfs("info --data=" + data + " --first=4 --last=5");
  ASSERT_EQ(window.exit_code, 0) << window.output;
  EXPECT_NE(window.output.find("on frames 4 to 5, "), std::string::npos) << window.output;
  EXPECT_EQ(window.output.find("of the selection"), std::string::npos) << window.output;

  // A recording without events: info still describes it, the section is one line.
  const fs::path quiet = scratch / "quiet";
  fs::create_directories(quiet);
  fs::copy(data, quiet / "data", fs::copy_options::recursive);
  std::ofstream(quiet / "data" / "events.txt", std::ios::trunc).close();
  const CommandResult none = RunEvfs("info --data=" + (quiet / "data").string());
  ASSERT_EQ(none.exit_code, 0) << none.output;
  EXPECT_NE(none.output.find("event model: cannot tell: "), std::string::npos) << none.output;
  EXPECT_NE(none.output.find("no events"), std::string::npos) << none.output;
  EXPECT_EQ(none.output.find("C_on"), std::string::npos) << none.output;
}

}  // namespace
}  // namespace evfs
