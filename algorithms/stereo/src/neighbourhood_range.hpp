#pragma once
// Neighbourhood minima and maxima of a disparity map with unmatched (NaN) pixels, by the
// morphology's separable float filters (internal to delineo_stereo).
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "workers.hpp"

namespace delineo::stereo::detail {

// The two inputs of the filters, in one pass by bands of rows: the map with its NaN pixels at
// `unmatchedLow` (taken for the minimum) and at `unmatchedHigh` (for the maximum). With +inf and
// -inf an unmatched pixel is ignored (an all-unmatched neighbourhood then has min > max); with
// -inf and +inf it makes its neighbourhood's spread infinite.
inline void rangeFilterInputs(const cv::Mat& disparity, float unmatchedLow, float unmatchedHigh,
                              int threads, cv::Mat& forMin, cv::Mat& forMax) {
  CV_Assert(disparity.type() == CV_32F);
  forMin.create(disparity.size(), CV_32F);
  forMax.create(disparity.size(), CV_32F);
  forRowBands(disparity.rows, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const float* __restrict d = disparity.ptr<float>(y);
      float* __restrict mn = forMin.ptr<float>(y);
      float* __restrict mx = forMax.ptr<float>(y);
      for (int x = 0; x < disparity.cols; ++x) {
        const bool isNumber = d[x] == d[x];  // false only for NaN
        mn[x] = isNumber ? d[x] : unmatchedLow;
        mx[x] = isNumber ? d[x] : unmatchedHigh;
      }
    }
  });
}

// The min filter of `forMin` and the max filter of `forMax` over `kernel`, the border taken as
// unmatched pixels, on two workers.
inline void rangeFilters(const cv::Mat& forMin, const cv::Mat& forMax, const cv::Mat& kernel,
                         float unmatchedLow, float unmatchedHigh, int threads, cv::Mat& lowest,
                         cv::Mat& highest) {
  runTasks({[&] {
              cv::erode(forMin, lowest, kernel, {-1, -1}, 1, cv::BORDER_CONSTANT, unmatchedLow);
            },
            [&] {
              cv::dilate(forMax, highest, kernel, {-1, -1}, 1, cv::BORDER_CONSTANT,
                         unmatchedHigh);
            }},
           threads);
}

}  // namespace delineo::stereo::detail
