// Which finest-level matches keep the coarser level's left/right check (internal
// coarselyChecked).
#include <gtest/gtest.h>

#include <cmath>

#include "coarse_check.hpp"

namespace delineo::stereo::detail {
namespace {

// A coarse map of one smooth surface at `value` and a fine level twice its size whose matches
// all lie at 2 · value + offset with NCC `score`.
struct Levels {
  cv::Mat coarse;
  LevelOutput fine;
};

Levels smoothSurface(float value, float offset, float score) {
  Levels l;
  l.coarse = cv::Mat(12, 16, CV_32F, cv::Scalar(value));
  l.fine.disparity = cv::Mat(24, 32, CV_32F, cv::Scalar(2 * value + offset));
  l.fine.score = cv::Mat(24, 32, CV_32F, cv::Scalar(score));
  l.fine.lineShift = cv::Mat::zeros(24, 32, CV_32F);
  return l;
}

int keptIn(const cv::Mat& kept, const cv::Rect& r) {
  return cv::countNonZero(kept(r));
}

TEST(CoarseCheck, KeepsConfidentMatchesThatAgreeWithASmoothValidatedSurface) {
  const Levels l = smoothSurface(5.0F, 0.4F, 0.95F);
  const cv::Mat kept = coarselyChecked(l.coarse, l.fine, 0.9, 2);
  ASSERT_EQ(kept.size(), l.fine.disparity.size());
  // Every fine pixel whose parent is not on the coarse border (whose 3x3 neighbourhood leaves
  // the map: not all of it validated).
  const cv::Rect inner(2, 2, 28, 20);
  EXPECT_EQ(keptIn(kept, inner), inner.area());
  EXPECT_EQ(cv::countNonZero(kept), inner.area());
}

TEST(CoarseCheck, ChecksAgainLowScoresAndMatchesOffTheCoarserSurface) {
  const cv::Rect inner(2, 2, 28, 20);
  Levels l = smoothSurface(5.0F, 0.4F, 0.85F);
  EXPECT_EQ(cv::countNonZero(coarselyChecked(l.coarse, l.fine, 0.9, 1)), 0);
  l = smoothSurface(5.0F, 1.5F, 0.95F);  // 1.5 px off twice the parent
  EXPECT_EQ(cv::countNonZero(coarselyChecked(l.coarse, l.fine, 0.9, 1)), 0);
  l = smoothSurface(5.0F, 0.4F, 0.95F);
  l.fine.disparity.at<float>(10, 10) = NAN;  // unmatched: nothing to keep
  EXPECT_EQ(keptIn(coarselyChecked(l.coarse, l.fine, 0.9, 1), inner), inner.area() - 1);
}

TEST(CoarseCheck, ChecksAgainNextToARejectedOrSteppingCoarsePixel) {
  Levels l = smoothSurface(5.0F, 0.4F, 0.95F);
  l.coarse.at<float>(5, 5) = NAN;  // rejected (an occlusion, say)
  // Its parent neighbourhoods: coarse 4..6 x 4..6, fine 8..13 x 8..13.
  cv::Mat kept = coarselyChecked(l.coarse, l.fine, 0.9, 2);
  EXPECT_EQ(keptIn(kept, cv::Rect(8, 8, 6, 6)), 0);
  EXPECT_EQ(keptIn(kept, cv::Rect(16, 2, 14, 20)), 14 * 20);
  l = smoothSurface(5.0F, 0.4F, 0.95F);
  l.coarse.at<float>(5, 5) = 6.5F;  // a depth step of 1.5 coarse px
  kept = coarselyChecked(l.coarse, l.fine, 0.9, 2);
  EXPECT_EQ(keptIn(kept, cv::Rect(8, 8, 6, 6)), 0);
  EXPECT_EQ(keptIn(kept, cv::Rect(16, 2, 14, 20)), 14 * 20);
}

}  // namespace
}  // namespace delineo::stereo::detail
