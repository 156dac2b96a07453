#include "evfs/runtime/progress.h"

#include <cstdarg>
#include <system_error>
#include <utility>

namespace evfs {

ProgressReporter::ProgressReporter(ProgressOptions options) : options_(std::move(options)) {
  if (options_.interval_s <= 0.0) return;
  // Progress lines are a convenience: without a thread for them (no address space for its
  // stack, a thread limit) the command runs on silently.
  try {
    thread_ = std::thread([this] { Run(); });
  } catch (const std::system_error&) {
  }
}

ProgressReporter::~ProgressReporter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  stop_requested_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void ProgressReporter::StartStage(const std::string& stage) {
  std::lock_guard<std::mutex> lock(mutex_);
  stage_ = stage;
  iteration_ = -1;
}

bool ProgressReporter::Iteration(const SolverIteration& iteration) {
  std::lock_guard<std::mutex> lock(mutex_);
  stage_ = "solve";
  iteration_ = iteration.iteration;
  cost_ = iteration.cost;
  if (options_.every_iteration) {
    PrintLocked("iter %4d  cost %.6e  %.2f s\n", iteration.iteration, iteration.cost,
                iteration.elapsed_s);
  }
  return true;
}

void ProgressReporter::Run() {
  const auto interval = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(options_.interval_s));
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    // Wakes an interval after the last line, whoever printed it.
    if (stop_requested_.wait_until(lock, last_line_ + interval, [this] { return stopping_; })) {
      break;
    }
    if (Clock::now() < last_line_ + interval) continue;
    const double elapsed_s = std::chrono::duration<double>(Clock::now() - start_).count();
    if (stage_.empty()) {
      PrintLocked("%s: %.1f s elapsed\n", options_.prefix.c_str(), elapsed_s);
    } else if (iteration_ >= 0) {
      PrintLocked("%s: %s, iteration %d (cost %.6e), %.1f s elapsed\n", options_.prefix.c_str(),
                  stage_.c_str(), iteration_, cost_, elapsed_s);
    } else {
      PrintLocked("%s: %s, %.1f s elapsed\n", options_.prefix.c_str(), stage_.c_str(), elapsed_s);
    }
  }
}

void ProgressReporter::PrintLocked(const char* format, ...) {
  va_list arguments;
  va_start(arguments, format);
  std::vfprintf(options_.out, format, arguments);
  va_end(arguments);
  std::fflush(options_.out);
  last_line_ = Clock::now();
}

}  // namespace evfs
