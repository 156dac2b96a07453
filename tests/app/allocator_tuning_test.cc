#include "evfs/runtime/allocator_tuning.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace evfs {
namespace {

// The VmFlags of the mapping of /proc/self/smaps that holds `address`; "" when none does.
std::string VmFlagsAt(const void* address) {
  const auto at = reinterpret_cast<uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= at && at < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}

// First in the file: the process's heap has not grown ahead yet (each test also runs in a
// process of its own under ctest). A child under an address-space limit below the 256 MB the
// heap grows ahead still gets the memory that fits.
TEST(AllocatorTuning, AnAddressSpaceLimitBelowTheHeadroomStillAllocates) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: no limit fits";
#endif
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::ifstream statm("/proc/self/statm");
    size_t pages = 0;
    statm >> pages;
    const rlim_t limit = pages * static_cast<size_t>(sysconf(_SC_PAGESIZE)) + (size_t{128} << 20);
    const rlimit as{limit, limit};
    if (setrlimit(RLIMIT_AS, &as) != 0) _exit(3);
    KeepFreedMemoryForReuse();
    // 64 MB in 8 blocks, well within the limit.
    for (int i = 0; i < 8; ++i) {
      char* volatile block = static_cast<char*>(std::malloc(size_t{8} << 20));
      if (block == nullptr) _exit(1);
      block[0] = 1;
    }
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: malloc failed under the limit; 3: setrlimit failed";
}

TEST(AllocatorTuning, TheHeapIsAdvisedHugePages) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer replaces glibc's malloc and its heap: nothing to advise";
#endif
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(mode, modes);
  if (modes.empty() || modes.find("[never]") != std::string::npos) {
    GTEST_SKIP() << "this kernel has no transparent huge pages (" << modes << ")";
  }
  KeepFreedMemoryForReuse();
  // A block of the size Ceres allocates per iteration comes from the advised heap: all of it
  // but the part before the first 2 MB boundary of the grown heap (advice covers whole huge
  // pages), so 4 MB into it is advised.
  void* volatile block = std::malloc(8 << 20);
  ASSERT_NE(block, nullptr);
  const std::string flags = VmFlagsAt(static_cast<char*>(block) + (4 << 20));
  std::free(block);
  ASSERT_FALSE(flags.empty()) << "no mapping holds the block";
  EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;  // VM_HUGEPAGE
}

}  // namespace
}  // namespace evfs
