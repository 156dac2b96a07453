// Events of a DAVIS-style sensor as a structure of arrays, sorted by time.
#ifndef EVFS_CORE_EVENT_STREAM_H_
#define EVFS_CORE_EVENT_STREAM_H_

#include <cstddef>
#include <cstdint>
#include <vector>

namespace evfs {

class EventStream {
 public:
  EventStream() = default;
  EventStream(int width, int height) : width_(width), height_(height) {}

  /// Sensor size; every event satisfies 0 <= x < width, 0 <= y < height.
  int width() const { return width_; }
  int height() const { return height_; }
  void set_sensor_size(int width, int height) {
    width_ = width;
    height_ = height;
  }

  size_t size() const { return t_ns_.size(); }
  bool empty() const { return t_ns_.empty(); }
  void reserve(size_t n);
  void clear();

  /// Appends one event; polarity is +1 (brighter) or -1 (darker).
  void push_back(int64_t t_ns, uint16_t x, uint16_t y, int8_t polarity) {
    t_ns_.push_back(t_ns);
    x_.push_back(x);
    y_.push_back(y);
    polarity_.push_back(polarity);
  }
  /// Appends all events of `other` (which must not start before this stream ends).
  void Append(const EventStream& other);

  int64_t t_ns(size_t i) const { return t_ns_[i]; }
  uint16_t x(size_t i) const { return x_[i]; }
  uint16_t y(size_t i) const { return y_[i]; }
  int8_t polarity(size_t i) const { return polarity_[i]; }

  const std::vector<int64_t>& t_ns() const { return t_ns_; }
  const std::vector<uint16_t>& x() const { return x_; }
  const std::vector<uint16_t>& y() const { return y_; }
  const std::vector<int8_t>& polarity() const { return polarity_; }

  int64_t first_t_ns() const { return t_ns_.front(); }
  int64_t last_t_ns() const { return t_ns_.back(); }

  /// Index of the first event with t >= t_ns (binary search; the stream is sorted).
  size_t LowerBound(int64_t t_ns) const;

  /// The events with t_begin_ns <= t < t_end_ns, same sensor size.
  EventStream Slice(int64_t t_begin_ns, int64_t t_end_ns) const;
  /// The events with index in [first, last).
  EventStream SliceIndex(size_t first, size_t last) const;

  /// True when timestamps never decrease.
  bool IsSorted() const;
  /// Number of events with polarity +1.
  size_t CountPositive() const;

  bool operator==(const EventStream& other) const;

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<int64_t> t_ns_;
  std::vector<uint16_t> x_;
  std::vector<uint16_t> y_;
  std::vector<int8_t> polarity_;
};

}  // namespace evfs

#endif  // EVFS_CORE_EVENT_STREAM_H_
