#pragma once
// Dense disparity for an epipolar pair (Cord, Paparoditis & Jordan): normalised cross-correlation
// on contour-adaptive template shapes, ±1 line shift, sub-pixel peak, symmetric left/right
// validation and coarse-to-fine search intervals. OpenCV's StereoSGBM is the alternative
// backend with the same conventions.
//
// Conventions: left = reference image, x_right = x_left - d, disparity ranges are any integers
// (negative allowed). Output disparity is float32 with NaN for rejected/unmatched pixels.
#include <string>

#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::stereo {

struct MatchParams {
  std::string method = "adaptive";  // adaptive | sgbm
  // The search range belongs to the pair, not to the method: it is not among the visited
  // fields (the CLI's --dmin/--dmax, the project's disparityRange).
  int dmin = 0;                      // px, smallest disparity searched (x_right = x_left - d)
  int dmax = 64;                     // px, largest disparity searched
  int levels = 0;                    // pyramid levels, 0 = auto: ceil(1 + log2(range / 20))
  int window = 15;                   // px, odd side of the (maximal) template window
  double tolerance = 1.0;            // px, τ of the symmetric left/right validation
  double coarseCheckScore = 0.9;     // NCC from which a finest-level match on a smooth surface
                                     // keeps the coarser level's check (0 = all checked anew)
  bool squareOnOneSurface = true;    // two finest levels: square windows where the coarser
                                     // level saw one surface under the window (shapes elsewhere)
  bool stepCut = true;               // windows cut at the depth steps of the validated map
  int stepCutLevel = 10;             // coarsest pyramid level it runs on (0 = full resolution only)
  double edgeLow = 40.0;             // Canny low threshold on the 0..255-normalised image
  double edgeHigh = 100.0;           // Canny high threshold
  double edgeSigma = 1.0;            // px, Gaussian smoothing before Canny (same at each level)
  int edgeGap = 1;                   // px, largest contour gap closed at a chain's end (0 = off)
  int minShape = 25;                 // px, adaptive shapes smaller than this use the square window
  int margin = 2;                    // px, half-width added around the coarser level's disparity
  int lineShift = 1;                 // px, search ±lineShift lines (0 or 1) across the epipolar direction
  double minScore = 0.3;             // NCC below this is rejected (flat or unmatched windows)
  bool subpixel = true;              // sub-pixel peak from the 3x3 correlation neighbourhood
  bool adaptive = true;              // contour-adaptive shapes (false: plain square windows)
  bool fillRegions = true;           // flat regions take the disparity lining up their outline
  double stepMinScore = 0.8;         // NCC: far-side matches beside a depth step scoring below
                                     // this are rejected after the fill (0 = off)
  double plainStepMinScore = 0.6;    // NCC: the same within 7 px of a step, on plain pixels only
  double unmatchedPlainMinScore = 0.5;  // NCC: matches on plain pixels within 5 px of a plain
                                        // region left unmatched (500 px or more) scoring below
                                        // this are rejected (0 = off)
  double facetMaxSlope = 0.6;        // px/px: unmatched regions matched on slanted planes up to
                                     // this slope (0 = off)
  bool snapSteps = true;             // the near side of a depth step ends at the image contour
  bool orderingCheck = true;         // matches a nearer one hides in the right view are rejected
  int speckleSize = 40;              // px, matched regions smaller than this are removed (0 = off)
  int speckleRange = 2;              // px, largest disparity difference within one such region
  int smoothWindow = 5;              // px, odd side of the surface-smoothing window (0 = off)
  double smoothTolerance = 1.0;      // px, largest difference to the centre within that window
  double planeResidual = 0.4;        // px, a raised surface planar within this RMS takes its
                                     // fitted plane (0 = off)
  int planeMinArea = 300;            // px, smallest surface fitted with a plane
  int tile = 2048;                   // px, side of a tile's kept part: a larger image is matched
                                     // in overlapping tiles one after another, in the memory of
                                     // one tile (0 = always whole, else at least 64)
  int threads = 0;                   // worker threads, 0 = all cores

  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"method", "Method", "", "Matcher: adaptive (Cord et al.) or sgbm (OpenCV)",
                      0, 0, "adaptive|sgbm"},
      method);
    v(core::ParamInfo{"levels", "Pyramid levels", "",
                      "Resolution levels, 0 = automatic from the range (coarsest range ~20 px)",
                      0, 10},
      levels);
    v(core::ParamInfo{"window", "Template size", "px",
                      "Odd side of the maximal template window (paper: 15)", 3, 31},
      window);
    v(core::ParamInfo{"tolerance", "Validation tolerance", "px",
                      "Symmetric left/right consistency tolerance τ", 0, 10},
      tolerance);
    v(core::ParamInfo{"coarse-check-score", "Coarse-check score", "",
                      "At full resolution, a match whose NCC is at least this, within 1 px of "
                      "its validated coarser-level disparity, and whose coarser 3x3 "
                      "neighbourhood is all validated within 1 px (a smooth surface: nothing "
                      "there is hidden from one view) keeps that level's left/right check "
                      "instead of being checked again; 0 = every match checked at full "
                      "resolution",
                      0, 1},
      coarseCheckScore);
    v(core::ParamInfo{"square-on-one-surface", "Square windows on one surface", "",
                      "At the two finest levels, a pixel whose window lies on one surface by the "
                      "coarser level's validated map (every coarse disparity under the window "
                      "and 2 coarse pixels around it validated, all within 1 px of each other) "
                      "is matched on the square window even when contours cross it: they are "
                      "texture there, not depth steps. Off: the adaptive shape wherever a "
                      "contour is in the window (the paper)"},
      squareOnOneSurface);
    v(core::ParamInfo{"step-cut", "Cut windows at depth steps", "",
                      "Near depth steps of the validated map, locate the step along the row and "
                      "match again on windows cut there"},
      stepCut);
    v(core::ParamInfo{"step-cut-level", "Step-cut levels", "",
                      "Coarsest pyramid level of the step cut (0 = full resolution only, 10 = all)",
                      0, 10},
      stepCutLevel);
    v(core::ParamInfo{"edge-low", "Edge low threshold", "",
                      "Canny hysteresis low threshold on the 0..255-normalised image", 0, 1000},
      edgeLow);
    v(core::ParamInfo{"edge-high", "Edge high threshold", "",
                      "Canny hysteresis high threshold on the 0..255-normalised image", 0, 1000},
      edgeHigh);
    v(core::ParamInfo{"edge-sigma", "Edge smoothing", "px",
                      "Gaussian sigma before edge detection, at every pyramid level", 0, 10},
      edgeSigma);
    v(core::ParamInfo{"edge-gap", "Edge gap closing", "px",
                      "A contour chain's end is joined to the nearest contour pixel ahead of it "
                      "across at most this many missing pixels (a roof outline Canny broke where "
                      "its contrast dips lets the adaptive windows leak through); 0 = off",
                      0, 10},
      edgeGap);
    v(core::ParamInfo{"min-shape", "Minimal shape", "px",
                      "Adaptive shapes with fewer pixels fall back to the square window", 1, 961},
      minShape);
    v(core::ParamInfo{"margin", "Interval margin", "px",
                      "Half-width around the coarser level's disparity for the finer search", 0,
                      64},
      margin);
    v(core::ParamInfo{"line-shift", "Line shift", "px",
                      "Search ±N lines across the epipolar direction (paper: 1)", 0, 1},
      lineShift);
    v(core::ParamInfo{"min-score", "Minimal score", "",
                      "Matches whose NCC peak is below this are rejected", -1, 1},
      minScore);
    v(core::ParamInfo{"subpixel", "Sub-pixel", "", "Sub-pixel peak interpolation"}, subpixel);
    v(core::ParamInfo{"adaptive", "Adaptive shapes", "",
                      "Contour-adaptive template shapes (off: plain square windows)"},
      adaptive);
    v(core::ParamInfo{"fill-regions", "Fill flat regions", "",
                      "Unmatched pixels of a flat region (a textureless roof, where NCC is noise) "
                      "take the disparity of the matches around it that lines up its outline in "
                      "both views, when that is clear (their score is min-score)"},
      fillRegions);
    v(core::ParamInfo{"step-min-score", "Score beside depth steps", "",
                      "After the fill, a match whose NCC peak is below this, whose 7 x 7 "
                      "neighbourhood holds a depth step (valid disparities at least 3 px apart) "
                      "and whose disparity is on the step's far side is rejected: a window that "
                      "reached the ground carries its disparity into a roof with a weaker peak, "
                      "and the snapping then closes the gap on the image contour; 0 = off "
                      "(adaptive method)",
                      0, 1},
      stepMinScore);
    v(core::ParamInfo{"plain-step-min-score", "Score of plain pixels near depth steps", "",
                      "Then, a match on a plain pixel (5 x 5 standard deviation below 3 noise "
                      "sigmas) whose NCC peak is below this, whose 15 x 15 neighbourhood holds a "
                      "depth step and whose disparity is on the step's far side is rejected: a "
                      "plain roof's window that reached the ground across a contour the edge "
                      "detector missed; 0 = off (adaptive method)",
                      0, 1},
      plainStepMinScore);
    v(core::ParamInfo{"unmatched-plain-min-score", "Score beside unmatched plain regions", "",
                      "Then, a match on a plain pixel within 5 px of a plain region the fill left "
                      "unmatched (500 px or more: a roof and the ground beside it of one grey, "
                      "whose disparity nothing tells) whose NCC peak is below this is rejected: "
                      "the window of the surface beside it reached into it; 0 = off (adaptive "
                      "method)",
                      0, 1},
      unmatchedPlainMinScore);
    v(core::ParamInfo{"facet-max-slope", "Steepest slanted facet", "px/px",
                      "Then, each unmatched region between contours (100 px or more) is matched "
                      "as a whole on planes d = a + gx x + gy y with |gx|, |gy| up to this: a "
                      "steep roof facet, stretched or squeezed in the right view, finds no peak "
                      "with windows at one disparity. The best plane is kept when the region's "
                      "score there (the mean NCC of its bands of 12 rows, the worst quarter left "
                      "out) is at least 0.75 and 0.05 above its best 2 px or more away, when it "
                      "continues at least 30 % of the matches around the region, and when at "
                      "least 80 % of the region's pixels score 0.6 or more on their own 7 x 7 "
                      "windows (those pixels take it); 0 = off (adaptive method)",
                      0, 2},
      facetMaxSlope);
    v(core::ParamInfo{"snap-steps", "Snap depth steps to contours", "",
                      "Along each row, the near side of a depth step between two matched pixels "
                      "(at most 16 px apart) is made to end at the strongest contour of the left "
                      "image there, where the pixels changed match better that way (adaptive "
                      "method only)"},
      snapSteps);
    v(core::ParamInfo{"ordering-check", "Ordering check", "",
                      "Along each row, a match that a nearer match to its right hides in the right "
                      "view (its right-view position beyond that match's by more than 1 px, the "
                      "other at least 2 px nearer) is rejected: the left/right check passes a "
                      "far surface's disparity carried alike into a nearer one in both views"},
      orderingCheck);
    v(core::ParamInfo{"speckle-size", "Speckle size", "px",
                      "Connected matched regions (8-neighbours within speckle-range) smaller "
                      "than this are made unmatched, last; 0 = off (adaptive method; SGBM "
                      "keeps its own filter, 100 px within 2 px)",
                      0, 100000},
      speckleSize);
    v(core::ParamInfo{"speckle-range", "Speckle range", "px",
                      "Largest disparity difference between neighbours of one speckle region", 1,
                      1000},
      speckleRange);
    v(core::ParamInfo{"smooth-window", "Surface smoothing", "px",
                      "Last, a matched pixel whose whole N x N neighbourhood is matched and "
                      "within smooth-tolerance of it takes the neighbourhood's mean disparity "
                      "(averages the sub-pixel noise of flat and sloped surfaces; steps larger "
                      "than the tolerance are not touched); odd, 0 = off (adaptive method)",
                      0, 31},
      smoothWindow);
    v(core::ParamInfo{"smooth-tolerance", "Smoothing tolerance", "px",
                      "Largest disparity difference to the centre within a smoothed window", 0,
                      100},
      smoothTolerance);
    v(core::ParamInfo{"plane-residual", "Roof planes", "px",
                      "Last, a surface raised above what surrounds it (matched 4-neighbours "
                      "within 0.5 px of each other, most pixels around it 1.5 px or more lower) "
                      "whose trimmed least-squares plane fits it within this RMS takes the "
                      "plane's value on its inliers (removes the correlation noise of planar "
                      "roofs); 0 = off (adaptive method)",
                      0, 10},
      planeResidual);
    v(core::ParamInfo{"plane-min-area", "Roof plane area", "px",
                      "Smallest surface fitted with a plane", 10, 100000},
      planeMinArea);
    v(core::ParamInfo{"tile", "Tile size", "px",
                      "An image wider or taller than this is matched in overlapping tiles, one "
                      "after another, each keeping a part of at most this side: the memory is "
                      "that of one tile instead of the whole image's; 0 = always whole (at least "
                      "64 otherwise)",
                      0, 1000000},
      tile);
    v(core::ParamInfo{"threads", "Threads", "", "Worker threads, 0 = all cores", 0, 256},
      threads);
  }
  void validate() const;
};

struct MatchResult {
  cv::Mat disparity;  // CV_32F, left-image geometry, NaN = rejected or unmatched
  cv::Mat score;      // CV_32F, NCC of the retained match (min-score where filled by
                      // fill-regions), NaN where disparity is NaN
  int levelsUsed = 1;
  core::RunStatus status = core::RunStatus::Completed;
};

// Pyramid depth N = ceil(1 + log2(ΔP1 / ΔPN)) with ΔP1 = dmax - dmin and ΔPN = 20 px, at least 1.
int autoLevels(int dmin, int dmax);

// left/right: single-channel float32 (NaN = nodata) of the same size. Throws core::Error:
// InvalidParameter (dmin > dmax, bad parameters), MismatchedInputs (sizes), UnsupportedInput
// (empty or not float32). Returns status Canceled (and empty maps) when `progress` is canceled.
MatchResult matchStereo(const cv::Mat& left, const cv::Mat& right, const MatchParams& params,
                        core::Progress* progress = nullptr);

}  // namespace delineo::stereo
