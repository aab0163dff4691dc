#pragma once
// Image noise and the grey-level map between the two views (internal to delineo_stereo).
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

// Noise sigma of a single-channel image (any depth), in its grey levels.
double noiseSigma(const cv::Mat& image);

// Gain and offset (left ≈ gain · right + offset) mapping the right view's grey levels to the
// left's, from the moments of the columns both views see for the mid disparity of [dmin, dmax].
// CV_32F images of the same size; NaN = nodata. {1, 0} when either view is flat.
std::pair<double, double> radiometricMap(const cv::Mat& left, const cv::Mat& right, int dmin,
                                         int dmax);

// The same map from the pixel pairs a disparity map matches (left x, right x - d rounded; NaN =
// unmatched): the moments of the grey levels both views give the same surface points, over the
// pairs that agree with a first, median-based map (wrong matches left out). `fallback` when fewer
// than `minPairs` pairs agree or either side is flat.
std::pair<double, double> radiometricMapOfMatches(const cv::Mat& left, const cv::Mat& right,
                                                  const cv::Mat& disparity,
                                                  std::pair<double, double> fallback,
                                                  int minPairs = 1000);

// The smallest and largest disparity of a map (CV_32F, NaN = unmatched); (0, 0) when none is
// matched, as cv::minMaxIdx under the matched mask gives.
std::pair<double, double> matchedRange(const cv::Mat& disparity);

// The middle value of `values`, the upper one of an even count: the element std::nth_element
// puts at size / 2, without reordering a copy of a large set.
double middleValue(const std::vector<double>& values);

}  // namespace delineo::stereo::detail
