// When does a sharp frame happen? Estimating, from the events, the moment an intensity frame
// represents relative to its timestamp.
//
// A DAVIS frame is exposed over an interval; depending on the recording its timestamp marks the
// start, the middle or the end of that interval, and the picture is (near) the scene at the
// middle of the exposure. Events are stamped when they happen. So between two frames i and j,
// the per-pixel signed event sum over [t_i + d, t_j + d] explains g(F_j) − g(F_i) best when d
// is the lag between a frame's timestamp and the moment it represents. EstimateFrameLag scans a
// grid of shifts d, scores each by the Pearson correlation, over all pixels, of the signed event
// sum with the change of log(F + b) between the frames, and refines around the best.
#ifndef EVFS_SCENE_FRAME_TIMING_H_
#define EVFS_SCENE_FRAME_TIMING_H_

#include <cstdint>
#include <string>
#include <vector>

#include "evfs/core/enum_names.h"
#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"

namespace evfs {

struct FrameLagOptions {
  /// The shifts tried: [min_lag_s, max_lag_s] in steps of coarse_step_s, then steps of
  /// fine_step_s within one coarse step of the best. A positive lag means the frame represents
  /// a moment after its timestamp.
  double min_lag_s = -0.010;
  double max_lag_s = 0.020;
  double coarse_step_s = 0.001;
  double fine_step_s = 0.0001;
  /// b in log(F + b), the change of the frames the events are compared with.
  double log_offset = 0.1;
  /// Fewest pixels with a nonzero signed event sum (at zero shift, summed over the pairs) for
  /// an estimate; below it the scene tells too little and the lag is reported as unknown (0).
  int min_pixels = 100;
  /// The estimate is kept only when it removes at least this fraction of the misfit at zero
  /// shift, (r − r0) ≥ f · (1 − r0) with r0 the correlation at zero; otherwise the lag is 0: a
  /// flat correlation curve says little about timing. 0.025 lies between the real pair whose
  /// shift costs PSNR and the simulated windows whose shift gains it
  /// (benchmarks/results/options_left_off.md, "Frame timing of sharp frames").
  double min_misfit_reduction = 0.025;

  bool IsValid(std::string* error) const;
};

/// Two frames and their timestamps (as the recording states them).
struct FramePair {
  const Image* first = nullptr;
  int64_t first_t_ns = 0;
  const Image* second = nullptr;
  int64_t second_t_ns = 0;  // > first_t_ns
};

/// One point of the correlation curve.
struct LagScore {
  int64_t lag_ns = 0;
  double correlation = 0.0;  // mean over the pairs
};

struct FrameLagEstimate {
  /// False when the scene could not tell (too few pixels with events, or no shift correlates
  /// better than zero by min_misfit_reduction): lag_ns is then 0.
  bool estimated = false;
  int64_t lag_ns = 0;
  double correlation = 0.0;          // mean over the pairs at lag_ns
  double correlation_at_zero = 0.0;  // mean over the pairs at zero shift
  /// The best shift tried and its correlation, whether or not it was kept as lag_ns.
  int64_t peak_lag_ns = 0;
  double peak_correlation = 0.0;
  int pairs = 0;
  int pixels = 0;  // pixels with a nonzero event sum at zero shift, summed over the pairs
  std::vector<LagScore> curve;  // every shift tried, in increasing order of lag
  /// One line for logs and reports, e.g.
  /// "frame lag +4.3 ms (correlation 0.912, 0.871 at 0 ms; 2 frame pairs, 8211 pixels)".
  std::string description;
};

/// Estimates the lag from the frame pairs and the events (which should cover every pair's
/// interval widened by the lag range; a shift that reaches beyond the events sees fewer of
/// them and scores lower). Throws InvalidArgumentError for invalid options, a pair whose
/// frames differ in size from the events' sensor, or whose second frame is not after its first.
FrameLagEstimate EstimateFrameLag(const std::vector<FramePair>& pairs, const EventStream& events,
                                  const FrameLagOptions& options);

/// What moment a sharp frame of a recording represents relative to its timestamp.
enum class FrameTime {
  kInstant,  // the timestamp itself (sharp frames as instants, the model before frame timing)
  kAuto,     // the timestamp plus the lag EstimateFrameLag finds (0 when it cannot tell)
  kLag,      // the timestamp plus a lag the user gives
  kStart,    // the frame is the mean over its exposure, which its timestamp starts
  kMiddle,   // the frame is the mean over its exposure, centred on its timestamp
  kEnd,      // the frame is the mean over its exposure, which its timestamp ends
};

/// --frame_time's names (kLag is written as a number of milliseconds).
inline constexpr EnumName<FrameTime> kFrameTimeNames[] = {
    {FrameTime::kInstant, "instant", "a sharp frame is the scene at its timestamp"},
    {FrameTime::kAuto, "auto", "at its timestamp plus the lag estimated from the events"},
    {FrameTime::kStart, "start", "the mean over its exposure, which the timestamp starts"},
    {FrameTime::kMiddle, "middle", "the mean over its exposure, centred on the timestamp"},
    {FrameTime::kEnd, "end", "the mean over its exposure, which the timestamp ends"},
};

/// Parses --frame_time: a name of kFrameTimeNames, or a lag in milliseconds ("6.5", "-2ms"),
/// which gives kLag and *lag_s. Returns false for anything else (and a lag beyond ±1 s).
bool ParseFrameTime(const std::string& text, FrameTime* time, double* lag_s);
/// The --frame_time text ParseFrameTime reads back: the name, or the lag in ms for kLag.
std::string FrameTimeName(FrameTime time, double lag_s);

/// The span a sharp frame stamped t_ns is modelled over (begin == end: an instant). kInstant:
/// t; kAuto and kLag: t + lag_ns; kStart, kMiddle, kEnd: its exposure from the data when it
/// has one (has_exposure), otherwise one of exposure_ns placed after, around or before t.
/// Throws InvalidArgumentError for kStart, kMiddle or kEnd without a known exposure (no data
/// exposure and exposure_ns <= 0).
struct FrameSpan {
  int64_t begin_ns = 0;
  int64_t end_ns = 0;
  int64_t middle_ns() const { return begin_ns + (end_ns - begin_ns) / 2; }
};
FrameSpan ModelledFrameSpan(int64_t t_ns, bool has_exposure, int64_t exposure_begin_ns,
                            int64_t exposure_end_ns, FrameTime time, int64_t lag_ns,
                            int64_t exposure_ns);

}  // namespace evfs

#endif  // EVFS_SCENE_FRAME_TIMING_H_
