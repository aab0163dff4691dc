#pragma once
// Small isolated regions of a disparity map removed (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

// Connected regions of matched pixels (8-neighbours whose disparities differ by at most `range`
// px) smaller than `maxSize` pixels become unmatched (NaN in `disparity`, and in `score` when it
// is not empty). Returns the number of pixels removed. `threads`: workers over bands of rows
// (same result on any number).
int removeSpeckles(cv::Mat& disparity, cv::Mat& score, int maxSize, double range, int threads = 1);

}  // namespace delineo::stereo::detail
