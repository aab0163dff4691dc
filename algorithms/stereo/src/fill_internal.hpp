#pragma once
// The flat-region fill's parts, shared by its files (internal to delineo_stereo; see
// fillFlatRegions in match_fill.hpp).
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "match_fill.hpp"

namespace delineo::stereo::detail {

// Half-width of the flat test's window (5x5).
inline constexpr int kFlatReach = 2;

// The flat regions of both views (fill_regions.cpp).

// Pixels of `image` whose 5x5 standard deviation is below flatSigmas noise sigmas (CV_8U
// 0/255); the image's noise sigma in `sigmaOut`.
cv::Mat flatMask(const cv::Mat& image, const RegionFillSettings& settings,
                 double* sigmaOut = nullptr, const LocalMoments* known = nullptr);

// The flat regions of the right view, labelled as the left ones, with their mean grey levels.
struct RightFlatRegions {
  cv::Mat labels;  // CV_32S, 0 off the flat regions
  std::vector<double> meanGrey;
};
RightFlatRegions rightFlatRegions(const cv::Mat& flat, const cv::Mat& right);

// The left view's flat regions (flatMask, 4-connected) and which of them the fill decides on.
struct LeftFlatRegions {
  double sigma = 0;   // the left view's noise sigma
  cv::Mat flatCores;  // the regions without their thin parts (empty without coreOpening)
  cv::Mat labels, stats, centroids;
  // By label: a region the fill decides on itself (the extension does not enter them).
  std::vector<uchar> ownFill;
};
LeftFlatRegions leftFlatRegions(const cv::Mat& left, const cv::Mat& disparity,
                                const RegionFillSettings& settings,
                                const LocalMoments* leftMoments);

}  // namespace delineo::stereo::detail
