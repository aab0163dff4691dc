#pragma once
// Steep roof facets matched on slanted planes (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct SlantedFacetSettings {
  double maxSlope = 0.6;  // px of disparity per px: largest |∂d/∂x| and |∂d/∂y| searched
  int minArea = 100;      // px: smaller unmatched regions are left alone
  double minRegionScore = 0.75;  // NCC of the whole region at its best plane
  double uniqueness = 0.05;      // the best coarse NCC 2 px or more away must be this lower
  double minRingShare = 0.3;     // share of the matches within 2 px of it within 1 px of it
  double minPixelScore = 0.6;    // NCC of a pixel's 7 x 7 window (region pixels only) there
  double minPixelShare = 0.8;    // share of the region's pixels that must reach minPixelScore
  int threads = 1;               // workers over regions (same result on any number)
};

// A steep facet (a hip roof's side sloping 0.37 px/px, sim seed 41 600²) is stretched or squeezed
// by a third in the right view: its fronto-parallel windows find no peak and it is left
// unmatched, outline included. Each unmatched region cut by the contours (`edges`, non-zero =
// contour; 4-connected, at least minArea pixels, with matched pixels around it) is matched as a
// whole on planes d = a + gx·x + gy·y: `a` within the disparities of the matches around it
// (±1 px), the slopes within ±maxSlope, by NCC of all its pixels against the right view
// (linearly interpolated along the row). When the best plane scores at least minRegionScore,
// its pixels whose own 7 x 7 window scores at least minPixelScore there take the plane's
// disparity and that score. Regions no plane lines up (occluded ground, two facets, plain
// surfaces) stay unmatched.
// Returns the number of pixels matched.
int recoverSlantedFacets(const cv::Mat& left, const cv::Mat& right, const cv::Mat& edges,
                         const SlantedFacetSettings& settings, int dmin, int dmax,
                         cv::Mat& disparity, cv::Mat& score);

}  // namespace delineo::stereo::detail
