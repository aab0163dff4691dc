#pragma once
// The adaptive matcher's pyramid levels matched coarse to fine (internal to delineo_stereo): at
// each level the left view, the right view on the pixels the left matches point to, the
// symmetric validation and the step cut; the validated maps guide the next finer level.
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/progress.hpp"
#include "delineo/stereo/match.hpp"
#include "level_matcher.hpp"

namespace delineo::stereo::detail {

// One level of the image pyramid: both images grey-mapped and centred (nodata 0), their
// validity (CV_8U 0/1), their contours, and the level's disparity range.
struct PyramidLevel {
  cv::Mat left, right, leftValid, rightValid, leftEdges, rightEdges;
  int dmin = 0, dmax = 0;
};

// The finest level's working buffers, kept past the levels to be released beside the fill
// rather than alone at the end of the last level.
struct FinestLevelBuffers {
  LevelInput left, right;
  cv::Mat rightLo, rightHi;
  LevelPreparations shared;
  LevelOutput mirrored;
};

// The maps of the level matched last (once all are, the finest): the validated disparities
// (CV_32F, NaN = rejected), which guide the next finer level, both views' outputs (the right one
// unmirrored, without scores), and the finest level's working buffers.
struct LevelMaps {
  cv::Mat validatedLeft, validatedRight;
  LevelOutput leftOut, rightOut;
  FinestLevelBuffers finestBuffers;
};

// Matches the levels of `pyramid` from the coarsest (its last) to the finest (its first), the
// progress going from 0 to `levelsShare`. Returns false when canceled (`maps` incomplete then).
bool matchLevelsCoarseToFine(const std::vector<PyramidLevel>& pyramid, const MatchParams& p,
                             int threads, double levelsShare, core::Progress* progress,
                             LevelMaps& maps);

}  // namespace delineo::stereo::detail
