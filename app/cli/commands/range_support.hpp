#pragma once
// The disparity range of a pair for the commands given none (match, delineate): estimated by
// stereo::estimateDisparityRange (docs/disparity-range.md), defined in range.cpp.
#include <string>

#include <opencv2/core.hpp>

#include "delineo/core/progress.hpp"
#include "delineo/stereo/disparity_range.hpp"

namespace delineo::cli {

// Estimates the range with the default parameters and prints "disparity range estimated from
// N matches: [a, b] px" on stderr unless `quiet`. A failure is rethrown with `byHand` appended
// (the flags that give the range by hand, e.g. "give --dmin and --dmax"). Throws Canceled.
stereo::RangeEstimate estimateRangeForCommand(const cv::Mat& left, const cv::Mat& right,
                                              const std::string& byHand, bool quiet,
                                              core::Progress* progress);

}  // namespace delineo::cli
