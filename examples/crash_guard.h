// Running a command in a child process so that a crash inside a library becomes a user error.
//
// libhdf5 1.10 dereferences offsets read from the file without checking them, so some corrupt
// .h5 files crash it (README.md, Robustness) where no error can be caught. The CLI therefore
// runs every command that opens an HDF5 file in a forked child: the child's exit status is
// passed on, and a child killed by a crash signal becomes one line naming the file and exit
// status 2, as every other bad input. The job writes its output folder only after reading all
// it needs, under a temporary name that it renames at the end, so a crash leaves nothing behind.
#ifndef EVFS_EXAMPLES_CRASH_GUARD_H_
#define EVFS_EXAMPLES_CRASH_GUARD_H_

#include <functional>
#include <string>

namespace evfs {

/// Runs `body` in a forked child and returns its return value (the child's exit status). When
/// the child dies of SIGSEGV, SIGBUS, SIGFPE, SIGILL or SIGABRT, prints "`prefix`: `path`:
/// crashed (<signal>) reading it; libhdf5 does so on some corrupt HDF5 files" on stderr and
/// returns 2. Any other signal that ends the child (SIGINT, SIGTERM, SIGKILL) is
/// raised again in this process, so the caller dies as the child did. When fork fails, runs
/// `body` here. Call it before any thread is started.
int RunInChildProcess(const std::function<int()>& body, const std::string& prefix,
                      const std::string& path);

}  // namespace evfs

#endif  // EVFS_EXAMPLES_CRASH_GUARD_H_
