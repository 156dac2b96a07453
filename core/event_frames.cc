#include "core/event_frames.h"

#include <cmath>

namespace evfs {

int EventFrames::AddFrame(const EventFrameSpan& span) {
  spans_.push_back(span);
  values_.resize(values_.size() + pixels_per_frame(), 0.0f);
  return num_frames() - 1;
}

double EventFrames::TotalAbsoluteValue() const {
  double total = 0.0;
  for (const float v : values_) total += std::abs(v);
  return total;
}

}  // namespace evfs
