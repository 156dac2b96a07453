#include "evfs/solver/event_model_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/events/scene_synthesizer.h"
#include "evfs/events/simulator.h"
#include "evfs/io/data_source.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

// Relative accuracy the brief of the calibration asks of the thresholds and of b >= 0.01.
constexpr double kRelativeTolerance = 0.10;
// b below 0.01 moves log(I + b) only at the darkest pixels: within this factor.
constexpr double kSmallOffsetFactor = 1.5;
// The spread comes from the scatter of the counts, which the phase dominates: within 35 %.
constexpr double kSpreadTolerance = 0.35;
// Background rate from the quiet pixels: a few hundred noise events, Poisson error about 5 %,
// plus the few signal events of pixels that changed a little: within 25 %.
constexpr double kRateTolerance = 0.25;

constexpr int kWidth = 64;
constexpr int kHeight = 48;
constexpr int kRenderHz = 1000;   // the scene as the simulator sees it
constexpr int kFrameStepMs = 10;  // the recording's frames
constexpr double kDurationS = 0.09;

// A recording simulated from a synthetic scene: frames every kFrameStepMs, events from a 1 kHz
// rendering. Intensities are cubed so that the frames reach from 1e-4 to 0.86: dark pixels are
// where b shows.
struct Recording {
  std::vector<Image> frames;
  std::vector<int64_t> times_ns;
  EventStream events;

  EventModelCalibration Calibrate(
      const EventModelCalibrationOptions& options = EventModelCalibrationOptions()) const {
    return CalibrateEventModel(frames, times_ns, events, options);
  }
};

// `pan_px_per_s`: the background's speed; at 0 only the shapes move and most pixels are quiet.
Recording Simulate(const SimulatorOptions& sensor, double pan_px_per_s = 300.0) {
  SceneOptions scene;
  scene.width = kWidth;
  scene.height = kHeight;
  scene.num_shapes = 4;
  scene.min_shape_size_px = 8.0;
  scene.max_shape_size_px = 18.0;
  scene.duration_s = kDurationS;
  scene.max_speed_px_per_s = 600.0;
  scene.background_speed_px_per_s = pan_px_per_s;
  Video video = SceneSynthesizer(scene).RenderAtRate(kRenderHz);
  for (int64_t i = 0; i < video.num_frames() * video.pixels_per_frame(); ++i) {
    video.data()[i] = std::pow(video.data()[i], 3.0);
  }
  Recording recording;
  recording.events = SimulateEvents(video, sensor);
  const int step = kFrameStepMs * kRenderHz / 1000;
  // Frame 0 is where the simulated sensor starts, every pixel at its reference level, which no
  // real recording's frame is: the recording starts one frame later.
  for (int t = step; t < video.num_frames(); t += step) {
    recording.frames.push_back(video.frame(t));
    recording.times_ns.push_back(video.timestamp_ns(t));
  }
  return recording;
}

struct Case {
  double log_offset;
  double threshold_on;
  double threshold_off;
};

class CalibrationRecovery : public ::testing::TestWithParam<Case> {};

TEST_P(CalibrationRecovery, FindsTheSimulatedOffsetAndThresholds) {
  const Case& c = GetParam();
  SimulatorOptions sensor;
  sensor.log_eps = c.log_offset;
  sensor.contrast_threshold_pos = c.threshold_on;
  sensor.contrast_threshold_neg = c.threshold_off;
  sensor.threshold_sigma = 0.03;
  const Recording recording = Simulate(sensor);
  EventModelCalibrationOptions options;
  // The simulated frames are exact, not 8-bit: their darkest pixels, where a small b shows,
  // can be used.
  options.min_intensity = 1e-3;
  const EventModelCalibration result = recording.Calibrate(options);
  SCOPED_TRACE(result.description);
  if (c.log_offset < 0.01) {
    EXPECT_GT(result.log_offset.value, c.log_offset / kSmallOffsetFactor);
    EXPECT_LT(result.log_offset.value, c.log_offset * kSmallOffsetFactor);
  } else {
    EXPECT_NEAR(result.log_offset.value, c.log_offset, kRelativeTolerance * c.log_offset);
  }
  EXPECT_NEAR(result.threshold_on.value, c.threshold_on, kRelativeTolerance * c.threshold_on);
  EXPECT_NEAR(result.threshold_off.value, c.threshold_off, kRelativeTolerance * c.threshold_off);
  EXPECT_FALSE(result.thresholds_tied);
  // Each value says what carried it and how sure it is.
  EXPECT_EQ(result.pairs_used, static_cast<int>(recording.frames.size()) - 1);
  EXPECT_GT(result.threshold_on.pixels, 100);
  EXPECT_GT(result.threshold_off.pixels, 100);
  EXPECT_GT(result.log_offset.standard_error, 0.0);
  EXPECT_GT(result.threshold_on.standard_error, 0.0);
  EXPECT_LT(result.threshold_on.standard_error, kRelativeTolerance * c.threshold_on);
}

INSTANTIATE_TEST_SUITE_P(OffsetsAndThresholds, CalibrationRecovery,
                         ::testing::Values(Case{0.001, 0.15, 0.25}, Case{0.001, 0.2, 0.2},
                                           Case{0.001, 0.3, 0.3}, Case{0.1, 0.15, 0.25},
                                           Case{0.1, 0.2, 0.2}, Case{0.1, 0.3, 0.3}));

