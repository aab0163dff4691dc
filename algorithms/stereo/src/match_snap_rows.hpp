#pragma once
// Depth steps between rows (outlines that run with the epipolar lines) moved onto the image
// contour between them (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct RowStepSnapSettings {
  double minStep = 2.0;         // px of disparity: smaller differences are slopes, not steps
  int maxGap = 8;               // rows: most unmatched pixels between the two sides of a step
  int reach = 6;                // rows: how far beyond the matched sides the contour is looked for
  double edgeSigmas = 4.0;      // × noise sigma: weakest contrast taken for the outline
  int stripHalf = 7;            // px: half-width of the row strip a moved pixel is checked on
  double winRatio = 0.7;        // most error at the new disparity, × the one at the pixel's own
  double maxErrorSigmas = 4.0;  // noise sigmas: most error the new disparity may leave
  double gapErrorSigmas = 3.0;  // noise sigmas: most 1 × 3 error of a gap pixel given its side's
                                //   disparity up to the outline (0: the gap stays unmatched)
  int maxPasses = 3;            // passes over the map, until one moves nothing
  int threads = 1;              // workers over bands of columns (same result on any number)
};

// Along each column, two matched pixels a < b (rows) with only unmatched pixels between them (at
// most maxGap) and disparities at least minStep apart are the two sides of a step across rows: an
// outline that runs with the epipolar lines. Windows there mix both surfaces, and the textured
// side's disparity is carried a few rows into a weakly textured one (seed 2 1000²: a roof's top 4
// rows took the ground's 4–6 for its 30.7), which no check of the order of the views sees. The
// outline is the strongest local maximum of the vertical contrast (kStepSide rows on each side)
// within [a − reach + 1, b + reach], when at least edgeSigmas noise sigmas. When it lies beyond a
// side's last matched pixel, that side's pixels past it take the other side's disparity, from the
// gap outwards, while each is explained by it clearly better on its own row: the mean |left −
// mapped right| over its 1 × (2 stripHalf + 1) strip (one surface only, the outline running with
// the rows; the strip's pixels that held the new disparity are left out) at most winRatio × the
// one at its own disparity and at most maxErrorSigmas. The gap's unmatched pixels stay unmatched
// (passed over when the new disparity explains them within maxErrorSigmas). When the outline lies
// in the gap, each side's unmatched pixels up to it take that side's disparity, from the side
// towards the outline, while the mean |left − mapped right| of the pixel and its two row
// neighbours is at most gapErrorSigmas there (its row strip would cross a slanted outline): the
// views are displaced along the rows only, so nothing is hidden across them, and those pixels,
// often a roof's first rows, were left unmatched by windows that straddled the outline. The first
// pixel that fails stops the column's move. Moved pixels get `fillScore`. The passes repeat while
// they move pixels: a run carried farther than `reach` past its outline moves up to a nearer
// contrast first, and the next pass sees the outline from the new step (seed 9 600²: 7 carried
// rows, a dark line on the roof 5 rows below its outline). `sigma` is the left image's noise sigma.
// The right view's grey levels are mapped to the left's by the grey map of the matched pixel pairs
// (radiometricMapOfMatches; the images' moments when too few are matched). Returns the number of
// pixels changed.
int snapStepsAcrossRows(const cv::Mat& left, const cv::Mat& right, double sigma,
                        const RowStepSnapSettings& settings, float fillScore, cv::Mat& disparity,
                        cv::Mat& score);

}  // namespace delineo::stereo::detail
