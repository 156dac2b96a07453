// A grey video: `num_frames` frames of `height × width` linear intensities, stored contiguously
// frame after frame (row-major inside a frame), with one timestamp per frame.
#ifndef EVFS_CORE_VIDEO_H_
#define EVFS_CORE_VIDEO_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace evfs {

/// One grey image, row-major so that it maps onto a frame of a Video without copying.
using Image = Eigen::Array<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using ImageMap = Eigen::Map<Image>;
using ConstImageMap = Eigen::Map<const Image>;

/// Index of the timestamp in `timestamps_ns` (increasing, not empty) nearest to `t_ns` (ties
/// go to the earlier one).
int NearestTimestamp(const std::vector<int64_t>& timestamps_ns, int64_t t_ns);

class Video {
 public:
  Video() = default;
  /// All values zero, all timestamps zero.
  Video(int height, int width, int num_frames);

  int height() const { return height_; }
  int width() const { return width_; }
  int num_frames() const { return static_cast<int>(timestamps_ns_.size()); }
  int64_t pixels_per_frame() const { return static_cast<int64_t>(height_) * width_; }
  bool empty() const { return num_frames() == 0; }

  double* data() { return data_.data(); }
  const double* data() const { return data_.data(); }
  double* frame_data(int t) { return data_.data() + t * pixels_per_frame(); }
  const double* frame_data(int t) const { return data_.data() + t * pixels_per_frame(); }

  double& at(int t, int y, int x) { return data_[Index(t, y, x)]; }
  double at(int t, int y, int x) const { return data_[Index(t, y, x)]; }

  ImageMap frame(int t) { return ImageMap(frame_data(t), height_, width_); }
  ConstImageMap frame(int t) const { return ConstImageMap(frame_data(t), height_, width_); }

  int64_t timestamp_ns(int t) const { return timestamps_ns_[t]; }
  double timestamp_s(int t) const;
  void set_timestamp_ns(int t, int64_t t_ns) { timestamps_ns_[t] = t_ns; }
  const std::vector<int64_t>& timestamps_ns() const { return timestamps_ns_; }

  /// Appends a frame of this video's size (the first frame sets the size); throws
  /// InvalidArgumentError for a frame of another size.
  void AppendFrame(const Image& image, int64_t timestamp_ns);

  /// Index of the frame whose timestamp is nearest to `t_ns` (ties go to the earlier frame).
  int NearestFrame(int64_t t_ns) const { return NearestTimestamp(timestamps_ns_, t_ns); }

  /// Linear interpolation between the two frames around `t_ns` (clamped at the ends).
  Image InterpolateAt(int64_t t_ns) const;

  /// The frames InterpolateAt(t_ns) reads: `*before` and `*after` with `*weight_after` for the
  /// later one (the same frame twice, weight 0, at or beyond the ends).
  void InterpolationFrames(int64_t t_ns, int* before, int* after, double* weight_after) const;

 private:
  size_t Index(int t, int y, int x) const {
    return static_cast<size_t>(t) * pixels_per_frame() + static_cast<size_t>(y) * width_ + x;
  }

  int height_ = 0;
  int width_ = 0;
  std::vector<double> data_;
  std::vector<int64_t> timestamps_ns_;
};

}  // namespace evfs

#endif  // EVFS_CORE_VIDEO_H_
