// Connected components with statistics (internal componentsWithStats): OpenCV's results exactly.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "components.hpp"

namespace delineo::stereo::detail {
namespace {

// Same labels, statistics and centroids (bit for bit, NaN where OpenCV's is NaN) as OpenCV's.
void expectSameAsOpenCv(const cv::Mat& mask, int connectivity, int threads) {
  cv::Mat labels, stats, centroids, cvLabels, cvStats, cvCentroids;
  const int count = componentsWithStats(mask, labels, stats, centroids, connectivity, threads);
  const int cvCount =
      cv::connectedComponentsWithStats(mask, cvLabels, cvStats, cvCentroids, connectivity, CV_32S);
  ASSERT_EQ(count, cvCount);
  EXPECT_EQ(cv::countNonZero(labels != cvLabels), 0);
  ASSERT_EQ(stats.size(), cvStats.size());
  EXPECT_EQ(cv::countNonZero(stats != cvStats), 0);
  ASSERT_EQ(centroids.size(), cvCentroids.size());
  for (int k = 0; k < count; ++k) {
    for (int c = 0; c < 2; ++c) {
      const double mine = centroids.at<double>(k, c), theirs = cvCentroids.at<double>(k, c);
      if (std::isnan(theirs)) {
        EXPECT_TRUE(std::isnan(mine)) << "label " << k;
      } else {
        EXPECT_EQ(mine, theirs) << "label " << k << " coordinate " << c;
      }
    }
  }
}

TEST(ComponentsWithStats, MatchOpenCvOnBlobsOfEverySize) {
  cv::Mat noise(301, 257, CV_32F);
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::NORMAL, 0, 1);
  for (const double blur : {0.0, 1.0, 3.0}) {
    cv::Mat smooth = noise;
    if (blur > 0) cv::GaussianBlur(noise, smooth, {0, 0}, blur);
    const cv::Mat mask = smooth > 0.1;
    for (const int connectivity : {4, 8}) {
      for (const int threads : {1, 2, 3}) {
        SCOPED_TRACE(testing::Message() << "blur " << blur << " connectivity " << connectivity
                                        << " threads " << threads);
        expectSameAsOpenCv(mask, connectivity, threads);
      }
    }
  }
}

TEST(ComponentsWithStats, MatchOpenCvOnEmptyFullAndThinMasks) {
  expectSameAsOpenCv(cv::Mat::zeros(40, 30, CV_8U), 4, 2);  // background only
  // No background: the one label as OpenCV's, the empty background as documented.
  cv::Mat labels, stats, centroids;
  ASSERT_EQ(
      componentsWithStats(cv::Mat(40, 30, CV_8U, cv::Scalar(255)), labels, stats, centroids, 4, 2),
      2);
  EXPECT_EQ(cv::countNonZero(labels != 1), 0);
  EXPECT_EQ(stats.at<int>(1, cv::CC_STAT_LEFT), 0);
  EXPECT_EQ(stats.at<int>(1, cv::CC_STAT_TOP), 0);
  EXPECT_EQ(stats.at<int>(1, cv::CC_STAT_WIDTH), 30);
  EXPECT_EQ(stats.at<int>(1, cv::CC_STAT_HEIGHT), 40);
  EXPECT_EQ(stats.at<int>(1, cv::CC_STAT_AREA), 1200);
  EXPECT_EQ(centroids.at<double>(1, 0), 14.5);
  EXPECT_EQ(centroids.at<double>(1, 1), 19.5);
  EXPECT_EQ(stats.at<int>(0, cv::CC_STAT_AREA), 0);
  EXPECT_EQ(stats.at<int>(0, cv::CC_STAT_WIDTH), 0);
  EXPECT_EQ(stats.at<int>(0, cv::CC_STAT_HEIGHT), 0);
  EXPECT_TRUE(std::isnan(centroids.at<double>(0, 0)));
  cv::Mat row = cv::Mat::zeros(1, 50, CV_8U);
  row.colRange(3, 9).setTo(1);
  row.colRange(20, 21).setTo(1);
  expectSameAsOpenCv(row, 8, 2);  // one row: fewer rows than workers
  cv::Mat column = cv::Mat::zeros(50, 1, CV_8U);
  column.rowRange(0, 7).setTo(1);
  column.rowRange(49, 50).setTo(1);
  expectSameAsOpenCv(column, 4, 3);
}

}  // namespace
}  // namespace delineo::stereo::detail
