// The frame lag of a recording (scene/frame_timing.h) estimated from its frames and events, as
// `evfs info` reports it and `evfs reconstruct --frame_time=auto` uses it.
#ifndef EVFS_APP_FRAME_LAG_H_
#define EVFS_APP_FRAME_LAG_H_

#include <vector>

#include "evfs/io/data_source.h"
#include "evfs/scene/frame_timing.h"

namespace evfs {

/// Estimates the lag from the consecutive pairs of the frames `indices` (increasing frames()
/// indices; fewer than two give an unknown lag) and the events around them. Throws as
/// DataSource's readers and EstimateFrameLag do.
FrameLagEstimate EstimateRecordingFrameLag(const DataSource& source,
                                           const std::vector<int>& indices,
                                           const FrameLagOptions& options);

}  // namespace evfs

#endif  // EVFS_APP_FRAME_LAG_H_
