#include "evfs/benchmarks/cell_runner.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "evfs/runtime/crash_guard.h"

namespace evfs {

namespace {

double Seconds(const timeval& time) { return time.tv_sec + 1e-6 * time.tv_usec; }

std::string DescribeEnd(int status, const CellLimits& limits) {
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) {
    return "timed out after " + std::to_string(limits.timeout_s) + " s";
  }
  if (WIFSIGNALED(status)) {
    return "killed by signal " + std::to_string(WTERMSIG(status)) +
           (limits.memory_mb > 0 ? " (memory limit " + std::to_string(limits.memory_mb) + " MB?)"
                                 : "");
  }
  return "exited with status " + std::to_string(WEXITSTATUS(status)) + " and no result";
}

}  // namespace

CellRun RunCellProcess(const std::vector<std::string>& args, const std::string& result_path,
                       const CellLimits& limits) {
  std::filesystem::remove(result_path);
  std::vector<std::string> arg_copies = args;
  std::vector<char*> argv;
  for (std::string& arg : arg_copies) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const ChildProcessEnd end = ForkAndWait(
      [&] {
        // A pending alarm and the limits survive execv: SIGALRM ends a cell that runs too long.
        alarm(static_cast<unsigned>(limits.timeout_s));
        if (limits.memory_mb > 0) {
          const rlim_t bytes = static_cast<rlim_t>(limits.memory_mb) << 20;
          const struct rlimit limit = {bytes, bytes};
          setrlimit(RLIMIT_AS, &limit);
        }
        execv(argv[0], argv.data());
        return 127;
      },
      nullptr, nullptr);
  const int fork_errno = errno;
  CellRun run;
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (end.forwarded_signal != 0) {
    // The run was stopped, not the cell: stop as the cell did.
    std::signal(end.forwarded_signal, SIG_DFL);
    std::raise(end.forwarded_signal);
  }
  if (!end.forked || end.wait_errno != 0) {
    run.failure = std::string(end.forked ? "lost the cell's process: " : "could not fork: ") +
                  std::strerror(end.forked ? end.wait_errno : fork_errno);
    return run;
  }
  std::ifstream in(result_path);
  if (in) {
    std::ostringstream text;
    text << in.rdbuf();
    run.has_result = true;
    run.result = text.str();
  } else {
    run.failure = DescribeEnd(end.status, limits);
  }
  std::filesystem::remove(result_path);
  run.cpu_s = Seconds(end.usage.ru_utime) + Seconds(end.usage.ru_stime);
  run.peak_memory_mb = end.usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
  return run;
}

}  // namespace evfs
