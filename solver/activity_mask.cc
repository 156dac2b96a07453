#include "solver/activity_mask.h"

#include <algorithm>

namespace evfs {
namespace {

// Chebyshev dilation of a binary mask by `radius` pixels, separably (rows, then columns), with
// a running count so that the cost does not grow with the radius.
std::vector<uint8_t> Dilate(const std::vector<uint8_t>& mask, int height, int width, int radius) {
  if (radius <= 0) return mask;
  std::vector<uint8_t> rows(mask.size(), 0), out(mask.size(), 0);
  const auto dilate_line = [radius](const uint8_t* in, uint8_t* result, int length,
                                    int64_t stride) {
    int count = 0;  // set pixels within [i - radius, i + radius]
    for (int i = 0; i < std::min(radius, length); ++i) count += in[i * stride];
    for (int i = 0; i < length; ++i) {
      if (i + radius < length) count += in[(i + radius) * stride];
      if (i - radius - 1 >= 0) count -= in[(i - radius - 1) * stride];
      result[i * stride] = count > 0;
    }
  };
  for (int y = 0; y < height; ++y) {
    dilate_line(&mask[static_cast<int64_t>(y) * width], &rows[static_cast<int64_t>(y) * width],
                width, 1);
  }
  for (int x = 0; x < width; ++x) dilate_line(&rows[x], &out[x], height, width);
  return out;
}

}  // namespace

ActivityMask::ActivityMask(const EventFrames& events, int radius_px) {
  const int height = events.height(), width = events.width();
  const int64_t pixels = static_cast<int64_t>(height) * width;
  if (radius_px < 0) {
    roles_.assign(pixels, Role::kActive);
    num_active_ = pixels;
    return;
  }
  std::vector<uint8_t> fired(pixels, 0);
  for (int k = 0; k < events.num_frames(); ++k) {
    const float* values = events.frame_data(k);
    for (int64_t p = 0; p < pixels; ++p) fired[p] |= values[p] != 0.0f;
  }
  const std::vector<uint8_t> active = Dilate(fired, height, width, radius_px);
  const std::vector<uint8_t> near_active = Dilate(active, height, width, 1);
  roles_.resize(pixels);
  for (int64_t p = 0; p < pixels; ++p) {
    roles_[p] = active[p] ? Role::kActive : near_active[p] ? Role::kRing : Role::kInactive;
    num_active_ += active[p];
  }
}

}  // namespace evfs
