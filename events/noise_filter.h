// Event filters for what the event model does not describe: background activity that no
// neighbouring pixel confirms, and pixels lit by a flickering light source.
#ifndef EVFS_EVENTS_NOISE_FILTER_H_
#define EVFS_EVENTS_NOISE_FILTER_H_

#include <cstdint>
#include <vector>

#include "evfs/core/event_stream.h"

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

/// Pixels that flicker in [t_begin_ns, t_end_ns): their events reverse polarity at least
/// `min_reversals` times (an ON event right after an OFF one, or the reverse, counts once) and
/// add up to almost no net change (|ON − OFF| at most a quarter of the events). A light that
/// blinks or follows the mains (an LED driven by PWM, a lamp at twice the mains frequency) makes
/// a pixel fire bursts of alternating sign many times between two frames while its level at the
/// frames hardly moves; an edge or a texture crossing a pixel reverses its sign only where the
/// intensity along the path has an extremum, a few times in a frame interval at most. The
/// event model integrates every event, so at these pixels the events describe the light's
/// waveform, not the scene, and the frames are the better witness. Returns row-major indices,
/// ascending; *events_at (optional) receives the number of events at them. min_reversals <= 0
/// finds none. O(events + pixels) time.
std::vector<int32_t> FindFlickeringPixels(const EventStream& events, int64_t t_begin_ns,
                                          int64_t t_end_ns, int min_reversals,
                                          int64_t* events_at = nullptr);

}  // namespace evfs

#endif  // EVFS_EVENTS_NOISE_FILTER_H_
