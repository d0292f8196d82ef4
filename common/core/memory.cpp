#include "common/core/memory.hpp"

#include <cstdlib>
#include <cstring>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace sf {

bool keep_freed_memory() {
  static const bool kept = [] {
#if defined(__GLIBC__)
    const char* tunables = std::getenv("GLIBC_TUNABLES");
    if ((tunables && std::strstr(tunables, "glibc.malloc")) || std::getenv("MALLOC_MMAP_MAX_") ||
        std::getenv("MALLOC_MMAP_THRESHOLD_") || std::getenv("MALLOC_TRIM_THRESHOLD_"))
      return false;
    const bool no_maps = mallopt(M_MMAP_MAX, 0) == 1;                 // large blocks come from the heap
    const bool no_trim = mallopt(M_TRIM_THRESHOLD, 2147483647) == 1;  // whose top is kept
    return no_maps && no_trim;
#else
    return false;
#endif
  }();
  return kept;
}

}  // namespace sf
