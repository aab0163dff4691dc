#pragma once
// Where the benchmarks find the real pairs: the folder named by DELINEO_DATA_DIR, else shared/data
// beside the repository (DELINEO_DEFAULT_DATA_DIR, set by tests/bench/CMakeLists.txt).
#include <cstdlib>
#include <string>

namespace delineo::bench {

inline std::string defaultDataRoot() {
  if (const char* dir = std::getenv("DELINEO_DATA_DIR"); dir && *dir) return dir;
  return DELINEO_DEFAULT_DATA_DIR;
}

}  // namespace delineo::bench
