#pragma once
// Matches that keep the coarser level's left/right check (internal to delineo_stereo).
#include <opencv2/core.hpp>

#include "level_matcher.hpp"

namespace delineo::stereo::detail {

// At the finest level, the left matches that keep the coarser level's left/right check instead
// of their own (MatchParams::coarseCheckScore): NCC ≥ minScore, within 1 px of twice their
// parent's validated disparity, and the parent's whole 3x3 neighbourhood validated within 1 px
// of each other. That is a smooth surface, where no depth step hides anything from one view:
// the fine check there removed noise matches only, and a confident match that agrees with the
// validated coarser surface is not one. Their right pixels then need no match of their own
// (about half of the right view's work at 1000² / 128 d). `coarse`: the coarser level's
// validated map (CV_32F, NaN = rejected), half the size (rounded up) of `fine`'s maps.
// CV_8U, 1 where kept.
cv::Mat coarselyChecked(const cv::Mat& coarse, const LevelOutput& fine, double minScore,
                        int threads);

}  // namespace delineo::stereo::detail
