#include "smoothing.hpp"

#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "workers.hpp"

namespace delineo::stereo::detail {

int smoothSurfaces(cv::Mat& disparity, int window, double tolerance, int threads) {
  CV_Assert(disparity.type() == CV_32F);
  const int r = window / 2;
  if (r < 1 || disparity.rows <= 2 * r || disparity.cols <= 2 * r) return 0;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // The window's lowest and highest disparity and its sum, as OpenCV's min, max and box filters
  // of the map with unmatched pixels at -inf, +inf and 0: an unmatched pixel then fails the test
  // below like a step. (The sums, of at most 31² floats, are exact in double.) The three inputs
  // and the source's copy in one pass by bands of rows.
  cv::Mat source(disparity.size(), CV_32F), forMin(disparity.size(), CV_32F),
      forMax(disparity.size(), CV_32F), forSum(disparity.size(), CV_32F);
  forRowBands(disparity.rows, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const float* __restrict d = disparity.ptr<float>(y);
      float* __restrict copy = source.ptr<float>(y);
      float* __restrict mn = forMin.ptr<float>(y);
      float* __restrict mx = forMax.ptr<float>(y);
      float* __restrict sm = forSum.ptr<float>(y);
      for (int x = 0; x < disparity.cols; ++x) {
        const bool isNumber = d[x] == d[x];  // false only for NaN
        copy[x] = d[x];
        mn[x] = isNumber ? d[x] : -kInf;
        mx[x] = isNumber ? d[x] : kInf;
        sm[x] = isNumber ? d[x] : 0.0F;
      }
    }
  });
  const cv::Mat square = cv::Mat::ones(window, window, CV_8U);
  cv::Mat lowest, highest, sums;
  runTasks(
      {[&] {
         cv::boxFilter(forSum, sums, CV_64F, {window, window}, {-1, -1}, false);
       },
       [&] { cv::erode(forMin, lowest, square); }, [&] { cv::dilate(forMax, highest, square); }},
      threads);
  const auto tol = static_cast<float>(tolerance);
  const double invCount = 1.0 / (static_cast<double>(window) * window);
  std::vector<int> averaged(static_cast<size_t>(disparity.rows), 0);
  // Only the windows inside the map (the border rows and columns keep their values).
  forRowBands(disparity.rows - 2 * r, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart + r; y < rowEnd + r; ++y) {
      const float* __restrict centre = source.ptr<float>(y);
      const float* __restrict low = lowest.ptr<float>(y);
      const float* __restrict high = highest.ptr<float>(y);
      const double* __restrict sum = sums.ptr<double>(y);
      float* __restrict out = disparity.ptr<float>(y);
      int count = 0;
      for (int x = r; x < disparity.cols - r; ++x) {
        // NaN fails the test.
        const bool smooth = low[x] >= centre[x] - tol && high[x] <= centre[x] + tol;
        out[x] = smooth ? static_cast<float>(sum[x] * invCount) : centre[x];
        count += smooth ? 1 : 0;
      }
      averaged[static_cast<size_t>(y)] = count;
    }
  });
  int total = 0;
  for (const int n : averaged) total += n;
  return total;
}

}  // namespace delineo::stereo::detail
