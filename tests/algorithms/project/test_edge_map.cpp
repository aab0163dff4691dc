// Edge map for vertex snapping: edges sit on the boundary of a textured rectangle, texture and
// noise away from it give (almost) none, parameters are validated.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/project/edge_map.hpp"

namespace {
using namespace delineo;

// A noisy, textured ground (grey 90 ± noise) with a brighter roof [60, 140) x [50, 110).
cv::Mat roofScene() {
  cv::Mat image(160, 200, CV_8U);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::NORMAL, 90, 6);
  cv::Mat roof = image(cv::Rect(60, 50, 80, 60));
  roof += cv::Scalar(45);
  return image;
}
}  // namespace

TEST(EdgeMap, EdgesLieOnTheRoofBoundary) {
  const cv::Mat edges = project::edgeMap(roofScene());
  ASSERT_EQ(edges.size(), cv::Size(200, 160));
  ASSERT_EQ(edges.type(), CV_8U);
  // Every row crossing the roof has an edge pixel at its left and right walls (x 59..60 and
  // 139..140: the boundary lies between two pixels and either side may carry it).
  int leftHits = 0, rightHits = 0;
  for (int y = 55; y < 105; ++y) {
    if (edges.at<uchar>(y, 59) || edges.at<uchar>(y, 60)) ++leftHits;
    if (edges.at<uchar>(y, 139) || edges.at<uchar>(y, 140)) ++rightHits;
  }
  EXPECT_GE(leftHits, 48);
  EXPECT_GE(rightHits, 48);
  // Thin: about one pixel per crossing, not a band.
  EXPECT_LE(cv::countNonZero(edges.row(80)), 6);
  // The textured ground far from the roof stays almost free of edges.
  const double groundEdges = cv::countNonZero(edges(cv::Rect(0, 0, 200, 40)));
  EXPECT_LT(groundEdges / (200.0 * 40.0), 0.02);
}

TEST(EdgeMap, FlatImageHasNoEdgeAndFloatInputIsAccepted) {
  EXPECT_EQ(cv::countNonZero(project::edgeMap(cv::Mat(50, 60, CV_8U, cv::Scalar(120)))), 0);
  cv::Mat asFloat;
  roofScene().convertTo(asFloat, CV_32F);
  asFloat.at<float>(3, 3) = std::nanf("");
  const cv::Mat edges = project::edgeMap(asFloat);
  EXPECT_GT(cv::countNonZero(edges.col(60)) + cv::countNonZero(edges.col(59)), 40);
  EXPECT_TRUE(project::edgeMap(cv::Mat()).empty());
}

TEST(EdgeMap, ParametersAreValidated) {
  project::EdgeMapParams params;
  params.contrast = 0.5;
  EXPECT_THROW(project::edgeMap(roofScene(), params), core::Error);
  params = {};
  params.smoothing = -1.0;
  EXPECT_THROW(params.validate(), core::Error);
}
