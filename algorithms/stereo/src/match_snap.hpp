#pragma once
// Depth steps moved onto the image contour between them (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct StepSnapSettings {
  double minStep = 2.0;     // px of disparity: smaller differences are slopes, not steps
  int maxGap = 16;          // px: most unmatched pixels between the two sides of a step
  int reach = 3;            // px: how far beyond the matched sides the contour is looked for
  double edgeSigmas = 4.0;  // × noise sigma: weakest contrast taken for the outline
};

// Along each row, two matched pixels a < b with only unmatched pixels between them (at most
// maxGap) and disparities at least minStep apart are the two sides of a depth step. Where the
// near side (larger disparity: the roof) meets the far one is the strongest contrast of the left
// image within [a − reach, b + reach] (|I(x+1) − I(x)| over 3 rows), when it is at least
// edgeSigmas noise sigmas. The near side is then made to end there: near pixels beyond it become
// unmatched and, when the near side is on the left (a roof's +x edge), the unmatched pixels up
// to the contour take its disparity (score `fillScore`). The far side is left alone, and so are
// the unmatched pixels before a near side on the right (seen by the left view only). `left`:
// the original left image (CV_32F, NaN = nodata). Returns the pixels changed.
int snapStepsToContours(const cv::Mat& left, const StepSnapSettings& settings, float fillScore,
                        cv::Mat& disparity, cv::Mat& score);

}  // namespace delineo::stereo::detail
