#include "app/allocator_tuning.h"

#include <malloc.h>

#include <climits>

namespace evfs {

void KeepFreedMemoryForReuse() {
  mallopt(M_MMAP_MAX, 0);              // every block from the heap
  mallopt(M_TRIM_THRESHOLD, INT_MAX);  // and the heap's free top is kept
}

}  // namespace evfs
