#include "evfs/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace evfs {

void ParallelForEach(int count, int workers, const std::function<void(int)>& task) {
  if (count <= 0) return;
  std::vector<std::exception_ptr> errors(count);
  std::atomic<int> next{0};
  const auto work = [&] {
    for (int i = next++; i < count; i = next++) {
      try {
        task(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> threads;
  for (int w = 1; w < std::min(std::max(workers, 1), count); ++w) {
    // A thread that cannot start (its stack is address space an RLIMIT_AS may not leave, or
    // the process ran into its thread limit) leaves its tasks to the threads that did: the
    // result is the same, only later.
    try {
      threads.emplace_back(work);
    } catch (const std::system_error&) {
      break;
    }
  }
  work();
  for (std::thread& thread : threads) thread.join();
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace evfs
