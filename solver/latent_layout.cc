#include "solver/latent_layout.h"

#include <limits>

#include "core/error.h"

namespace evfs {

LatentLayout::LatentLayout(const Scene& scene, const ActivityMask& mask, const Video& initial,
                           bool merge_quiet_steps)
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
  std::vector<uint8_t> starts(static_cast<size_t>(num_latent) * pixels, merge_quiet_steps ? 0 : 1);
  if (merge_quiet_steps) {
    for (int k = 0; k < scene.events.num_frames(); ++k) {
      const EventFrameSpan& span = scene.events.span(k);
      const float* values = scene.events.frame_data(k);
      for (int64_t p = 0; p < pixels; ++p) {
        if (values[p] == 0.0f || !mask.active(p)) continue;
        for (int t = span.latent_first + 1; t <= span.latent_last; ++t) starts[t * pixels + p] = 1;
      }
    }
    for (int t = 1; t < num_latent; ++t) {
      const double* now = initial.frame_data(t);
      const double* before = initial.frame_data(t - 1);
      for (int64_t p = 0; p < pixels; ++p) {
        if (mask.role(p) == ActivityMask::Role::kRing && now[p] != before[p]) {
          starts[t * pixels + p] = 1;
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
      if (t > 0 && starts[t * pixels + p]) {
        segment.last = t - 1;
        segments_.push_back(segment);
        segment.first = t;
      }
      segment_of_voxel_[t * pixels + p] = static_cast<int32_t>(segments_.size());
    }
    segment.last = num_latent - 1;
    segments_.push_back(segment);
  }
  if (segments_.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max())) {
    throw InvalidArgumentError("latent layout: too many segments");
  }
  for (const Segment& segment : segments_) num_variable_segments_ += !segment.constant;
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
    const double value = latent->frame_data(segment.first)[segment.pixel];
    for (int t = segment.first + 1; t <= segment.last; ++t) {
      latent->frame_data(t)[segment.pixel] = value;
    }
  }
}

}  // namespace evfs
