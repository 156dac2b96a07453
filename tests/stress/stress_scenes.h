// Scenes with a known truth for the numerical-stability sweeps: small enough that the
// whole stress suite runs in seconds, built either by the simulator (moving shapes) or by hand
// from a truth video through an ideal event sensor, so that degenerate cases (black, white,
// one row, every pixel firing, 500 latent frames, contradictory events) are exactly what they
// say.
#ifndef EVFS_TESTS_STRESS_STRESS_SCENES_H_
#define EVFS_TESTS_STRESS_STRESS_SCENES_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"
#include "evfs/events/random.h"
#include "evfs/scene/event_model.h"
#include "evfs/scene/scene.h"
#include "evfs/tests/scene/scene_test_scenes.h"

namespace evfs {
namespace test {

/// A scene and the truth on its latent timeline.
struct StressScene {
  Scene scene;
  Video truth;
};

/// The truth of a simulated recording on `scene`'s latent timeline: the rendered frames (1 kHz)
/// interpolated linearly at each latent timestamp.
inline Video TruthOnTimeline(const SyntheticRecording& recording, const Scene& scene) {
  Video truth(scene.height, scene.width, scene.num_latent_frames());
  for (int t = 0; t < truth.num_frames(); ++t) {
    truth.set_timestamp_ns(t, scene.latent_timestamps_ns()[t]);
    truth.frame(t) = recording.rendered.InterpolateAt(truth.timestamp_ns(t));
  }
  return truth;
}

/// The simulated 24×20 recording (moving textured shapes, 21 frames at 1 kHz).
inline const SyntheticRecording& SmallRecording() {
  static const SyntheticRecording recording(/*width=*/24, /*height=*/20);
  return recording;
}

/// Interpolation between rendered frames 0 and 20 of SmallRecording.
inline const StressScene& SimulatedInterpolation() {
  static const StressScene stress = [] {
    const SyntheticRecording& recording = SmallRecording();
    StressScene s;
    s.scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20), recording.events,
                                     BinningOptions());
    s.truth = TruthOnTimeline(recording, s.scene);
    return s;
  }();
  return stress;
}

/// Prediction from rendered frame 0 of SmallRecording over the events up to frame 10.
inline StressScene SimulatedPrediction(EventModel /*sensor: the simulator's*/) {
  const SyntheticRecording& recording = SmallRecording();
  StressScene s;
  s.scene = MakePredictionScene(recording.Sharp(0), recording.rendered.timestamp_ns(10),
                                recording.events, BinningOptions());
  s.truth = TruthOnTimeline(recording, s.scene);
  return s;
}

/// Deblurring the mean of rendered frames 0..20 of SmallRecording.
inline StressScene SimulatedDeblur(EventModel /*sensor: the simulator's*/) {
  const SyntheticRecording& recording = SmallRecording();
  StressScene s;
  s.scene = MakeDeblurScene(recording.Blurred(0, 20), recording.events, BinningOptions());
  s.truth = TruthOnTimeline(recording, s.scene);
  return s;
}

/// Latent time step of the hand-built scenes.
constexpr int64_t kStepNs = 1000000;

/// An ideal event sensor on the latent timeline of `truth` (frame t at t·kStepNs): one collision
/// event frame per step holding sign(Δ) wherever |Δ| reaches the sensor's threshold, Δ the
/// step's change of g, and a sharp frame observation of each latent frame in `observed`. The
/// truth is returned with it. A kLinear sensor fires at |Δx| ≥ 0.05, half the smallest
/// change the hand-built scenes make; a kLog sensor at |Δ log(x + 0.1)| ≥ 0.1 (b as the event
/// model's default; 0.1 is just below the smallest such change, 0.8 → 0.9).
inline StressScene IdealScene(const Video& truth, const std::vector<int>& observed,
                              EventModel sensor) {
  const double threshold = sensor == EventModel::kLinear ? 0.05 : 0.1;
  const double log_offset = EventModelParams().log_offset;
  StressScene s;
  s.truth = truth;
  Scene& scene = s.scene;
  scene.height = truth.height();
  scene.width = truth.width();
  scene.events = EventFrames(scene.height, scene.width);
  std::vector<int64_t> timestamps_ns;
  for (int t = 0; t < truth.num_frames(); ++t) {
    s.truth.set_timestamp_ns(t, t * kStepNs);
    timestamps_ns.push_back(t * kStepNs);
  }
  scene.events.set_latent_timestamps_ns(timestamps_ns);
  const auto g = [&](double x) {
    return sensor == EventModel::kLinear ? x : std::log(x + log_offset);
  };
  for (int t = 0; t + 1 < truth.num_frames(); ++t) {
    EventFrameSpan span{t, t + 1, t * kStepNs, (t + 1) * kStepNs, 0};
    const int k = scene.events.AddFrame(span);
    for (int y = 0; y < scene.height; ++y) {
      for (int x = 0; x < scene.width; ++x) {
        const double change = g(truth.at(t + 1, y, x)) - g(truth.at(t, y, x));
        if (std::abs(change) < threshold) continue;
        scene.events.value(k, y, x) = change > 0.0 ? 1.0f : -1.0f;
        ++scene.events.span(k).num_events;
        ++scene.num_events;
      }
    }
  }
  for (const int t : observed) {
    scene.frames.push_back({truth.frame(t), t, t, "truth frame " + std::to_string(t)});
  }
  return s;
}

