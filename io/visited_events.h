// For readers whose file hands the events of a time window to a visitor, one at a time as
// visit(t_ns, x, y, polarity): the stream and the summary DataSource returns, built one way.
#ifndef EVFS_IO_VISITED_EVENTS_H_
#define EVFS_IO_VISITED_EVENTS_H_

#include <cstdint>
#include <limits>

#include "evfs/core/event_stream.h"
#include "evfs/io/data_source.h"

namespace evfs {

/// The window that holds every event: ForEachEvent(kAllEventsBeginNs, kAllEventsEndNs, visit).
constexpr int64_t kAllEventsBeginNs = std::numeric_limits<int64_t>::min();
constexpr int64_t kAllEventsEndNs = std::numeric_limits<int64_t>::max();

/// The events for_each(visit) visits, as a stream on a width x height sensor.
template <typename ForEach>
EventStream CollectVisitedEvents(int width, int height, ForEach&& for_each) {
  EventStream events(width, height);
  for_each([&](int64_t t_ns, int x, int y, int polarity) {
    events.push_back(t_ns, static_cast<uint16_t>(x), static_cast<uint16_t>(y),
                     static_cast<int8_t>(polarity));
  });
  return events;
}

/// The summary of the events for_each(visit) visits.
template <typename ForEach>
EventSummary SummarizeVisitedEvents(ForEach&& for_each) {
  EventSummary summary;
  for_each([&](int64_t t_ns, int x, int y, int polarity) { summary.Add(t_ns, x, y, polarity); });
  return summary;
}

}  // namespace evfs

#endif  // EVFS_IO_VISITED_EVENTS_H_
