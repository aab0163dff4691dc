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

TEST(IntervalsFromCoarse, ARejectedNeighbourhoodTakesTheWideOneThenTheWidestThenTheFullRange) {
  cv::Mat coarse(50, 50, CV_32F, cv::Scalar(10.0));
  coarse(cv::Rect(2, 2, 5, 5)).setTo(kNaN);     // (4, 4)'s 3x3 all rejected, its 9x9 not
  coarse(cv::Rect(40, 0, 10, 12)).setTo(kNaN);  // (45, 5)'s 9x9 all rejected, its 33x33 not
  coarse.at<float>(0, 30) = 12.0F;              // ... which holds 12 too (15 px left of it)
  coarse(cv::Rect(0, 16, 50, 34)).setTo(kNaN);  // (25, 33)'s 33x33 all rejected
  const Intervals iv = intervals(coarse, false);
  EXPECT_EQ(iv.at(4, 4), std::make_pair(20 - kMargin - 7, 20 + kMargin + 7));
  EXPECT_EQ(iv.at(45, 5), std::make_pair(20 - kMargin - 7, 24 + kMargin + 7));
  EXPECT_EQ(iv.at(25, 33), std::make_pair(kDmin, kDmax));
}

TEST(IntervalsFromCoarse, TheWidestRangeBesideARejectedPixelOnlyWhenAsked) {
  cv::Mat coarse(30, 30, CV_32F, cv::Scalar(10.0));
  coarse.at<float>(3, 3) = kNaN;
  coarse.at<float>(3, 14) = 13.0F;  // 9 to 12 coarse px right of the rejected pixel's 3x3
  const Intervals narrow = intervals(coarse, false);
  const Intervals widened = intervals(coarse, true, 3);
  // The rejected pixel and its 8 neighbours: from their valid neighbours, or from the 25x25
  // neighbourhood (which reaches the 13) with the wider margin.
  for (int cy = 2; cy <= 4; ++cy) {
    for (int cx = 2; cx <= 4; ++cx) {
      EXPECT_EQ(narrow.at(cx, cy), std::make_pair(18, 22)) << cx << "," << cy;
      EXPECT_EQ(widened.at(cx, cy), std::make_pair(20 - kMargin - 7, 26 + kMargin + 7))
          << cx << "," << cy;
    }
  }
  // One pixel farther, the same either way.
  EXPECT_EQ(widened.at(5, 3), std::make_pair(18, 22));
  EXPECT_EQ(widened.at(3, 1), std::make_pair(18, 22));
  // One valid pixel in a rejected level: its widened interval up to 12 coarse px from it, the
  // full range farther.
  cv::Mat oneValid(30, 30, CV_32F, cv::Scalar(kNaN));
  oneValid.at<float>(0, 29) = 10.0F;
  const Intervals sparse = intervals(oneValid, true);
  EXPECT_EQ(sparse.at(17, 12), std::make_pair(20 - kMargin - 7, 20 + kMargin + 7));
  EXPECT_EQ(sparse.at(16, 1), std::make_pair(kDmin, kDmax));
  EXPECT_EQ(sparse.at(3, 28), std::make_pair(kDmin, kDmax));
}

TEST(IntervalsFromCoarse, AnOddLevelSizeTakesTheLastCoarsePixel) {
  const cv::Mat coarse(6, 7, CV_32F, cv::Scalar(5.0));
  Intervals iv;
  intervalsFromCoarse(coarse, {15, 13}, kDmin, kDmax, kMargin, false, 2, iv.lo, iv.hi);
  ASSERT_EQ(iv.lo.size(), cv::Size(15, 13));
  EXPECT_EQ(iv.lo.at<int>(12, 14), 8);
  EXPECT_EQ(iv.hi.at<int>(12, 14), 12);
}

// A pixel's window lies on one surface when every coarse pixel within the radius of its parent
// is validated and their values lie within the spread: not near a step, a rejected pixel or
// the border; a gentle slope is one surface, a steeper one is not.
TEST(OneSurfacePixels, OnlyWhereTheWholeNeighbourhoodIsValidatedAndWithinTheSpread) {
  cv::Mat coarse(30, 40, CV_32F, cv::Scalar(10.0));
  coarse(cv::Rect(20, 0, 20, 15)).setTo(20.0);  // a step at column 20 (upper half)
  coarse.at<float>(24, 8) = kNaN;               // a rejected pixel
  for (int y = 15; y < 30; ++y) {
    for (int x = 20; x < 40; ++x) coarse.at<float>(y, x) = 30.0F + 0.05F * static_cast<float>(x);
  }
  for (int x = 30; x < 40; ++x) coarse.at<float>(20, x) += 0.2F * static_cast<float>(x - 29);
  const int radius = 2;
  const cv::Mat one = oneSurfacePixels(coarse, {80, 60}, radius, 0.5F, 2);
  ASSERT_EQ(one.size(), cv::Size(80, 60));
  ASSERT_EQ(one.type(), CV_8U);
  const auto at = [&](int cx, int cy) {
    // The four finer pixels under a coarse one agree.
    const uchar v = one.at<uchar>(2 * cy, 2 * cx);
    EXPECT_EQ(one.at<uchar>(2 * cy + 1, 2 * cx + 1), v) << cx << ", " << cy;
    return v;
  };
  EXPECT_EQ(at(10, 7), 1);   // inside the flat surface
  EXPECT_EQ(at(17, 7), 1);   // 3 px from the step
  EXPECT_EQ(at(18, 7), 0);   // 2 px from it
  EXPECT_EQ(at(21, 7), 0);   // on the step's other side, 1 px from it
  EXPECT_EQ(at(8, 21), 1);   // 3 px above the rejected pixel
  EXPECT_EQ(at(9, 23), 0);   // next to it
  EXPECT_EQ(at(1, 7), 0);    // its neighbourhood leaves the image
  EXPECT_EQ(at(2, 7), 1);    // it does not
  EXPECT_EQ(at(25, 25), 1);  // a slope of 0.05 px a pixel: 0.2 over the neighbourhood
  EXPECT_EQ(at(34, 20), 0);  // the row steeper by 0.2 px a pixel
  EXPECT_EQ(at(34, 17), 1);  // 3 rows from it
  // The odd size of a level takes the last coarse pixel.
  const cv::Mat odd = oneSurfacePixels(coarse, {81, 61}, radius, 0.5F, 1);
  EXPECT_EQ(odd.at<uchar>(60, 20), one.at<uchar>(59, 20));
}

}  // namespace
}  // namespace delineo::stereo::detail
