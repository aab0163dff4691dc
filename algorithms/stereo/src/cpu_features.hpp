#pragma once
// What the CPU offers to the stereo kernels built for several instruction sets (internal to
// delineo_stereo): the x86 check done once, shared by every file that picks a build at run time.
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define DELINEO_STEREO_X86 1
#endif

// A function built for several instruction sets, picked at load time (GCC's target_clones).
// ThreadSanitizer instruments the pickers (ifunc resolvers), which the loader runs before the
// sanitizer's runtime is set up: the program crashes at start. Its builds keep the default
// version only.
#if defined(__SANITIZE_THREAD__)
#define DELINEO_TARGET_CLONES(...)
#else
#define DELINEO_TARGET_CLONES(...) __attribute__((target_clones(__VA_ARGS__)))
#endif

namespace delineo::stereo::detail {

inline bool cpuHasAvx2() {
#ifdef DELINEO_STEREO_X86
  static const bool has = __builtin_cpu_supports("avx2") != 0;
  return has;
#else
  return false;
#endif
}

inline bool cpuHasAvx512Vl() {
#ifdef DELINEO_STEREO_X86
  static const bool has = cpuHasAvx2() && __builtin_cpu_supports("avx512vl") != 0 &&
                          __builtin_cpu_supports("avx512bw") != 0;
  return has;
#else
  return false;
#endif
}

}  // namespace delineo::stereo::detail
