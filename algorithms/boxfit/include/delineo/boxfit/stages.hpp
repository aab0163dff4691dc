#pragma once
// The stages of box-fitting, one function each, in region-of-interest coordinates (pixel (i, j)
// of the ROI). fitBoxes() chains them; they are public for tests and benchmarks.
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/boxfit/box_fitting.hpp"
#include "delineo/boxfit/params.hpp"
#include "delineo/core/geometry.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::boxfit {

// ---- 1. Building segment from the DEM -------------------------------------------------------

// No-data gaps filled along rows (then columns): a gap takes the lower of the heights at its two
// ends, since a gap beside a wall is ground hidden in the other view. CV_32F; all-NaN stays NaN.
cv::Mat fillHeightGaps(const cv::Mat& heights);

// The local ground: a grey opening of the (median-filtered) heights with a square of side
// `window` px, computed at a reduced scale. An opening keeps planar slopes and removes anything
// narrower than the square (buildings, trees). CV_32F, same size.
cv::Mat localGround(const cv::Mat& filledHeights, int window);

// The roof's height above the ground inside `mask` (CV_8U): the peak of the histogram (0.25 m
// bins smoothed over ±1 m) of the heights >= minHeight, each pixel weighted by its distance to
// the mask's border (the centre of an operator's rectangle is the building, its rim may be a
// neighbour). NaN when fewer than 20 pixels are that high.
double roofLevel(const cv::Mat& aboveGround, const cv::Mat& mask, double minHeight);

// The building segment: heights above the ground between threshold-fraction x roofHeight and
// (1 + roof-band) x roofHeight + min-height, within `leash` px of `initMask`, holes smaller than
// min-area filled, eroded by erosion-radius; the component overlapping `initMask` most (at least
// min-area px) is kept and grown back by the erosion radius inside the thresholded mask.
// CV_8U 255/0; all zero when no component qualifies.
cv::Mat buildingSegment(const cv::Mat& aboveGround, const cv::Mat& initMask, double roofHeight,
                        const BoxFitParams& params);

// Whole-image mode: masks (CV_8U, image size) of the connected regions higher than min-height
// above the ground that keep at least min-area px after the erosion, grown back by its radius.
std::vector<cv::Mat> candidateRegions(const cv::Mat& aboveGround, const BoxFitParams& params);

// Canny edges (CV_8U 255/0) of the bilateral-filtered image: thresholds relative to the median
// gradient of `image` (any one-channel type, NaN = 0).
cv::Mat boxEdges(const cv::Mat& image, const BoxFitParams& params);

// ---- 2. Seeds from the skeleton -------------------------------------------------------------

struct Seed {
  cv::Point point;     // a skeleton pixel (the piece's pixel nearest its centre of mass)
  double depth = 0.0;  // px, distance from the seed to the segment's border
  double window = 0.0; // px, side of the square window its box grows in
};

struct SkeletonSeeds {
  cv::Mat skeleton;  // CV_8U 255 on the one-pixel-wide skeleton
  int junctions = 0;
  std::vector<Seed> seeds;  // deepest first
};

// Skeleton (Zhang-Suen thinning) of the segment, split at its junctions (pixels with more than
// two skeleton neighbours) and into pieces of piece-length px; each piece's centre of mass
// (snapped to the piece) is a seed. A segment whose skeleton gives no piece gets one seed at its
// deepest pixel.
SkeletonSeeds skeletonSeeds(const cv::Mat& segment, const BoxFitParams& params);

// Seeds for the parts of the segment that the boxes grown from the skeleton leave uncovered (a
// short wing whose spur was too short to seed, a corner): the residual opened with a disk of
// erosion-radius px, one seed at the deepest pixel of each piece of at least min-area / 5 px
// and 3 px deep. `boxes` in ROI coordinates.
std::vector<Seed> uncoveredSeeds(const cv::Mat& segment, const std::vector<Box>& boxes,
                                 const BoxFitParams& params);

// ---- 3. Boxes -------------------------------------------------------------------------------

struct BoxFitting {
  std::vector<Box> boxes;  // ROI coordinates, kept boxes only
  int seedsSkipped = 0;
  int anglesEvaluated = 0;
  double mainOrientationDeg = 0.0;
  int boxesAtMainOrientation = 0;
  core::RunStatus status = core::RunStatus::Completed;
};

// Grows one box per seed over the sweep of orientations and keeps, per seed, the orientation of
// least energy (mean cost of the box sides: capped distance to the nearest edge plus the
// segment's disagreement, see SideCosts in src/boxes.cpp), the largest box among equals.
// `segment` and `edges`
// are CV_8U of the ROI's size; `imageBorder` says which sides of the ROI are the image's border
// (left, top, right, bottom), along which a box side needs no edge.
BoxFitting fitSeedBoxes(const cv::Mat& segment, const cv::Mat& edges,
                        const std::vector<Seed>& seeds, const BoxFitParams& params,
                        const cv::Vec4b& imageBorder = {0, 0, 0, 0},
                        core::Progress* progress = nullptr);

// ---- 4. Outline -----------------------------------------------------------------------------

// The boxes filled (at twice the resolution), groups of boxes that do not touch joined by the
// pieces of `segment` (CV_8U, ROI size; may be empty) no box covers, closed with a disk of
// closing-radius px; the
// largest region's border, with its holes of at least min-hole-area px², cut at its corners and
// into pieces of at most refine-length px, one least-squares line per piece, collinear
// neighbours merged, consecutive lines intersected. ROI coordinates. Empty when no box.
core::Polygon mergeBoxes(const std::vector<Box>& boxes, cv::Size roiSize,
                         const BoxFitParams& params, const cv::Mat& segment = {},
                         int* mergedArea = nullptr);

// The boxes an outline is made of: largest first, a box is kept when it covers at least
// `minShare` of its own area that the boxes kept before it do not (the others add nothing an
// operator could see). ROI coordinates; the order of the kept boxes is the input's.
std::vector<Box> essentialBoxes(const std::vector<Box>& boxes, cv::Size roiSize, double minShare = 0.05);

}  // namespace delineo::boxfit
