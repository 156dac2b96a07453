// Running one benchmark cell in a process of its own, so that its peak memory (the child's
// ru_maxrss) and CPU time are its own, and a cell that runs too long or takes too much memory
// fails alone. The process isolation is the CLI's (ForkAndWait, runtime/crash_guard.h); the
// cell adds a time limit (SIGALRM), an address-space limit (RLIMIT_AS) and a result file.
#ifndef EVFS_BENCHMARKS_CELL_RUNNER_H_
#define EVFS_BENCHMARKS_CELL_RUNNER_H_

#include <string>
#include <vector>

namespace evfs {

/// The limits of one cell's process.
struct CellLimits {
  int timeout_s = 600;  // SIGALRM ends the cell after this many seconds
  int memory_mb = 0;    // its address space (RLIMIT_AS), MB; 0: unlimited
};

/// What the parent learns of one cell's process.
struct CellRun {
  bool has_result = false;      // the cell wrote its result file
  std::string result;           // the text of that file
  std::string failure;          // without a result: how the process ended
  double wall_s = 0.0;          // the whole process, start to end
  double cpu_s = 0.0;           // its user + system CPU time
  double peak_memory_mb = 0.0;  // its maximum resident set size
};

/// Executes `args` (args[0]: the executable) in a child process under `limits` and returns
/// what the child wrote into `result_path` (removed before and after), its wall and CPU time
/// and peak memory. Without a result, `failure` says why: "timed out after N s", "killed by
/// signal N (memory limit M MB?)", "exited with status N and no result". SIGINT, SIGTERM or
/// SIGHUP sent to this process stop the cell and then this process, by the same signal.
CellRun RunCellProcess(const std::vector<std::string>& args, const std::string& result_path,
                       const CellLimits& limits);

}  // namespace evfs

#endif  // EVFS_BENCHMARKS_CELL_RUNNER_H_
