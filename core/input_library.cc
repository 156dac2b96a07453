#include "evfs/core/input_library.h"

#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>

namespace evfs {
namespace {

// The marked thread (its kernel thread id, 0 when none) and its library: read in a crash signal
// handler, hence lock-free atomics.
std::atomic<pid_t> marked_thread{0};
std::atomic<const InputLibrary*> marked_library{nullptr};
std::atomic<const InputLibrary*> last_library{nullptr};
static_assert(std::atomic<pid_t>::is_always_lock_free, "read in a signal handler");
static_assert(std::atomic<const InputLibrary*>::is_always_lock_free, "read in a signal handler");

pid_t ThreadId() { return static_cast<pid_t>(syscall(SYS_gettid)); }

}  // namespace

ScopedInputLibraryRead::ScopedInputLibraryRead(const InputLibrary& library)
    : previous_thread_(marked_thread.load()), previous_library_(marked_library.load()) {
  last_library.store(&library);
  // The library first: a handler that sees this thread marked finds its library set.
  marked_library.store(&library);
  marked_thread.store(ThreadId());
}

ScopedInputLibraryRead::~ScopedInputLibraryRead() {
  marked_thread.store(previous_thread_);
  marked_library.store(previous_library_);
}

const InputLibrary* InputLibraryOfThisThread() {
  const pid_t thread = marked_thread.load();
  return thread != 0 && thread == ThreadId() ? marked_library.load() : nullptr;
}

const InputLibrary* LastInputLibrary() { return last_library.load(); }

}  // namespace evfs
