#include "evfs/scene/activity_mask.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace evfs {
namespace {

// Chebyshev dilation of a binary mask by `radius` pixels, separably (rows, then columns), with
// a running count so that the cost does not grow with the radius. A radius beyond the longer
// side dilates exactly as that side does; indices are int64, so no radius overflows them.
std::vector<uint8_t> Dilate(const std::vector<uint8_t>& mask, int height, int width,
                            int64_t radius_px) {
  if (radius_px <= 0) return mask;
  const int64_t radius = std::min<int64_t>(radius_px, std::max(height, width));
  std::vector<uint8_t> rows(mask.size(), 0), out(mask.size(), 0);
  const auto dilate_line = [radius](const uint8_t* in, uint8_t* result, int64_t length,
                                    int64_t stride) {
    int64_t count = 0;  // set pixels within [i - radius, i + radius]
    for (int64_t i = 0; i < std::min(radius, length); ++i) count += in[i * stride];
    for (int64_t i = 0; i < length; ++i) {
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

ActivityMask::ActivityMask(const EventFrames& events, int radius_px)
    : height_(events.height()), width_(events.width()) {
  const int height = height_, width = width_;
  const int64_t pixels = static_cast<int64_t>(height) * width;
  if (radius_px < 0) {
    roles_.assign(pixels, Role::kActive);
    num_active_ = pixels;
    return;
  }
  const std::vector<uint8_t> active = Dilate(events.FiredPixels(), height, width, radius_px);
  const std::vector<uint8_t> near_active = Dilate(active, height, width, 1);
  roles_.resize(pixels);
  for (int64_t p = 0; p < pixels; ++p) {
    roles_[p] = active[p] ? Role::kActive : near_active[p] ? Role::kRing : Role::kInactive;
    num_active_ += active[p];
  }
}

std::vector<std::vector<int64_t>> ActivityMask::IndependentParts(int64_t min_part_pixels) const {
  cv::Mat in_problem(height_, width_, CV_8U);
  for (int64_t p = 0; p < num_pixels(); ++p) in_problem.data[p] = roles_[p] != Role::kInactive;
  cv::Mat labels;
  const int count = cv::connectedComponents(in_problem, labels, 8, CV_32S);
  std::vector<std::vector<int64_t>> components(std::max(0, count - 1));  // label 0: background
  const int32_t* label = labels.ptr<int32_t>();
  for (int64_t p = 0; p < num_pixels(); ++p) {
    if (label[p] > 0) components[label[p] - 1].push_back(p);
  }
  std::stable_sort(components.begin(), components.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  std::vector<std::vector<int64_t>> parts;
  bool packing = false;  // the last part collects small components
  for (std::vector<int64_t>& component : components) {
    if (packing && static_cast<int64_t>(parts.back().size()) < min_part_pixels) {
      parts.back().insert(parts.back().end(), component.begin(), component.end());
    } else {
      packing = static_cast<int64_t>(component.size()) < min_part_pixels;
      parts.push_back(std::move(component));
    }
  }
  for (std::vector<int64_t>& part : parts) std::sort(part.begin(), part.end());
  return parts;
}

}  // namespace evfs
