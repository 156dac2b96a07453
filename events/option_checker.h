// Checks the fields of an XxxOptions struct for its IsValid, keeping the first failure as a
// readable reason. Shared by the options of binning, the simulator and the scene synthesizer.
#ifndef EVFS_EVENTS_OPTION_CHECKER_H_
#define EVFS_EVENTS_OPTION_CHECKER_H_

#include <cmath>
#include <string>

namespace evfs {

/// Chained requirements; after the first failure the others are skipped.
///   OptionChecker check;
///   check.Positive("log_eps", log_eps).AtLeast("num_frames", num_frames, 1);
///   return check.Passed(error);
class OptionChecker {
 public:
  /// Requires a finite value > 0.
  OptionChecker& Positive(const char* name, double value) {
    return Require(value > 0.0 && std::isfinite(value), name, "finite and > 0");
  }

  /// Requires a finite value >= 0.
  OptionChecker& NonNegative(const char* name, double value) {
    return Require(value >= 0.0 && std::isfinite(value), name, "finite and >= 0");
  }

  /// Requires an integer in [low, high].
  OptionChecker& InRange(const char* name, long long value, long long low, long long high) {
    return Require(value >= low && value <= high, name,
                   "in [" + std::to_string(low) + ", " + std::to_string(high) + "], got " +
                       std::to_string(value));
  }

  /// Requires `ok`; otherwise "`name` must be `expected`" becomes the reason.
  OptionChecker& Require(bool ok, const std::string& name, const std::string& expected) {
    if (reason_.empty() && !ok) reason_ = name + " must be " + expected;
    return *this;
  }

  /// True when every requirement held; otherwise false with the first failure in `error`
  /// (which may be null). `error` is cleared on success.
  bool Passed(std::string* error) const {
    if (error != nullptr) *error = reason_;
    return reason_.empty();
  }

 private:
  std::string reason_;
};

}  // namespace evfs

#endif  // EVFS_EVENTS_OPTION_CHECKER_H_
