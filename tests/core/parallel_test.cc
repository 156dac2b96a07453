#include "evfs/core/parallel.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

#if defined(__has_feature)
#define EVFS_HAS_FEATURE(x) __has_feature(x)
#else
#define EVFS_HAS_FEATURE(x) 0
#endif

namespace evfs {
namespace {

// Address space of the child in ThreadsThatCannotStartLeaveTheirTasksToTheOthers: the test
// binary fits, a few hundred 8 MiB thread stacks do not.
constexpr rlim_t kChildAddressSpaceBytes = rlim_t{512} << 20;
constexpr int kManyWorkers = 4096;

#if !defined(__SANITIZE_ADDRESS__) && !EVFS_HAS_FEATURE(address_sanitizer) && \
    !EVFS_HAS_FEATURE(memory_sanitizer) && !defined(__SANITIZE_THREAD__)
// Sanitizers reserve terabytes of shadow memory, so an address space limit stops them first.
TEST(ParallelForEach, ThreadsThatCannotStartLeaveTheirTasksToTheOthers) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const rlimit limit{kChildAddressSpaceBytes, kChildAddressSpaceBytes};
    if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(2);
    std::vector<std::atomic<int>> runs(kManyWorkers);
    ParallelForEach(kManyWorkers, kManyWorkers, [&](int i) { ++runs[i]; });
    for (const std::atomic<int>& run : runs) {
      if (run != 1) _exit(3);
    }
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the child ended by signal " << WTERMSIG(status)
                                 << " (std::terminate aborts)";
  EXPECT_EQ(WEXITSTATUS(status), 0);
}
#endif

TEST(ParallelForEach, RunsEveryTaskOnce) {
  for (const int workers : {1, 2, 5}) {
    std::vector<std::atomic<int>> runs(37);
    ParallelForEach(37, workers, [&](int i) { ++runs[i]; });
    for (const auto& count : runs) EXPECT_EQ(count.load(), 1);
  }
  ParallelForEach(0, 2, [](int) { FAIL() << "no task to run"; });
}

TEST(ParallelForEach, RethrowsTheFirstFailureAfterTheOthersRan) {
  std::atomic<int> ran{0};
  try {
    ParallelForEach(10, 3, [&](int i) {
      ++ran;
      if (i == 4 || i == 7) throw std::runtime_error("task " + std::to_string(i));
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "task 4");
  }
  EXPECT_EQ(ran.load(), 10);
}

}  // namespace
}  // namespace evfs
