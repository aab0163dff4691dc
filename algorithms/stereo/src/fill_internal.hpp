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

// The error of a region's outline ring at a plane's disparity.

// Calls visit(residual) for each pixel of `ring` (over `box`) with data in both views, residual =
// left − (gain · right + offset) with the right view read at the plane's disparity by linear
// interpolation (the candidates are sub-pixel); `stopAtRow()` is asked before each row. False
// when the outline leaves the right image or stopAtRow() said stop.
template <typename Visit, typename StopAtRow>
bool visitRingResiduals(const cv::Mat& left, const cv::Mat& right, const cv::Mat& ring,
                        const cv::Rect& box, const FillPlane& plane,
                        const std::pair<double, double>& map, Visit&& visit,
                        StopAtRow&& stopAtRow) {
  const auto [mapGain, mapOffset] = map;
  for (int y = 0; y < box.height; ++y) {
    if (stopAtRow()) return false;
    const uchar* m = ring.ptr<uchar>(y);
    const float* a = left.ptr<float>(box.y + y) + box.x;
    const float* b = right.ptr<float>(box.y + y);
    for (int x = 0; x < box.width; ++x) {
      if (!m[x]) continue;
      const double value = plane.at(box.x + x, box.y + y);
      const int whole = static_cast<int>(std::floor(value));
      const float t = static_cast<float>(value - whole);
      const int xr = box.x + x - whole;  // x − value lies in [xr − 1, xr]
      if (xr - 1 < 0 || xr >= right.cols) return false;
      const float bv = (1 - t) * b[xr] + t * b[xr - 1];
      if (!std::isfinite(a[x]) || !std::isfinite(bv)) continue;
      visit(a[x] - (mapGain * bv + mapOffset));
    }
  }
  return true;
}

// The ring's error in the region's own light (see RegionFillSettings::shadowOwnLight): mean
// |residual − median residual|; 1e30 when the outline leaves the right image or has no data
// (fill_own_light.cpp).
double ringErrorInOwnLight(const cv::Mat& left, const cv::Mat& right, const cv::Mat& ring,
                           const cv::Rect& box, const FillPlane& plane,
                           const std::pair<double, double>& map);

// The median grey of the valid pixels of `image`, from about 10 000 of them (fill_own_light.cpp).
double medianGrey(const cv::Mat& image);

}  // namespace delineo::stereo::detail
