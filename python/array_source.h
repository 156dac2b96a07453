// A recording held in the caller's arrays (the Python module's NumPy inputs), seen through the
// DataSource interface so that the reconstruction job reads it exactly as it reads a file.
// Nothing is copied up front: a frame is converted when the job asks for it, and only the
// events of the requested window are copied.
#ifndef EVFS_PYTHON_ARRAY_SOURCE_H_
#define EVFS_PYTHON_ARRAY_SOURCE_H_

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "evfs/core/event_stream.h"
#include "evfs/core/video.h"
#include "evfs/io/data_source.h"

namespace evfs {

/// Largest side of the frames: event coordinates are uint16. Their area is bounded further by
/// kMaxSensorPixels (io/image_io.h), as for every recording evfs reads.
inline constexpr int kMaxSensorSide = 65536;

/// Most frames an array recording may hold: one per millisecond for over 16 minutes. Each frame
/// costs bookkeeping (its time, its name) whatever its pixels, and a zero-stride view declares
/// any count without occupying memory.
inline constexpr int64_t kMaxArrayFrames = 1000000;
/// Most events an array recording may hold: what 32-bit signed indexes count.
inline constexpr int64_t kMaxArrayEvents = (int64_t{1} << 31) - 1;

/// One element of T every `stride` bytes from `data` (any sign, zero included, unaligned
/// allowed): a 1-D NumPy array read where it lies, without a copy.
template <typename T>
struct StridedArray {
  const char* data = nullptr;
  int64_t stride = 0;

  T operator[](size_t i) const {
    T value;
    std::memcpy(&value, data + static_cast<int64_t>(i) * stride, sizeof(value));
    return value;
  }
};

/// Borrowed arrays of a recording. Every pointer must stay valid, and its data unchanged, for
/// the lifetime of the ArraySource made from it.
struct RecordingArrays {
  /// num_frames × height × width intensities in [0, 1], float32 or float64 (frames_float32),
  /// element [f, r, c] at frames_data + f * frame_stride + r * row_stride + c * column_stride
  /// bytes. Strides may be negative or zero and elements unaligned: a NumPy view is read where
  /// it lies, so that no layout (a broadcast view of a huge array included) costs a copy.
  const char* frames_data = nullptr;
  bool frames_float32 = false;
  int64_t frame_stride = 0;
  int64_t row_stride = 0;
  int64_t column_stride = 0;
  int num_frames = 0;
  int height = 0;
  int width = 0;
  /// One timestamp per frame, strictly increasing.
  std::vector<int64_t> frame_t_ns;
  /// Per frame: exposure begin and end, or none (has_exposure false) when empty.
  std::vector<bool> has_exposure;
  std::vector<int64_t> exposure_begin_ns;
  std::vector<int64_t> exposure_end_ns;
  /// num_events events in time order: t in seconds (never decreasing), x < width, y < height,
  /// polarity ±1.
  StridedArray<double> event_t_s;
  StridedArray<uint16_t> event_x;
  StridedArray<uint16_t> event_y;
  StridedArray<int8_t> event_polarity;
  size_t num_events = 0;
};

/// `t_s` seconds as int64 nanoseconds (core/time.h); throws InvalidArgumentError naming `what`
/// when it is not finite or beyond int64 nanoseconds (about 292 years).
int64_t CheckedNanoseconds(double t_s, const std::string& what);

/// Checks a RecordingArrays against the contract above and throws InvalidArgumentError naming
/// the first thing that breaks it: `frames_name` and `events_name` are how the message calls
/// the arrays (the Python argument names). When `cancel` is given and becomes true, it throws
/// Interrupted at its next frame or million events: a zero-stride view may declare far more
/// values than it holds, and its check must not outlast Ctrl-C.
void CheckRecordingArrays(const RecordingArrays& arrays, const std::string& frames_name,
                          const std::string& events_name,
                          const std::atomic<bool>* cancel = nullptr);

/// The DataSource over checked RecordingArrays. Frames are named "frame N" in messages and
/// summaries; path() is `label`.
class ArraySource : public DataSource {
 public:
  ArraySource(const RecordingArrays& arrays, const std::string& label);

  Image ReadImage(int index) const override;
  EventStream ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const override;
  EventStream ReadAllEvents() const override;
  EventSummary Summarize() const override;

 private:
  // Index of the first event with SecondsToNanoseconds(t) >= t_ns (binary search).
  size_t LowerBound(int64_t t_ns) const;
  EventStream Copy(size_t first, size_t last) const;

  RecordingArrays arrays_;
};

}  // namespace evfs

#endif  // EVFS_PYTHON_ARRAY_SOURCE_H_
