// Sub-pixel noise averaged out on smooth surfaces (internal smoothSurfaces).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <opencv2/core.hpp>

#include "delineo/stereo/match.hpp"
#include "smoothing.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A sloped plane (0.05 px/px along x, 0.02 along y) around 20 px.
float plane(int x, int y) {
  return 20.0F + 0.05F * static_cast<float>(x) + 0.02F * static_cast<float>(y);
}

double rmsToPlane(const cv::Mat& disparity, const cv::Rect& area) {
  double sq = 0;
  int n = 0;
  for (int y = area.y; y < area.y + area.height; ++y) {
    for (int x = area.x; x < area.x + area.width; ++x) {
      const double e = disparity.at<float>(y, x) - plane(x, y);
      sq += e * e;
      ++n;
    }
  }
  return std::sqrt(sq / n);
}

cv::Mat noisyPlane(int rows, int cols, double sigma) {
  cv::Mat noise(rows, cols, CV_32F);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat disparity(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) disparity.at<float>(y, x) = plane(x, y) + noise.at<float>(y, x);
  }
  return disparity;
}

TEST(SmoothSurfaces, AveragesIndependentNoiseOnAPlane) {
  cv::Mat disparity = noisyPlane(60, 80, 0.15);
  const cv::Rect inner(2, 2, 76, 56);  // the pixels with a whole 5x5 neighbourhood
  const double before = rmsToPlane(disparity, inner);
  // A neighbour 1 px off the centre is a 4.7-sigma difference: nearly every window averages.
  EXPECT_GT(smoothSurfaces(disparity, 5, 1.0), inner.area() * 99 / 100);
  const double after = rmsToPlane(disparity, inner);
  // Independent noise over 25 pixels: sigma / 5 (0.03 px).
  EXPECT_NEAR(before, 0.15, 0.01);
  EXPECT_LT(after, 0.045);
}

TEST(SmoothSurfaces, KeepsAPlaneItself) {
  cv::Mat disparity = noisyPlane(40, 40, 0.0);
  const cv::Mat original = disparity.clone();
  smoothSurfaces(disparity, 5, 1.0);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 40; ++x)
      EXPECT_NEAR(disparity.at<float>(y, x), original.at<float>(y, x), 1e-4);
  }
}

TEST(SmoothSurfaces, DoesNotAverageAcrossAStepOrNextToUnmatchedPixels) {
  // Roof (30 px) on the left, ground (27 px) on the right of column 40, both noisy; one
  // unmatched pixel on the roof.
  cv::Mat disparity = noisyPlane(40, 80, 0.2);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 80; ++x) disparity.at<float>(y, x) += x < 40 ? 10.0F : 7.0F;
  }
  disparity.at<float>(20, 20) = kNaN;
  const cv::Mat original = disparity.clone();
  smoothSurfaces(disparity, 5, 1.0);
  for (int y = 2; y < 38; ++y) {
    // The two columns on each side of the step keep their own values: the step stays put.
    for (int x = 38; x < 42; ++x) EXPECT_EQ(disparity.at<float>(y, x), original.at<float>(y, x));
  }
  for (int y = 18; y <= 22; ++y) {
    for (int x = 18; x <= 22; ++x) {
      if (y == 20 && x == 20) {
        EXPECT_TRUE(std::isnan(disparity.at<float>(y, x)));
      } else {
        EXPECT_EQ(disparity.at<float>(y, x), original.at<float>(y, x));
      }
    }
  }
  // Away from both, averaged.
  EXPECT_NE(disparity.at<float>(10, 10), original.at<float>(10, 10));
  EXPECT_NE(disparity.at<float>(10, 60), original.at<float>(10, 60));
}

TEST(SmoothSurfaces, SameResultOnAnyNumberOfThreads) {
  cv::Mat one = noisyPlane(100, 90, 0.4);
  one.at<float>(50, 50) = kNaN;
  cv::Mat two = one.clone();
  const int n1 = smoothSurfaces(one, 7, 1.0, 1);
  const int n2 = smoothSurfaces(two, 7, 1.0, 2);
  EXPECT_EQ(n1, n2);
  EXPECT_EQ(cv::norm(one != two, cv::NORM_L1), 0.0);
}

TEST(SmoothSurfaces, WindowParameterMustBeOffOrOdd) {
  MatchParams p;
  p.smoothWindow = 4;
  EXPECT_THROW(p.validate(), std::exception);
  p.smoothWindow = 1;
  EXPECT_THROW(p.validate(), std::exception);
  p.smoothWindow = 0;
  EXPECT_NO_THROW(p.validate());
  p.smoothWindow = 7;
  EXPECT_NO_THROW(p.validate());
}

}  // namespace
}  // namespace delineo::stereo::detail
