// Small gaps of the contour map closed (see contour_gaps.hpp).
#include "contour_gaps.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace delineo::stereo::detail {
namespace {

// The 8 neighbours (0 1 2 / 3 . 4 / 5 6 7) as (x, y).
constexpr int kDx[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
constexpr int kDy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};

// bridgeContourGaps in its steps: the chain ends of a row (markEnds); for each end, the contour
// pixels ahead of it (lookAhead), the chain's own pixels near it (markOwnChain) and the nearest
// pixel ahead that is not one of them (bridgeFrom).
class ContourGaps {
 public:
  ContourGaps(const cv::Mat& edges, int maxGap);
  void markEnds(int y, std::vector<uchar>& isEnd) const;
  cv::Point bridgeFrom(int x, int y);

 private:
  bool lookAhead(const uchar* p);
  void markOwnChain(const uchar* p);
  int& ownAt(int dx, int dy) {
    return ownChain_[static_cast<size_t>((dy + box_) * side_ + (dx + box_))];
  }
  double lengthOf(int dx, int dy) const {
    return lengths_[static_cast<size_t>((dy + reach_) * across_ + dx + reach_)];
  }

  const int cols_;
  const int reach_;  // Chebyshev distance from an end across maxGap missing pixels
  // The chain's own pixels near an end: 8-connected to it within `box_` px.
  const int box_ = reach_ + 2;
  const int side_ = 2 * box_ + 1;
  const int across_ = 2 * reach_ + 1;
  cv::Mat padded_;
  std::ptrdiff_t step_ = 0;
  std::ptrdiff_t around_[8] = {};  // the 8 neighbours' offsets in `padded_`
  std::vector<int> ownChain_;      // a stamp per end
  std::vector<double> lengths_;
  int stamp_ = 0;
  std::vector<cv::Point> queue_;  // offsets from the end
  std::vector<std::pair<double, cv::Point>> ahead_;
};

ContourGaps::ContourGaps(const cv::Mat& edges, int maxGap) : cols_(edges.cols), reach_(maxGap + 1) {
  // A copy with a border of `box_` empty pixels: every read below is in bounds. (About a fifth
  // of a textured scene's pixels are contour pixels; the bounds checks cost more than the copy.)
  cv::copyMakeBorder(edges, padded_, box_, box_, box_, box_, cv::BORDER_CONSTANT, cv::Scalar(0));
  step_ = static_cast<std::ptrdiff_t>(padded_.step1());
  for (int k = 0; k < 8; ++k) around_[k] = kDy[k] * step_ + kDx[k];
  ownChain_.assign(static_cast<size_t>(side_ * side_), 0);
  // std::hypot(dx, dy) for |dx|, |dy| <= reach, computed once (it was a third of this pass).
  lengths_.resize(static_cast<size_t>(across_ * across_));
  for (int dy = -reach_; dy <= reach_; ++dy) {
    for (int dx = -reach_; dx <= reach_; ++dx) {
      lengths_[static_cast<size_t>((dy + reach_) * across_ + dx + reach_)] = std::hypot(dx, dy);
    }
  }
}

// Chain ends (contour pixels with exactly one contour neighbour) of row y marked in a loop
// without branches, which vectorises; the scan then branches on the ends only (about a fifth of
// a textured scene's pixels are contour pixels: a branch on each cost more than the rest of this
// pass).
void ContourGaps::markEnds(int y, std::vector<uchar>& isEnd) const {
  const uchar* row = padded_.ptr<uchar>(y + box_) + box_;
  const uchar* up = row - step_;
  const uchar* down = row + step_;
  for (int x = 0; x < cols_; ++x) {
    const int neighbours = (up[x - 1] != 0) + (up[x] != 0) + (up[x + 1] != 0) + (row[x - 1] != 0) +
                           (row[x + 1] != 0) + (down[x - 1] != 0) + (down[x] != 0) +
                           (down[x + 1] != 0);
    isEnd[static_cast<size_t>(x)] = static_cast<uchar>((row[x] != 0) & (neighbours == 1));
  }
}

// The pixel the chain end (x, y) is joined to: the nearest contour pixel ahead of it that is
// not its chain's own; (-1, -1) when there is none.
cv::Point ContourGaps::bridgeFrom(int x, int y) {
  const uchar* p = padded_.ptr<uchar>(y + box_) + box_ + x;
  if (!lookAhead(p)) return {-1, -1};
  markOwnChain(p);
  double nearest = 1e30;
  cv::Point target(-1, -1);
  for (const auto& [length, d] : ahead_) {
    if (length < nearest && ownAt(d.x, d.y) != stamp_) {
      nearest = length;
      target = {x + d.x, y + d.y};
    }
  }
  return target;
}

// The contour pixels ahead of the end at `p` (ahead_, with their distances): the chain runs out
// away from its one neighbour. False when there are none.
bool ContourGaps::lookAhead(const uchar* p) {
  int last = 0;
  while (p[around_[last]] == 0) ++last;
  const int ox = kDx[last], oy = kDy[last];
  const double outLength = lengthOf(ox, oy);
  ahead_.clear();
  for (int dy = -reach_; dy <= reach_; ++dy) {
    for (int dx = -reach_; dx <= reach_; ++dx) {
      if (p[dy * step_ + dx] == 0 || std::max(std::abs(dx), std::abs(dy)) < 2) continue;
      const double length = lengthOf(dx, dy);
      if (-(dx * ox + dy * oy) < 0.5 * length * outLength) continue;  // beyond 60°
      ahead_.push_back({length, cv::Point(dx, dy)});
    }
  }
  return !ahead_.empty();
}

// The chain's own pixels near the end at `p`, stamped in ownChain_ (most ends have none ahead:
// this walk is only paid for the rest).
void ContourGaps::markOwnChain(const uchar* p) {
  ++stamp_;
  queue_.assign(1, cv::Point(0, 0));
  ownAt(0, 0) = stamp_;
  for (size_t i = 0; i < queue_.size(); ++i) {
    const cv::Point c = queue_[i];
    for (int k = 0; k < 8; ++k) {
      const int u = c.x + kDx[k], v = c.y + kDy[k];
      if (std::abs(u) > box_ || std::abs(v) > box_ || p[v * step_ + u] == 0) continue;
      int& mark = ownAt(u, v);
      if (mark == stamp_) continue;
      mark = stamp_;
      queue_.emplace_back(u, v);
    }
  }
}

}  // namespace

int bridgeContourGaps(cv::Mat& edges, int maxGap) {
  CV_Assert(edges.type() == CV_8U);
  if (maxGap < 1 || edges.empty()) return 0;
  ContourGaps gaps(edges, maxGap);
  std::vector<std::pair<cv::Point, cv::Point>> segments;
  std::vector<uchar> isEnd(static_cast<size_t>(edges.cols));
  for (int y = 0; y < edges.rows; ++y) {
    gaps.markEnds(y, isEnd);
    for (int x = 0; x < edges.cols; ++x) {
      if (isEnd[static_cast<size_t>(x)] == 0) continue;
      const cv::Point target = gaps.bridgeFrom(x, y);
      if (target.x >= 0) segments.emplace_back(cv::Point(x, y), target);
    }
  }
  // Drawn once all ends are found: a segment does not make new ends.
  for (const auto& [from, to] : segments) cv::line(edges, from, to, cv::Scalar(255), 1, cv::LINE_8);
  return static_cast<int>(segments.size());
}

}  // namespace delineo::stereo::detail
