#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

namespace evfs {
namespace {

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