// Real frames at 240 fps (the shared nfs_basketball_7 clip, 200x200): between frames most
// pixels change by less than a threshold and fire rarely or never. Fitted too, such pixels
// tripled the thresholds and ran b to its lower bound (a regression test).
TEST(CalibrateEventModel, PixelsThatRarelyFireDoNotInflateTheThresholds) {
  EVFS_REQUIRE_SHARED_DATA(data_dir);
  const auto source = DataSource::Open(data_dir + "/nfs_basketball_7");
  ASSERT_GE(source->frames().size(), 15u);
  Video video(source->height(), source->width(), 15);
  for (int k = 0; k < 15; ++k) {
    video.frame(k) = source->ReadImage(k);
    video.set_timestamp_ns(k, source->frames()[k].t_ns);
  }
  SimulatorOptions sensor;
  sensor.log_eps = 0.1;
  sensor.contrast_threshold_pos = 0.2;
  sensor.contrast_threshold_neg = 0.3;
  const EventStream events = SimulateEvents(video, sensor);
  std::vector<Image> frames;
  std::vector<int64_t> times_ns;
  for (int k = 10; k < 15; ++k) {
    frames.push_back(video.frame(k));
    times_ns.push_back(video.timestamp_ns(k));
  }
  const EventModelCalibration result =
      CalibrateEventModel(frames, times_ns, events, EventModelCalibrationOptions());
  SCOPED_TRACE(result.description);
  // Few events per pixel and 8-bit frames: the OFF threshold comes out about 11 % low, b about
  // 15 % high; the bounds leave a margin over those.
  constexpr double kOnTolerance = 0.10;
  constexpr double kOffTolerance = 0.15;
  constexpr double kOffsetTolerance = 0.30;
  EXPECT_NEAR(result.threshold_on.value, 0.2, kOnTolerance * 0.2);
  EXPECT_NEAR(result.threshold_off.value, 0.3, kOffTolerance * 0.3);
  EXPECT_NEAR(result.log_offset.value, 0.1, kOffsetTolerance * 0.1);
}

TEST(CalibrateEventModel, MeasuresTheThresholdSpread) {
  SimulatorOptions sensor;
  sensor.log_eps = 0.01;
  sensor.threshold_sigma = 0.04;
  const Recording recording = Simulate(sensor);
  const EventModelCalibration result = recording.Calibrate();
  SCOPED_TRACE(result.description);
  ASSERT_TRUE(result.threshold_sigma.estimated);
  EXPECT_NEAR(result.threshold_sigma.value, sensor.threshold_sigma,
              kSpreadTolerance * sensor.threshold_sigma);
}

// A cap on the pixels fitted (evfs info's) thins them and still finds the thresholds; the
// counts it reports are those of the pixels fitted.
TEST(CalibrateEventModel, AThinnedFitFindsTheSameThresholds) {
  SimulatorOptions sensor;
  sensor.log_eps = 0.1;
  const Recording recording = Simulate(sensor);
  const EventModelCalibration all = recording.Calibrate();
  EventModelCalibrationOptions thinned_options;
  thinned_options.max_fit_pixels = all.pixels_used / 4;
  const EventModelCalibration thinned = recording.Calibrate(thinned_options);
  SCOPED_TRACE(thinned.description);
  EXPECT_LE(thinned.pixels_used, thinned_options.max_fit_pixels);
  EXPECT_GT(thinned.pixels_used, thinned_options.max_fit_pixels / 2);
  EXPECT_NEAR(thinned.threshold_on.value, all.threshold_on.value,
              kRelativeTolerance * all.threshold_on.value);
  EXPECT_NEAR(thinned.threshold_off.value, all.threshold_off.value,
              kRelativeTolerance * all.threshold_off.value);
  EXPECT_GT(thinned.threshold_on.standard_error, all.threshold_on.standard_error);
}

TEST(CalibrateEventModel, MeasuresTheBackgroundRate) {
  SimulatorOptions sensor;
  sensor.log_eps = 0.01;
  sensor.noise_rate_hz = 20.0;
  const Recording recording = Simulate(sensor, /*pan_px_per_s=*/0.0);
  const EventModelCalibration result = recording.Calibrate();
  SCOPED_TRACE(result.description);
  ASSERT_TRUE(result.background_rate_hz.estimated);
  EXPECT_NEAR(result.background_rate_hz.value, sensor.noise_rate_hz,
              kRateTolerance * sensor.noise_rate_hz);
  EXPECT_GT(result.background_rate_hz.pixels, 100);
  // Without noise, the quiet pixels stay (almost) silent.
  const Recording clean = Simulate(SimulatorOptions(), /*pan_px_per_s=*/0.0);
  const EventModelCalibration clean_result = clean.Calibrate();
  EXPECT_LT(clean_result.background_rate_hz.value, kRateTolerance * sensor.noise_rate_hz);
}

TEST(CalibrateEventModel, RefusesDataThatCannotTell) {
  const Recording recording = Simulate(SimulatorOptions());
  const EventModelCalibrationOptions options;
  // One frame.
  EXPECT_THROW(CalibrateEventModel({recording.frames[0]}, {recording.times_ns[0]}, recording.events,
                                   options),
               InvalidArgumentError);
  // No events.
  const EventStream none(kWidth, kHeight);
  EXPECT_THROW(CalibrateEventModel(recording.frames, recording.times_ns, none, options),
               InvalidArgumentError);
  // Frames that do not change, with events between them.
  const std::vector<Image> still = {recording.frames[1], recording.frames[1]};
  try {
    CalibrateEventModel(still, {recording.times_ns[1], recording.times_ns[2]}, recording.events,
                        options);
    ADD_FAILURE() << "calibrated from frames that do not change";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("change"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace evfs
