#pragma once
// One resolution level of the adaptive-window matcher (internal to delineo_stereo).
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/progress.hpp"

namespace delineo::stereo::detail {

struct LevelInput {
  cv::Mat ref;         // CV_32F, reference image, values finite (nodata filled)
  cv::Mat other;       // CV_32F, image searched at x_other = x_ref - d, y_other = y_ref + dy
  cv::Mat refValid;    // CV_8U, 1 where ref holds data
  cv::Mat otherValid;  // CV_8U, 1 where other holds data
  cv::Mat refEdges;    // CV_8U, non-zero on contour pixels of ref
  cv::Mat lo, hi;      // CV_32S, per-pixel inclusive search interval (lo > hi: not searched)
  // CV_8U, optional: non-zero where the window lies on one surface by the coarser level
  // (oneSurfacePixels): the square window serves such a pixel even when its window holds
  // contours, and the adaptive shape only where a depth step may lie.
  cv::Mat oneSurface;
  int dmin = 0;        // the level's full range; an interval touching neither end of it whose
  int dmax = 0;        // peak lies on its border is rejected (true peak outside the interval)
};

struct LevelSettings {
  int window = 15;
  int lineShift = 1;  // 0 or 1
  int minShape = 25;
  double minScore = 0.3;
  bool subpixel = true;
  bool adaptive = true;
  // Uniqueness of the peak in wide intervals: a pixel searching at least uniqueMinInterval
  // disparities is rejected when a score 3 or more disparities from its peak comes within
  // uniqueMargin of it in 1 − NCC (second ≥ 1 − (1 − best)(1 + uniqueMargin)). Wide intervals
  // are the widest neighbourhood's next to rejected pixels (above the finest level) and the
  // fallbacks of rejected parents (coarse_intervals.hpp),
  // where repeated structure (a roof's seams, a tree beside a roof) can line up elsewhere; guided
  // intervals of a few disparities are not tested, nor, with automatic levels, the coarsest
  // level's range (at most about 20 disparities). 0 = off.
  int uniqueMinInterval = 24;
  double uniqueMargin = 0.1;
  int threads = 1;
};

struct LevelOutput {
  cv::Mat disparity;  // CV_32F, NaN = no match
  cv::Mat lineShift;  // CV_32F, sub-pixel shift across lines of the match
  cv::Mat score;      // CV_32F, NCC of the peak
};

// Window moments of one image as the matcher pads it: mean and standard deviation of each square
// window that holds only valid pixels and is not flat (`usable` 1), 0 elsewhere.
struct WindowMoments {
  cv::Mat mean, sd;  // CV_32F
  cv::Mat usable;    // CV_8U
};

// Working buffers of a view's matcher (padded inputs, contour and nodata words, prefix sums),
// left to the other view of the level, which overwrites them: the same sizes, and buffers new to
// the process cost a page fault per 4 KiB (~1.7 us each on the development machine; ~40 MB a
// view at 1 Mpx).
struct LevelScratch {
  LevelInput padded;
  cv::Mat blocked, blockedBits, nearEdge, otherInvalidBits, prefixB, prefixBB, otherSq;
  std::vector<uint16_t> freeColumns;
};

// What the matcher prepares from the two images of a level, kept for the other view: the right
// view's inputs are the left view's mirrored (ref = flip(right), other = flip(left), the masks
// likewise), so its moments and quantised copies are the left view's, mirrored in place.
struct LevelPreparations {
  double scale = 0;          // quantisation scale, the same for both images
  WindowMoments ref, other;  // of the view's ref and other images, padded
  cv::Mat refQ, otherQ;      // CV_16S, quantised copies, padded
  LevelScratch scratch;      // overwritten by the other view
  bool empty() const { return ref.mean.empty(); }
};

// Returns false when `progress` was canceled (outputs are then incomplete).
// `shared` (optional): empty, it receives this view's preparations; filled by the other view of
// the same level (`in` being that view's inputs mirrored), they are taken over from it (and
// modified: it keeps only the scale).
bool matchLevel(const LevelInput& in, const LevelSettings& settings, LevelOutput& out,
                core::Progress* progress, LevelPreparations* shared = nullptr);

// Sub-pixel offset of a peak from its 3x3 neighbourhood s[i][j], i = d-1..d+1, j = dy-1..dy+1
// (NaN where not evaluated): separable parabolas through the peak's row and column. A
// least-squares 2D quadratic over the 3x3 patch (the closed form of the paper's local
// interpolation) was measured noisier on weakly textured roofs (flat-roof RMS of the matches
// within 1 px: 0.285 vs 0.209 px on the simulated 400² scene), the d-offset being coupled to the
// poorly conditioned dy direction. Returns (offset along d, offset along dy), each in [-1, 1].
cv::Point2f subpixelPeak(const float s[3][3]);

}  // namespace delineo::stereo::detail
