#include "evfs/core/event_frames.h"

#include <cmath>

namespace evfs {

int EventFrames::AddFrame(const EventFrameSpan& span) {
  spans_.push_back(span);
  values_.resize(values_.size() + pixels_per_frame(), 0.0f);
  return num_frames() - 1;
}

void EventFrames::Reserve(int num_frames) {
  spans_.reserve(static_cast<size_t>(num_frames));
  values_.reserve(static_cast<size_t>(num_frames) * static_cast<size_t>(pixels_per_frame()));
}

double EventFrames::TotalAbsoluteValue() const {
  double total = 0.0;
  for (const float v : values_) total += std::abs(v);
  return total;
}

std::vector<uint8_t> EventFrames::FiredPixels() const {
  const int64_t pixels = pixels_per_frame();
  std::vector<uint8_t> fired(pixels, 0);
  for (int k = 0; k < num_frames(); ++k) {
    const float* values = frame_data(k);
    for (int64_t p = 0; p < pixels; ++p) fired[p] |= values[p] != 0.0f;
  }
  return fired;
}

int PolarityReversals(const EventFrames& events, int64_t pixel) {
  int reversals = 0;
  float last = 0.0f;
  for (int k = 0; k < events.num_frames(); ++k) {
    const float value = events.frame_data(k)[pixel];
    if (value == 0.0f) continue;
    if (last != 0.0f && (value > 0.0f) != (last > 0.0f)) ++reversals;
    last = value;
  }
  return reversals;
}

}  // namespace evfs
