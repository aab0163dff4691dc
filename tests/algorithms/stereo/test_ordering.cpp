// Matches hidden in the right view by a nearer match to their right (internal
// rejectOrderingViolations).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "ordering.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// One row of disparities.
cv::Mat row(const std::vector<float>& values) {
  cv::Mat m(1, static_cast<int>(values.size()), CV_32F);
  for (size_t i = 0; i < values.size(); ++i) m.at<float>(0, static_cast<int>(i)) = values[i];
  return m;
}

// Columns of `m` that are NaN.
std::vector<int> unmatched(const cv::Mat& m) {
  std::vector<int> columns;
  for (int x = 0; x < m.cols; ++x) {
    if (std::isnan(m.at<float>(0, x))) columns.push_back(x);
  }
  return columns;
}

TEST(OrderingCheck, RejectsAFarSurfacesBandInsideANearerOne) {
  // A roof at 20 whose columns 8-11 carry the ground's 4: in the right view they would lie at
  // 4-7, right of where the roof's column 12 lies (12 - 20 = -8): the roof hides them. They are
  // rejected; the roof stays.
  std::vector<float> values(24, 20.0f);
  for (int x = 8; x < 12; ++x) values[static_cast<size_t>(x)] = 4.0f;
  cv::Mat disparity = row(values);
  cv::Mat score(disparity.size(), CV_32F, cv::Scalar(0.9));
  EXPECT_EQ(rejectOrderingViolations(disparity, score, OrderingSettings{}), 4);
  EXPECT_EQ(unmatched(disparity), (std::vector<int>{8, 9, 10, 11}));
  EXPECT_TRUE(std::isnan(score.at<float>(0, 9)));
  EXPECT_FLOAT_EQ(score.at<float>(0, 12), 0.9f);
}

TEST(OrderingCheck, RejectsTheGroundTheRightViewCannotSeeLeftOfARoof) {
  // Ground at 4 up to column 29, a roof at 20 from column 30 (right-view column 10): the ground
  // within the 16 px parallax difference left of the roof, columns 14-29, is hidden in the right
  // view; with the 1 px tolerance, those mapped beyond 11 are rejected.
  std::vector<float> values(50, 4.0f);
  for (int x = 30; x < 50; ++x) values[static_cast<size_t>(x)] = 20.0f;
  cv::Mat disparity = row(values);
  cv::Mat score;
  rejectOrderingViolations(disparity, score, OrderingSettings{});
  // x − 4 > 10 + 1  <=>  x > 15: columns 16-29 rejected, 0-15 kept.
  std::vector<int> expected;
  for (int x = 16; x < 30; ++x) expected.push_back(x);
  EXPECT_EQ(unmatched(disparity), expected);
}

TEST(OrderingCheck, KeepsTheGroundThatAppearsRightOfARoof) {
  // The roof first, then the ground: the ground right of a roof is seen in the right view.
  std::vector<float> values(50, 20.0f);
  for (int x = 30; x < 50; ++x) values[static_cast<size_t>(x)] = 4.0f;
  cv::Mat disparity = row(values);
  cv::Mat score;
  EXPECT_EQ(rejectOrderingViolations(disparity, score, OrderingSettings{}), 0);
}

TEST(OrderingCheck, KeepsSmallReversalsOfASlantedOrNoisySurface) {
  // A steep slant whose matches step back by 1.5 px in disparity (below the 2 px jump) and a
  // reversal of 0.8 px (within the 1 px tolerance) are kept.
  cv::Mat disparity = row({10.0f, 10.0f, 11.5f, 13.0f, 11.5f, 10.0f, 10.8f, 12.0f, 12.0f});
  cv::Mat score;
  EXPECT_EQ(rejectOrderingViolations(disparity, score, OrderingSettings{}), 0);
  // Reversals of 3 and 6 px are rejected.
  cv::Mat deeper = row({10.0f, 10.0f, 13.0f, 13.0f, 10.0f, 10.0f, 16.0f, 16.0f, 16.0f});
  EXPECT_GT(rejectOrderingViolations(deeper, score, OrderingSettings{}), 0);
}

TEST(OrderingCheck, UnmatchedPixelsHideNothing) {
  // The roof's pixels right of the band unmatched: nothing to its right hides the band.
  std::vector<float> values(24, kNaN);
  for (int x = 0; x < 8; ++x) values[static_cast<size_t>(x)] = 20.0f;
  for (int x = 8; x < 12; ++x) values[static_cast<size_t>(x)] = 4.0f;
  cv::Mat disparity = row(values);
  cv::Mat score;
  EXPECT_EQ(rejectOrderingViolations(disparity, score, OrderingSettings{}), 0);
}

}  // namespace
}  // namespace delineo::stereo::detail
