#pragma once
// Masks of NaN pixels. Do not write `m != m` for this: OpenCV 4.6's vectorised CMP_NE is an
// ordered comparison on AVX-512 machines (NaN != NaN gives 0 there), so only the scalar tail of a
// row was caught. `m == m` is ordered too and therefore right; these helpers build on it.
#include <opencv2/core.hpp>

namespace delineo::core {

// CV_8U, 255 where the single-channel float matrix `m` is NaN, 0 elsewhere.
cv::Mat nanMask(const cv::Mat& m);

// CV_8U, 255 where `m` holds a number (not NaN), 0 elsewhere.
cv::Mat numberMask(const cv::Mat& m);

}  // namespace delineo::core
