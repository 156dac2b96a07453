// Removing unfinished output when the process writing it dies: by SIGINT, SIGTERM or SIGHUP, by
// a crash, or by the kernel's out-of-memory killer.
//
// Nothing can clean up reliably inside the process that a signal is ending: a signal handler
// may not remove a folder tree, and while one thread removes it another may still be writing
// into it. So the CLI runs each command in a worker child (runtime/crash_guard.h) and cleans up
// from the parent, once the worker is gone and nothing writes any more: the worker reports
// through a pipe each path it starts writing and each it has finished with (ScopedCleanupPath,
// used by OutputTarget); the parent removes the paths still open when the worker ended.
#ifndef EVFS_RUNTIME_SIGNAL_CLEANUP_H_
#define EVFS_RUNTIME_SIGNAL_CLEANUP_H_

#include <string>
#include <vector>

namespace evfs {

/// The pipe between a worker and its parent. Make it before fork, then call AttachWorker() in
/// the child and AttachSupervisor() in the parent.
class CleanupChannel {
 public:
  /// Opens the pipe; valid() is false when that failed (then nothing is reported).
  CleanupChannel();
  ~CleanupChannel();
  CleanupChannel(const CleanupChannel&) = delete;
  CleanupChannel& operator=(const CleanupChannel&) = delete;

  bool valid() const { return read_fd_ >= 0 || write_fd_ >= 0; }

  /// In the worker: from now on ScopedCleanupPath reports to the parent.
  void AttachWorker();
  /// In the parent: keeps only the reading end, so that the pipe ends when the worker does.
  void AttachSupervisor();
  /// In the parent: collects the worker's reports until its end of the pipe closes, which
  /// happens when the worker and all its threads are gone. Reading as it goes, the parent
  /// never lets the pipe fill up. Retries when a signal interrupts it.
  void ReadUntilWorkerEnds();
  /// In the parent, once the worker ended (it reads the rest first): removes every path the
  /// worker registered and did not release, the last registered first. Returns those paths.
  std::vector<std::string> RemoveLeftovers();

 private:
  int read_fd_ = -1;
  int write_fd_ = -1;
  std::string reports_;
};

/// Registers `path` (a file or a folder tree) for removal should the process die, for its
/// lifetime. In a process without a CleanupChannel it does nothing: the owner removes the path
/// on every failure it sees (OutputTarget's destructor).
class ScopedCleanupPath {
 public:
  explicit ScopedCleanupPath(std::string path);
  ~ScopedCleanupPath();
  ScopedCleanupPath(const ScopedCleanupPath&) = delete;
  ScopedCleanupPath& operator=(const ScopedCleanupPath&) = delete;

  /// Unregisters the path early (once it was removed, or renamed into place). Idempotent.
  void Release();

 private:
  std::string path_;
  bool registered_ = false;
};

}  // namespace evfs

#endif  // EVFS_RUNTIME_SIGNAL_CLEANUP_H_
