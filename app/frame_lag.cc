#include "evfs/app/frame_lag.h"

#include <algorithm>

#include "evfs/core/time.h"

namespace evfs {

FrameLagEstimate EstimateRecordingFrameLag(const DataSource& source,
                                           const std::vector<int>& indices,
                                           const FrameLagOptions& options) {
  std::vector<Image> images;
  std::vector<int64_t> times_ns;
  for (const int index : indices) {
    images.push_back(source.ReadImage(index));
    times_ns.push_back(source.frames()[index].t_ns);
  }
  std::vector<FramePair> pairs;
  for (size_t i = 1; i < images.size(); ++i) {
    pairs.push_back({&images[i - 1], times_ns[i - 1], &images[i], times_ns[i]});
  }
  if (pairs.empty())
    return EstimateFrameLag({}, EventStream(source.width(), source.height()), options);
  const EventStream events = source.ReadEvents(
      times_ns.front() + SecondsToNanoseconds(std::min(0.0, options.min_lag_s)),
      times_ns.back() + SecondsToNanoseconds(std::max(0.0, options.max_lag_s)) + 1);
  return EstimateFrameLag(pairs, events, options);
}

}  // namespace evfs
