// When a long computation should end early: a deadline (a time budget for the whole solve) and a
// flag another thread raises (an interrupt such as Python's Ctrl-C). Every iterative loop of evfs
// checks Reached() between iterations and keeps its best answer so far; a Ceres solve gets
// SecondsLeft() as its time limit and stops at the iteration where the condition is reached.
// Copies share the deadline and the flag, so one condition bounds every stage of a command.
#ifndef EVFS_CORE_STOP_CONDITION_H_
#define EVFS_CORE_STOP_CONDITION_H_

#include <atomic>
#include <chrono>
#include <limits>

namespace evfs {

class StopCondition {
 public:
  using Clock = std::chrono::steady_clock;

  /// Never reached.
  StopCondition() = default;

  /// Reached `seconds` from now; a budget beyond a year (or infinite) sets no deadline, and a
  /// budget of 0 or less is reached at once.
  static StopCondition After(double seconds) {
    StopCondition condition;
    if (!(seconds < kNoDeadlineS)) return condition;
    condition.has_deadline_ = true;
    condition.deadline_ =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(seconds > 0.0 ? seconds : 0.0));
    return condition;
  }

  /// Also reached once `*flag` is true; `flag` (may be null: none) must outlive every copy.
  StopCondition& WhenRaised(const std::atomic<bool>* flag) {
    flag_ = flag;
    return *this;
  }

  /// True when it can ever be reached: a deadline or a flag.
  bool active() const { return has_deadline_ || flag_ != nullptr; }
  /// The flag was raised.
  bool Interrupted() const { return flag_ != nullptr && flag_->load(std::memory_order_relaxed); }
  /// The deadline passed.
  bool TimedOut() const { return has_deadline_ && Clock::now() >= deadline_; }
  bool Reached() const { return Interrupted() || TimedOut(); }
  /// Seconds to the deadline (0 once passed), +infinity without one.
  double SecondsLeft() const {
    if (!has_deadline_) return std::numeric_limits<double>::infinity();
    const double left = std::chrono::duration<double>(deadline_ - Clock::now()).count();
    return left > 0.0 ? left : 0.0;
  }
  /// Why it was reached, for summaries: "interrupted", "time limit reached" or "".
  const char* Reason() const {
    return Interrupted() ? "interrupted" : TimedOut() ? "time limit --max_time_s reached" : "";
  }

 private:
  static constexpr double kNoDeadlineS = 365.0 * 24 * 3600;
  bool has_deadline_ = false;
  Clock::time_point deadline_{};
  const std::atomic<bool>* flag_ = nullptr;
};

}  // namespace evfs

#endif  // EVFS_CORE_STOP_CONDITION_H_
