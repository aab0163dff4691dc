#include "smoothing.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "delineo/core/nan_mask.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

int smoothSurfaces(cv::Mat& disparity, int window, double tolerance, int threads) {
  CV_Assert(disparity.type() == CV_32F);
  const int r = window / 2;
  if (r < 1 || disparity.rows <= 2 * r || disparity.cols <= 2 * r) return 0;
  const cv::Mat source = disparity.clone();
  const auto tol = static_cast<float>(tolerance);
  const double invCount = 1.0 / ((2.0 * r + 1) * (2.0 * r + 1));
  std::atomic<int> averaged{0};
  const int cols = disparity.cols;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // The map three times: unmatched pixels as -inf (for the lowest value of a window), +inf (the
  // highest) and 0 (the sum), so that the loops below carry no test.
  const cv::Mat unmatched = core::nanMask(source);
  cv::Mat lowest = source.clone(), highest = source.clone(), values = source.clone();
  lowest.setTo(-kInf, unmatched);
  highest.setTo(kInf, unmatched);
  values.setTo(0.0F, unmatched);
  forRowBands(disparity.rows, threads, [&](int rowStart, int rowEnd) {
    // Per column, over the window's rows: the lowest and highest disparity (an unmatched pixel
    // makes them -inf and +inf: it fails the test like a step) and the sum; then per window,
    // those of its columns. Plain loops over arrays, which the compiler vectorises.
    std::vector<float> columns(4 * static_cast<size_t>(cols));
    std::vector<double> sums(2 * static_cast<size_t>(cols));
    float* __restrict colLow = columns.data();
    float* __restrict colHigh = colLow + cols;
    float* __restrict winLow = colHigh + cols;
    float* __restrict winHigh = winLow + cols;
    double* __restrict colSum = sums.data();
    double* __restrict winSum = colSum + cols;
    const int inner = cols - 2 * r;  // windows x = r .. cols − r − 1, stored from 0
    int count = 0;
    for (int y = std::max(rowStart, r); y < std::min(rowEnd, disparity.rows - r); ++y) {
      std::fill(colLow, colLow + cols, kInf);
      std::fill(colHigh, colHigh + cols, -kInf);
      std::fill(colSum, colSum + cols, 0.0);
      for (int v = -r; v <= r; ++v) {
        const float* __restrict low = lowest.ptr<float>(y + v);
        const float* __restrict high = highest.ptr<float>(y + v);
        const float* __restrict value = values.ptr<float>(y + v);
        for (int x = 0; x < cols; ++x) {
          colLow[x] = std::min(colLow[x], low[x]);
          colHigh[x] = std::max(colHigh[x], high[x]);
          colSum[x] += static_cast<double>(value[x]);
        }
      }
      std::copy(colLow, colLow + inner, winLow);
      std::copy(colHigh, colHigh + inner, winHigh);
      std::copy(colSum, colSum + inner, winSum);
      for (int u = 1; u <= 2 * r; ++u) {
        for (int i = 0; i < inner; ++i) {
          winLow[i] = std::min(winLow[i], colLow[i + u]);
          winHigh[i] = std::max(winHigh[i], colHigh[i + u]);
          winSum[i] += colSum[i + u];
        }
      }
      const float* __restrict centreRow = source.ptr<float>(y) + r;
      float* __restrict out = disparity.ptr<float>(y) + r;
      for (int i = 0; i < inner; ++i) {
        const float centre = centreRow[i];  // NaN fails the test
        const bool smooth = winLow[i] >= centre - tol && winHigh[i] <= centre + tol;
        out[i] = smooth ? static_cast<float>(winSum[i] * invCount) : centre;
        count += smooth ? 1 : 0;
      }
    }
    averaged += count;
  });
  return averaged.load();
}

}  // namespace delineo::stereo::detail
