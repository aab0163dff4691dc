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
  const float tol = static_cast<float>(range);
  cv::Mat seen(disparity.size(), CV_8U, cv::Scalar(0));
  std::vector<int> region, stack;
  int removed = 0;
  for (int y0 = 0; y0 < h; ++y0) {
    for (int x0 = 0; x0 < w; ++x0) {
      if (seen.at<uchar>(y0, x0) || !std::isfinite(disparity.at<float>(y0, x0))) continue;
      region.clear();
      stack.assign(1, y0 * w + x0);
      seen.at<uchar>(y0, x0) = 1;
      while (!stack.empty()) {
        const int i = stack.back();
        stack.pop_back();
        region.push_back(i);
        const int y = i / w, x = i % w;
        const float d = disparity.at<float>(y, x);
        for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v) {
          const float* row = disparity.ptr<float>(v);
          uchar* mark = seen.ptr<uchar>(v);
          for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u) {
            // NaN fails the comparison: unmatched pixels never join.
            if (mark[u] || !(std::abs(row[u] - d) <= tol)) continue;
            mark[u] = 1;
            stack.push_back(v * w + u);
          }
        }
      }
      if (static_cast<int>(region.size()) >= maxSize) continue;
      removed += static_cast<int>(region.size());
      for (const int i : region) {
        disparity.at<float>(i / w, i % w) = kNaN;
        if (!score.empty()) score.at<float>(i / w, i % w) = kNaN;
      }
    }
  }
  return removed;
}

}  // namespace delineo::stereo::detail
