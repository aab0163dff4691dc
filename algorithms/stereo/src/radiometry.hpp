#pragma once
// Image noise and the grey-level map between the two views (internal to delineo_stereo).
#include <functional>
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
// pairs that agree with a first, median-based map (wrong matches left out). `fallback()` when
// fewer than `minPairs` pairs agree or either side is flat (only then is it called).
// `threads` workers share the passes over the pairs; the result does not depend on their number
// (the moments are summed in one order).
std::pair<double, double> radiometricMapOfMatches(
    const cv::Mat& left, const cv::Mat& right, const cv::Mat& disparity,
    const std::function<std::pair<double, double>()>& fallback, int minPairs = 1000,
    int threads = 1);
std::pair<double, double> radiometricMapOfMatches(const cv::Mat& left, const cv::Mat& right,
                                                  const cv::Mat& disparity,
                                                  std::pair<double, double> fallback,
                                                  int minPairs = 1000, int threads = 1);

// The smallest and largest disparity of a map (CV_32F, NaN = unmatched); (0, 0) when none is
// matched, as cv::minMaxIdx under the matched mask gives.
std::pair<double, double> matchedRange(const cv::Mat& disparity, int threads = 1);

// The middle value of `values`, the upper one of an even count: the element std::nth_element
// puts at size / 2, without reordering a copy of a large set. The same value for any `threads`.
double middleValue(const std::vector<double>& values, int threads = 1);

}  // namespace delineo::stereo::detail