/// A truth video of `num_frames` frames of height × width, every voxel set by
/// `intensity(t, y, x)`.
template <typename Intensity>
Video MakeTruth(int height, int width, int num_frames, Intensity intensity) {
  Video video(height, width, num_frames);
  for (int t = 0; t < num_frames; ++t) {
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) video.at(t, y, x) = intensity(t, y, x);
    }
  }
  return video;
}

/// 20×16, half black (0) and half white (1), with a 6×6 mid-grey square moving right by a pixel
/// per step across the boundary, so that pixels go 0 → 0.5 → 0 and 1 → 0.5 → 1; sharp frames at
/// both ends.
inline StressScene SaturatedScene(EventModel sensor) {
  constexpr int kHeight = 16, kWidth = 20, kLatent = 11;
  const Video truth = MakeTruth(kHeight, kWidth, kLatent, [](int t, int y, int x) {
    const bool in_square = y >= 5 && y < 11 && x >= 4 + t && x < 10 + t;
    return in_square ? 0.5 : x < kWidth / 2 ? 0.0 : 1.0;
  });
  return IdealScene(truth, {0, kLatent - 1}, sensor);
}

/// 8×6, a 3×3 square of 0.8 moving right over 0.2 by a pixel per step for 6 steps, sharp frames
/// at both ends: small enough for dense linear algebra.
inline StressScene TinyMovingSquare(EventModel sensor) {
  const Video truth = MakeTruth(6, 8, 7, [](int t, int y, int x) {
    return y >= 1 && y < 4 && x >= t / 2 && x < 3 + t / 2 ? 0.8 : 0.2;
  });
  return IdealScene(truth, {0, 6}, sensor);
}

/// `stress` with its frame observations replaced by one frame blurred over the whole window:
/// the mean of the truth over every latent frame (motion deblur, paper §3.2).
inline StressScene BlurredOverWindow(StressScene stress) {
  const int last = stress.truth.num_frames() - 1;
  Image blurred = Image::Zero(stress.truth.height(), stress.truth.width());
  for (int t = 0; t <= last; ++t) blurred += stress.truth.frame(t);
  blurred /= last + 1;
  stress.scene.frames = {{blurred, 0, last, "truth blurred over the window"}};
  return stress;
}

/// Black everywhere, at every latent frame: no events.
inline StressScene AllBlack(EventModel sensor) {
  return IdealScene(MakeTruth(12, 10, 6, [](int, int, int) { return 0.0; }), {0, 5}, sensor);
}

/// White (1) everywhere, at every latent frame: no events.
inline StressScene AllWhite(EventModel sensor) {
  return IdealScene(MakeTruth(12, 10, 6, [](int, int, int) { return 1.0; }), {0, 5}, sensor);
}

/// Mid-grey everywhere, at every latent frame: no events.
inline StressScene Constant(EventModel sensor) {
  return IdealScene(MakeTruth(12, 10, 6, [](int, int, int) { return 0.5; }), {0, 5}, sensor);
}

/// A 6×6 square of `square` sliding in from the left edge over `background`, one pixel per step;
/// only the first frame (the square still outside) is observed: the prediction starts from a
/// frame that is `background` everywhere.
inline StressScene SquareEntering(double background, double square, EventModel sensor) {
  const Video truth = MakeTruth(16, 20, 10, [=](int t, int y, int x) {
    return y >= 5 && y < 11 && x < t && x >= t - 6 ? square : background;
  });
  return IdealScene(truth, {0}, sensor);
}

/// SquareEntering with intensities exactly 0 at the start (a black first frame).
inline StressScene BlackStartPrediction(EventModel sensor) {
  return SquareEntering(0.0, 0.5, sensor);
}
/// SquareEntering with intensities exactly 1 at the start (a white first frame).
inline StressScene WhiteStartPrediction(EventModel sensor) {
  return SquareEntering(1.0, 0.2, sensor);
}

/// BlackStartPrediction blurred over its window: black (0) where the square never passed.
inline StressScene BlackStartDeblur(EventModel sensor) {
  return BlurredOverWindow(BlackStartPrediction(sensor));
}

/// SaturatedScene blurred over its window: 0 and 1 where the square never passed.
inline StressScene SaturatedDeblur(EventModel sensor) {
  return BlurredOverWindow(SaturatedScene(sensor));
}

/// One row of 32 pixels with an edge from 0.8 to 0.2 moving right by a pixel per step.
inline StressScene SingleRow(EventModel sensor) {
  const Video truth =
      MakeTruth(1, 32, 11, [](int t, int, int x) { return x < 10 + t ? 0.8 : 0.2; });
  return IdealScene(truth, {0, 10}, sensor);
}

