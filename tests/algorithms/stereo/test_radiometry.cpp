// The grey-level map between the views (internal radiometry): from the matched pixel pairs it is
// the exposures' map even where the views see different things; from the images' moments it is
// not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "radiometry.hpp"

namespace delineo::stereo::detail {
namespace {

TEST(Radiometry, MatchedPairsGiveTheExposureMapWhereTheViewsSeeDifferentThings) {
  // Right = 0.92 · left + 6 on the surfaces both views see (disparity 10), noise sigma 2; the
  // left view's leftmost 60 columns hold a bright facade the right view does not see (there, a
  // dark one), which skews both images' moments but no matched pair.
  const int rows = 120, cols = 240, shift = 10;
  const double rightGain = 0.92, rightOffset = 6.0;
  cv::RNG rng(7);
  cv::Mat surface(rows, cols + shift, CV_32F);
  rng.fill(surface, cv::RNG::UNIFORM, 40.0, 160.0);
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  cv::Mat disparity(rows, cols, CV_32F, cv::Scalar(static_cast<float>(shift)));
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      left.at<float>(y, x) = surface.at<float>(y, x) + static_cast<float>(rng.gaussian(2.0));
      right.at<float>(y, x) = static_cast<float>(rightGain * surface.at<float>(y, x + shift) +
                                                 rightOffset + rng.gaussian(2.0));
    }
  }
  left(cv::Rect(0, 0, 60, rows)).setTo(230.0);
  right(cv::Rect(0, 0, 60 - shift, rows)).setTo(20.0);
  disparity(cv::Rect(0, 0, 60, rows)).setTo(std::numeric_limits<float>::quiet_NaN());

  // left ≈ gain · right + offset: the inverse of the right view's exposure map.
  const double gain = 1.0 / rightGain, offset = -rightOffset / rightGain;
  const auto [matchedGain, matchedOffset] =
      radiometricMapOfMatches(left, right, disparity, {1.0, 0.0});
  EXPECT_NEAR(matchedGain, gain, 0.01);
  EXPECT_NEAR(matchedOffset, offset, 1.0);
  // A grey level of 60 in the right view: where each map puts it in the left's levels.
  const double truth = gain * 60.0 + offset;
  EXPECT_NEAR(matchedGain * 60.0 + matchedOffset, truth, 0.5);
  const auto [imageGain, imageOffset] = radiometricMap(left, right, shift, shift);
  EXPECT_GT(std::abs(imageGain * 60.0 + imageOffset - truth), 3.0);

  // Too few matches: the fallback.
  cv::Mat none(rows, cols, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  const auto fallback = radiometricMapOfMatches(left, right, none, {1.5, 2.5});
  EXPECT_EQ(fallback.first, 1.5);
  EXPECT_EQ(fallback.second, 2.5);
}

TEST(Radiometry, WrongMatchesAtTheEndOfTheGreyRangeDoNotPullTheMatchesMap) {
  // The same exposures in both views, noise sigma 1.5: a weakly textured ground (grey 100 ± 8)
  // and a plain roof (140) matched right, and 10 % of the pairs wrong, a dark band (grey ~65)
  // matched to a plain wall only the right view shows (grey 40): a roof's value carried onto the
  // ground beside it. Those few pairs lie far from the others in the right view's grey, so the
  // moments of all pairs, and refits within 2.5 RMS of them, lean towards them (gain 0.887 and
  // offset 12.6 here).
  const int rows = 100, cols = 300;
  cv::RNG rng(5);
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      const double ground = 100.0 + rng.gaussian(8.0);
      double l = ground, r = ground;
      if (x >= 200 && x < 245) l = r = 140.0;  // the roof
      if (x >= 245 && x < 275) {               // the wrong pairs
        l = 65.0 + rng.gaussian(3.0);
        r = 40.0;
      }
      left.at<float>(y, x) = static_cast<float>(l + rng.gaussian(1.5));
      right.at<float>(y, x) = static_cast<float>(r + rng.gaussian(1.5));
    }
  }
  const cv::Mat disparity(rows, cols, CV_32F, cv::Scalar(0.0f));
  const auto [gain, offset] = radiometricMapOfMatches(left, right, disparity, {1.0, 0.0});
  EXPECT_NEAR(gain, 1.0, 0.02);
  EXPECT_NEAR(offset, 0.0, 2.0);
  // Where a grey level of 140 (the roof) and of 60 land in the left view's levels.
  EXPECT_NEAR(gain * 140.0 + offset, 140.0, 0.5);
  EXPECT_NEAR(gain * 60.0 + offset, 60.0, 1.0);
}

