#include "evfs/events/noise_filter.h"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <vector>

namespace evfs {
namespace {

constexpr int64_t kNever = std::numeric_limits<int64_t>::min() / 2;

// True when one of the 8 neighbours of (x, y) has its time in `last` within window_ns before t.
bool NeighbourFiredWithin(const std::vector<int64_t>& last, int width, int height, int x, int y,
                          int64_t t, int64_t window_ns) {
  for (int qy = std::max(y - 1, 0); qy <= std::min(y + 1, height - 1); ++qy) {
    for (int qx = std::max(x - 1, 0); qx <= std::min(x + 1, width - 1); ++qx) {
      if ((qx != x || qy != y) && t - last[static_cast<size_t>(qy) * width + qx] <= window_ns) {
        return true;
      }
    }
  }
  return false;
}

// One pass over the events in the order `order` (+1: forward in time, -1: backward). Marks in
// *supported the events for which a neighbour fired within window_ns on the side already
// passed: `last[q]` holds the time of pixel q's latest event seen, negated when going backward
// so that "within the window" reads the same both ways.
void MarkSupport(const EventStream& events, int64_t window_ns, int order,
                 std::vector<uint8_t>* supported) {
  const int width = events.width();
  const int height = events.height();
  std::vector<int64_t> last(static_cast<size_t>(width) * height, kNever);
  const int64_t n = static_cast<int64_t>(events.size());
  for (int64_t k = 0; k < n; ++k) {
    const size_t i = static_cast<size_t>(order > 0 ? k : n - 1 - k);
    const int x = events.x(i);
    const int y = events.y(i);
    if (x >= width || y >= height) continue;
    const int64_t t = order > 0 ? events.t_ns(i) : -events.t_ns(i);
    if (!(*supported)[i]) {
      (*supported)[i] = NeighbourFiredWithin(last, width, height, x, y, t, window_ns);
    }
    last[static_cast<size_t>(y) * width + x] = t;
  }
}

}  // namespace

EventStream WithoutUnsupportedEvents(const EventStream& events, int64_t window_ns,
                                     int64_t* removed) {
  if (removed != nullptr) *removed = 0;
  if (window_ns <= 0 || events.empty()) return events;
  std::vector<uint8_t> keep(events.size(), 0);
  MarkSupport(events, window_ns, +1, &keep);
  MarkSupport(events, window_ns, -1, &keep);
  size_t count = 0;
  for (size_t i = 0; i < events.size(); ++i) {
    if (events.x(i) >= events.width() || events.y(i) >= events.height()) keep[i] = 1;
    count += keep[i];
  }
  EventStream kept(events.width(), events.height());
  kept.reserve(count);
  for (size_t i = 0; i < events.size(); ++i) {
    if (keep[i]) kept.push_back(events.t_ns(i), events.x(i), events.y(i), events.polarity(i));
  }
  if (removed != nullptr) *removed = static_cast<int64_t>(events.size() - count);
  return kept;
}

std::vector<int32_t> FindFlickeringPixels(const EventStream& events, int64_t t_begin_ns,
                                          int64_t t_end_ns, int min_reversals, int64_t* events_at) {
  if (events_at != nullptr) *events_at = 0;
  std::vector<int32_t> flickering;
  if (min_reversals <= 0 || events.empty()) return flickering;
  const int width = events.width();
  const int height = events.height();
  const size_t pixels = static_cast<size_t>(width) * height;
  std::vector<int32_t> count(pixels, 0), net(pixels, 0), reversals(pixels, 0);
  std::vector<int8_t> last(pixels, 0);
  const size_t end = events.LowerBound(t_end_ns);
  for (size_t i = events.LowerBound(t_begin_ns); i < end; ++i) {
    if (events.x(i) >= width || events.y(i) >= height) continue;
    const size_t p = static_cast<size_t>(events.y(i)) * width + events.x(i);
    const int8_t polarity = events.polarity(i) > 0 ? 1 : -1;
    if (last[p] != 0 && last[p] != polarity) ++reversals[p];
    last[p] = polarity;
    ++count[p];
    net[p] += polarity;
  }
  for (size_t p = 0; p < pixels; ++p) {
    if (reversals[p] >= min_reversals && 4 * std::abs(net[p]) <= count[p]) {
      flickering.push_back(static_cast<int32_t>(p));
      if (events_at != nullptr) *events_at += count[p];
    }
  }
  return flickering;
}

}  // namespace evfs
