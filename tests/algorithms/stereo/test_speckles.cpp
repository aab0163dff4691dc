// Small isolated regions of a disparity map removed (internal removeSpeckles).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/nan_mask.hpp"
#include "speckles.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

int matchedCount(const cv::Mat& disparity) {
  int n = 0;
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) n += std::isfinite(disparity.at<float>(y, x)) ? 1 : 0;
  }
  return n;
}

TEST(RemoveSpeckles, RemovesSmallIslandsAndKeepsSurfaces) {
  cv::Mat disparity(60, 80, CV_32F, cv::Scalar(kNaN));
  disparity(cv::Rect(0, 0, 30, 30)).setTo(10.0F);  // a surface, 900 px
  disparity(cv::Rect(10, 10, 3, 3)).setTo(40.0F);  // a wrong island inside it, 9 px
  disparity(cv::Rect(50, 40, 4, 4)).setTo(25.0F);  // an isolated blob, 16 px
  cv::Mat score(disparity.size(), CV_32F, cv::Scalar(0.8));
  score.setTo(kNaN, core::nanMask(disparity));
  EXPECT_EQ(removeSpeckles(disparity, score, 20, 2.0), 9 + 16);
  EXPECT_TRUE(std::isnan(disparity.at<float>(11, 11)));
  EXPECT_TRUE(std::isnan(score.at<float>(11, 11)));
  EXPECT_TRUE(std::isnan(disparity.at<float>(41, 51)));
  EXPECT_EQ(disparity.at<float>(5, 5), 10.0F);
  EXPECT_EQ(matchedCount(disparity), 900 - 9);
}

TEST(RemoveSpecklesConnectivity, KeepsADiagonalStaircaseAndSlopes) {
  // The matched rim of an unmatched roof along a slanted outline: two pixels a row, each row
  // shifted by two, so rows touch only corner to corner (4-connectivity would cut every row).
  cv::Mat disparity(40, 100, CV_32F, cv::Scalar(kNaN));
  for (int y = 0; y < 30; ++y) {
    disparity.at<float>(y, 2 * y) = 54.0F;
    disparity.at<float>(y, 2 * y + 1) = 54.2F;
  }
  // A slope of 1.5 px a column over 40 px: neighbours within the range, one region.
  for (int x = 0; x < 40; ++x) disparity.at<float>(35, 60 + x) = 1.5F * static_cast<float>(x);
  cv::Mat noScore;
  EXPECT_EQ(removeSpeckles(disparity, noScore, 20, 2.0), 0);
  EXPECT_EQ(matchedCount(disparity), 60 + 40);
  // With a range below the slope's step, every pixel of the slope is its own region.
  EXPECT_EQ(removeSpeckles(disparity, noScore, 20, 1.0), 40);
}

// The regions of `disparity` smaller than maxSize by a plain flood fill (the reference).
cv::Mat smallRegions(const cv::Mat& disparity, int maxSize, float range) {
  cv::Mat label(disparity.size(), CV_32S, cv::Scalar(-1));
  cv::Mat small(disparity.size(), CV_8U, cv::Scalar(0));
  std::vector<cv::Point> region;
  for (int y0 = 0; y0 < disparity.rows; ++y0) {
    for (int x0 = 0; x0 < disparity.cols; ++x0) {
      if (!std::isfinite(disparity.at<float>(y0, x0)) || label.at<int>(y0, x0) >= 0) continue;
      region.assign(1, {x0, y0});
      label.at<int>(y0, x0) = 1;
      for (size_t k = 0; k < region.size(); ++k) {
        const cv::Point p = region[k];
        for (int v = -1; v <= 1; ++v) {
          for (int u = -1; u <= 1; ++u) {
            const cv::Point q(p.x + u, p.y + v);
            if (q.x < 0 || q.y < 0 || q.x >= disparity.cols || q.y >= disparity.rows ||
                label.at<int>(q) >= 0 ||
                !(std::abs(disparity.at<float>(q) - disparity.at<float>(p)) <= range)) {
              continue;
            }
            label.at<int>(q) = 1;
            region.push_back(q);
          }
        }
      }
      if (static_cast<int>(region.size()) < maxSize) {
        for (const cv::Point& p : region) small.at<uchar>(p) = 255;
      }
    }
  }
  return small;
}

TEST(RemoveSpecklesThreads, SameRemovalsInBandsOfRows) {
  // Random patches of a few disparities: many regions cross the band borders, some through a
  // single diagonal neighbour.
  cv::Mat base(301, 257, CV_32F);
  cv::RNG rng(7);
  for (int y = 0; y < base.rows; ++y) {
    for (int x = 0; x < base.cols; ++x) {
      const int k = rng.uniform(0, 10);
      base.at<float>(y, x) = k < 3 ? kNaN : static_cast<float>(4 * (k % 3));
    }
  }
  const cv::Mat expected = smallRegions(base, 20, 2.0F);
  const int expectedCount = cv::countNonZero(expected);
  ASSERT_GT(expectedCount, 0);
  for (const int threads : {1, 2, 3, 8}) {
    cv::Mat banded = base.clone(), bandedScore = base.clone();
    EXPECT_EQ(removeSpeckles(banded, bandedScore, 20, 2.0, threads), expectedCount);
    const cv::Mat removed = core::nanMask(banded) & ~core::nanMask(base);
    EXPECT_EQ(cv::countNonZero(removed != expected), 0) << threads << " threads";
    EXPECT_EQ(cv::countNonZero(core::nanMask(bandedScore) != core::nanMask(banded)), 0);
  }
}

}  // namespace
}  // namespace delineo::stereo::detail
