// Which third-party library, if any, a thread is running on a file the user gave.
//
// Some libraries that read input files dereference what they read without checking it, so a
// corrupt file crashes them where no error can be caught (libhdf5 1.10: docs/robustness.md). A
// reader marks each stretch of such a library's calls with a ScopedInputLibraryRead; the process
// runtime (runtime/crash_guard.h), which owns the crash handling, asks InputLibraryOfThisThread()
// in its crash handler and reports a crash inside a marked stretch as the input file's fault. Every
// other crash stays an internal error. Neither side knows the other: a format reader names its
// library, and the runtime reports whichever it finds.
#ifndef EVFS_CORE_INPUT_LIBRARY_H_
#define EVFS_CORE_INPUT_LIBRARY_H_

#include <sys/types.h>

namespace evfs {

/// A library that reads users' files. Instances are static: the runtime keeps their address.
struct InputLibrary {
  const char* name;   // as the user knows it, e.g. "libhdf5"
  const char* fault;  // the files it crashes on, e.g. "some corrupt HDF5 files"
};

/// Marks, for its lifetime, the calling thread as running `library` on a file the user gave.
/// One thread is marked at a time (the last to enter); the mark before is restored on
/// destruction, so marks nest.
class ScopedInputLibraryRead {
 public:
  explicit ScopedInputLibraryRead(const InputLibrary& library);
  ~ScopedInputLibraryRead();
  ScopedInputLibraryRead(const ScopedInputLibraryRead&) = delete;
  ScopedInputLibraryRead& operator=(const ScopedInputLibraryRead&) = delete;

 private:
  pid_t previous_thread_;
  const InputLibrary* previous_library_;
};

/// The library the calling thread is marked as running, or null. Async-signal-safe: meant for a
/// crash signal handler, which runs on the thread that crashed.
const InputLibrary* InputLibraryOfThisThread();

/// The library a ScopedInputLibraryRead last marked in this process (it may have returned since),
/// or null when none ever did. Async-signal-safe.
const InputLibrary* LastInputLibrary();

}  // namespace evfs

#endif  // EVFS_CORE_INPUT_LIBRARY_H_
