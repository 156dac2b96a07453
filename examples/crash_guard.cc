#include "examples/crash_guard.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <vector>

#include "io/signal_cleanup.h"

namespace evfs {

namespace {

bool IsCrashSignal(int signal_number) {
  return signal_number == SIGSEGV || signal_number == SIGBUS || signal_number == SIGFPE ||
         signal_number == SIGILL || signal_number == SIGABRT;
}

// Signals that stop a job: forwarded to the worker, which dies of them; the parent then cleans up
// and dies of the same signal.
constexpr int kTerminationSignals[] = {SIGINT, SIGTERM, SIGHUP};

volatile sig_atomic_t worker_pid = 0;

void ForwardToWorker(int signal_number) {
  const pid_t pid = worker_pid;
  if (pid > 0) kill(pid, signal_number);
}

}  // namespace

int RunInChildProcess(const std::function<int()>& body, const std::string& prefix,
                      const std::string& path) {
  // Buffered output would otherwise be written twice, once by each process.
  std::fflush(nullptr);
  CleanupChannel channel;
  // Blocked across fork, so that a signal arriving before the parent forwards them is held
  // until it does (and the child starts with the signals' default actions).
  sigset_t termination, previous_mask;
  sigemptyset(&termination);
  for (const int signal_number : kTerminationSignals) sigaddset(&termination, signal_number);
  sigprocmask(SIG_BLOCK, &termination, &previous_mask);
  const pid_t child = fork();
  if (child < 0) {
    sigprocmask(SIG_SETMASK, &previous_mask, nullptr);
    return body();
  }
  if (child == 0) {
    channel.AttachWorker();
    sigprocmask(SIG_SETMASK, &previous_mask, nullptr);
    const int status = body();
    std::fflush(nullptr);
    _exit(status);
  }
  channel.AttachSupervisor();
  worker_pid = child;
  struct sigaction forward = {};
  forward.sa_handler = ForwardToWorker;
  sigemptyset(&forward.sa_mask);
  struct sigaction previous_actions[std::size(kTerminationSignals)];
  for (size_t i = 0; i < std::size(kTerminationSignals); ++i) {
    sigaction(kTerminationSignals[i], &forward, &previous_actions[i]);
  }
  sigprocmask(SIG_SETMASK, &previous_mask, nullptr);

  channel.ReadUntilWorkerEnds();
  int status = 0;
  while (waitpid(child, &status, 0) < 0) {
    if (errno != EINTR) {
      std::fprintf(stderr, "%s: lost the worker process: %s\n", prefix.c_str(),
                   std::strerror(errno));
      return 1;
    }
  }
  for (size_t i = 0; i < std::size(kTerminationSignals); ++i) {
    sigaction(kTerminationSignals[i], &previous_actions[i], nullptr);
  }
  worker_pid = 0;
  // Whatever ended the worker, nothing writes any more: what it left unfinished goes now.
  const std::vector<std::string> removed = channel.RemoveLeftovers();
  const char* removed_note = removed.empty() ? "" : "; the unfinished output was removed";

  if (WIFEXITED(status)) return WEXITSTATUS(status);
  const int signal_number = WTERMSIG(status);
  if (IsCrashSignal(signal_number)) {
    if (path.empty()) {
      std::fprintf(stderr, "%s: internal error: crashed (%s)%s; please report it\n",
                   prefix.c_str(), strsignal(signal_number), removed_note);
      return 3;
    }
    std::fprintf(stderr,
                 "%s: %s: crashed (%s) reading it; libhdf5 does so on some corrupt HDF5 files\n",
                 prefix.c_str(), path.c_str(), strsignal(signal_number));
    return 2;
  }
  std::fprintf(stderr, "%s: stopped by %s%s\n", prefix.c_str(), strsignal(signal_number),
               removed_note);
  std::fflush(stderr);
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
  return 128 + signal_number;
}

}  // namespace evfs
