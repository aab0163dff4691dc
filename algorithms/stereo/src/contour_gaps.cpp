// Small gaps of the contour map closed (see contour_gaps.hpp).
#include "contour_gaps.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace delineo::stereo::detail {

int bridgeContourGaps(cv::Mat& edges, int maxGap) {
  CV_Assert(edges.type() == CV_8U);
  if (maxGap < 1 || edges.empty()) return 0;
  const int reach = maxGap + 1;  // Chebyshev distance from an end across maxGap missing pixels
  // The chain's own pixels near an end: 8-connected to it within `box` px.
  const int box = reach + 2;
  // A copy with a border of `box` empty pixels: every read below is in bounds. (About a fifth of
  // a textured scene's pixels are contour pixels; the bounds checks cost more than the copy.)
  cv::Mat padded;
  cv::copyMakeBorder(edges, padded, box, box, box, box, cv::BORDER_CONSTANT, cv::Scalar(0));
  const auto step = static_cast<std::ptrdiff_t>(padded.step1());
  // The 8 neighbours (0 1 2 / 3 . 4 / 5 6 7): offsets in `padded`, and as (x, y).
  const std::ptrdiff_t around[8] = {-step - 1, -step, -step + 1, -1, 1, step - 1, step, step + 1};
  static constexpr int kDx[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
  static constexpr int kDy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
  const int side = 2 * box + 1;
  std::vector<int> ownChain(static_cast<size_t>(side * side), 0);  // a stamp per end
  const auto ownAt = [&](int dx, int dy) -> int& {
    return ownChain[static_cast<size_t>((dy + box) * side + (dx + box))];
  };
  // std::hypot(dx, dy) for |dx|, |dy| <= reach, computed once (it was a third of this pass).
  const int across = 2 * reach + 1;
  std::vector<double> lengths(static_cast<size_t>(across * across));
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      lengths[static_cast<size_t>((dy + reach) * across + dx + reach)] = std::hypot(dx, dy);
    }
  }
  const auto lengthOf = [&](int dx, int dy) {
    return lengths[static_cast<size_t>((dy + reach) * across + dx + reach)];
  };
  int stamp = 0;
  std::vector<cv::Point> queue;  // offsets from the end
  std::vector<std::pair<double, cv::Point>> ahead;
  std::vector<std::pair<cv::Point, cv::Point>> segments;
  // Chain ends (contour pixels with exactly one contour neighbour) marked a row at a time in a
  // loop without branches, which vectorises; the scan below then branches on the ends only
  // (about a fifth of a textured scene's pixels are contour pixels: a branch on each cost more
  // than the rest of this pass).
  std::vector<uchar> isEnd(static_cast<size_t>(edges.cols));
  for (int y = 0; y < edges.rows; ++y) {
    const uchar* row = padded.ptr<uchar>(y + box) + box;
    const uchar* up = row - step;
    const uchar* down = row + step;
    for (int x = 0; x < edges.cols; ++x) {
      const int neighbours = (up[x - 1] != 0) + (up[x] != 0) + (up[x + 1] != 0) +
                             (row[x - 1] != 0) + (row[x + 1] != 0) + (down[x - 1] != 0) +
                             (down[x] != 0) + (down[x + 1] != 0);
      isEnd[static_cast<size_t>(x)] = static_cast<uchar>((row[x] != 0) & (neighbours == 1));
    }
    for (int x = 0; x < edges.cols; ++x) {
      if (isEnd[static_cast<size_t>(x)] == 0) continue;
      const uchar* p = row + x;
      int last = 0;
      while (p[around[last]] == 0) ++last;
      const int ox = kDx[last], oy = kDy[last];
      // The contour pixels ahead: the chain runs out away from its one neighbour, (-ox, -oy).
      const double outLength = lengthOf(ox, oy);
      ahead.clear();
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) {
          if (p[dy * step + dx] == 0 || std::max(std::abs(dx), std::abs(dy)) < 2) continue;
          const double length = lengthOf(dx, dy);
          if (-(dx * ox + dy * oy) < 0.5 * length * outLength) continue;  // beyond 60°
          ahead.push_back({length, cv::Point(dx, dy)});
        }
      }
      if (ahead.empty()) continue;
      // The chain's own pixels (most ends have none ahead: this walk is only paid for the rest).
      ++stamp;
      queue.assign(1, cv::Point(0, 0));
      ownAt(0, 0) = stamp;
      for (size_t i = 0; i < queue.size(); ++i) {
        const cv::Point c = queue[i];
        for (int k = 0; k < 8; ++k) {
          const int u = c.x + kDx[k], v = c.y + kDy[k];
          if (std::abs(u) > box || std::abs(v) > box || p[v * step + u] == 0) continue;
          int& mark = ownAt(u, v);
          if (mark == stamp) continue;
          mark = stamp;
          queue.emplace_back(u, v);
        }
      }
      double nearest = 1e30;
      cv::Point target(-1, -1);
      for (const auto& [length, d] : ahead) {
        if (length < nearest && ownAt(d.x, d.y) != stamp) {
          nearest = length;
          target = {x + d.x, y + d.y};
        }
      }
      if (target.x >= 0) segments.emplace_back(cv::Point(x, y), target);
    }
  }
  for (const auto& [from, to] : segments) cv::line(edges, from, to, cv::Scalar(255), 1, cv::LINE_8);
  return static_cast<int>(segments.size());
}

}  // namespace delineo::stereo::detail
