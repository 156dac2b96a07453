// Background-activity filter: leaves out events that no neighbouring pixel confirms.
#ifndef EVFS_EVENTS_NOISE_FILTER_H_
#define EVFS_EVENTS_NOISE_FILTER_H_

#include <cstdint>

#include "core/event_stream.h"

namespace evfs {

/// The events of `events` that have support: an event of one of the 8 neighbouring pixels at
/// most `window_ns` before or after it. A moving edge crosses neighbouring pixels within a short
/// time, so its events support each other; the background activity of a DAVIS pixel (leak and
/// shot-noise events at ~0.1–1 Hz) is isolated in space and time and is left out. This is the
/// nearest-neighbour filter of the iniVation and Prophesee SDKs, looking both ways in time since
/// the whole window is known (the first event of an edge is supported by the ones after it).
/// window_ns <= 0 keeps every event. Events off the sensor are kept, for the binning to reject.
/// O(events + pixels) time: two passes, one int64 per pixel. *removed (optional) receives the
/// number of events left out.
EventStream WithoutUnsupportedEvents(const EventStream& events, int64_t window_ns,
                                     int64_t* removed = nullptr);

}  // namespace evfs

#endif  // EVFS_EVENTS_NOISE_FILTER_H_
