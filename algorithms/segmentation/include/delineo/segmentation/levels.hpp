#pragma once
// Height levels of one building piece (docs/dem.md, "Building vs vegetation, objects and
// proposals"): touching buildings of different heights come out of the classification as one
// 8-connected piece; the ground segmentation's regions split it into one part per building.
//
// Regions of the piece whose step along their common border (read `step-band` inside each side,
// median over the border) is under the critical height δ_0 form one level; wall regions (steep
// on most of their pixels: the ramps of walls in left-image geometry) join the level they touch
// whose height is nearest their top (the roof they hang from); a level smaller than the least
// building area, touching nothing outside the piece (a superstructure or an atrium inside its
// roof), or spanning more than 2 δ_0 from its 10th to its 90th height percentile (a wall's ramp
// less steep than the wall slope) joins the neighbour it shares most border with.
#include <opencv2/core.hpp>

namespace delineo::segmentation {

// The split's thresholds. They are other stages' parameters (the CLI's and the project's
// critical-height, step-band, wall-slope and min-building-area), so it has no flags of its own.
struct LevelSplit {
  double minStep = 2.0;        // m, δ_0: levels whose border step is at least this stay apart (0: no split)
  double stepBand = 2.0;       // m, how far inside each side of a border its step is read
  double wallSlope = 60.0;     // °, a region steeper than this on most of its pixels is a wall
  double minPartArea = 50.0;   // m², smaller levels join their neighbour
};

// Splits the non-zero pixels of `piece` (CV_8U) by `regions` (CV_32S region index, -1 none) and
// `ndsm` (CV_32F m, NaN no height), all of one size, `gsd` m per px. Returns CV_32S part labels
// 1..count (0 outside the piece); `count` receives the count (1 when nothing splits, 0 for an
// empty piece).
cv::Mat splitLevels(const cv::Mat& piece, const cv::Mat& regions, const cv::Mat& ndsm, double gsd,
                    const LevelSplit& rules, int& count);

}  // namespace delineo::segmentation
