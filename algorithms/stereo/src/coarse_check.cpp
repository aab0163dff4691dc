// Matches that keep the coarser level's left/right check (see coarse_check.hpp).
#include "coarse_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "neighbourhood_range.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

cv::Mat coarselyChecked(const cv::Mat& coarse, const LevelOutput& fine, double minScore,
                        int threads) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // Rejected neighbours (and the border) at −inf for the minimum and +inf for the maximum: the
  // spread is then infinite, never smooth.
  const int cw = coarse.cols, ch = coarse.rows;
  cv::Mat forMin, forMax, lowest, highest;
  rangeFilterInputs(coarse, -kInf, kInf, threads, forMin, forMax);
  rangeFilters(forMin, forMax, cv::Mat::ones(3, 3, CV_8U), -kInf, kInf, threads, lowest, highest);
  cv::Mat kept(fine.disparity.size(), CV_8U);
  const auto floor = static_cast<float>(minScore);
  forRowBands(kept.rows, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const int cy = std::min(ch - 1, y / 2);
      const float* c = coarse.ptr<float>(cy);
      const float* lo = lowest.ptr<float>(cy);
      const float* hi = highest.ptr<float>(cy);
      const float* d = fine.disparity.ptr<float>(y);
      const float* sc = fine.score.ptr<float>(y);
      uchar* out = kept.ptr<uchar>(y);
      for (int x = 0; x < kept.cols; ++x) {
        const int cx = std::min(cw - 1, x / 2);
        // (NaN fails every comparison.)
        out[x] = hi[cx] - lo[cx] <= 1.0F && sc[x] >= floor && std::abs(d[x] - 2.0F * c[cx]) <= 1.0F
                     ? 1
                     : 0;
      }
    }
  });
  return kept;
}

}  // namespace delineo::stereo::detail
