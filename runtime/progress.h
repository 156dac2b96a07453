// Progress of a long command on stderr, on a terminal or not.
//
// On a terminal (or with --progress) every solver iteration is a line, as it always was. And
// wherever stderr goes (a log file, a batch queue, a pipe), a command that runs longer than an
// interval prints one line per interval saying what it does and for how long it has run:
//
//   evfs reconstruct: solve, iteration 42 (cost 1.234567e+03), 15.0 s elapsed
//   evfs convert: 10.0 s elapsed              (a command that names no stage)
//
// so that a job run from a script shows it is alive and where. A command that ends within its
// first interval prints nothing: quick commands and their error lines stay as they are.
#ifndef EVFS_RUNTIME_PROGRESS_H_
#define EVFS_RUNTIME_PROGRESS_H_

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>

#include "evfs/solver/iteration_callback.h"

namespace evfs {

struct ProgressOptions {
  std::string prefix;            // starts every interval line ("evfs reconstruct")
  double interval_s = 5.0;       // between interval lines; <= 0: none
  bool every_iteration = false;  // a line per solver iteration too (a terminal, or --progress)
  std::FILE* out = stderr;       // where the lines go
};

/// Reports a command's progress (see above). Stages and iterations may be reported from any
/// thread. Start it in the process that does the work, after any fork: it runs a thread of its
/// own until destroyed.
class ProgressReporter {
 public:
  explicit ProgressReporter(ProgressOptions options);
  ~ProgressReporter();
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;

  /// The command reached `stage` ("read", "bin", "build", "solve", "write"): the name the next
  /// interval lines give.
  void StartStage(const std::string& stage);

  /// An iterative solver's iteration: the stage becomes "solve"; printed at once when
  /// every_iteration. Always returns true (never stops the solve).
  bool Iteration(const SolverIteration& iteration);

  /// Iteration() as a solver callback.
  IterationCallback callback() {
    return [this](const SolverIteration& iteration) { return Iteration(iteration); };
  }

 private:
  using Clock = std::chrono::steady_clock;

  // The interval thread: a line whenever an interval passed without one.
  void Run();
  // Writes one line and notes when; requires mutex_.
  void PrintLocked(const char* format, ...) __attribute__((format(printf, 2, 3)));

  const ProgressOptions options_;
  const Clock::time_point start_ = Clock::now();
  std::mutex mutex_;
  std::condition_variable stop_requested_;
  bool stopping_ = false;
  std::string stage_;
  int iteration_ = -1;  // the last iteration seen in this stage; -1: none
  double cost_ = 0.0;
  Clock::time_point last_line_ = start_;
  std::thread thread_;
};

}  // namespace evfs

#endif  // EVFS_RUNTIME_PROGRESS_H_
