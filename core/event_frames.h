// Event frames: events binned onto the pixel grid, each frame tied to a span of the latent
// timeline (docs/design.md §2). Frame k models the change from latent frame `latent_first` to
// `latent_last` (latent_last > latent_first).
#ifndef EVFS_CORE_EVENT_FRAMES_H_
#define EVFS_CORE_EVENT_FRAMES_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include "evfs/core/video.h"

namespace evfs {

/// Where one event frame sits on the latent timeline and which events it holds.
struct EventFrameSpan {
  int latent_first = 0;    // first latent frame of the span (H_a)
  int latent_last = 1;     // last latent frame of the span (H_b), > latent_first
  int64_t t_first_ns = 0;  // time of the first event in the frame (window start if empty)
  int64_t t_last_ns = 0;   // time of the last event in the frame (window start if empty)
  int64_t num_events = 0;  // events binned into this frame
};

class EventFrames {
 public:
  EventFrames() = default;
  EventFrames(int height, int width) : height_(height), width_(width) {}

  int height() const { return height_; }
  int width() const { return width_; }
  int64_t pixels_per_frame() const { return static_cast<int64_t>(height_) * width_; }
  int num_frames() const { return static_cast<int>(spans_.size()); }
  /// Number of latent frames K + 1 the spans refer to.
  int num_latent_frames() const { return static_cast<int>(latent_timestamps_ns_.size()); }

  /// Appends an all-zero frame with the given span and returns its index.
  int AddFrame(const EventFrameSpan& span);
  /// Makes room for `num_frames` frames in all, so that adding them allocates once (growing one
  /// frame at a time would hold up to twice the voxels).
  void Reserve(int num_frames);

  const EventFrameSpan& span(int k) const { return spans_[k]; }
  EventFrameSpan& span(int k) { return spans_[k]; }
  const std::vector<EventFrameSpan>& spans() const { return spans_; }

  /// Signed value of frame k at a pixel: {-1, 0, 1} for collision frames, counts when stacked.
  float& value(int k, int y, int x) { return values_[Index(k, y, x)]; }
  float value(int k, int y, int x) const { return values_[Index(k, y, x)]; }
  const float* frame_data(int k) const { return values_.data() + k * pixels_per_frame(); }
  float* frame_data(int k) { return values_.data() + k * pixels_per_frame(); }

  /// Timestamps of the latent frames H_0 … H_K (strictly increasing).
  const std::vector<int64_t>& latent_timestamps_ns() const { return latent_timestamps_ns_; }
  void set_latent_timestamps_ns(std::vector<int64_t> timestamps_ns) {
    latent_timestamps_ns_ = std::move(timestamps_ns);
  }

  /// Sum over frames of |value| (the number of events for collision frames).
  double TotalAbsoluteValue() const;
  /// Per pixel (row-major), 1 where some frame holds a non-zero value, else 0.
  std::vector<uint8_t> FiredPixels() const;

 private:
  size_t Index(int k, int y, int x) const {
    return static_cast<size_t>(k) * pixels_per_frame() + static_cast<size_t>(y) * width_ + x;
  }

  int height_ = 0;
  int width_ = 0;
  std::vector<EventFrameSpan> spans_;
  std::vector<float> values_;
  std::vector<int64_t> latent_timestamps_ns_;
};

/// How many times pixel `pixel`'s events change sign from one event frame that fired to the next
/// (a flickering light makes many; a moving edge or texture rarely more than two).
int PolarityReversals(const EventFrames& events, int64_t pixel);

}  // namespace evfs

#endif  // EVFS_CORE_EVENT_FRAMES_H_
