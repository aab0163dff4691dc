#pragma once
// Depth steps moved onto the image contour between them (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct StepSnapSettings {
  double minStep = 2.0;     // px of disparity: smaller differences are slopes, not steps
  int maxGap = 16;          // px: most unmatched pixels between the two sides of a step
  int reach = 3;            // px: how far beyond the matched sides the contour is looked for
  double edgeSigmas = 4.0;  // × noise sigma: weakest contrast taken for the outline
  double checkSigmas = 3.0;  // × noise sigma: photometric check of the pixels changed (0 = off)
  int threads = 1;           // workers over bands of rows (same result on any number)
};

// Along each row, two matched pixels a < b with only unmatched pixels between them (at most
// maxGap) and disparities at least minStep apart are the two sides of a depth step. Where the
// near side (larger disparity: the roof) meets the far one is the strongest contrast of the left
// image within [a − reach, b + reach] (|I(x+1) − I(x)| over 3 rows), when it is at least
// edgeSigmas noise sigmas. The near side is then made to end there: near pixels beyond it become
// unmatched and, when the near side is on the left (a roof's +x edge), the unmatched pixels up
// to the contour take its disparity (score `fillScore`). The far side is left alone, and so are
// the unmatched pixels before a near side on the right (seen by the left view only).
// With `right` given and checkSigmas > 0, each change is checked on the pixel and its two
// vertical neighbours (mean |left − mapped right| in noise sigmas): a near pixel beyond the
// contour is cut only when the far disparity explains it better, and the extension stops at the
// first pixel that does not match at the near disparity within checkSigmas — the strongest
// contrast near a step is often texture, not the outline. `left`, `right`: the original images
// (CV_32F, NaN = nodata; `right` may be empty: unchecked). Returns the pixels changed.
int snapStepsToContours(const cv::Mat& left, const cv::Mat& right, const StepSnapSettings& settings,
                        float fillScore, cv::Mat& disparity, cv::Mat& score);

}  // namespace delineo::stereo::detail
