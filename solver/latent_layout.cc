#include "evfs/solver/latent_layout.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "evfs/core/error.h"

namespace evfs {
namespace {

// Start marks of LatentLayout's segment starts (t >= 1).
constexpr uint8_t kContinues = 0, kStarts = 1, kStartsUnfiredChange = 2;

// Fewest events at an unfired pixel's 8 neighbours after the last frame for it to change: one
// event is as likely noise. Measured: benchmarks/results/model_choices.md, "Unfired pixels after
// the last frame".
constexpr float kMinNeighbourEvents = 2.0f;

// The event frame at which each unfired active pixel changes (latent_layout.h), or -1: the
// frame holding the median of its 8 neighbours' events after the last frame observation.
std::vector<int> UnfiredChangeFrames(const Scene& scene, const ActivityMask& mask) {
  const int width = scene.width, height = scene.height;
  const int64_t pixels = static_cast<int64_t>(width) * height;
  int last_frame_latent = 0;
  for (const FrameObservation& frame : scene.frames) {
    last_frame_latent = std::max(last_frame_latent, frame.latent_last);
  }
  const std::vector<uint8_t> fired = scene.events.FiredPixels();
  // Calls visit(k, q, n) for the n events of event frame k (after the last frame) at each
  // neighbour of every unfired active pixel q.
  const auto for_each_neighbour_event = [&](const auto& visit) {
    for (int k = 0; k < scene.events.num_frames(); ++k) {
      if (scene.events.span(k).latent_first < last_frame_latent) continue;
      const float* values = scene.events.frame_data(k);
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          const float count = std::abs(values[static_cast<int64_t>(y) * width + x]);
          if (count == 0.0f) continue;
          for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny) {
            for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx) {
              const int64_t q = static_cast<int64_t>(ny) * width + nx;
              if (!fired[q] && mask.active(q)) visit(k, q, count);
            }
          }
        }
      }
    }
  };
  std::vector<double> total(pixels, 0.0);
  for_each_neighbour_event([&](int, int64_t q, float count) { total[q] += count; });
  std::vector<double> seen(pixels, 0.0);
  std::vector<int> change_frame(pixels, -1);
  for_each_neighbour_event([&](int k, int64_t q, float count) {
    if (change_frame[q] >= 0 || total[q] < kMinNeighbourEvents) return;
    seen[q] += count;
    if (seen[q] > total[q] / 2.0) change_frame[q] = k;
  });
  return change_frame;
}

}  // namespace

LatentLayout::LatentLayout(const Scene& scene, const ActivityMask& mask, const Video& initial,
                           bool merge_quiet_steps, bool unfired_changes, double ring_tolerance)
    : num_latent_frames_(scene.num_latent_frames()),
      pixels_per_frame_(static_cast<int64_t>(scene.height) * scene.width) {
  const int num_latent = num_latent_frames_;
  const int64_t pixels = pixels_per_frame_;
  if (initial.num_frames() != num_latent || initial.pixels_per_frame() != pixels ||
      mask.num_pixels() != pixels) {
    throw InvalidArgumentError("latent layout: the initial video or mask does not match the scene");
  }
  if (static_cast<double>(num_latent) * static_cast<double>(pixels) >
      static_cast<double>(std::numeric_limits<int32_t>::max())) {
    throw InvalidArgumentError("latent layout: too many latent voxels");
  }

  // starts[t * pixels + p]: H_t(p) begins a new segment (t >= 1).
  std::vector<uint8_t> starts(static_cast<size_t>(num_latent) * pixels,
                              merge_quiet_steps ? kContinues : kStarts);
  if (merge_quiet_steps) {
    for (int k = 0; k < scene.events.num_frames(); ++k) {
      const EventFrameSpan& span = scene.events.span(k);
      const float* values = scene.events.frame_data(k);
      for (int64_t p = 0; p < pixels; ++p) {
        if (values[p] == 0.0f || !mask.active(p)) continue;
        for (int t = span.latent_first + 1; t <= span.latent_last; ++t) {
          starts[t * pixels + p] = kStarts;
        }
      }
    }
    if (unfired_changes) {
      const std::vector<int> change_frame = UnfiredChangeFrames(scene, mask);
      for (int64_t p = 0; p < pixels; ++p) {
        if (change_frame[p] < 0) continue;
        const EventFrameSpan& span = scene.events.span(change_frame[p]);
        for (int t = span.latent_first + 1; t <= span.latent_last; ++t) {
          starts[t * pixels + p] = kStartsUnfiredChange;
        }
      }
    }
    // A ring pixel's segment holds while its initial value stays within `ring_tolerance` of its
    // value where the segment began; the problem sees the segment's mean (Segment::held).
    std::vector<double> began_at(initial.frame_data(0), initial.frame_data(0) + pixels);
    for (int t = 1; t < num_latent; ++t) {
      const double* now = initial.frame_data(t);
      for (int64_t p = 0; p < pixels; ++p) {
        if (mask.role(p) == ActivityMask::Role::kRing &&
            std::abs(now[p] - began_at[p]) > ring_tolerance) {
          starts[t * pixels + p] = kStarts;
          began_at[p] = now[p];
        }
      }
    }
  }

  segment_of_voxel_.assign(static_cast<size_t>(num_latent) * pixels, -1);
  for (int64_t p = 0; p < pixels; ++p) {
    if (!mask.in_problem(p)) continue;
    Segment segment;
    segment.pixel = p;
    segment.constant = !mask.active(p);
    for (int t = 0; t < num_latent; ++t) {
      if (t > 0 && starts[t * pixels + p] != kContinues) {
        segment.last = t - 1;
        segments_.push_back(segment);
        segment.first = t;
        segment.unfired_change = starts[t * pixels + p] == kStartsUnfiredChange;
      }
      segment_of_voxel_[t * pixels + p] = static_cast<int32_t>(segments_.size());
    }
    segment.last = num_latent - 1;
    segments_.push_back(segment);
  }
  if (segments_.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    throw InvalidArgumentError("latent layout: too many segments");
  }
  for (Segment& segment : segments_) {
    num_variable_segments_ += !segment.constant;
    if (!segment.constant) continue;
    double sum = 0.0;
    for (int t = segment.first; t <= segment.last; ++t) sum += initial.frame_data(t)[segment.pixel];
    segment.held = sum / segment.length();
  }
}

void LatentLayout::ProjectOnto(Video* latent) const {
  for (const Segment& segment : segments_) {
    if (segment.constant || segment.length() == 1) continue;
    double sum = 0.0;
    for (int t = segment.first; t <= segment.last; ++t) sum += latent->frame_data(t)[segment.pixel];
    latent->frame_data(segment.first)[segment.pixel] = sum / segment.length();
  }
  Expand(latent);
}

void LatentLayout::Expand(Video* latent) const {
  for (const Segment& segment : segments_) {
    if (segment.constant) continue;  // a ring pixel's voxels keep their initial values
    const double value = latent->frame_data(segment.first)[segment.pixel];
    for (int t = segment.first + 1; t <= segment.last; ++t) {
      latent->frame_data(t)[segment.pixel] = value;
    }
  }
}

}  // namespace evfs
