#include "evfs/core/video.h"

#include <algorithm>
#include <string>

#include "evfs/core/error.h"
#include "evfs/core/time.h"

namespace evfs {

Video::Video(int height, int width, int num_frames)
    : height_(height),
      width_(width),
      data_(static_cast<size_t>(height) * width * num_frames, 0.0),
      timestamps_ns_(num_frames, 0) {}

double Video::timestamp_s(int t) const { return NanosecondsToSeconds(timestamps_ns_[t]); }

void Video::AppendFrame(const Image& image, int64_t timestamp_ns) {
  if (empty()) {
    height_ = static_cast<int>(image.rows());
    width_ = static_cast<int>(image.cols());
  }
  if (image.rows() != height_ || image.cols() != width_) {
    throw InvalidArgumentError("cannot append a " + std::to_string(image.cols()) + "x" +
                               std::to_string(image.rows()) + " frame to a " +
                               std::to_string(width_) + "x" + std::to_string(height_) + " video");
  }
  data_.insert(data_.end(), image.data(), image.data() + image.size());
  timestamps_ns_.push_back(timestamp_ns);
}

int NearestTimestamp(const std::vector<int64_t>& timestamps_ns, int64_t t_ns) {
  const auto upper = std::lower_bound(timestamps_ns.begin(), timestamps_ns.end(), t_ns);
  if (upper == timestamps_ns.begin()) return 0;
  if (upper == timestamps_ns.end()) return static_cast<int>(timestamps_ns.size()) - 1;
  const int after = static_cast<int>(upper - timestamps_ns.begin());
  const int before = after - 1;
  return (t_ns - timestamps_ns[before] <= timestamps_ns[after] - t_ns) ? before : after;
}

void Video::InterpolationFrames(int64_t t_ns, int* before, int* after, double* weight_after) const {
  const auto upper = std::upper_bound(timestamps_ns_.begin(), timestamps_ns_.end(), t_ns);
  *weight_after = 0.0;
  if (upper == timestamps_ns_.begin() || upper == timestamps_ns_.end()) {
    *before = *after = upper == timestamps_ns_.begin() ? 0 : num_frames() - 1;
    return;
  }
  *after = static_cast<int>(upper - timestamps_ns_.begin());
  *before = *after - 1;
  const double span = static_cast<double>(timestamps_ns_[*after] - timestamps_ns_[*before]);
  *weight_after = static_cast<double>(t_ns - timestamps_ns_[*before]) / span;
}

Image Video::InterpolateAt(int64_t t_ns) const {
  int before = 0, after = 0;
  double weight_after = 0.0;
  InterpolationFrames(t_ns, &before, &after, &weight_after);
  if (before == after) return frame(before);
  return (1.0 - weight_after) * frame(before) + weight_after * frame(after);
}

}  // namespace evfs
