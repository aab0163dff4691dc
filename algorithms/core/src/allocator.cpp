#include "delineo/core/allocator.hpp"

#include <cstdlib>  // (any C library header defines __GLIBC__ under glibc)

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace delineo::core {

bool tuneAllocatorForLargeImages() {
#if defined(__GLIBC__)
  // 32 MB is the largest mmap threshold glibc accepts on 64-bit systems (HEAP_MAX_SIZE / 2).
  constexpr int kMmapThreshold = 32 * 1024 * 1024;
  constexpr int kTrimThreshold = 128 * 1024 * 1024;
  const bool mmapSet = mallopt(M_MMAP_THRESHOLD, kMmapThreshold) == 1;
  const bool trimSet = mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1;
  return mmapSet && trimSet;
#else
  return false;
#endif
}

}  // namespace delineo::core
