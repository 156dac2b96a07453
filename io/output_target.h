// Where a command writes: checked before any work, written under a temporary name, moved into
// place at the end, and never anything evfs did not create itself.
//
//   OutputTarget out(options);            // refuses a dangerous --out in milliseconds
//   WriteEverything(out.staging());       // a fresh folder (or file name) beside --out
//   out.Commit();                          // marker, then the earlier output is replaced
//
// An output folder is marked as evfs's by OUT/.evfs-output, written last, which names the
// command ("evfs reconstruct") and lists every path evfs wrote there. An existing OUT is
// replaced only when it is an empty folder, or an earlier output of the same command that holds
// nothing the marker does not list, and the user asked to overwrite it: what the user added to
// an output is never deleted. A staging folder is marked at once as unfinished, so that one
// left by a killed process (SIGKILL: nothing can clean up) is known as evfs's; a later run on
// the same OUT removes such leftovers, and says so. A file output (an
// .h5 file) is recognised by a predicate the caller gives (the HDF5 writer's own attribute).
// Until Commit() the staging path is removed on every failure (the destructor) and when the
// process dies (SIGINT, SIGTERM, SIGHUP, a crash: runtime/signal_cleanup.h); the earlier output
// stays untouched until the new one is complete, and then one atomic rename swaps them.
#ifndef EVFS_IO_OUTPUT_TARGET_H_
#define EVFS_IO_OUTPUT_TARGET_H_

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "evfs/runtime/signal_cleanup.h"

namespace evfs {

class ScopedCleanupPath;

/// Name of the marker file in every output folder evfs writes.
extern const char kOutputMarkerFile[];

/// A folder an output must never be, nor contain.
struct ProtectedFolder {
  std::string path;
  std::string what;  // "the current folder": how a refusal names it
};

/// The file-system root, the current folder and the home folder (from $HOME and the password
/// database).
std::vector<ProtectedFolder> DefaultProtectedFolders();

struct OutputOptions {
  enum class Kind {
    kFolder,  // OUT is a folder the command fills
    kFile,    // OUT is one file (convert to .h5)
  };

  std::string path;     // --out as given
  std::string command;  // the command writing it ("reconstruct"): the marker's content
  Kind kind = Kind::kFolder;
  bool overwrite = false;           // replace an earlier output of the same command
  std::vector<std::string> inputs;  // OUT may neither be, lie inside, nor contain any of them
  std::vector<ProtectedFolder> protected_folders = DefaultProtectedFolders();
  /// kFile: whether an existing file at OUT is an earlier output of this command.
  std::function<bool(const std::string& path)> is_own_file;
  /// Where notes about leftovers go (one line each, no newline); empty: stderr, after "evfs: ".
  std::function<void(const std::string& message)> warn;
};

/// An exclusive lock on one --out path, so that two evfs runs never write the same output (nor
/// the work folder beside it) at once. It is flock(2) on the file .NAME.evfs-lock beside the
/// output, which holds the holder's process id: the kernel releases it when the process ends in
/// any way (SIGKILL included), so a lock file left by a killed run never blocks; the holder
/// removes the file when it lets go, and a worker process registers it for cleanup, so that its
/// parent removes it when the worker dies (runtime/signal_cleanup.h). The lock file lies beside
/// OUT, never inside it, so it is no part of an output.
class OutputLock {
 public:
  /// Takes the lock on `out_path` without waiting: throws InvalidArgumentError, naming the output
  /// and the holder's process id, when another process holds it, and InputError(kUnwritable)
  /// when the lock file cannot be created. A file of the lock's name that evfs did not write
  /// (not empty and not a process id) is left alone and refused with InvalidArgumentError. The
  /// folder holding `out_path` must exist.
  explicit OutputLock(const std::string& out_path);
  /// Removes the lock file and releases the lock.
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  /// The lock file's path.
  const std::string& path() const { return path_; }

  /// The lock file of `out_path`: .NAME.evfs-lock in the same folder.
  static std::string LockPath(const std::string& out_path);

 private:
  /// The longest lock file evfs writes: a process id and a newline.
  static constexpr int kMaxLockFileBytes = 24;
  /// Throws InvalidArgumentError (closing fd_) unless the locked file is evfs' own.
  void RefuseForeignLockFile(const std::string& out_path);

  std::string path_;
  int fd_ = -1;
  std::unique_ptr<ScopedCleanupPath> cleanup_;
};

class OutputTarget {
 public:
  /// Checks `options.path`, takes its OutputLock (a second run on the same --out is refused
  /// while the first runs) and creates the staging folder (kFolder) or an empty staging file
  /// (kFile) beside it, creating missing parent folders. Throws InvalidArgumentError for a path
  /// evfs must not write (naming the reason) and InputError(kUnwritable) when it cannot.
  explicit OutputTarget(OutputOptions options);
  /// Removes the staging path and the parent folders it created, unless committed.
  ~OutputTarget();
  OutputTarget(const OutputTarget&) = delete;
  OutputTarget& operator=(const OutputTarget&) = delete;

  /// The final path, absolute and normalised ("out/" and "out" are the same).
  const std::string& path() const { return path_; }
  /// Where to write: a new empty folder, or a file name in the same folder as path().
  const std::string& staging() const { return staging_; }

  /// Marks the staging folder as this command's output and moves it to path(). An earlier
  /// output is swapped out in one atomic rename (RENAME_EXCHANGE; where the file system lacks
  /// it, moved aside first) and then removed. Throws InputError(kUnwritable) when the move fails
  /// (the earlier output is then still in place) and InvalidArgumentError when something that
  /// evfs did not write appeared at path() meanwhile.
  void Commit();

 private:
  // Throws unless what is at path_ now may be replaced.
  void CheckExisting() const;
  // Removes the staging and aside paths of path_ that a dead evfs process left, when evfs shows
  // them to be its own, and says so through Warn.
  void RemoveLeftovers() const;
  // Removes an earlier output once replaced; warns when it cannot.
  void RemoveReplaced(const std::filesystem::path& replaced) const;
  // Removes the parent folders this target created, deepest first, each only while empty.
  void RemoveCreatedParents() const;
  void Warn(const std::string& message) const;

  OutputOptions options_;
  std::string path_;
  std::string staging_;
  std::vector<std::string> created_parents_;  // deepest last
  std::unique_ptr<ScopedCleanupPath> cleanup_;
  std::unique_ptr<OutputLock> lock_;  // held from the checks until this object ends
  bool committed_ = false;
};

}  // namespace evfs

#endif  // EVFS_IO_OUTPUT_TARGET_H_
