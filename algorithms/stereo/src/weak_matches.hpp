#pragma once
// Weak matches beside depth steps rejected (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct WeakMatchSettings {
  double minScore = 0.8;  // NCC: a match beside a step scoring below this is rejected (0 = off)
  int radius = 3;         // px: a pixel is beside a step when the valid disparities of its
                          //   (2 radius + 1)² neighbourhood span at least minStep
  double minStep = 3.0;   // px of disparity
  int threads = 1;        // workers over bands of rows (same result on any number)
};

// Beside a depth step a window that reached the far surface can carry its disparity a few pixels
// into the near one, and the left/right check passes it when the right view's window does the
// same (sim seed 7 1000²: a plain roof's 4 bottom rows took the ground's 3 for 35.3). Such matches
// peak lower than those of windows that stay on one surface: a match whose score is below
// minScore, whose neighbourhood holds a step, and whose disparity is nearer the neighbourhood's
// lowest than its highest (the far side's) is made unmatched (NaN in `disparity` and `score`),
// and the step's gap is then closed by the snapping on the image contour. Weak near-side matches
// are kept: a roof carried onto the ground is what the snapping cuts back, and rejecting them too
// left roof corners unmatched (sim seed 14 600² edge 90.6 -> 89.0 %, against 90.3 % with the far
// side only). Pixels scoring exactly `fillScore` (set by the fill, not matched) are kept.
// `candidates` (CV_8U, non-zero = may be rejected; empty = every pixel) restricts the test, as
// for the second, wider pass over plain pixels (see MatchParams::plainStepMinScore).
// Returns the number of pixels rejected.
int rejectWeakMatchesBesideSteps(const WeakMatchSettings& settings, float fillScore,
                                 cv::Mat& disparity, cv::Mat& score,
                                 const cv::Mat& candidates = cv::Mat());

struct UnmatchedPlainSettings {
  double minScore = 0.5;  // NCC: a match beside such a region scoring below this is rejected
                          //   (0 = off)
  int radius = 5;         // px: beside = within this Chebyshev distance of the region
  int minArea = 500;      // px: smaller unmatched plain regions are left alone
  int threads = 1;        // workers over bands of rows (same result on any number)
};

// A plain region the fill left unmatched (at least minArea 4-connected pixels that are plain in
// `plain`, CV_8U non-zero, and unmatched) is a surface no disparity could be told for: a roof and
// the ground beside it of one grey. The windows of the surface beside it that reached into it
// carried that surface's disparity across its outline with a weak peak (sim seed 15 1000²: the
// ground's matches 4 px into a plain roof at NCC 0.3-0.4, 42 px off, three of them 74 % of the
// roof's squared error). Matches on plain pixels within `radius` of such a region that score below
// minScore are made unmatched (NaN in `disparity` and `score`); pixels scoring exactly
// `fillScore` (set by the fill) are kept. Returns the number of pixels rejected.
int rejectWeakMatchesBesideUnmatchedPlain(const UnmatchedPlainSettings& settings, float fillScore,
                                          const cv::Mat& plain, cv::Mat& disparity, cv::Mat& score);

}  // namespace delineo::stereo::detail
