#include "evfs/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"
#include "evfs/events/noise_filter.h"

namespace evfs {
namespace {

// "20001 latent frames × 43200 pixels = 864043200 voxels"
std::string VoxelCount(int64_t latent_frames, int64_t pixels) {
  return std::to_string(latent_frames) + " latent frames × " + std::to_string(pixels) +
         " pixels = " + std::to_string(latent_frames * pixels) + " voxels";
}

// The pixels at or above `level` in every one of `frames` (none when there are none),
// row-major and ascending.
std::vector<int32_t> SaturatedPixels(const std::vector<const Image*>& frames, int width, int height,
                                     double level) {
  std::vector<int32_t> saturated;
  if (level > 1.0) return saturated;
  const int64_t pixels = static_cast<int64_t>(width) * height;
  for (const Image* frame : frames) {
    if (frame->rows() != height || frame->cols() != width) {
      throw InvalidArgumentError("a frame is " + std::to_string(frame->cols()) + "x" +
                                 std::to_string(frame->rows()) + " but the event sensor is " +
                                 std::to_string(width) + "x" + std::to_string(height));
    }
  }
  if (frames.empty()) return saturated;
  for (int64_t p = 0; p < pixels; ++p) {
    const bool everywhere = std::all_of(frames.begin(), frames.end(), [&](const Image* frame) {
      return frame->data()[p] >= level;
    });
    if (everywhere) saturated.push_back(static_cast<int32_t>(p));
  }
  return saturated;
}

// Pixels within this many pixels of a saturated frame pixel are near saturation: a bright light
// blooms into the pixels around it, which see it flicker without reaching full scale.
constexpr int kSaturationReachPx = 2;

// The pixels of `pixels` (row-major, ascending) that lie within kSaturationReachPx of a pixel
// at or above `level` in any of `frames`.
std::vector<int32_t> NearSaturation(const std::vector<int32_t>& pixels,
                                    const std::vector<const Image*>& frames, int width, int height,
                                    double level) {
  std::vector<int32_t> near;
  if (pixels.empty() || level > 1.0) return near;
  std::vector<uint8_t> saturated(static_cast<size_t>(width) * height, 0);
  for (const Image* frame : frames) {
    for (size_t p = 0; p < saturated.size(); ++p) saturated[p] |= frame->data()[p] >= level;
  }
  for (const int32_t pixel : pixels) {
    const int x = pixel % width, y = pixel / width;
    bool found = false;
    for (int qy = std::max(0, y - kSaturationReachPx);
         !found && qy <= std::min(height - 1, y + kSaturationReachPx); ++qy) {
      for (int qx = std::max(0, x - kSaturationReachPx);
           !found && qx <= std::min(width - 1, x + kSaturationReachPx); ++qx) {
        found = saturated[static_cast<size_t>(qy) * width + qx] != 0;
      }
    }
    if (found) near.push_back(pixel);
  }
  return near;
}

// The events in [begin_ns, end_ns) at `pixels` (row-major, ascending).
int64_t EventsAt(const EventStream& events, int64_t begin_ns, int64_t end_ns,
                 const std::vector<int32_t>& pixels) {
  if (pixels.empty()) return 0;
  std::vector<uint8_t> at(static_cast<size_t>(events.width()) * events.height(), 0);
  for (const int32_t p : pixels) at[static_cast<size_t>(p)] = 1;
  int64_t count = 0;
  const size_t end = events.LowerBound(end_ns);
  for (size_t i = events.LowerBound(begin_ns); i < end; ++i) {
    if (events.x(i) < events.width() && events.y(i) < events.height()) {
      count += at[static_cast<size_t>(events.y(i)) * events.width() + events.x(i)];
    }
  }
  return count;
}

// `pixels` without those in `taken` (both ascending).
std::vector<int32_t> Untaken(const std::vector<int32_t>& pixels,
                             const std::vector<int32_t>& taken) {
  std::vector<int32_t> rest;
  std::set_difference(pixels.begin(), pixels.end(), taken.begin(), taken.end(),
                      std::back_inserter(rest));
  return rest;
}

// PlanBinning; *binned receives the events it bins: `events`, or *kept when hot, saturated or
// flickering pixels or unsupported events were left out.
BinningPlan PlanAndFilter(const EventStream& events, int64_t begin_ns, int64_t end_ns,
                          const BinningOptions& binning, const std::vector<const Image*>& frames,
                          EventStream* kept, const EventStream** binned) {
  std::string error;
  if (!binning.IsValid(&error)) throw InvalidArgumentError("binning: " + error);
  BinningPlan plan;
  plan.pixels = static_cast<int64_t>(events.width()) * events.height();
  plan.activity = MeasurePixelActivity(events, begin_ns, end_ns, binning.hot_pixel_factor);
  // Each rule takes the pixels the rules before it left, so that every pixel left out is
  // counted once.
  std::vector<int32_t> left_out = plan.activity.hot_pixels;
  if (binning.leave_out_saturated) {
    plan.saturated_pixels =
        Untaken(SaturatedPixels(frames, events.width(), events.height(), binning.saturation_level),
                left_out);
  }
  plan.saturated_pixel_events = EventsAt(events, begin_ns, end_ns, plan.saturated_pixels);
  std::vector<int32_t> merged;
  std::merge(left_out.begin(), left_out.end(), plan.saturated_pixels.begin(),
             plan.saturated_pixels.end(), std::back_inserter(merged));
  left_out.swap(merged);
  plan.flickering_pixels = Untaken(
      NearSaturation(FindFlickeringPixels(events, begin_ns, end_ns, binning.flicker_min_reversals),
                     frames, events.width(), events.height(), binning.saturation_level),
      left_out);
  plan.flickering_pixel_events = EventsAt(events, begin_ns, end_ns, plan.flickering_pixels);
  merged.clear();
  std::merge(left_out.begin(), left_out.end(), plan.flickering_pixels.begin(),
             plan.flickering_pixels.end(), std::back_inserter(merged));
  left_out.swap(merged);
  *binned = &events;
  if (!left_out.empty()) {
    *kept = WithoutPixels(events, left_out);
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
      .Check(saturation_level > 0.0 && std::isfinite(saturation_level),
             "saturation_level must be a positive level (above 1 keeps every event)")
      .NonNegative("flicker_min_reversals", flicker_min_reversals)
      .Check(noise_filter_ms >= 0.0 && noise_filter_ms <= kMaxNoiseFilterMs,
             "noise_filter_ms must lie in [0, 3600000] (an hour)");
  if (method == Method::kStacked) check.Valid(stacked);
  return check.Passed(error);
}

void CheckSensorFitsLatentVoxels(int width, int height, const BinningOptions& binning) {
  const int64_t pixels = static_cast<int64_t>(std::max(width, 0)) * std::max(height, 0);
  if (pixels == 0) return;
  const int64_t fewest_latent_frames =
      binning.method == BinningOptions::Method::kStacked
          ? static_cast<int64_t>(binning.stacked.num_frames) * binning.stacked.steps_per_frame + 1
          : 2;
  if (fewest_latent_frames > binning.max_latent_voxels / pixels) {
    throw InvalidArgumentError(
        "the " + std::to_string(width) + "x" + std::to_string(height) + " sensor needs at least " +
        VoxelCount(fewest_latent_frames, pixels) +
        ", more than max_latent_voxels = " + std::to_string(binning.max_latent_voxels));
  }
}

BinningPlan PlanBinning(const EventStream& events, int64_t window_begin_ns, int64_t window_end_ns,
                        const BinningOptions& binning, const std::vector<const Image*>& frames) {
  EventStream kept;
  const EventStream* binned = nullptr;
  return PlanAndFilter(events, window_begin_ns, window_end_ns, binning, frames, &kept, &binned);
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
  std::vector<const Image*> images;
  for (const TimedFrame& frame : frames) {
    if (frame.image.rows() != scene.height || frame.image.cols() != scene.width) {
      throw InvalidArgumentError(frame.label + ": frame size differs from the scene's");
    }
    images.push_back(&frame.image);
  }
  EventStream kept;
  const EventStream* binned = nullptr;
  const BinningPlan plan =
      PlanAndFilter(events, window_begin_ns, window_end_ns, binning, images, &kept, &binned);
  scene.events =
      plan.method == BinningOptions::Method::kCollision
          ? BinByCollision(*binned, window_begin_ns, window_end_ns, plan.min_latent_steps)
          : BinStacked(*binned, window_begin_ns, window_end_ns, plan.stacked);
  for (const EventFrameSpan& span : scene.events.spans()) scene.num_events += span.num_events;
  scene.hot_pixels = plan.activity.hot_pixels;
  scene.hot_pixel_events = plan.activity.hot_pixel_events;
  scene.noise_events = plan.noise_events;
  scene.saturated_pixels = plan.saturated_pixels;
  scene.saturated_pixel_events = plan.saturated_pixel_events;
  scene.flickering_pixels = plan.flickering_pixels;
  scene.flickering_pixel_events = plan.flickering_pixel_events;

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
