#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/option_checker.h"
#include "events/noise_filter.h"

namespace evfs {
namespace {

// "20001 latent frames × 43200 pixels = 864043200 voxels"
std::string VoxelCount(int64_t latent_frames, int64_t pixels) {
  return std::to_string(latent_frames) + " latent frames × " + std::to_string(pixels) +
         " pixels = " + std::to_string(latent_frames * pixels) + " voxels";
}

// PlanBinning; *binned receives the events it bins: `events`, or *kept when hot pixels or
// unsupported events were left out.
BinningPlan PlanAndFilter(const EventStream& events, int64_t begin_ns, int64_t end_ns,
                          const BinningOptions& binning, EventStream* kept,
                          const EventStream** binned) {
  std::string error;
  if (!binning.IsValid(&error)) throw InvalidArgumentError("binning: " + error);
  BinningPlan plan;
  plan.pixels = static_cast<int64_t>(events.width()) * events.height();
  plan.activity = MeasurePixelActivity(events, begin_ns, end_ns, binning.hot_pixel_factor);
  *binned = &events;
  if (!plan.activity.hot_pixels.empty()) {
    *kept = WithoutPixels(events, plan.activity.hot_pixels);
    *binned = kept;
  }
  if (binning.noise_filter_ms > 0.0) {
    const int64_t window_ns = std::llround(binning.noise_filter_ms * 1e6);
    *kept = WithoutUnsupportedEvents(**binned, window_ns, &plan.noise_events);
    *binned = kept;
  }
  // Counting first is what bounds the memory: collision frames are allocated only once they
  // are known to fit (one hot pixel or a busy large sensor gives thousands of them).
  plan.collision_frames = CountCollisionFrames(**binned, begin_ns, end_ns);
  // N collision frames span N + 1 latent frames; an empty window still has its two ends.
  const int64_t collision_latent_frames = std::max<int64_t>(plan.collision_frames, 1) + 1;
  const int64_t cap = binning.max_latent_voxels;
  const int64_t max_latent_frames =
      plan.pixels > 0 ? cap / plan.pixels : std::numeric_limits<int64_t>::max();
  const std::string limit = ", more than max_latent_voxels = " + std::to_string(cap);
  switch (binning.method) {
    case BinningOptions::Method::kCollision:
      if (collision_latent_frames > max_latent_frames) {
        throw InvalidArgumentError(
            "collision binning gives " + VoxelCount(collision_latent_frames, plan.pixels) + limit +
            " (auto binning falls back to stacked frames; or raise the limit)");
      }
      plan.method = BinningOptions::Method::kCollision;
      break;
    case BinningOptions::Method::kStacked: {
      const int64_t latent_frames =
          static_cast<int64_t>(binning.stacked.num_frames) * binning.stacked.steps_per_frame + 1;
      if (latent_frames > max_latent_frames) {
        throw InvalidArgumentError("stacked binning gives " +
                                   VoxelCount(latent_frames, plan.pixels) + limit +
                                   " (use fewer stacked frames or raise the limit)");
      }
      plan.method = BinningOptions::Method::kStacked;
      plan.stacked = binning.stacked;
      break;
    }
    case BinningOptions::Method::kAuto: {
      const int64_t max_steps = std::min<int64_t>(binning.max_latent_frames, max_latent_frames - 1);
      if (max_steps < 1) {
        throw InvalidArgumentError("the " + std::to_string(events.width()) + "x" +
                                   std::to_string(events.height()) + " sensor needs at least " +
                                   VoxelCount(2, plan.pixels) + limit);
      }
      if (plan.collision_frames <= max_steps) {
        plan.method = BinningOptions::Method::kCollision;
        plan.min_latent_steps = std::min<int64_t>(binning.min_latent_steps, max_steps);
      } else {
        plan.method = BinningOptions::Method::kStacked;
        plan.stacked.num_frames = static_cast<int>(max_steps);
        plan.stacked.split = StackedBinningOptions::Split::kEqualTime;
        plan.stacked.steps_per_frame = 1;
      }
      break;
    }
  }
  if (plan.method == BinningOptions::Method::kCollision) {
    const int64_t steps =
        CollisionLatentSteps(plan.collision_frames, plan.min_latent_steps, end_ns - begin_ns);
    plan.num_event_frames = plan.collision_frames > 0 ? static_cast<int>(steps) : 0;
    plan.num_latent_frames = static_cast<int>(steps) + 1;
  } else {
    plan.num_event_frames = plan.stacked.num_frames;
    plan.num_latent_frames = plan.stacked.num_frames * plan.stacked.steps_per_frame + 1;
  }
  return plan;
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
  OptionChecker check;
  check
      .Check(max_latent_frames >= 1 && max_latent_voxels >= 1,
             "max_latent_frames and max_latent_voxels must be at least 1")
      .NonNegative("min_latent_steps", min_latent_steps)
      .NonNegative("hot_pixel_factor", hot_pixel_factor)
      .Check(noise_filter_ms >= 0.0 && noise_filter_ms <= kMaxNoiseFilterMs,
             "noise_filter_ms must lie in [0, 3600000] (an hour)");
  if (method == Method::kStacked) check.Valid(stacked);
  return check.Passed(error);
}

BinningPlan PlanBinning(const EventStream& events, int64_t window_begin_ns, int64_t window_end_ns,
                        const BinningOptions& binning) {
  EventStream kept;
  const EventStream* binned = nullptr;
  return PlanAndFilter(events, window_begin_ns, window_end_ns, binning, &kept, &binned);
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
  EventStream kept;
  const EventStream* binned = nullptr;
  const BinningPlan plan =
      PlanAndFilter(events, window_begin_ns, window_end_ns, binning, &kept, &binned);
  scene.events =
      plan.method == BinningOptions::Method::kCollision
          ? BinByCollision(*binned, window_begin_ns, window_end_ns, plan.min_latent_steps)
          : BinStacked(*binned, window_begin_ns, window_end_ns, plan.stacked);
  for (const EventFrameSpan& span : scene.events.spans()) scene.num_events += span.num_events;
  scene.hot_pixels = plan.activity.hot_pixels;
  scene.hot_pixel_events = plan.activity.hot_pixel_events;
  scene.noise_events = plan.noise_events;

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
      const auto first =
          std::lower_bound(latent_ns.begin(), latent_ns.end(), frame.exposure_begin_ns);
      const auto last = std::upper_bound(latent_ns.begin(), latent_ns.end(), frame.exposure_end_ns);
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
  return MakeScene({first, last}, events, first.exposure_begin_ns, last.exposure_end_ns, binning);
}

Scene MakePredictionScene(const TimedFrame& first, int64_t window_end_ns, const EventStream& events,
                          const BinningOptions& binning) {
  return MakeScene({first}, events, first.exposure_begin_ns, window_end_ns, binning);
}

Scene MakeDeblurScene(const TimedFrame& blurred, const EventStream& events,
                      const BinningOptions& binning) {
  return MakeScene({blurred}, events, blurred.exposure_begin_ns, blurred.exposure_end_ns, binning);
}

Video InitializeLatentVideo(const Scene& scene) {
  const std::vector<int64_t>& latent_ns = scene.latent_timestamps_ns();
  // Each observation sits at the centre of its exposure on the latent timeline.
  Video anchors;
  std::vector<const FrameObservation*> sorted;
  for (const FrameObservation& frame : scene.frames) sorted.push_back(&frame);
  std::stable_sort(sorted.begin(), sorted.end(), [&](const auto* a, const auto* b) {
    return a->latent_first + a->latent_last < b->latent_first + b->latent_last;
  });
  for (const FrameObservation* frame : sorted) {
    const int64_t centre_ns = (latent_ns[frame->latent_first] + latent_ns[frame->latent_last]) / 2;
    if (!anchors.empty() && anchors.timestamp_ns(anchors.num_frames() - 1) == centre_ns) continue;
    anchors.AppendFrame(frame->image, centre_ns);
  }
  Video latent(scene.height, scene.width, static_cast<int>(latent_ns.size()));
  for (int t = 0; t < latent.num_frames(); ++t) {
    latent.set_timestamp_ns(t, latent_ns[t]);
    latent.frame(t) = anchors.InterpolateAt(latent_ns[t]);
  }
  return latent;
}

}  // namespace evfs
