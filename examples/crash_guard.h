// Running a command in a worker child process, so that neither a crash nor a signal leaves a
// half-written output behind, and a crash inside libhdf5 becomes a user error.
//
// The parent forwards SIGINT, SIGTERM and SIGHUP to the worker, waits for it, then removes the
// paths the worker had registered and not finished (io/signal_cleanup.h: the staging folder of
// an OutputTarget). Only then does it report: a signal ends the parent the same way, after one
// line; a crash is one line and a non-zero status.
//
// libhdf5 1.10 dereferences offsets read from the file without checking them, so some corrupt
// .h5 files crash it (README.md, Robustness) where no error can be caught: when the command
// reads an HDF5 file, a crash is reported as that file's fault.
#ifndef EVFS_EXAMPLES_CRASH_GUARD_H_
#define EVFS_EXAMPLES_CRASH_GUARD_H_

#include <functional>
#include <string>

namespace evfs {

/// Runs `body` in a forked child and returns its return value (the child's exit status), after
/// removing what the child left registered for cleanup. When the child dies of SIGSEGV,
/// SIGBUS, SIGFPE, SIGILL or SIGABRT, prints "`prefix`: `path`: crashed (<signal>) reading it;
/// libhdf5 does so on some corrupt HDF5 files" and returns 2 when `path` (the HDF5 file read)
/// is not empty, else "`prefix`: internal error: crashed (<signal>)...; please report it" and
/// returns 3. Any other signal that ends the child (SIGINT, SIGTERM, SIGHUP, SIGKILL) is
/// reported in one line and raised again in this process, so the caller dies as the child did.
/// When fork fails, runs `body` here. Call it before any thread is started.
int RunInChildProcess(const std::function<int()>& body, const std::string& prefix,
                      const std::string& path);

}  // namespace evfs

#endif  // EVFS_EXAMPLES_CRASH_GUARD_H_
