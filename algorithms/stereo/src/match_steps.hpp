#pragma once
// Depth steps without an image contour (internal to delineo_stereo): windows cut at the steps.
#include <opencv2/core.hpp>

#include "level_matcher.hpp"

namespace delineo::stereo::detail {

struct StepRefineSettings {
  int window = 15;        // px, side of the template window
  int minStep = 2;        // px, disparity difference between the two sides that makes a step
  double minScore = 0.3;  // NCC floor of the re-matched (cut) window
  int minShape = 25;      // px, smallest cut window matched
  // px, half height of the pixel column whose error locates the boundary. 0 (the pixel alone):
  // a taller column straddles diagonal outlines (sim 400², edge% 69.5 with 0, 67.2 with 1).
  int costRadius = 0;
  // px, longest gap of unmatched pixels between two validated pixels of one surface (ends
  // within gapTolerance) matched again around that surface; 0: none. Along the rows only:
  // gaps along the columns too (sim 600²) raised roofRMS1 to 0.250-0.251 px.
  int gapFill = 5;
  float gapTolerance = 1.0F;  // px
  // At a step whose +x side is nearer (larger d), the |Δd| columns just before the near surface
  // are seen by the reference view only (hidden behind it in the other): they are left out of
  // the boundary's cost and of both sides' windows, and left unmatched.
  bool occlusionStrip = true;
  // Steps along the columns too (outlines that run with the rows), where no row's segment
  // decided the pixel.
  bool columnSteps = true;
  int threads = 1;  // worker threads (1: the calling thread only)
};

// Depth steps that have no image contour (roof and ground of similar brightness: about half of
// the roof outlines of the simulated scenes) give the adaptive shape nothing to stop at, and the
// window straddling the step fattens the surface with the stronger texture. Where a row of
// `validated` (the reference map after the left/right check) steps by ≥ minStep between two
// validated pixels p < q, the segment [p − h, q + h] (h = window/2: the fattening reaches half a
// window) is re-decided:
//  1. the two sides' disparities da, db are read beyond the segment (first validated pixel);
//  2. the boundary β minimises Σ_{x≤β} eA(x) + Σ_{x>β} eB(x), e the squared grey difference of
//     the pixel (column y ± costRadius) under each side's disparity: both hypotheses are
//     scored on the same pixels, so a stronger texture on one side does not bias the choice (it
//     does when two windows' NCCs are compared: measured, the roof then grew by 1–3 px);
//  3. every pixel of a segment is matched again around its side's disparity (±2 px, parabola
//     sub-pixel) on its window cut at the steps: the pixels of the same side, plus validated
//     pixels outside the segments within 1.5 px of that side (the step acts as a contour, in
//     2D, so diagonal outlines are cut along their true direction).
// Segments holding a validated value on neither side (a third surface) are left alone.
// An outline that runs with the rows has no step along any row: the same is then done along
// the columns (columnSteps), where no row steps within half a window of the column's step, on
// the validated pixels no row's segment decided, with each pixel's error summed over x ± 2 of
// its row (one pixel alone placed the boundary on noise) and no occluded strip (the views are
// displaced along the rows only). Unmatched pixels are not given a side there: next to a
// diagonal outline they are mostly the ground hidden in the other view (sim 400² edge 95.8 →
// 92.1 % when they were).
// Gaps of one surface (≤ gapFill unmatched pixels of a row between two validated pixels whose
// values differ by ≤ gapTolerance) are matched again the same way around that surface: their
// first match failed the left/right check or the score floor with the full adaptive window
// and search interval; the cut window holds only that surface and the search ±2 px around it.
// `raw` (the reference map before validation) is updated in place: disparity, line shift (that
// of the side's source pixel), score (NaN disparity when the cut window's NCC < minScore); the
// caller validates it again. ref/other follow LevelInput: x_other = x_ref − d,
// y_other = y_ref + dy. `matchOnly` (CV_8U, optional): only its non-zero pixels are matched
// again. Returns the number of pixels whose value changed.
long refineDepthSteps(const cv::Mat& ref, const cv::Mat& other, const cv::Mat& refValid,
                      const cv::Mat& otherValid, const cv::Mat& validated,
                      const StepRefineSettings& settings, LevelOutput& raw,
                      const cv::Mat& matchOnly = cv::Mat());

}  // namespace delineo::stereo::detail
