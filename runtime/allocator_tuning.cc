#include "evfs/runtime/allocator_tuning.h"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <climits>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

namespace evfs {
namespace {

constexpr uintptr_t kHugePageBytes = uintptr_t{2} << 20;
constexpr size_t kHugePageHeapBytes = size_t{256} << 20;
constexpr int kGlibcDefaultTopPad = 128 * 1024;

void BackTheHeapWithHugePages() {
  // The heap grows this much more than it needs, once: the probe below makes it grow.
  mallopt(M_TOP_PAD, static_cast<int>(kHugePageHeapBytes));
  const auto before = reinterpret_cast<uintptr_t>(sbrk(0));
  // More than the heap's free top holds: glibc extends the heap (by the pad too) to serve it.
  // (volatile: a compiler may drop a malloc whose block is only freed.)
  void* volatile probe = std::malloc(kHugePageBytes);
  std::free(probe);
  const auto after = reinterpret_cast<uintptr_t>(sbrk(0));
  // Later growth is glibc's usual size, so that a process near an address-space limit
  // (ulimit -v) is not refused memory it could have had. Under a limit below the pad, the
  // probe fails, nothing grows and nothing is advised.
  mallopt(M_TOP_PAD, kGlibcDefaultTopPad);
  const uintptr_t begin = (before + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
  const uintptr_t end = after & ~(kHugePageBytes - 1);
  // Advice only: where the kernel has no transparent huge pages, nothing changes.
  if (probe != nullptr && end > begin) {
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
}

}  // namespace

void KeepFreedMemoryForReuse() {
  mallopt(M_MMAP_MAX, 0);              // every block from the heap
  mallopt(M_TRIM_THRESHOLD, INT_MAX);  // and the heap's free top is kept
  BackTheHeapWithHugePages();
}

}  // namespace evfs