/// Every pixel brightens by 0.1 at every step: each event frame is all +1. The blend of the two
/// frames is the truth itself.
inline StressScene EveryPixelEveryStep(EventModel sensor) {
  const Video truth = MakeTruth(12, 10, 9, [](int t, int, int) { return 0.1 + 0.1 * t; });
  return IdealScene(truth, {0, 8}, sensor);
}

/// A single latent frame: no event frame can span a step.
inline StressScene OneLatentFrame(EventModel sensor) {
  const Video truth = MakeTruth(12, 10, 1, [](int, int y, int x) { return 0.05 * (x + y); });
  return IdealScene(truth, {0}, sensor);
}

/// 3×4 pixels over 500 latent frames, each pixel a random walk that jumps by ±0.1 with
/// probability 0.05 per step (kept within [0.1, 0.9]); frames at both ends.
inline StressScene FiveHundredLatentFrames(EventModel sensor) {
  constexpr int kHeight = 3, kWidth = 4, kLatent = 500;
  Random random(11);
  Video truth(kHeight, kWidth, kLatent);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      double intensity = 0.5;
      for (int t = 0; t < kLatent; ++t) {
        if (random.Uniform() < 0.05) {
          intensity = std::clamp(intensity + 0.1 * random.Sign(), 0.1, 0.9);
        }
        truth.at(t, y, x) = intensity;
      }
    }
  }
  return IdealScene(truth, {0, kLatent - 1}, sensor);
}

/// A grey square moving over a 0.3 background, plus ON and OFF at one still background pixel in
/// one step: a second event frame over the same step holds −1 where the first holds +1.
inline StressScene ContradictoryEventFrames(EventModel sensor) {
  const Video truth = MakeTruth(16, 20, 9, [](int t, int y, int x) {
    return y >= 4 && y < 10 && x >= 2 + t && x < 8 + t ? 0.7 : 0.3;
  });
  StressScene stress = IdealScene(truth, {0, 8}, sensor);
  EventFrames& events = stress.scene.events;
  const int steps = events.num_frames();
  for (int k = 0; k < steps; ++k) {
    const int contradiction = events.AddFrame(events.span(k));
    events.span(contradiction).num_events = 0;
    for (int x = 0; x < events.width(); x += 3) {  // row 13 stays at the background
      events.value(k, 13, x) = 1.0f;
      events.value(contradiction, 13, x) = -1.0f;
      ++events.span(k).num_events;
      ++events.span(contradiction).num_events;
      stress.scene.num_events += 2;
    }
  }
  return stress;
}

/// The simulated recording with an ON and an OFF event 1 µs apart at every fifth pixel of its
/// first row in each millisecond, binned into 10 stacked frames: where a pair falls in one frame
/// the count is 0 although two events fired.
inline StressScene ContradictoryStackedEvents(EventModel /*sensor: the simulator's*/) {
  const SyntheticRecording& recording = SmallRecording();
  struct Event {
    int64_t t_ns;
    uint16_t x, y;
    int8_t polarity;
  };
  std::vector<Event> events;
  const EventStream& simulated = recording.events;
  for (size_t i = 0; i < simulated.size(); ++i) {
    events.push_back({simulated.t_ns(i), simulated.x(i), simulated.y(i), simulated.polarity(i)});
  }
  for (int t = 0; t < 20; ++t) {
    for (uint16_t x = 0; x < simulated.width(); x += 5) {
      const int64_t t_ns = recording.rendered.timestamp_ns(t) + 300000;
      events.push_back({t_ns, x, 0, 1});
      events.push_back({t_ns + 1000, x, 0, -1});
    }
  }
  std::stable_sort(events.begin(), events.end(),
                   [](const Event& a, const Event& b) { return a.t_ns < b.t_ns; });
  EventStream stream(simulated.width(), simulated.height());
  for (const Event& e : events) stream.push_back(e.t_ns, e.x, e.y, e.polarity);
  BinningOptions binning;
  binning.method = BinningOptions::Method::kStacked;
  binning.stacked.num_frames = 10;
  StressScene stress;
  stress.scene = MakeInterpolationScene(recording.Sharp(0), recording.Sharp(20), stream, binning);
  stress.truth = TruthOnTimeline(recording, stress.scene);
  return stress;
}

/// Frames brightening from 0.2 to 0.8 over 6 steps while every event says OFF. The frames are
/// taken as the truth.
inline StressScene EventsDisagreeWithFrames(EventModel sensor) {
  const Video truth = MakeTruth(12, 10, 7, [](int t, int, int) { return 0.2 + 0.1 * t; });
  StressScene stress = IdealScene(truth, {0, 6}, sensor);
  for (int k = 0; k < stress.scene.events.num_frames(); ++k) {
    float* values = stress.scene.events.frame_data(k);
    std::transform(values, values + stress.scene.events.pixels_per_frame(), values,
                   [](float v) { return -v; });
  }
  return stress;
}

}  // namespace test
}  // namespace evfs

#endif  // EVFS_TESTS_STRESS_STRESS_SCENES_H_
