#pragma once
// Union-find over indices 0..n−1 in which the smaller index always becomes the root: every
// element's parent precedes it (internal to delineo_stereo; speckles and roof planes).
#include <cstddef>
#include <vector>

namespace delineo::stereo::detail {

inline int findRoot(std::vector<int>& parent, int i) {
  while (parent[static_cast<size_t>(i)] != i) {
    const int up = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
    parent[static_cast<size_t>(i)] = up;  // path halving
    i = up;
  }
  return i;
}

inline void joinRoots(std::vector<int>& parent, int a, int b) {
  const int ra = findRoot(parent, a), rb = findRoot(parent, b);
  if (ra < rb) {
    parent[static_cast<size_t>(rb)] = ra;
  } else if (rb < ra) {
    parent[static_cast<size_t>(ra)] = rb;
  }
}

}  // namespace delineo::stereo::detail
