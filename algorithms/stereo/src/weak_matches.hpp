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

// Beside a depth step a window that reached the other surface can carry that surface's
// disparity a few pixels over the outline, and the left/right check passes it when the right
// view's window does the same (sim seed 7 1000²: a plain roof's 4 bottom rows took the ground's
// 3 for 35.3). Such matches peak lower than those of windows that stay on one surface: matches
// whose score is below minScore and whose neighbourhood holds a step are made unmatched (NaN in
// `disparity` and `score`), and the steps' gaps are then closed by the snapping on image
// contours. Pixels scoring exactly `fillScore` (set by the fill, not matched) are kept. Returns
// the number of pixels rejected.
int rejectWeakMatchesBesideSteps(const WeakMatchSettings& settings, float fillScore,
                                 cv::Mat& disparity, cv::Mat& score);

}  // namespace delineo::stereo::detail
