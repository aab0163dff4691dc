// The allocator set-up of the programs (tuneAllocatorForLargeImages).
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cstdlib>

#include "delineo/core/allocator.hpp"

namespace {

long minorFaults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// Writes a byte in every 4 KiB page (volatile: the writes to a buffer freed right after are not
// left out by the compiler).
void touchPages(char* buffer, size_t bytes) {
  volatile char* pages = buffer;
  for (size_t i = 0; i < bytes; i += 4096) pages[i] = 1;
}

// AddressSanitizer and ThreadSanitizer replace malloc: mallopt() does nothing there and freed
// memory is held in quarantine, so the test only means something with glibc's own allocator.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define DELINEO_SANITIZER_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define DELINEO_SANITIZER_ALLOCATOR 1
#endif
#endif

#if defined(__GLIBC__)
TEST(Allocator, AFreedImageSizedBufferIsReusedWithoutNewPageFaults) {
#if defined(DELINEO_SANITIZER_ALLOCATOR)
  GTEST_SKIP() << "a sanitizer's allocator replaces glibc's (mallopt has no effect)";
#endif
  ASSERT_TRUE(delineo::core::tuneAllocatorForLargeImages());
  // A 16 MB buffer (a 2000² float image), written, freed, and another of the same size written:
  // from the heap, the second reuses the first's pages (a buffer mapped fresh, as by default,
  // takes a page fault per 4 KiB written: 4096 here).
  constexpr size_t kBytes = 16U << 20;
  char* first = static_cast<char*>(std::malloc(kBytes));
  ASSERT_NE(first, nullptr);
  touchPages(first, kBytes);
  std::free(first);
  const long before = minorFaults();
  char* second = static_cast<char*>(std::malloc(kBytes));
  ASSERT_NE(second, nullptr);
  touchPages(second, kBytes);
  const long faults = minorFaults() - before;
  std::free(second);
  EXPECT_LT(faults, 256) << faults << " page faults writing the second buffer";
}
#endif

}  // namespace
