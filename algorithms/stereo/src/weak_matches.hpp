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

}  // namespace delineo::stereo::detail
