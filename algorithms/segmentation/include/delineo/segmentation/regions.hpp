#pragma once
// Regions of homogeneous height on a DEM and their adjacency graph (after Baillard and Maître,
// docs/dem.md "Ground / above-ground segmentation and DTM").
//
// A region is a 4-connected set of pixels with a height where neighbours differ by at most a
// step threshold and are alike in steepness (a wall's ramp does not join the roof and the
// ground it links, see steepPixels()); small regions are then merged into the neighbour of closest mean height. The
// graph links regions that touch (4-adjacency) and regions on both sides of a no-data run along
// a row: in an epipolar pair the hidden parts beside walls run along the rows, and the two
// surfaces at the ends of such a run touch in the other view. Each link carries the height step
// between its two regions read a little inside each of them, so that a long region on a slope
// is compared with its neighbour where they meet, not through its mean.
#include <vector>

#include <opencv2/core.hpp>

namespace delineo::segmentation {

struct Region {
  int pixels = 0;
  double meanHeight = 0.0;  // m
  float minHeight = 0.0f;   // m
  float maxHeight = 0.0f;   // m
};

struct RegionLink {
  int a = 0, b = 0;         // region indices, a < b
  double step = 0.0;        // m, height of a minus height of b next to where they meet
  int contacts = 0;         // 4-neighbour pixel pairs and row runs across gaps measured
  bool acrossGap = false;   // linked only across a no-data run along a row
};

struct RegionGraph {
  cv::Mat labels;  // CV_32S, region index per pixel, -1 where the DEM has no height
  std::vector<Region> regions;
  std::vector<RegionLink> links;
  int gapLinks = 0;  // links that exist only across a no-data run
};

// CV_8U, 255 where the DEM's slope (central differences, one-sided beside no data) exceeds
// `maxRise` metres per pixel. In left-image geometry the walls the left view sees obliquely are
// ramps of about one pixel of disparity per pixel: much steeper than roofs and terrain.
cv::Mat steepPixels(const cv::Mat& dem, double maxRise);

// 4-connected regions of `dem` (CV_32F, m, NaN = no data) whose neighbouring pixels differ by at
// most `maxStep` metres and are both steep or both not (`steep` from steepPixels(); empty: no
// such split). Returns CV_32S labels 0..count-1, -1 on NaN; `count` receives the count.
cv::Mat growRegions(const cv::Mat& dem, double maxStep, const cv::Mat& steep, int& count);

// Merges every region of fewer than `minPixels` pixels, smallest first, into the 4-adjacent
// region of closest mean height (a region without neighbours stays). Relabels 0..n-1 and
// returns n.
int mergeSmallRegions(cv::Mat& labels, const cv::Mat& dem, int count, int minPixels);

// The regions' statistics and links. `bandPx`: how far inside each region (px) the heights of a
// link's step are read. `maxGapRunPx`: longest no-data run along a row (px) across which the
// regions at its two ends are linked (0: no links across gaps).
RegionGraph buildRegionGraph(const cv::Mat& labels, const cv::Mat& dem, int count, int bandPx,
                             int maxGapRunPx);

}  // namespace delineo::segmentation
