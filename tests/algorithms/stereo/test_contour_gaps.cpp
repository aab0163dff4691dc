// Small gaps of the contour map closed (internal bridgeContourGaps).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "contour_gaps.hpp"
#include "delineo/stereo/match.hpp"

namespace delineo::stereo::detail {
namespace {

// A 40 x 20 map with a horizontal contour on row 10 from x = 2 to 37, broken at x = 20 over
// `gap` pixels.
cv::Mat brokenLine(int gap) {
  cv::Mat edges = cv::Mat::zeros(20, 40, CV_8U);
  cv::line(edges, {2, 10}, {19, 10}, cv::Scalar(255));
  cv::line(edges, {20 + gap, 10}, {37, 10}, cv::Scalar(255));
  return edges;
}

TEST(BridgeContourGaps, ClosesAGapUpToMaxGapAndNoWider) {
  for (const int gap : {1, 2, 3}) {
    cv::Mat edges = brokenLine(gap);
    const cv::Mat before = edges.clone();
    const int drawn = bridgeContourGaps(edges, 2);
    if (gap <= 2) {
      // Both ends of the gap see each other: two segments, the same pixels.
      EXPECT_EQ(drawn, 2) << "gap " << gap;
      for (int x = 2; x <= 37; ++x) EXPECT_NE(edges.at<uchar>(10, x), 0) << "gap " << gap;
      EXPECT_EQ(cv::countNonZero(edges), 36) << "gap " << gap;
    } else {
      EXPECT_EQ(drawn, 0);
      EXPECT_EQ(cv::countNonZero(edges != before), 0);
    }
  }
  cv::Mat wider = brokenLine(3);
  EXPECT_EQ(bridgeContourGaps(wider, 3), 2);
  EXPECT_EQ(cv::countNonZero(wider), 36);
}

TEST(BridgeContourGaps, ClosesAStaggeredGapSoAFourConnectedFillStaysInside) {
  // A square outline whose top side is broken over 2 px, the side's two parts one row apart
  // (the gap on the roof of sim seed 15 1000²: ends at (254, 660) and (257, 659)).
  cv::Mat edges = cv::Mat::zeros(30, 30, CV_8U);
  cv::line(edges, {5, 5}, {12, 5}, cv::Scalar(255));
  cv::line(edges, {15, 4}, {24, 4}, cv::Scalar(255));
  cv::line(edges, {24, 4}, {24, 24}, cv::Scalar(255));
  cv::line(edges, {24, 24}, {5, 24}, cv::Scalar(255));
  cv::line(edges, {5, 24}, {5, 5}, cv::Scalar(255));
  const auto insideReachesOutside = [](const cv::Mat& contour) {
    cv::Mat fill = contour.clone();
    cv::floodFill(fill, cv::Point(15, 15), cv::Scalar(128), nullptr, 0, 0, 4);
    return fill.at<uchar>(1, 1) == 128;
  };
  EXPECT_TRUE(insideReachesOutside(edges));
  EXPECT_GT(bridgeContourGaps(edges, 2), 0);
  EXPECT_FALSE(insideReachesOutside(edges));
}

TEST(BridgeContourGaps, LeavesLoneEndsAndContoursBehindAnEndAlone) {
  cv::Mat edges = cv::Mat::zeros(20, 40, CV_8U);
  cv::line(edges, {10, 5}, {20, 5}, cv::Scalar(255));
  // Two rows below the line, 2 px in from its left end: behind that end, not ahead of it.
  edges.at<uchar>(7, 12) = 255;
  // A hook: the chain bends back on itself within the end's reach, and is not joined to itself.
  cv::line(edges, {25, 15}, {35, 15}, cv::Scalar(255));
  cv::line(edges, {35, 15}, {35, 12}, cv::Scalar(255));
  cv::line(edges, {35, 12}, {33, 12}, cv::Scalar(255));
  const cv::Mat before = edges.clone();
  EXPECT_EQ(bridgeContourGaps(edges, 3), 0);
  EXPECT_EQ(cv::countNonZero(edges != before), 0);
}

TEST(BridgeContourGaps, ZeroIsOffAndTheParameterIsBounded) {
  cv::Mat edges = brokenLine(1);
  EXPECT_EQ(bridgeContourGaps(edges, 0), 0);
  MatchParams p;
  EXPECT_EQ(p.edgeGap, 1);
  p.edgeGap = 11;
  EXPECT_THROW(p.validate(), std::exception);
  p.edgeGap = -1;
  EXPECT_THROW(p.validate(), std::exception);
  p.edgeGap = 0;
  EXPECT_NO_THROW(p.validate());
}

}  // namespace
}  // namespace delineo::stereo::detail
