#include "evfs/python/array_source.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "evfs/core/error.h"
#include "evfs/core/time.h"
#include "evfs/io/image_io.h"

namespace evfs {
namespace {

// Largest |time| in seconds that int64 nanoseconds hold with room to spare (2^63 ns ≈ 9.2e9 s).
constexpr double kMaxAbsTimeS = 9.0e9;

std::vector<FrameInfo> FrameInfos(const RecordingArrays& arrays) {
  std::vector<FrameInfo> frames(arrays.num_frames);
  for (int i = 0; i < arrays.num_frames; ++i) {
    FrameInfo& frame = frames[i];
    frame.t_ns = arrays.frame_t_ns[i];
    frame.path = "frame " + std::to_string(i);
    if (!arrays.has_exposure.empty() && arrays.has_exposure[i]) {
      frame.has_exposure = true;
      frame.exposure_begin_ns = arrays.exposure_begin_ns[i];
      frame.exposure_end_ns = arrays.exposure_end_ns[i];
    }
  }
  return frames;
}

// Element [frame, row, column]; memcpy, since a view's elements need not be aligned.
double FrameValue(const RecordingArrays& arrays, int frame, int row, int column) {
  const char* element = arrays.frames_data + frame * arrays.frame_stride + row * arrays.row_stride +
                        column * arrays.column_stride;
  if (arrays.frames_float32) {
    float value = 0.0f;
    std::memcpy(&value, element, sizeof(value));
    return value;
  }
  double value = 0.0;
  std::memcpy(&value, element, sizeof(value));
  return value;
}

}  // namespace

int64_t CheckedNanoseconds(double t_s, const std::string& what) {
  if (!(std::fabs(t_s) <= kMaxAbsTimeS)) {
    throw InvalidArgumentError(what + " is " + std::to_string(t_s) +
                               ": times must be finite seconds within +-9e9");
  }
  return SecondsToNanoseconds(t_s);
}

void CheckRecordingArrays(const RecordingArrays& arrays, const std::string& frames_name,
                          const std::string& events_name, const std::atomic<bool>* cancel) {
  const auto fail = [](const std::string& message) { throw InvalidArgumentError(message); };
  const auto stop_if_cancelled = [cancel] {
    if (cancel != nullptr && *cancel) throw InterruptedError();
  };
  if (arrays.num_frames < 1 || arrays.height < 1 || arrays.width < 1) {
    fail(frames_name + " must hold at least one frame of at least 1x1 pixels");
  }
  if (arrays.height > kMaxSensorSide || arrays.width > kMaxSensorSide) {
    fail(frames_name + " frames must be at most " + std::to_string(kMaxSensorSide) +
         " pixels on a side (event coordinates are uint16)");
  }
  if (static_cast<int64_t>(arrays.height) * arrays.width > kMaxSensorPixels) {
    fail(frames_name + " holds frames of " + std::to_string(arrays.width) + "x" +
         std::to_string(arrays.height) + " pixels, more than the " +
         std::to_string(kMaxSensorPixels) + " pixels (8192x8192) evfs reads");
  }
  for (int frame = 0; frame < arrays.num_frames; ++frame) {
    stop_if_cancelled();
    for (int row = 0; row < arrays.height; ++row) {
      for (int column = 0; column < arrays.width; ++column) {
        const double value = FrameValue(arrays, frame, row, column);
        if (!(value >= 0.0 && value <= 1.0)) {
          fail(frames_name + " must hold intensities in [0, 1]: [" + std::to_string(frame) + ", " +
               std::to_string(row) + ", " + std::to_string(column) + "] is " +
               std::to_string(value));
        }
      }
    }
  }
  if (arrays.num_frames > kMaxArrayFrames) {
    fail(frames_name + " holds " + std::to_string(arrays.num_frames) + " frames, more than the " +
         std::to_string(kMaxArrayFrames) + " an array recording may hold");
  }
  if (arrays.num_events > static_cast<size_t>(kMaxArrayEvents)) {
    fail(events_name + " holds " + std::to_string(arrays.num_events) + " events, more than the " +
         std::to_string(kMaxArrayEvents) + " an array recording may hold");
  }
  if (arrays.frame_t_ns.size() != static_cast<size_t>(arrays.num_frames)) {
    fail("frame_times must hold one time per frame: " + std::to_string(arrays.num_frames) +
         " frames, " + std::to_string(arrays.frame_t_ns.size()) + " times");
  }
  for (int i = 1; i < arrays.num_frames; ++i) {
    if (arrays.frame_t_ns[i] <= arrays.frame_t_ns[i - 1]) {
      fail("frame_times must increase strictly: [" + std::to_string(i) + "] is not after [" +
           std::to_string(i - 1) + "]");
    }
  }
  if (!arrays.has_exposure.empty()) {
    for (int i = 0; i < arrays.num_frames; ++i) {
      if (arrays.has_exposure[i] && arrays.exposure_end_ns[i] < arrays.exposure_begin_ns[i]) {
        fail("exposures[" + std::to_string(i) + "] ends before it begins");
      }
    }
  }
  double previous_t_s = -std::numeric_limits<double>::infinity();
  constexpr size_t kEventsBetweenCancelChecks = size_t{1} << 20;
  for (size_t i = 0; i < arrays.num_events; ++i) {
    if (i % kEventsBetweenCancelChecks == 0) stop_if_cancelled();
    const double t_s = arrays.event_t_s[i];
    CheckedNanoseconds(t_s, events_name + "['t'][" + std::to_string(i) + "]");
    if (t_s < previous_t_s) {
      fail(events_name + "['t'] must be sorted: [" + std::to_string(i) + "] comes before [" +
           std::to_string(i - 1) + "]");
    }
    previous_t_s = t_s;
    if (arrays.event_x[i] >= arrays.width || arrays.event_y[i] >= arrays.height) {
      fail(events_name + " event " + std::to_string(i) +
           " at x=" + std::to_string(arrays.event_x[i]) +
           ", y=" + std::to_string(arrays.event_y[i]) + " lies outside the " +
           std::to_string(arrays.width) + "x" + std::to_string(arrays.height) + " frames");
    }
    const int polarity = arrays.event_polarity[i];
    if (polarity != 1 && polarity != -1) {
      fail(events_name + "['p'][" + std::to_string(i) + "] is " + std::to_string(polarity) +
           ": polarities are +1 or -1");
    }
  }
}

ArraySource::ArraySource(const RecordingArrays& arrays, const std::string& label)
    : DataSource(label, arrays.width, arrays.height, FrameInfos(arrays)), arrays_(arrays) {}

Image ArraySource::ReadImage(int index) const {
  if (index < 0 || index >= arrays_.num_frames) {
    throw InvalidArgumentError("frame " + std::to_string(index) + " is out of range: " + path() +
                               " has " + std::to_string(arrays_.num_frames) + " frames");
  }
  Image image(arrays_.height, arrays_.width);
  for (int row = 0; row < arrays_.height; ++row) {
    for (int column = 0; column < arrays_.width; ++column) {
      image(row, column) = FrameValue(arrays_, index, row, column);
    }
  }
  return image;
}

size_t ArraySource::LowerBound(int64_t t_ns) const {
  // SecondsToNanoseconds is non-decreasing, so the converted times are sorted too.
  size_t first = 0, count = arrays_.num_events;
  while (count > 0) {
    const size_t half = count / 2;
    if (SecondsToNanoseconds(arrays_.event_t_s[first + half]) < t_ns) {
      first += half + 1;
      count -= half + 1;
    } else {
      count = half;
    }
  }
  return first;
}

EventStream ArraySource::Copy(size_t first, size_t last) const {
  EventStream events(arrays_.width, arrays_.height);
  events.reserve(last - first);
  for (size_t i = first; i < last; ++i) {
    events.push_back(SecondsToNanoseconds(arrays_.event_t_s[i]), arrays_.event_x[i],
                     arrays_.event_y[i], arrays_.event_polarity[i]);
  }
  return events;
}

EventStream ArraySource::ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const {
  const size_t first = LowerBound(t_begin_ns);
  return Copy(first, std::max(first, LowerBound(t_end_ns)));
}

EventStream ArraySource::ReadAllEvents() const { return Copy(0, arrays_.num_events); }

EventSummary ArraySource::Summarize() const {
  EventSummary summary;
  for (size_t i = 0; i < arrays_.num_events; ++i) {
    summary.Add(SecondsToNanoseconds(arrays_.event_t_s[i]), arrays_.event_x[i], arrays_.event_y[i],
                arrays_.event_polarity[i]);
  }
  return summary;
}

}  // namespace evfs