// Several workers give the same map as one, bit for bit (the sums are taken in one order), and
// the fallback is only computed when it is the answer.
TEST(Radiometry, MapOfMatchesIsTheSameOnAnyNumberOfThreads) {
  const int rows = 301, cols = 257;
  cv::RNG rng(11);
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F), disparity(rows, cols, CV_32F);
  rng.fill(left, cv::RNG::UNIFORM, 20.0, 220.0);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      const int d = x < 120 ? 4 : 9;
      disparity.at<float>(y, x) = rng.uniform(0, 10) == 0
                                      ? std::numeric_limits<float>::quiet_NaN()
                                      : static_cast<float>(d) + rng.uniform(-0.4f, 0.4f);
      const int xl = std::min(cols - 1, x + d);
      right.at<float>(y, x) =
          static_cast<float>(0.9 * left.at<float>(y, xl) + 5.0 + rng.gaussian(2.0));
    }
  }
  int fallbacks = 0;
  const auto fallback = [&] {
    ++fallbacks;
    return std::pair{1.0, 0.0};
  };
  const auto one = radiometricMapOfMatches(left, right, disparity, fallback, 1000, 1);
  for (const int threads : {2, 3}) {
    const auto many = radiometricMapOfMatches(left, right, disparity, fallback, 1000, threads);
    EXPECT_EQ(many.first, one.first) << threads;
    EXPECT_EQ(many.second, one.second) << threads;
  }
  EXPECT_EQ(fallbacks, 0);
  EXPECT_NEAR(one.first, 1.0 / 0.9, 0.02);
  // Too few pairs: the fallback, computed once.
  const auto few = radiometricMapOfMatches(left, right, disparity, fallback, rows * cols, 2);
  EXPECT_EQ(few.first, 1.0);
  EXPECT_EQ(fallbacks, 1);
  const auto [lo, hi] = matchedRange(disparity, 1);
  const auto [lo2, hi2] = matchedRange(disparity, 3);
  EXPECT_EQ(lo, lo2);
  EXPECT_EQ(hi, hi2);
  EXPECT_GE(lo, 3.6);
  EXPECT_LE(hi, 9.4);
}

// The bucket selection gives the element nth_element puts in the middle, on sets with heavy
// ties, a long tail, negative values, one value only, and both parities.
TEST(Radiometry, MiddleValueIsTheMiddleElement) {
  cv::RNG rng(7);
  const auto nthMiddle = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  for (const int n : {1, 2, 101, 4095, 4096, 20001, 250000}) {
    std::vector<double> uniform(static_cast<size_t>(n)), tied(static_cast<size_t>(n)),
        tailed(static_cast<size_t>(n)), constant(static_cast<size_t>(n), -3.25);
    for (int i = 0; i < n; ++i) {
      uniform[static_cast<size_t>(i)] = rng.uniform(-50.0, 200.0);
      tied[static_cast<size_t>(i)] = std::round(rng.uniform(0.0, 4.0));  // five values
      // Most within a grey level, a few thousand levels out: one bin would hold nearly all.
      tailed[static_cast<size_t>(i)] =
          i % 97 == 0 ? rng.uniform(1000.0, 5000.0) : std::abs(rng.gaussian(0.7));
    }
    for (const auto* values : {&uniform, &tied, &tailed, &constant}) {
      EXPECT_EQ(middleValue(*values), nthMiddle(*values)) << n;
      EXPECT_EQ(middleValue(*values, 3), nthMiddle(*values)) << n << ", 3 threads";
    }
  }
}

}  // namespace
}  // namespace delineo::stereo::detail
