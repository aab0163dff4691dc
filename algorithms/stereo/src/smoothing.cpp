#include "smoothing.hpp"

#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/nan_mask.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

int smoothSurfaces(cv::Mat& disparity, int window, double tolerance, int threads) {
  CV_Assert(disparity.type() == CV_32F);
  const int r = window / 2;
  if (r < 1 || disparity.rows <= 2 * r || disparity.cols <= 2 * r) return 0;
  const cv::Mat source = disparity.clone();
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // The window's lowest and highest disparity and its sum, as OpenCV's min, max and box filters
  // of the map with unmatched pixels at -inf, +inf and 0: an unmatched pixel then fails the test
  // below like a step. (The sums, of at most 31² floats, are exact in double.)
  const cv::Mat unmatched = core::nanMask(source);
  const cv::Mat square = cv::Mat::ones(window, window, CV_8U);
  cv::Mat lowest, highest, sums;
  runTasks({[&] {
              cv::Mat m = source.clone();
              m.setTo(-kInf, unmatched);
              cv::erode(m, lowest, square);
            },
            [&] {
              cv::Mat m = source.clone();
              m.setTo(kInf, unmatched);
              cv::dilate(m, highest, square);
            },
            [&] {
              cv::Mat m = source.clone();
              m.setTo(0.0F, unmatched);
              cv::boxFilter(m, sums, CV_64F, {window, window}, {-1, -1}, false);
            }},
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
