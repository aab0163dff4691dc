#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"

using namespace delineo::core;

TEST(Geometry, AreaWithHole) {
  Polygon p;
  p.outer = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  p.holes.push_back({{2, 2}, {4, 2}, {4, 4}, {2, 4}});
  EXPECT_DOUBLE_EQ(area(p), 96.0);
}

TEST(Geometry, SimpleAndSelfIntersecting) {
  EXPECT_TRUE(isSimple({{0, 0}, {4, 0}, {4, 4}, {0, 4}}));
  EXPECT_FALSE(isSimple({{0, 0}, {4, 4}, {4, 0}, {0, 4}}));  // bow tie
  EXPECT_FALSE(isSimple({{0, 0}, {1, 1}}));
  EXPECT_FALSE(isSimple({{0, 0}, {1, 1}, {2, 2}}));  // zero area
}

TEST(Geometry, RasterizeCountsPixelCentres) {
  Polygon p;
  p.outer = {{2, 3}, {12, 3}, {12, 8}, {2, 8}};  // 10 x 5 pixels exactly
  p.holes.push_back({{4, 4}, {6, 4}, {6, 6}, {4, 6}});  // 2 x 2 hole
  const cv::Mat m = rasterize(p, {20, 20});
  EXPECT_EQ(cv::countNonZero(m), 50 - 4);
  EXPECT_EQ(m.at<uchar>(3, 2), 255);
  EXPECT_EQ(m.at<uchar>(2, 2), 0);
  EXPECT_EQ(m.at<uchar>(4, 4), 0);
}

TEST(Geometry, ARingOfManyVerticesIsCheckedForCrossings) {
  // 20 000 vertices (the grid path): a circle is simple; swapping two vertices far apart, or
  // two neighbours, makes edges cross.
  delineo::core::Ring circle;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * 3.14159265358979 * i / n;
    circle.emplace_back(1000.0 + 900.0 * std::cos(a), 1000.0 + 900.0 * std::sin(a));
  }
  EXPECT_TRUE(delineo::core::isSimple(circle));
  delineo::core::Ring far = circle;
  std::swap(far[100], far[12000]);
  EXPECT_FALSE(delineo::core::isSimple(far));
  delineo::core::Ring near = circle;
  std::swap(near[5000], near[5001]);
  EXPECT_FALSE(delineo::core::isSimple(near));
}
