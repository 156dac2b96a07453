// Running independent tasks on a few threads.
#ifndef EVFS_CORE_PARALLEL_H_
#define EVFS_CORE_PARALLEL_H_

#include <functional>

namespace evfs {

/// Calls task(0) … task(count - 1) on min(workers, count) threads (the calling thread among
/// them), each thread taking the next index as it becomes free, so tasks given largest first
/// balance well. When tasks throw, the others still run and the exception of the lowest index
/// is rethrown once all have finished. Threads that cannot be started (std::system_error: no
/// address space for their stacks, a thread limit) are done without: the tasks run on the
/// threads that did start, at least the calling one.
void ParallelForEach(int count, int workers, const std::function<void(int)>& task);

}  // namespace evfs

#endif  // EVFS_CORE_PARALLEL_H_
