#include "evfs/core/value_range.h"

#include <cmath>
#include <cstdio>

namespace evfs {

bool ValueRange::Contains(double value) const {
  if (std::isnan(value)) return false;
  if (has_also_ && value == also_) return true;
  const bool above_low = low_open_ ? value > low_ : value >= low_;
  const bool below_high = high_open_ ? value < high_ : value <= high_;
  return above_low && below_high;
}

std::string RangeNumberText(double value) {
  char text[32];
  if (std::abs(value) < 1e7 && value == std::floor(value)) {
    std::snprintf(text, sizeof(text), "%.0f", value);
  } else {
    std::snprintf(text, sizeof(text), "%.9g", value);
  }
  return text;
}

std::string ValueRange::Text() const {
  std::string text;
  if (low_ == -kInfinity && high_ == kInfinity) {
    text = "a number";
  } else if (high_ == kInfinity) {
    text = (low_open_ ? "> " : ">= ") + RangeNumberText(low_);
    if (!high_open_) text += " or inf";
  } else if (low_ == -kInfinity) {
    text = (high_open_ ? "< " : "<= ") + RangeNumberText(high_);
  } else {
    text = std::string("in ") + (low_open_ ? "(" : "[") + RangeNumberText(low_) + ", " +
           RangeNumberText(high_) + (high_open_ ? ")" : "]");
  }
  return has_also_ ? RangeNumberText(also_) + ", or " + text : text;
}

}  // namespace evfs
