#include "solver/scene.h"

#include <algorithm>

#include "core/error.h"

namespace evfs {
namespace {

// Fewest latent steps automatic binning falls back to, however large the sensor.
constexpr int64_t kMinAutoSteps = 4;

EventFrames BinEvents(const EventStream& events, int64_t begin_ns, int64_t end_ns,
                      const BinningOptions& binning) {
  switch (binning.method) {
    case BinningOptions::Method::kCollision:
      return BinByCollision(events, begin_ns, end_ns);
    case BinningOptions::Method::kStacked:
      return BinStacked(events, begin_ns, end_ns, binning.stacked);
    case BinningOptions::Method::kAuto: {
      const int64_t pixels = static_cast<int64_t>(events.width()) * events.height();
      const int max_steps = static_cast<int>(std::max<int64_t>(
          kMinAutoSteps,
          std::min<int64_t>(binning.max_latent_frames, binning.max_latent_voxels / pixels - 1)));
      EventFrames collision = BinByCollision(events, begin_ns, end_ns);
      if (collision.num_frames() <= max_steps) return collision;
      StackedBinningOptions stacked;
      stacked.num_frames = max_steps;
      stacked.split = StackedBinningOptions::Split::kEqualTime;
      return BinStacked(events, begin_ns, end_ns, stacked);
    }
  }
  return {};
}

// Index of the latent frame nearest to t_ns.
int NearestLatent(const std::vector<int64_t>& latent_ns, int64_t t_ns) {
  const auto upper = std::lower_bound(latent_ns.begin(), latent_ns.end(), t_ns);
  if (upper == latent_ns.begin()) return 0;
  if (upper == latent_ns.end()) return static_cast<int>(latent_ns.size()) - 1;
  const int after = static_cast<int>(upper - latent_ns.begin());
  return (t_ns - latent_ns[after - 1] <= latent_ns[after] - t_ns) ? after - 1 : after;
}

}  // namespace

bool BinningOptions::IsValid(std::string* error) const {
  if (max_latent_frames < 1 || max_latent_voxels < 1) {
    *error = "max_latent_frames and max_latent_voxels must be at least 1";
    return false;
  }
  return method != Method::kStacked || stacked.IsValid(error);
}

Scene MakeScene(const std::vector<TimedFrame>& frames, const EventStream& events,
                int64_t window_begin_ns, int64_t window_end_ns, const BinningOptions& binning) {
  std::string error;
  if (!binning.IsValid(&error)) throw InvalidArgumentError("binning: " + error);
  if (window_end_ns <= window_begin_ns) {
    throw InvalidArgumentError("the time window is empty: it must end after it begins");
  }
  if (frames.empty()) throw InvalidArgumentError("a scene needs at least one frame");

  Scene scene;
  scene.height = static_cast<int>(frames.front().image.rows());
  scene.width = static_cast<int>(frames.front().image.cols());
  if (events.width() != scene.width || events.height() != scene.height) {
    throw InvalidArgumentError("the event sensor is " + std::to_string(events.width()) + "x" +
                               std::to_string(events.height()) + " but the frames are " +
                               std::to_string(scene.width) + "x" + std::to_string(scene.height));
  }
  scene.events = BinEvents(events, window_begin_ns, window_end_ns, binning);
  for (const EventFrameSpan& span : scene.events.spans()) scene.num_events += span.num_events;

  const std::vector<int64_t>& latent_ns = scene.latent_timestamps_ns();
  for (const TimedFrame& frame : frames) {
    if (frame.image.rows() != scene.height || frame.image.cols() != scene.width) {
      throw InvalidArgumentError(frame.label + ": frame size differs from the scene's");
    }
    if (frame.exposure_end_ns < frame.exposure_begin_ns ||
        frame.exposure_begin_ns < window_begin_ns || frame.exposure_end_ns > window_end_ns) {
      throw InvalidArgumentError(frame.label + ": exposure lies outside the event window");
    }
    FrameObservation observation;
    observation.image = frame.image;
    observation.label = frame.label;
    if (frame.exposure_begin_ns == frame.exposure_end_ns) {
      observation.latent_first = observation.latent_last =
          NearestLatent(latent_ns, frame.exposure_begin_ns);
    } else {
      // A blurred frame averages every latent frame inside its exposure (at least one).
      const auto first = std::lower_bound(latent_ns.begin(), latent_ns.end(),
                                          frame.exposure_begin_ns);
      const auto last = std::upper_bound(latent_ns.begin(), latent_ns.end(),
                                         frame.exposure_end_ns);
      if (first >= last) {
        observation.latent_first = observation.latent_last =
            NearestLatent(latent_ns, (frame.exposure_begin_ns + frame.exposure_end_ns) / 2);
      } else {
        observation.latent_first = static_cast<int>(first - latent_ns.begin());
        observation.latent_last = static_cast<int>(last - latent_ns.begin()) - 1;
      }
    }
    scene.frames.push_back(std::move(observation));
  }
  return scene;
}

Scene MakeInterpolationScene(const TimedFrame& first, const TimedFrame& last,
                             const EventStream& events, const BinningOptions& binning) {
  return MakeScene({first, last}, events, first.exposure_begin_ns, last.exposure_end_ns,
                   binning);
}

Scene MakePredictionScene(const TimedFrame& first, int64_t window_end_ns,
                          const EventStream& events, const BinningOptions& binning) {
  return MakeScene({first}, events, first.exposure_begin_ns, window_end_ns, binning);
}

Scene MakeDeblurScene(const TimedFrame& blurred, const EventStream& events,
                      const BinningOptions& binning) {
  return MakeScene({blurred}, events, blurred.exposure_begin_ns, blurred.exposure_end_ns,
                   binning);
}

}  // namespace evfs
