#pragma once
// Per-pixel search intervals of a pyramid level from the coarser level's validated disparities
// (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

// Search intervals of a level from the validated disparities of the next coarser level: the
// min..max of the valid coarse disparities in the 3x3 neighbourhood of the parent pixel, doubled,
// ± margin. Where that neighbourhood holds no valid disparity (the parent was rejected), the
// same from a wider 9x9 neighbourhood: a rejected pixel lies on the surfaces
// around it far more often than anywhere in the range, and searching the full range there made
// the finer level both slower and more prone to wrong peaks. Where that one is empty too, the
// same from the widest neighbourhood (25x25 coarse pixels above the finest level, 33x33 for the
// finest); only when that is empty as well is the level's full range searched (as in the paper).
// Such wider neighbourhoods say less about the pixel: their intervals get 7 px more on each
// side. Rejected coarse pixels cluster on large weakly textured roofs, whose true value
// then often lay just outside the interval, a border peak that was rejected (sim 1000²/128 d:
// density 84.6 → 85.2 %, bad-1 1.55 → 1.43 %; 8+ raised the 600² roofRMS1 to 0.250–0.252 px).
//
// With `widenNearRejected`, a pixel whose coarse 3x3 neighbourhood holds a rejected pixel gets the
// widest neighbourhood's interval (the paper gives the full range to the rejected pixels only):
// next to a rejected pixel the coarse disparities are the least sure (a tree's carried into the
// roof beside it, 2000²), and a wrong interval is never left again. Only above the finest level:
// there the finest level's repeated seams lined up elsewhere (1000² / 128 d). The widest
// neighbourhood (50 px at the finer level) holds the surfaces on both sides of such a boundary;
// the full range there (41 % of the pixels of the level below the finest at 1000² / 128 d) cost a
// fifth of the matching's time with the same targets met (docs/stereo.md, step 4).
//
// `coarse`: CV_32F, NaN where rejected; `size`: the level's size (twice the coarse one, ±1);
// `lo`, `hi`: out, CV_32S, the inclusive interval of each pixel within dmin..dmax.
void intervalsFromCoarse(const cv::Mat& coarse, cv::Size size, int dmin, int dmax, int margin,
                         bool widenNearRejected, int threads, cv::Mat& lo, cv::Mat& hi);

// The pixels of a level whose window lies on one surface by the next coarser level's validated
// map `coarse` (CV_32F, NaN where rejected): every coarse pixel within `radius` (a square
// neighbourhood) of the pixel's parent validated, the image's border counting as rejected, and
// their disparities within `spread` coarse px of each other. CV_8U at `size` (twice the coarse
// one, ±1): 1 there, 0 elsewhere. Such a window holds no depth step the coarse level saw; a
// rejected coarse pixel (an occlusion, a surface neither view matched) may hide one.
cv::Mat oneSurfacePixels(const cv::Mat& coarse, cv::Size size, int radius, float spread,
                         int threads);

}  // namespace delineo::stereo::detail
