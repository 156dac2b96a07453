#include "evfs/events/binning.h"

#include <algorithm>
#include <functional>
#include <limits>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"

namespace evfs {
namespace {

/// Index range [first, last) of the events in [t_begin_ns, t_end_ns), after checking the window
/// and those events (sorted, on the sensor, polarity ±1).
struct WindowRange {
  size_t first = 0;
  size_t last = 0;
};

WindowRange CheckedWindow(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns,
                          const char* caller) {
  if (t_end_ns <= t_begin_ns) {
    throw InvalidArgumentError(std::string(caller) + ": empty or reversed window [" +
                               std::to_string(t_begin_ns) + ", " + std::to_string(t_end_ns) +
                               ") ns");
  }
  WindowRange range;
  range.first = events.LowerBound(t_begin_ns);
  range.last = std::max(range.first, events.LowerBound(t_end_ns));
  if (range.first == range.last) return range;
  if (events.width() <= 0 || events.height() <= 0) {
    throw InvalidArgumentError(std::string(caller) + ": the event stream has no sensor size");
  }
  const auto& t_ns = events.t_ns();
  if (!std::is_sorted(t_ns.begin() + range.first, t_ns.begin() + range.last)) {
    throw InvalidArgumentError(std::string(caller) + ": events are not sorted by time");
  }
  for (size_t i = range.first; i < range.last; ++i) {
    if (events.x(i) >= events.width() || events.y(i) >= events.height() ||
        (events.polarity(i) != 1 && events.polarity(i) != -1)) {
      throw InvalidArgumentError(
          std::string(caller) + ": event " + std::to_string(i) + " (x " +
          std::to_string(events.x(i)) + ", y " + std::to_string(events.y(i)) + ", polarity " +
          std::to_string(events.polarity(i)) + ") is off the " + std::to_string(events.width()) +
          "x" + std::to_string(events.height()) + " sensor or has a polarity other than ±1");
    }
  }
  return range;
}

/// ⌊value · numerator / denominator⌋ for value >= 0 without overflowing the product.
int64_t FloorFraction(int64_t value, int64_t numerator, int64_t denominator) {
  return (value / denominator) * numerator + (value % denominator) * numerator / denominator;
}

/// The midpoint of a <= b, rounded up, so that a < result <= b whenever a < b.
int64_t MidpointRoundedUp(int64_t a, int64_t b) { return a + (b - a + 1) / 2; }

/// Moves the inner entries of `times` (the first and last stay) by the fewest nanoseconds that
/// make consecutive entries at least `min_gap_ns` apart: forward from the first, then backward
/// from the last. Entries already far enough apart are unchanged.
void MakeStrictlyIncreasing(std::vector<int64_t>* times, int64_t min_gap_ns, const char* caller) {
  const size_t n = times->size();
  if ((*times)[n - 1] - (*times)[0] < static_cast<int64_t>(n - 1) * min_gap_ns) {
    throw InvalidArgumentError(std::string(caller) + ": a window of " +
                               std::to_string((*times)[n - 1] - (*times)[0]) + " ns cannot hold " +
                               std::to_string(n - 1) + " latent steps of " +
                               std::to_string(min_gap_ns) + " ns or more");
  }
  for (size_t i = 1; i + 1 < n; ++i) {
    (*times)[i] = std::max((*times)[i], (*times)[i - 1] + min_gap_ns);
  }
  for (size_t i = n - 1; i-- > 1;) {
    (*times)[i] = std::min((*times)[i], (*times)[i + 1] - min_gap_ns);
  }
}

int PixelIndex(const EventStream& events, size_t i) {
  return static_cast<int>(events.y(i)) * events.width() + events.x(i);
}

/// The index of the first event in [first, last) at or after t_ns (the events sorted by time).
size_t FirstAtOrAfter(const EventStream& events, size_t first, size_t last, int64_t t_ns) {
  const auto begin = events.t_ns().begin();
  return static_cast<size_t>(std::lower_bound(begin + first, begin + last, t_ns) - begin);
}

/// Appends the event frame of events [first, last), spanning latent frames latent_first …
/// latent_last: each pixel holds the sum of its polarities. An empty frame is timed at empty_ns.
void AppendEventFrame(const EventStream& events, size_t first, size_t last, int latent_first,
                      int latent_last, int64_t empty_ns, EventFrames* frames) {
  EventFrameSpan span;
  span.latent_first = latent_first;
  span.latent_last = latent_last;
  span.num_events = static_cast<int64_t>(last - first);
  span.t_first_ns = span.num_events > 0 ? events.t_ns(first) : empty_ns;
  span.t_last_ns = span.num_events > 0 ? events.t_ns(last - 1) : empty_ns;
  float* values = frames->frame_data(frames->AddFrame(span));
  for (size_t i = first; i < last; ++i) {
    values[PixelIndex(events, i)] += static_cast<float>(events.polarity(i));
  }
}

/// The paper's collision walk over the events of `range`: calls frame_opened(i) with the index
/// of the event that opens each collision frame and returns their number. last_fired[p] is the
/// last frame in which pixel p fired (-1: none yet); frame indices only grow, so comparing with
/// the current one replaces clearing (one int32 per pixel, O(events) time).
template <typename FrameOpened>
int64_t WalkCollisionFrames(const EventStream& events, const WindowRange& range,
                            FrameOpened frame_opened) {
  if (range.first == range.last) return 0;
  std::vector<int32_t> last_fired(static_cast<size_t>(events.width()) * events.height(), -1);
  int32_t current = -1;
  for (size_t i = range.first; i < range.last; ++i) {
    const int pixel = PixelIndex(events, i);
    if (current < 0 || last_fired[pixel] == current) {
      if (current == std::numeric_limits<int32_t>::max() - 1) {
        throw InvalidArgumentError("binning: more than 2^31 collision frames");
      }
      frame_opened(i);
      ++current;
    }
    last_fired[pixel] = current;
  }
  return static_cast<int64_t>(current) + 1;
}

}  // namespace

int64_t CountCollisionFrames(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns) {
  const WindowRange range = CheckedWindow(events, t_begin_ns, t_end_ns, "CountCollisionFrames");
  return WalkCollisionFrames(events, range, [](size_t) {});
}

PixelActivity MeasurePixelActivity(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns,
                                   double hot_pixel_factor) {
  const WindowRange range = CheckedWindow(events, t_begin_ns, t_end_ns, "MeasurePixelActivity");
  PixelActivity activity;
  activity.num_events = static_cast<int64_t>(range.last - range.first);
  if (range.first == range.last) return activity;
  std::vector<int32_t> counts(static_cast<size_t>(events.width()) * events.height(), 0);
  for (size_t i = range.first; i < range.last; ++i) {
    int32_t& count = counts[PixelIndex(events, i)];
    count += count < std::numeric_limits<int32_t>::max();  // saturates: only compared
  }
  std::vector<int32_t> fired_counts;
  for (const int32_t count : counts) {
    if (count > 0) fired_counts.push_back(count);
  }
  activity.pixels_fired = static_cast<int64_t>(fired_counts.size());
  activity.busiest_count = *std::max_element(fired_counts.begin(), fired_counts.end());
  // The reference is the pixel of rank ceil(n / 100) from the busiest (rank 0), at least rank 1.
  const size_t rank = std::max<size_t>(1, (fired_counts.size() + 99) / 100);
  if (rank >= fired_counts.size()) return activity;  // one pixel fired: nothing to compare with
  std::nth_element(fired_counts.begin(), fired_counts.begin() + rank, fired_counts.end(),
                   std::greater<int32_t>());
  activity.reference_count = fired_counts[rank];
  if (!(hot_pixel_factor > 0.0)) return activity;
  const double hot_above = hot_pixel_factor * static_cast<double>(activity.reference_count);
  for (size_t p = 0; p < counts.size(); ++p) {
    if (static_cast<double>(counts[p]) > hot_above) {
      activity.hot_pixels.push_back(static_cast<int32_t>(p));
      activity.hot_pixel_events += counts[p];
    }
  }
  return activity;
}

EventStream WithoutPixels(const EventStream& events, const std::vector<int32_t>& pixels) {
  EventStream kept(events.width(), events.height());
  if (pixels.empty()) {
    kept = events;
    return kept;
  }
  std::vector<uint8_t> dropped(static_cast<size_t>(events.width()) * events.height(), 0);
  for (const int32_t pixel : pixels) dropped.at(static_cast<size_t>(pixel)) = 1;
  // Events off the sensor are kept, for the binning to reject.
  const auto keep = [&](size_t i) {
    return events.x(i) >= events.width() || events.y(i) >= events.height() ||
           !dropped[PixelIndex(events, i)];
  };
  size_t count = 0;
  for (size_t i = 0; i < events.size(); ++i) count += keep(i);
  kept.reserve(count);
  for (size_t i = 0; i < events.size(); ++i) {
    if (keep(i)) {
      kept.push_back(events.t_ns(i), events.x(i), events.y(i), events.polarity(i));
    }
  }
  return kept;
}

int64_t CollisionLatentSteps(int64_t collision_frames, int64_t min_latent_steps,
                             int64_t window_ns) {
  if (collision_frames == 0) return 1;
  return std::max(collision_frames, std::min(min_latent_steps, window_ns));
}

EventFrames BinByCollision(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns,
                           int64_t min_latent_steps) {
  const WindowRange range = CheckedWindow(events, t_begin_ns, t_end_ns, "BinByCollision");
  // The collision frames first, as the index of each one's first event.
  std::vector<size_t> frame_first;
  WalkCollisionFrames(events, range, [&](size_t i) { frame_first.push_back(i); });
  const size_t num_collision = frame_first.size();
  frame_first.push_back(range.last);
  std::vector<int64_t> boundaries_ns = {t_begin_ns};
  for (size_t k = 1; k < num_collision; ++k) {
    boundaries_ns.push_back(
        MidpointRoundedUp(events.t_ns(frame_first[k] - 1), events.t_ns(frame_first[k])));
  }
  boundaries_ns.push_back(t_end_ns);
  MakeStrictlyIncreasing(&boundaries_ns, 1, "BinByCollision");

  // Parts per collision frame: one each, then one more at a time to the frame whose parts are
  // longest, while a part can still be 1 ns.
  std::vector<int64_t> parts(num_collision, 1);
  const int64_t num_steps = CollisionLatentSteps(static_cast<int64_t>(num_collision),
                                                 min_latent_steps, t_end_ns - t_begin_ns);
  if (num_collision > 0 && num_steps > static_cast<int64_t>(num_collision)) {
    auto part_ns = [&](size_t k) {
      return static_cast<double>(boundaries_ns[k + 1] - boundaries_ns[k]) /
             static_cast<double>(parts[k]);
    };
    auto shorter = [&](size_t a, size_t b) { return part_ns(a) < part_ns(b); };
    std::vector<size_t> heap(num_collision);
    for (size_t k = 0; k < num_collision; ++k) heap[k] = k;
    std::make_heap(heap.begin(), heap.end(), shorter);
    for (int64_t added = static_cast<int64_t>(num_collision); added < num_steps && !heap.empty();) {
      std::pop_heap(heap.begin(), heap.end(), shorter);
      const size_t k = heap.back();
      heap.pop_back();
      if (parts[k] >= boundaries_ns[k + 1] - boundaries_ns[k]) continue;  // 1 ns parts already
      ++parts[k];
      ++added;
      heap.push_back(k);
      std::push_heap(heap.begin(), heap.end(), shorter);
    }
  }

  EventFrames frames(events.height(), events.width());
  int64_t num_frames = 0;
  for (const int64_t frame_parts : parts) num_frames += frame_parts;
  frames.Reserve(static_cast<int>(num_frames));
  std::vector<int64_t> latent_timestamps_ns;
  latent_timestamps_ns.reserve(static_cast<size_t>(num_steps) + 1);
  for (size_t k = 0; k < num_collision; ++k) {
    const int64_t frame_ns = boundaries_ns[k + 1] - boundaries_ns[k];
    size_t first = frame_first[k];
    for (int64_t j = 0; j < parts[k]; ++j) {
      const int64_t part_begin_ns = boundaries_ns[k] + FloorFraction(frame_ns, j, parts[k]);
      const int64_t part_end_ns = boundaries_ns[k] + FloorFraction(frame_ns, j + 1, parts[k]);
      // The frame's own events only (a collision decides the frame, not the time), the last
      // part taking the rest.
      const size_t last = j + 1 == parts[k]
                              ? frame_first[k + 1]
                              : FirstAtOrAfter(events, first, frame_first[k + 1], part_end_ns);
      const int latent = static_cast<int>(latent_timestamps_ns.size());
      AppendEventFrame(events, first, last, latent, latent + 1, part_begin_ns, &frames);
      latent_timestamps_ns.push_back(part_begin_ns);
      first = last;
    }
  }
  if (latent_timestamps_ns.empty()) latent_timestamps_ns.push_back(t_begin_ns);
  latent_timestamps_ns.push_back(t_end_ns);
  frames.set_latent_timestamps_ns(std::move(latent_timestamps_ns));
  return frames;
}

bool StackedBinningOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.InRange("num_frames", num_frames, 1, std::numeric_limits<int>::max())
      .InRange("steps_per_frame", steps_per_frame, 1, std::numeric_limits<int>::max())
      .InRange("num_frames * steps_per_frame", static_cast<long long>(num_frames) * steps_per_frame,
               1, std::numeric_limits<int>::max() - 1)
      .Require(split == Split::kEqualTime || split == Split::kEqualCount, "split",
               "kEqualTime or kEqualCount");
  return check.Passed(error);
}

