#include "common/core/memory.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace sf {

void keep_freed_memory() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_MAX, 0);                 // no separate mapping per large block: they come from the heap
  mallopt(M_TRIM_THRESHOLD, 2147483647);  // and the heap's top is not returned to the system
#endif
}

}  // namespace sf
