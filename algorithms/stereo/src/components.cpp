#include "components.hpp"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
// One label's sums over part of the image; `right` and `bottom` are the last column and row.
struct Tally {
  int64_t area = 0;
  int left = INT_MAX, top = INT_MAX, right = INT_MIN, bottom = INT_MIN;
  uint64_t sumX = 0, sumY = 0;
};

void tallyRows(const cv::Mat& labels, int rowStart, int rowEnd, std::vector<Tally>& tallies) {
  for (int y = rowStart; y < rowEnd; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols;) {
      const int label = l[x];
      int end = x + 1;
      while (end < labels.cols && l[end] == label) ++end;
      Tally& t = tallies[static_cast<size_t>(label)];
      const auto n = static_cast<uint64_t>(end - x);
      t.area += static_cast<int64_t>(n);
      t.left = std::min(t.left, x);
      t.right = std::max(t.right, end - 1);
      t.top = std::min(t.top, y);
      t.bottom = y;  // rows come in increasing order
      // x + (end − 1) is odd only when n is even: the product is always even.
      t.sumX += static_cast<uint64_t>(x + end - 1) * n / 2;
      t.sumY += static_cast<uint64_t>(y) * n;
      x = end;
    }
  }
}
}  // namespace

int componentsWithStats(const cv::Mat& mask, cv::Mat& labels, cv::Mat& stats, cv::Mat& centroids,
                        int connectivity, int threads) {
  const int count = cv::connectedComponents(mask, labels, connectivity, CV_32S);
  // The rows in one contiguous chunk per worker, each with its own tallies, merged after.
  const int chunks = std::max(1, std::min(threads, labels.rows));
  std::vector<std::vector<Tally>> tallies(static_cast<size_t>(chunks),
                                          std::vector<Tally>(static_cast<size_t>(count)));
  std::vector<std::function<void()>> tasks;
  for (int c = 0; c < chunks; ++c) {
    tasks.emplace_back([&, c] {
      tallyRows(labels, labels.rows * c / chunks, labels.rows * (c + 1) / chunks,
                tallies[static_cast<size_t>(c)]);
    });
  }
  runTasks(tasks, threads);
  stats.create(count, cv::CC_STAT_MAX, CV_32S);
  centroids.create(count, 2, CV_64F);
  for (int k = 0; k < count; ++k) {
    Tally all = tallies[0][static_cast<size_t>(k)];
    for (int c = 1; c < chunks; ++c) {
      const Tally& t = tallies[static_cast<size_t>(c)][static_cast<size_t>(k)];
      all.area += t.area;
      all.left = std::min(all.left, t.left);
      all.top = std::min(all.top, t.top);
      all.right = std::max(all.right, t.right);
      all.bottom = std::max(all.bottom, t.bottom);
      all.sumX += t.sumX;
      all.sumY += t.sumY;
    }
    int* row = stats.ptr<int>(k);
    row[cv::CC_STAT_AREA] = static_cast<int>(all.area);
    if (all.area == 0) {
      // Only the background of an all-foreground mask: an empty box at the origin.
      row[cv::CC_STAT_LEFT] = row[cv::CC_STAT_TOP] = 0;
      row[cv::CC_STAT_WIDTH] = row[cv::CC_STAT_HEIGHT] = 0;
    } else {
      row[cv::CC_STAT_LEFT] = all.left;
      row[cv::CC_STAT_TOP] = all.top;
      row[cv::CC_STAT_WIDTH] = all.right - all.left + 1;
      row[cv::CC_STAT_HEIGHT] = all.bottom - all.top + 1;
    }
    double* centre = centroids.ptr<double>(k);
    const auto area = static_cast<double>(all.area);
    // NaN for the empty label, as OpenCV's.
    centre[0] = static_cast<double>(all.sumX) / area;
    centre[1] = static_cast<double>(all.sumY) / area;
  }
  return count;
}

}  // namespace delineo::stereo::detail
