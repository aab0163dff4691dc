#include "delineo/project/edge_map.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace delineo::project {

cv::Mat edgeMap(const cv::Mat& grey, const EdgeMapParams& params) {
  params.validate();
  if (grey.empty()) return {};
  CV_Assert(grey.channels() == 1);
  cv::Mat image8;
  if (grey.depth() == CV_8U) {
    image8 = grey;
  } else {
    cv::Mat finite;
    grey.convertTo(finite, CV_32F);
    cv::patchNaNs(finite, 0.0);
    cv::normalize(finite, image8, 0, 255, cv::NORM_MINMAX, CV_8U);
  }
  cv::Mat smooth = image8;
  if (params.smoothing > 0.0) cv::GaussianBlur(image8, smooth, cv::Size(), params.smoothing);
  cv::Mat dx, dy;
  cv::Sobel(smooth, dx, CV_16S, 1, 0, 3);
  cv::Sobel(smooth, dy, CV_16S, 0, 1, 3);

  // Median of the L2 gradient magnitude, from a histogram of a regular subsample (a few
  // 100 000 pixels are plenty for a quantile).
  const int step = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(grey.total()) / 250000.0)));
  constexpr int kBins = 4096;
  constexpr double kMaxMagnitude = 4.0 * 255.0 * 1.5;  // |Sobel 3x3| <= 1020 per axis
  std::vector<long long> histogram(kBins, 0);
  long long samples = 0;
  for (int y = 0; y < dx.rows; y += step) {
    const short* gx = dx.ptr<short>(y);
    const short* gy = dy.ptr<short>(y);
    for (int x = 0; x < dx.cols; x += step) {
      const double m = std::hypot(static_cast<double>(gx[x]), static_cast<double>(gy[x]));
      const int bin = std::min(kBins - 1, static_cast<int>(m / kMaxMagnitude * kBins));
      ++histogram[static_cast<size_t>(bin)];
      ++samples;
    }
  }
  long long below = 0;
  int bin = 0;
  for (; bin < kBins - 1; ++bin) {
    below += histogram[static_cast<size_t>(bin)];
    if (2 * below >= samples) break;
  }
  const double median = (bin + 0.5) * kMaxMagnitude / kBins;
  // A flat image has no edge at all: never let the threshold fall to the noise floor of zero.
  const double high = std::max(8.0, params.contrast * median);
  cv::Mat edges;
  cv::Canny(dx, dy, edges, 0.5 * high, high, true);
  return edges;
}

}  // namespace delineo::project
