#include "examples/crash_guard.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>

namespace evfs {

namespace {

bool IsCrashSignal(int signal_number) {
  return signal_number == SIGSEGV || signal_number == SIGBUS || signal_number == SIGFPE ||
         signal_number == SIGILL || signal_number == SIGABRT;
}

}  // namespace

int RunInChildProcess(const std::function<int()>& body, const std::string& prefix,
                      const std::string& path) {
  // Buffered output would otherwise be written twice, once by each process.
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child < 0) return body();
  if (child == 0) {
    const int status = body();
    std::fflush(nullptr);
    _exit(status);
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0) {
    if (errno != EINTR) {
      std::fprintf(stderr, "%s: lost the worker process: %s\n", prefix.c_str(),
                   std::strerror(errno));
      return 1;
    }
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  const int signal_number = WTERMSIG(status);
  if (IsCrashSignal(signal_number)) {
    std::fprintf(stderr,
                 "%s: %s: crashed (%s) reading it; libhdf5 does so on some corrupt HDF5 files\n",
                 prefix.c_str(), path.c_str(), strsignal(signal_number));
    return 2;
  }
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
  return 128 + signal_number;
}

}  // namespace evfs
