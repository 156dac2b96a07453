#include "evfs/runtime/crash_guard.h"

#include <glog/logging.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/core/input_library.h"
#include "evfs/runtime/signal_cleanup.h"

namespace evfs {

namespace {

constexpr int kCrashSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};

bool IsCrashSignal(int signal_number) {
  return std::find(std::begin(kCrashSignals), std::end(kCrashSignals), signal_number) !=
         std::end(kCrashSignals);
}

// Where the worker crashed, written by its crash handler into memory it shares with the parent.
// The libraries are static objects of the program, at the same addresses in the parent and the
// worker it forked.
struct CrashPlace {
  volatile sig_atomic_t recorded = 0;             // 0: no handler ran (a signal sent from outside)
  const InputLibrary* volatile inside = nullptr;  // the input library the crash happened in
  const InputLibrary* volatile last = nullptr;    // the input library the worker last ran
};

// One page shared by the parent and the worker it forks.
class SharedCrashPlace {
 public:
  SharedCrashPlace() {
    void* page = mmap(nullptr, sizeof(CrashPlace), PROT_READ | PROT_WRITE,
                      MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (page != MAP_FAILED) place_ = new (page) CrashPlace();
  }
  ~SharedCrashPlace() {
    if (place_ != nullptr) munmap(place_, sizeof(CrashPlace));
  }
  SharedCrashPlace(const SharedCrashPlace&) = delete;
  SharedCrashPlace& operator=(const SharedCrashPlace&) = delete;

  CrashPlace* get() const { return place_; }
  /// What the worker's handler recorded; all null when it recorded nothing.
  CrashPlace value() const {
    CrashPlace copy;
    if (place_ != nullptr && place_->recorded) {
      copy.recorded = 1;
      copy.inside = place_->inside;
      copy.last = place_->last;
    }
    return copy;
  }

 private:
  CrashPlace* place_ = nullptr;
};

CrashPlace* crash_place = nullptr;  // in the worker: the shared page

// Async-signal-safe. A crash signal runs its handler on the thread that crashed, which is what
// InputLibraryOfThisThread() asks about.
void RecordCrashPlace(int signal_number) {
  if (crash_place != nullptr) {
    crash_place->inside = InputLibraryOfThisThread();
    crash_place->last = LastInputLibrary();
    crash_place->recorded = 1;
  }
  // SA_RESETHAND put the default action back and SA_NODEFER lets it act at once: the worker
  // dies of the signal it received.
  raise(signal_number);
}

// In the worker. The handler runs on a stack of its own: a library recursing on a corrupt file
// may have used up the thread's.
void InstallCrashRecorder(CrashPlace* place) {
  if (place == nullptr) return;
  crash_place = place;
  static char alternate_stack[1 << 16];
  stack_t stack = {};
  stack.ss_sp = alternate_stack;
  stack.ss_size = sizeof(alternate_stack);
  sigaltstack(&stack, nullptr);
  struct sigaction action = {};
  action.sa_handler = RecordCrashPlace;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND | SA_NODEFER | SA_ONSTACK;
  for (const int signal_number : kCrashSignals) sigaction(signal_number, &action, nullptr);
}

// glog's output, through one sink: a FATAL message (a failed CHECK) becomes the internal-error
// line and ends the process; the others are written as glog writes them to stderr.
class InternalErrorSink : public google::LogSink {
 public:
  explicit InternalErrorSink(std::string prefix) : prefix_(std::move(prefix)) {}

  void send(google::LogSeverity severity, const char* /*full_filename*/, const char* base_filename,
            int line, const google::LogMessageTime& time, const char* message,
            size_t message_length) override {
    if (severity == google::GLOG_FATAL) {
      std::string text(message, message_length);
      std::replace(text.begin(), text.end(), '\n', ' ');
      std::fprintf(stderr, "%s: internal error: %s:%d: %s; please report it\n", prefix_.c_str(),
                   base_filename, line, text.c_str());
      std::fflush(stderr);
      _exit(kExitInternalError);
    }
    const std::string text = ToString(severity, base_filename, line, time, message, message_length);
    std::fprintf(stderr, "%s\n", text.c_str());
  }

