// Binning events into event frames and the latent timeline (paper §3.3, docs/design.md §2).
//
// Both strategies take the events with t_begin_ns <= t < t_end_ns (a half-open window, like
// EventStream::Slice) and return EventFrames whose latent timestamps start at t_begin_ns and end
// at t_end_ns, strictly increasing.
#ifndef EVFS_EVENTS_BINNING_H_
#define EVFS_EVENTS_BINNING_H_

#include <cstdint>
#include <string>
#include <vector>

#include "evfs/core/event_frames.h"
#include "evfs/core/event_stream.h"

namespace evfs {

/// The paper's Binning 1 (proposed): walk the events in time order; an event whose pixel already
/// fired in the current frame closes that frame and opens a new one. Frames hold {-1, 0, +1}.
///
/// N collision frames give N latent steps: latent frames 0…N, event frame k spans latent k → k+1.
/// τ_0 = t_begin_ns, τ_N = t_end_ns, and τ_k (0 < k < N) lies midway between the last event of
/// frame k-1 and the first event of frame k (rounded up, so it is after the former). Where
/// events share a timestamp two boundaries can coincide; each is then moved by the fewest
/// nanoseconds that keep τ strictly increasing (forward first, then backward from t_end_ns), so
/// it stays inside (τ_{k-1}, τ_{k+1}). With no events in the window there are no event frames
/// and the latent timestamps are {t_begin_ns, t_end_ns} (K = 1).
///
/// O(number of events) time: a per-pixel index of the last frame that fired replaces clearing.
///
/// min_latent_steps > N splits the collision frames in time until the window has that many
/// latent steps (a window without events is not split): each collision frame k gets n_k >= 1
/// equal parts, chosen greedily to make the longest part as short as possible (Σ n_k =
/// min_latent_steps, a part at least 1 ns), and each event goes to the part of its frame that
/// holds its time. A part of a collision frame is itself collision-free, so the frames still hold
/// {-1, 0, +1}; parts without events are empty frames. Where events are few the collision
/// frames are long (a window in which barely a pixel fires twice is a handful of steps), and
/// every reconstruction on that timeline is a step function at that coarse a resolution: its
/// changes land up to a step away from the events' times, and a frame asked for between two
/// latent frames is read from the nearer one. The split puts the latent frames where the events
/// are without adding a collision.
///
/// Throws InvalidArgumentError when t_end_ns <= t_begin_ns, when the events are not sorted or
/// lie outside the sensor, or when the window has fewer nanoseconds than collision frames (only
/// possible when one pixel fires repeatedly at the same timestamp).
EventFrames BinByCollision(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns,
                           int64_t min_latent_steps = 0);

/// The latent steps BinByCollision gives for `collision_frames` collision frames in a window of
/// window_ns nanoseconds and min_latent_steps: without events 1, else max(collision_frames,
/// min_latent_steps), at most one per nanosecond.
int64_t CollisionLatentSteps(int64_t collision_frames, int64_t min_latent_steps, int64_t window_ns);

/// The number of event frames BinByCollision(events, t_begin_ns, t_end_ns) gives, counted
/// without allocating a frame (O(events) time, one int32 per pixel), so that a caller can decide
/// the binning, and so its memory (frames × pixels values), before allocating anything. Throws
/// as BinByCollision does for a bad window or bad events.
int64_t CountCollisionFrames(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns);

/// How the pixels of a window fired, and which of them are hot.
///
/// A hot pixel is a sensor defect that fires on its own, often at kHz, while the scene around it
/// is quiet. Collision binning opens a frame at every repeat of a pixel, so one hot pixel firing
/// N times would turn the window into N latent steps of the whole sensor (N × pixels unknowns)
/// for events that record no change of the scene.
struct PixelActivity {
  int64_t num_events = 0;           // events in the window
  int64_t pixels_fired = 0;         // pixels with at least one event
  int64_t busiest_count = 0;        // events of the busiest pixel
  int64_t reference_count = 0;      // events of the reference pixel (see MeasurePixelActivity)
  std::vector<int32_t> hot_pixels;  // row-major indices (y · width + x) of hot pixels, ascending
  int64_t hot_pixel_events = 0;     // events at the hot pixels
};

/// Counts the events of every pixel in [t_begin_ns, t_end_ns) and finds the hot pixels: those
/// with more than `hot_pixel_factor` times the events of the reference pixel, the busiest pixel
/// outside the busiest 1 % of the pixels that fired (the second busiest when at most 100
/// fired). Up to 1 % of the firing pixels can thus be hot without hiding one another, and with
/// a single pixel firing nothing is hot: there is no scene to compare it with.
/// hot_pixel_factor <= 0 finds none. O(events + pixels) time, one int32 per pixel. Throws as
/// BinByCollision does for a bad window or bad events.
PixelActivity MeasurePixelActivity(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns,
                                   double hot_pixel_factor);

/// The events of `events` except those at `pixels` (row-major indices, ascending); same sensor.
EventStream WithoutPixels(const EventStream& events, const std::vector<int32_t>& pixels);

/// Options of the paper's Binning 2 (stacking).
struct StackedBinningOptions {
  /// How the window is split into frames.
  enum class Split {
    kEqualTime,   // frames of equal duration
    kEqualCount,  // frames of (about) equal event count
  };

  int num_frames = 8;               // event frames M over the window, >= 1
  Split split = Split::kEqualTime;  // how frame boundaries are placed
  int steps_per_frame = 1;          // latent steps S each frame spans, >= 1, M · S < 2^31 - 1

  /// False (with a reason in `error`, which may be null) when a field is out of range.
  bool IsValid(std::string* error) const;
};

/// The paper's Binning 2: `options.num_frames` frames over the window holding signed event
/// counts. Frame m spans latent frames m·S … (m+1)·S, S = options.steps_per_frame, so there are
/// M·S + 1 latent frames; within a frame the latent timestamps are uniform.
///
/// kEqualTime: frame boundaries (and so all latent timestamps) uniform over [t_begin, t_end].
/// kEqualCount: boundary m (0 < m < M) lies midway between events ⌊n·m/M⌋-1 and ⌊n·m/M⌋ of the
/// n events in the window (rounded up). Events are then assigned by time (boundary <= t), so
/// events sharing a timestamp share a frame and counts are about n/M. With fewer events than
/// frames (n < M) equal count is undefined and the split falls back to equal time. Boundaries
/// that coincide are separated as in BinByCollision, by S ns at least.
///
/// Each span records its first and last event time and event count (an empty frame records its
/// start boundary as both times). Throws InvalidArgumentError for invalid options, an empty or
/// reversed window, a window shorter than M·S ns (before allocating anything), unsorted events
/// or events off the sensor.
EventFrames BinStacked(const EventStream& events, int64_t t_begin_ns, int64_t t_end_ns,
                       const StackedBinningOptions& options);

}  // namespace evfs

#endif  // EVFS_EVENTS_BINNING_H_
