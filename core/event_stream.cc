#include "evfs/core/event_stream.h"

#include <algorithm>

namespace evfs {

void EventStream::reserve(size_t n) {
  t_ns_.reserve(n);
  x_.reserve(n);
  y_.reserve(n);
  polarity_.reserve(n);
}

void EventStream::clear() {
  t_ns_.clear();
  x_.clear();
  y_.clear();
  polarity_.clear();
}

void EventStream::Append(const EventStream& other) {
  t_ns_.insert(t_ns_.end(), other.t_ns_.begin(), other.t_ns_.end());
  x_.insert(x_.end(), other.x_.begin(), other.x_.end());
  y_.insert(y_.end(), other.y_.begin(), other.y_.end());
  polarity_.insert(polarity_.end(), other.polarity_.begin(), other.polarity_.end());
}

size_t EventStream::LowerBound(int64_t t_ns) const {
  return static_cast<size_t>(std::lower_bound(t_ns_.begin(), t_ns_.end(), t_ns) - t_ns_.begin());
}

EventStream EventStream::Slice(int64_t t_begin_ns, int64_t t_end_ns) const {
  const size_t first = LowerBound(t_begin_ns);
  const size_t last = std::max(first, LowerBound(t_end_ns));
  return SliceIndex(first, last);
}

EventStream EventStream::SliceIndex(size_t first, size_t last) const {
  EventStream slice(width_, height_);
  slice.t_ns_.assign(t_ns_.begin() + first, t_ns_.begin() + last);
  slice.x_.assign(x_.begin() + first, x_.begin() + last);
  slice.y_.assign(y_.begin() + first, y_.begin() + last);
  slice.polarity_.assign(polarity_.begin() + first, polarity_.begin() + last);
  return slice;
}

bool EventStream::IsSorted() const { return std::is_sorted(t_ns_.begin(), t_ns_.end()); }

size_t EventStream::CountPositive() const {
  return static_cast<size_t>(std::count(polarity_.begin(), polarity_.end(), int8_t{1}));
}

bool EventStream::operator==(const EventStream& other) const {
  return width_ == other.width_ && height_ == other.height_ && t_ns_ == other.t_ns_ &&
         x_ == other.x_ && y_ == other.y_ && polarity_ == other.polarity_;
}

}  // namespace evfs
