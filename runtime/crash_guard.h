// Running a command in a worker child process, so that neither a crash nor a signal leaves a
// half-written output behind, and a crash inside a library reading the user's file becomes a
// user error.
//
// The parent forwards SIGINT, SIGTERM and SIGHUP to the worker, waits for it, then removes the
// paths the worker had registered and not finished (runtime/signal_cleanup.h: the staging folder of
// an OutputTarget). Only then does it report: a signal ends the parent the same way, after one
// line; a crash is one line and a non-zero status.
//
// Some libraries dereference what they read from a file without checking it, so a corrupt file
// crashes them where no error can be caught (libhdf5 1.10 on some .h5 files: docs/robustness.md).
// A crash on a thread inside such a library reading the user's file (core/input_library.h,
// ScopedInputLibraryRead) is reported as that file's fault. Every other crash, and every failed
// CHECK, is a bug of evfs': an internal error.
#ifndef EVFS_RUNTIME_CRASH_GUARD_H_
#define EVFS_RUNTIME_CRASH_GUARD_H_

#include <sys/resource.h>

#include <functional>
#include <string>

namespace evfs {

/// How a child of ForkAndWait ended.
struct ChildProcessEnd {
  bool forked = false;       // false: fork failed (errno says why) and nothing ran
  int wait_errno = 0;        // not 0: waiting for the child failed, and the fields below are unset
  int status = 0;            // as waitpid gives it (WIFEXITED, WTERMSIG, ...)
  int forwarded_signal = 0;  // the last signal this process received and forwarded; 0: none
  struct rusage usage = {};  // the child's resource use (wait4): ru_maxrss, ru_utime, ru_stime
};

/// The process isolation that RunInChildProcess and the benchmarks' cell runner share. Flushes
/// stdio (buffered output would be written twice), forks a child that dies with this process
/// (PR_SET_PDEATHSIG), runs `in_child` in it, then `body` with this process's signal mask,
/// and exits with `body`'s return value (`body` may also exec). Meanwhile this process forwards
/// SIGINT, SIGTERM and SIGHUP to the child (blocked across fork, so that none is lost), runs
/// `in_parent`, then waits for the child. Empty hooks are skipped. Call it before any thread
/// is started.
ChildProcessEnd ForkAndWait(const std::function<int()>& body, const std::function<void()>& in_child,
                            const std::function<void()>& in_parent);

/// Runs `body` in a forked child and returns its return value (the child's exit status), after
/// removing what the child left registered for cleanup. When the child dies of SIGSEGV,
/// SIGBUS, SIGFPE, SIGILL or SIGABRT inside an input library (InputLibraryOfThisThread() on the
/// crashing thread) and `path` (the file such a library reads) is not empty, prints "`prefix`:
/// `path`: crashed (<signal>) reading it; <library> does so on <its fault>", e.g. "libhdf5 does
/// so on some corrupt HDF5 files", and returns 2 (kExitUserError); anywhere else "`prefix`:
/// internal error: crashed (<signal>)[ outside <the library last run>]...; please report it"
/// and returns 3 (kExitInternalError). Any other signal that ends the child (SIGINT, SIGTERM,
/// SIGHUP, SIGKILL) is reported in one line and raised again in this process, so the caller
/// dies as the child did. When fork fails, runs `body` here. Call it before any thread is started.
int RunInChildProcess(const std::function<int()>& body, const std::string& prefix,
                      const std::string& path);

/// Makes a failed CHECK (or LOG(FATAL)) anywhere in the process, in evfs or in a library, one
/// line on stderr, "`prefix`: internal error: file.cc:123: Check failed: ...; please report
/// it", and exit status 3 (kExitInternalError), instead of glog's message, stack trace and
/// abort. Other log messages still reach stderr as glog formats them, and no log file is
/// written. Call it after google::InitGoogleLogging, before RunInChildProcess: in a worker, the
/// parent then removes the unfinished output as for any other exit.
void InstallInternalErrorReporting(const std::string& prefix);

}  // namespace evfs

#endif  // EVFS_RUNTIME_CRASH_GUARD_H_
