#pragma once
// Steep roof facets matched on slanted planes (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct SlantedFacetSettings {
  double maxSlope = 0.6;         // px/px: steepest slope searched, along x and along y
  int minArea = 100;             // px: smaller unmatched regions are left alone
  double minRegionScore = 0.75;  // the region's score at its best plane (see below)
  double uniqueness = 0.05;      // its best score 2 px or more away must be this lower
  double minRingShare = 0.3;     // share of the matches within 2 px of it within 1 px of it
  double minPixelScore = 0.6;    // NCC of a pixel's 7 x 7 window (region pixels only) there
  double minPixelShare = 0.8;    // share of the region's pixels that must reach minPixelScore
  int threads = 1;               // workers over regions (same result on any number)
};

// A steep facet (a hip roof's side sloping 0.35 px/px, sim seed 41 600²) is stretched or squeezed
// by a third in the right view: its fronto-parallel windows find no peak and it is left
// unmatched, outline included. Each unmatched region cut by the contours (`edges`, non-zero =
// contour; 4-connected, at least minArea pixels, with matched pixels around it) is matched as a
// whole on planes d = a + gx·x + gy·y: `a` within the disparities of the matches around it
// (±1 px), the slopes within ±maxSlope, against the right view read at x − d (linearly
// interpolated along the row). A plane's score is the NCC of each band of 12 rows of the region,
// the worst quarter of the bands dropped, averaged (one NCC over all in regions under 3 bands):
// unmatched ground joined to a facet's region beyond an eave without contour would rule one NCC
// over all of it. When the best plane scores at least minRegionScore, uniqueness above its best
// 2 px or more away, agrees within 1 px with minRingShare of the matches around the region, and
// minPixelShare of the region's pixels score at least minPixelScore on their own 7 x 7 window
// there, those pixels take the plane's disparity (within [dmin, dmax]) and that score. Regions no
// plane lines up (occluded ground, plain surfaces) stay unmatched.
// Returns the number of pixels matched.
int recoverSlantedFacets(const cv::Mat& left, const cv::Mat& right, const cv::Mat& edges,
                         const SlantedFacetSettings& settings, int dmin, int dmax,
                         cv::Mat& disparity, cv::Mat& score);

}  // namespace delineo::stereo::detail
