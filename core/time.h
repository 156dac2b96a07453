// Timestamps are int64 nanoseconds everywhere inside evfs: exact for every DAVIS clock (µs) and
// every decimal seconds value with up to 9 digits, and cheap to compare.
#ifndef EVFS_CORE_TIME_H_
#define EVFS_CORE_TIME_H_

#include <chrono>
#include <cmath>
#include <cstdint>

namespace evfs {

constexpr int64_t kNanosecondsPerSecond = 1000000000;

/// Longest duration an option gives in seconds (an exposure, a prediction): an hour keeps every
/// time derived from it far inside int64 nanoseconds.
constexpr double kMaxDurationS = 3600.0;

inline double NanosecondsToSeconds(int64_t t_ns) {
  return static_cast<double>(t_ns) / static_cast<double>(kNanosecondsPerSecond);
}

inline int64_t SecondsToNanoseconds(double t_s) {
  return static_cast<int64_t>(std::llround(t_s * static_cast<double>(kNanosecondsPerSecond)));
}

/// Seconds elapsed since `start` on the monotonic clock, for stage and solve timings.
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace evfs

#endif  // EVFS_CORE_TIME_H_
