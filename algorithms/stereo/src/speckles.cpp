#include "speckles.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace delineo::stereo::detail {

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
}  // namespace

// Connected regions of matched pixels (8-neighbours within `range` px of each other) smaller
// than `maxSize` pixels become unmatched: isolated islands are mostly wrong matches (repetitive
// texture, windows straddling a step) and a real surface is rarely that small. 8-connected, not
// 4 like OpenCV's filterSpeckles: the matched rim of an otherwise unmatched roof is a diagonal
// staircase that 4-connectivity cuts into pieces at every step of a slanted outline.
int removeSpeckles(cv::Mat& disparity, cv::Mat& score, int maxSize, double range) {
  CV_Assert(disparity.type() == CV_32F && (score.empty() || score.size() == disparity.size()));
  const int w = disparity.cols, h = disparity.rows;
  if (w == 0 || h == 0 || maxSize <= 1) return 0;
  const float tol = static_cast<float>(range);
  // Union-find over pixel indices in one raster pass (each pixel joins its left and three upper
  // neighbours), then region sizes by root: sequential memory, no per-region lists (a flood
  // fill was 20 ms at 1 Mpx, most of it walking the large regions).
  std::vector<int> parent(static_cast<size_t>(w) * static_cast<size_t>(h), -1);
  const auto root = [&](int i) {
    while (parent[static_cast<size_t>(i)] != i) {
      const int up = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
      parent[static_cast<size_t>(i)] = up;  // path halving
      i = up;
    }
    return i;
  };
  // The smaller index becomes the root: every pixel's parent precedes it in raster order.
  const auto join = [&](int a, int b) {
    const int ra = root(a), rb = root(b);
    if (ra < rb) {
      parent[static_cast<size_t>(rb)] = ra;
    } else if (rb < ra) {
      parent[static_cast<size_t>(ra)] = rb;
    }
  };
  for (int y = 0; y < h; ++y) {
    const float* row = disparity.ptr<float>(y);
    const float* up = y > 0 ? disparity.ptr<float>(y - 1) : nullptr;
    for (int x = 0; x < w; ++x) {
      const float d = row[x];
      if (!std::isfinite(d)) continue;
      const int i = y * w + x;
      // NaN fails the comparisons: unmatched pixels never join.
      const bool left = x > 0 && std::abs(row[x - 1] - d) <= tol;
      parent[static_cast<size_t>(i)] = left ? parent[static_cast<size_t>(i - 1)] : i;
      if (up == nullptr) continue;
      for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u) {
        if (std::abs(up[u] - d) <= tol) join(i, i - w + (u - x));
      }
    }
  }
  // Flattened in raster order (a parent precedes its child, so it is flat already), counting
  // each region's size in its root's own entry, as -(1 + size): a region's root is its first
  // pixel in raster order, so it is met before its other pixels. No second w × h array.
  for (size_t i = 0; i < parent.size(); ++i) {
    const int p = parent[i];
    if (p < 0) continue;
    if (static_cast<size_t>(p) == i) {
      parent[i] = -2;  // a root, size 1 so far
      continue;
    }
    // The parent is the root itself (its entry now holds the count) or a flattened pixel.
    const int r = parent[static_cast<size_t>(p)] <= -2 ? p : parent[static_cast<size_t>(p)];
    parent[i] = r;
    --parent[static_cast<size_t>(r)];
  }
  const auto regionSize = [&](size_t i) {
    const int p = parent[i];
    return p <= -2 ? -p - 1 : -parent[static_cast<size_t>(p)] - 1;
  };
  int removed = 0;
  for (int y = 0; y < h; ++y) {
    float* row = disparity.ptr<float>(y);
    float* sc = score.empty() ? nullptr : score.ptr<float>(y);
    const size_t first = static_cast<size_t>(y) * static_cast<size_t>(w);
    for (int x = 0; x < w; ++x) {
      const size_t i = first + static_cast<size_t>(x);
      if (parent[i] == -1 || regionSize(i) >= maxSize) continue;
      row[x] = kNaN;
      if (sc != nullptr) sc[x] = kNaN;
      ++removed;
    }
  }
  return removed;
}

}  // namespace delineo::stereo::detail
