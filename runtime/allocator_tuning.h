// Process-wide malloc settings for the evfs executables (not the libraries: how a process
// allocates is its owner's choice).
#ifndef EVFS_RUNTIME_ALLOCATOR_TUNING_H_
#define EVFS_RUNTIME_ALLOCATOR_TUNING_H_

namespace evfs {

/// Makes glibc keep freed memory for reuse instead of handing large blocks back to the kernel.
/// By default every block above 128 KB is a fresh mmap whose pages fault in on first touch and
/// are unmapped on free; Ceres allocates vectors of the problem's size in every iteration (L-BFGS
/// in every line-search step), so on this 2-core VM the page faults took 19 % of an L-BFGS solve
/// and evaluating them cost more than the objective. With mmap off and no trimming, L-BFGS on
/// shapes_rotation prediction took 4.3 s instead of 15.0 s and Levenberg–Marquardt on
/// slider_depth 0.56 s instead of 0.65 s, at the same peak memory (164 MB instead of 159 MB).
/// The memory goes back to the kernel when the process ends.
///
/// It also backs the first 256 MB of the heap with transparent huge pages (madvise
/// MADV_HUGEPAGE over a heap grown ahead by that much, what glibc's own
/// GLIBC_TUNABLES=glibc.malloc.hugetlb=1 does, which is read only from the environment at
/// start-up): the Ceres problem's blocks and vectors then take 2 MB pages instead of 4 KB ones,
/// 512 times fewer page faults and TLB entries. Whole `evfs reconstruct` on slider_depth took
/// 0.79 times the time without it (benchmarks/results/speed_mechanisms.md, "Huge pages for the
/// heap"). The growth is address space only; memory is used when touched. Later growth is glibc's
/// usual, and under an address-space limit below 256 MB nothing grows ahead and nothing is advised.
/// Where the kernel has no transparent huge pages (or they are off) the advice changes nothing.
void KeepFreedMemoryForReuse();

}  // namespace evfs

#endif  // EVFS_RUNTIME_ALLOCATOR_TUNING_H_