 private:
  const std::string prefix_;
};

// Signals that stop a job: forwarded to the worker, which dies of them; the parent then cleans up
// and dies of the same signal.
constexpr int kTerminationSignals[] = {SIGINT, SIGTERM, SIGHUP};

volatile sig_atomic_t worker_pid = 0;
volatile sig_atomic_t forwarded_signal = 0;

void ForwardToWorker(int signal_number) {
  const pid_t pid = worker_pid;
  if (pid > 0) kill(pid, signal_number);
  forwarded_signal = signal_number;
}

}  // namespace

ChildProcessEnd ForkAndWait(const std::function<int()>& body, const std::function<void()>& in_child,
                            const std::function<void()>& in_parent) {
  std::fflush(nullptr);
  ChildProcessEnd end;
  // Blocked across fork, so that a signal arriving before the parent forwards them is held
  // until it does (and the child starts with the signals' default actions).
  sigset_t termination, previous_mask;
  sigemptyset(&termination);
  for (const int signal_number : kTerminationSignals) sigaddset(&termination, signal_number);
  sigprocmask(SIG_BLOCK, &termination, &previous_mask);
  const pid_t parent = getpid();
  const pid_t child = fork();
  if (child < 0) {
    const int fork_errno = errno;
    sigprocmask(SIG_SETMASK, &previous_mask, nullptr);
    errno = fork_errno;
    return end;
  }
  end.forked = true;
  if (child == 0) {
    // A worker whose parent was killed (kill -9) stops too, instead of writing on unseen.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(128 + SIGKILL);
    if (in_child) in_child();
    sigprocmask(SIG_SETMASK, &previous_mask, nullptr);
    const int status = body();
    std::fflush(nullptr);
    _exit(status);
  }
  worker_pid = child;
  forwarded_signal = 0;
  struct sigaction forward = {};
  forward.sa_handler = ForwardToWorker;
  sigemptyset(&forward.sa_mask);
  struct sigaction previous_actions[std::size(kTerminationSignals)];
  for (size_t i = 0; i < std::size(kTerminationSignals); ++i) {
    sigaction(kTerminationSignals[i], &forward, &previous_actions[i]);
  }
  sigprocmask(SIG_SETMASK, &previous_mask, nullptr);

  if (in_parent) in_parent();
  while (wait4(child, &end.status, 0, &end.usage) < 0) {
    if (errno != EINTR) {
      end.wait_errno = errno;
      break;
    }
  }
  for (size_t i = 0; i < std::size(kTerminationSignals); ++i) {
    sigaction(kTerminationSignals[i], &previous_actions[i], nullptr);
  }
  worker_pid = 0;
  end.forwarded_signal = forwarded_signal;
  return end;
}

int RunInChildProcess(const std::function<int()>& body, const std::string& prefix,
                      const std::string& path) {
  CleanupChannel channel;
  const SharedCrashPlace place;
  const ChildProcessEnd end = ForkAndWait(
      body,
      [&] {
        channel.AttachWorker();
        InstallCrashRecorder(place.get());
      },
      [&] {
        channel.AttachSupervisor();
        channel.ReadUntilWorkerEnds();
      });
  if (!end.forked) return body();
  if (end.wait_errno != 0) {
    std::fprintf(stderr, "%s: lost the worker process: %s\n", prefix.c_str(),
                 std::strerror(end.wait_errno));
    return 1;
  }
  const int status = end.status;
  // Whatever ended the worker, nothing writes any more: what it left unfinished goes now.
  const std::vector<std::string> removed = channel.RemoveLeftovers();
  const char* removed_note = removed.empty() ? "" : "; the unfinished output was removed";

  if (WIFEXITED(status)) return WEXITSTATUS(status);
  const int signal_number = WTERMSIG(status);
  if (IsCrashSignal(signal_number)) {
    // Only an input library's own crash, while it read the user's file, is that file's fault.
    const CrashPlace crash = place.value();
    if (!path.empty() && crash.inside != nullptr) {
      std::fprintf(stderr, "%s: %s: crashed (%s) reading it; %s does so on %s\n", prefix.c_str(),
                   path.c_str(), strsignal(signal_number), crash.inside->name, crash.inside->fault);
      return kExitUserError;
    }
    const std::string outside =
        !path.empty() && crash.last != nullptr ? std::string(" outside ") + crash.last->name : "";
    std::fprintf(stderr, "%s: internal error: crashed (%s)%s%s; please report it\n", prefix.c_str(),
                 strsignal(signal_number), outside.c_str(), removed_note);
    return kExitInternalError;
  }
  std::fprintf(stderr, "%s: stopped by %s%s\n", prefix.c_str(), strsignal(signal_number),
               removed_note);
  std::fflush(stderr);
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
  return 128 + signal_number;
}

void InstallInternalErrorReporting(const std::string& prefix) {
  static InternalErrorSink* sink = nullptr;
  if (sink != nullptr) google::RemoveLogSink(sink);
  delete sink;
  sink = new InternalErrorSink(prefix);
  // glog itself writes nothing, neither to stderr nor to log files: the sink does.
  FLAGS_logtostderr = false;
  FLAGS_alsologtostderr = false;
  FLAGS_stderrthreshold = google::NUM_SEVERITIES;
  for (int severity = 0; severity < google::NUM_SEVERITIES; ++severity) {
    google::SetLogDestination(severity, "");
  }
  google::AddLogSink(sink);
}

}  // namespace evfs
