// Checks the fields of an XxxOptions struct for its IsValid, keeping the first failure as a
// readable reason. Every IsValid of the project goes through it, so all of them treat `error`
// the same way: it may be null, it receives the first failure and it is cleared on success.
#ifndef EVFS_CORE_OPTION_CHECKER_H_
#define EVFS_CORE_OPTION_CHECKER_H_

#include <cmath>
#include <string>

namespace evfs {

/// Chained requirements; after the first failure the others are skipped.
///   OptionChecker check;
///   check.Positive("log_eps", log_eps).InRange("num_frames", num_frames, 1, 1000);
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
    if (!reason_.empty() || (value >= low && value <= high)) return *this;
    return Require(false, name,
                   "in [" + std::to_string(low) + ", " + std::to_string(high) + "], got " +
                       std::to_string(value));
  }

  /// Requires `ok`; otherwise "`name` must be `expected`" becomes the reason.
  OptionChecker& Require(bool ok, const std::string& name, const std::string& expected) {
    return Check(ok, name + " must be " + expected);
  }

  /// Requires `ok`; otherwise `reason`, word for word, becomes the reason.
  OptionChecker& Check(bool ok, const std::string& reason) {
    if (reason_.empty() && !ok) reason_ = reason.empty() ? "invalid options" : reason;
    return *this;
  }

  /// Requires `nested.IsValid` (nested options: ours, or Ceres' solver options, whose IsValid
  /// needs a non-null error); its reason becomes ours. Skipped after an earlier failure.
  template <typename Options>
  OptionChecker& Valid(const Options& nested) {
    if (!reason_.empty()) return *this;
    std::string reason;
    if (!nested.IsValid(&reason)) Check(false, reason);
    return *this;
  }

  /// True while no requirement has failed.
  bool ok() const { return reason_.empty(); }

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

#endif  // EVFS_CORE_OPTION_CHECKER_H_
