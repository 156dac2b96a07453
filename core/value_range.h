// The values a numeric option accepts, declared beside the option (app/evfs_options.cc) and
// checked wherever a value enters: the command line, Python, the option table's builders.
//
//   ValueRange::AtLeast(0.0)               >= 0
//   ValueRange::Between(0.0, 1.0)          in [0, 1]
//   ValueRange::Above(0.0).Or(-1.0)        -1, or > 0
//
// A range holds only numbers: NaN never, and an infinity only at an end that is +-infinity and
// closed (AtLeast(0).WithInfinity() takes +infinity).
#ifndef EVFS_CORE_VALUE_RANGE_H_
#define EVFS_CORE_VALUE_RANGE_H_

#include <limits>
#include <string>

namespace evfs {

class ValueRange {
 public:
  /// Every finite number.
  static constexpr ValueRange Any() { return ValueRange(-kInfinity, kInfinity, true, true); }
  /// [low, +infinity), finite.
  static constexpr ValueRange AtLeast(double low) {
    return ValueRange(low, kInfinity, false, true);
  }
  /// (low, +infinity), finite.
  static constexpr ValueRange Above(double low) { return ValueRange(low, kInfinity, true, true); }
  /// (-infinity, high], finite.
  static constexpr ValueRange AtMost(double high) {
    return ValueRange(-kInfinity, high, true, false);
  }
  /// [low, high].
  static constexpr ValueRange Between(double low, double high) {
    return ValueRange(low, high, false, false);
  }
  /// (low, high).
  static constexpr ValueRange Inside(double low, double high) {
    return ValueRange(low, high, true, true);
  }
  /// [low, high).
  static constexpr ValueRange From(double low, double below) {
    return ValueRange(low, below, false, true);
  }

  /// The same range, also accepting `value` (a value with a meaning of its own: 0 derives it).
  constexpr ValueRange Or(double value) const {
    ValueRange range = *this;
    range.also_ = value;
    range.has_also_ = true;
    return range;
  }
  /// The same range, its infinite upper end included (+infinity: no limit).
  constexpr ValueRange WithInfinity() const {
    ValueRange range = *this;
    range.high_open_ = false;
    return range;
  }

  /// Whether the range bounds anything: false for Any().
  constexpr bool Bounded() const { return low_ != -kInfinity || high_ != kInfinity || has_also_; }
  bool Contains(double value) const;

  /// "in [0, 1]", ">= 1", "0, or in [1, 100000]": what a message or a help line says.
  std::string Text() const;

  constexpr double low() const { return low_; }
  constexpr double high() const { return high_; }
  constexpr bool low_open() const { return low_open_; }
  constexpr bool high_open() const { return high_open_; }
  /// The one value accepted beside the interval, when there is one (Or).
  constexpr bool has_also() const { return has_also_; }
  constexpr double also() const { return also_; }

 private:
  static constexpr double kInfinity = std::numeric_limits<double>::infinity();

  constexpr ValueRange(double low, double high, bool low_open, bool high_open)
      : low_(low), high_(high), low_open_(low_open), high_open_(high_open) {}

  double low_;
  double high_;
  bool low_open_;
  bool high_open_;
  double also_ = 0.0;
  bool has_also_ = false;
};

/// A number as a message shows it: "3600", "0.5", "1000000.5", "1e+30" (a whole number below
/// 1e7 in full, any other to 9 significant digits).
std::string RangeNumberText(double value);

}  // namespace evfs

#endif  // EVFS_CORE_VALUE_RANGE_H_
