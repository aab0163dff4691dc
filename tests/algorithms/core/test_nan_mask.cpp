#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "delineo/core/nan_mask.hpp"

namespace {
using delineo::core::nanMask;
using delineo::core::numberMask;

// Large enough for OpenCV's vectorised paths (the plain `m != m` missed NaNs there on AVX-512).
TEST(NanMask, FindsEveryNaNOfALargeMatrix) {
  cv::Mat m(64, 97, CV_32F, cv::Scalar(3.5));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  int placed = 0;
  for (int y = 0; y < m.rows; y += 5) {
    for (int x = y % 7; x < m.cols; x += 11) {
      m.at<float>(y, x) = nan;
      ++placed;
    }
  }
  m.at<float>(10, 20) = std::numeric_limits<float>::infinity();  // a number, not NaN
  const cv::Mat isNaN = nanMask(m);
  const cv::Mat isNumber = numberMask(m);
  ASSERT_EQ(isNaN.type(), CV_8U);
  EXPECT_EQ(cv::countNonZero(isNaN), placed);
  EXPECT_EQ(cv::countNonZero(isNumber), static_cast<int>(m.total()) - placed);
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) {
      ASSERT_EQ(isNaN.at<uchar>(y, x) != 0, std::isnan(m.at<float>(y, x))) << y << "," << x;
    }
  }
}

TEST(NanMask, WorksOnDoublesAndOnEmptyInput) {
  cv::Mat m(40, 40, CV_64F, cv::Scalar(1.0));
  m.at<double>(39, 39) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(cv::countNonZero(nanMask(m)), 1);
  EXPECT_TRUE(nanMask(cv::Mat()).empty());
}

}  // namespace
