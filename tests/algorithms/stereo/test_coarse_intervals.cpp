// Search intervals of a pyramid level from the coarser level (internal intervalsFromCoarse).
#include <gtest/gtest.h>

#include <limits>
#include <utility>

#include <opencv2/core.hpp>

#include "coarse_intervals.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kDmin = 0, kDmax = 64, kMargin = 2;

struct Intervals {
  cv::Mat lo, hi;
  // The interval of the finer pixels under coarse pixel (cx, cy) (all four alike).
  std::pair<int, int> at(int cx, int cy) const {
    const int l = lo.at<int>(2 * cy, 2 * cx), h = hi.at<int>(2 * cy, 2 * cx);
    EXPECT_EQ(lo.at<int>(2 * cy + 1, 2 * cx + 1), l);
    EXPECT_EQ(hi.at<int>(2 * cy + 1, 2 * cx + 1), h);
    return {l, h};
  }
};

Intervals intervals(const cv::Mat& coarse, bool fullNearRejected, int threads = 1) {
  Intervals out;
  intervalsFromCoarse(coarse, {2 * coarse.cols, 2 * coarse.rows}, kDmin, kDmax, kMargin,
                      fullNearRejected, threads, out.lo, out.hi);
  return out;
}

TEST(IntervalsFromCoarse, TheParentsNeighbourhoodDoubledWithTheMargin) {
  cv::Mat coarse(10, 10, CV_32F, cv::Scalar(10.0));
  coarse.at<float>(3, 3) = 12.25F;
  coarse.at<float>(8, 1) = 40.0F;  // doubled past dmax: clamped
  const Intervals iv = intervals(coarse, false);
  EXPECT_EQ(iv.at(0, 0), std::make_pair(18, 22));
  EXPECT_EQ(iv.at(4, 4), std::make_pair(18, 25 + kMargin));  // ceil(24.5) + 2
  EXPECT_EQ(iv.at(2, 2), std::make_pair(18, 27));
  EXPECT_EQ(iv.at(1, 8), std::make_pair(18, kDmax));
}

TEST(IntervalsFromCoarse, ARejectedNeighbourhoodTakesTheWideOneAndAnEmptyOneTheFullRange) {
  cv::Mat coarse(20, 20, CV_32F, cv::Scalar(10.0));
  coarse(cv::Rect(2, 2, 5, 5)).setTo(kNaN);    // (4, 4)'s 3x3 all rejected, its 9x9 not
  coarse(cv::Rect(11, 0, 9, 20)).setTo(kNaN);  // (16, 10)'s 9x9 all rejected
  const Intervals iv = intervals(coarse, false);
  EXPECT_EQ(iv.at(4, 4), std::make_pair(20 - kMargin - 7, 20 + kMargin + 7));
  EXPECT_EQ(iv.at(16, 10), std::make_pair(kDmin, kDmax));
}

TEST(IntervalsFromCoarse, TheFullRangeBesideARejectedPixelOnlyWhenAsked) {
  cv::Mat coarse(10, 10, CV_32F, cv::Scalar(10.0));
  coarse.at<float>(3, 3) = kNaN;
  const Intervals narrow = intervals(coarse, false);
  const Intervals full = intervals(coarse, true, 3);
  // The rejected pixel and its 8 neighbours: from their valid neighbours, or the full range.
  for (int cy = 2; cy <= 4; ++cy) {
    for (int cx = 2; cx <= 4; ++cx) {
      EXPECT_EQ(narrow.at(cx, cy), std::make_pair(18, 22)) << cx << "," << cy;
      EXPECT_EQ(full.at(cx, cy), std::make_pair(kDmin, kDmax)) << cx << "," << cy;
    }
  }
  // One pixel farther, the same either way.
  EXPECT_EQ(full.at(5, 3), std::make_pair(18, 22));
  EXPECT_EQ(full.at(3, 1), std::make_pair(18, 22));
}

TEST(IntervalsFromCoarse, AnOddLevelSizeTakesTheLastCoarsePixel) {
  const cv::Mat coarse(6, 7, CV_32F, cv::Scalar(5.0));
  Intervals iv;
  intervalsFromCoarse(coarse, {15, 13}, kDmin, kDmax, kMargin, false, 2, iv.lo, iv.hi);
  ASSERT_EQ(iv.lo.size(), cv::Size(15, 13));
  EXPECT_EQ(iv.lo.at<int>(12, 14), 8);
  EXPECT_EQ(iv.hi.at<int>(12, 14), 12);
}

}  // namespace
}  // namespace delineo::stereo::detail