EventFrames BinStacked(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns,
                       const StackedBinningOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgumentError("BinStacked: " + error);
  const WindowRange range = CheckedWindow(events, t_begin_ns, t_end_ns, "BinStacked");
  const int num_frames = options.num_frames;
  const int steps = options.steps_per_frame;
  const int64_t duration_ns = t_end_ns - t_begin_ns;
  const int64_t num_events = static_cast<int64_t>(range.last - range.first);
  // Checked before the boundaries are allocated; MakeStrictlyIncreasing checks it again.
  if (duration_ns < static_cast<int64_t>(num_frames) * steps) {
    throw InvalidArgumentError("BinStacked: a window of " + std::to_string(duration_ns) +
                               " ns cannot hold " + std::to_string(num_frames) + " frames of " +
                               std::to_string(steps) + " latent steps of 1 ns or more");
  }

  std::vector<int64_t> boundaries_ns(num_frames + 1);
  boundaries_ns.front() = t_begin_ns;
  boundaries_ns.back() = t_end_ns;
  const bool equal_count =
      options.split == StackedBinningOptions::Split::kEqualCount && num_events >= num_frames;
  for (int m = 1; m < num_frames; ++m) {
    if (equal_count) {
      const size_t i = range.first + FloorFraction(num_events, m, num_frames);
      boundaries_ns[m] = MidpointRoundedUp(events.t_ns(i - 1), events.t_ns(i));
    } else {
      boundaries_ns[m] = t_begin_ns + FloorFraction(duration_ns, m, num_frames);
    }
  }
  MakeStrictlyIncreasing(&boundaries_ns, steps, "BinStacked");

  std::vector<int64_t> latent_timestamps_ns;
  latent_timestamps_ns.reserve(static_cast<size_t>(num_frames) * steps + 1);
  for (int m = 0; m < num_frames; ++m) {
    const int64_t frame_ns = boundaries_ns[m + 1] - boundaries_ns[m];
    for (int s = 0; s < steps; ++s) {
      latent_timestamps_ns.push_back(boundaries_ns[m] + FloorFraction(frame_ns, s, steps));
    }
  }
  latent_timestamps_ns.push_back(t_end_ns);

  EventFrames frames(events.height(), events.width());
  frames.Reserve(num_frames);
  size_t frame_first = range.first;
  for (int m = 0; m < num_frames; ++m) {
    const size_t frame_last =
        m + 1 == num_frames ? range.last
                            : FirstAtOrAfter(events, frame_first, range.last, boundaries_ns[m + 1]);
    AppendEventFrame(events, frame_first, frame_last, m * steps, (m + 1) * steps, boundaries_ns[m],
                     &frames);
    frame_first = frame_last;
  }
  frames.set_latent_timestamps_ns(std::move(latent_timestamps_ns));
  return frames;
}

}  // namespace evfs
