// Small isolated regions of a disparity map removed (internal removeSpeckles).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

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

}  // namespace
}  // namespace delineo::stereo::detail
