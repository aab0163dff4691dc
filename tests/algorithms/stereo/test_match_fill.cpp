// Flat regions filled from their outline (internal fillFlatRegions): the fill reaches the image
// contour.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <opencv2/core.hpp>

#include "match_fill.hpp"
#include "synthetic.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kRoof = 20.0f, kGround = 4.0f;

// A textureless roof (grey 200, 50x40 px) at disparity 20 on textured ground at disparity 4,
// noise sigma 2 in each view; and the map a window matcher leaves there: ground matched up to
// 3 px from the roof, the roof's top and bottom 2 rows matched (their windows reach the
// outline), the rest of the roof unmatched, except 10 rows of its last column that carry the
// ground's value over the outline.
struct Scene {
  cv::Mat left, right, disparity, score;
  cv::Rect roof{60, 40, 50, 40};
};

Scene scene(float roofGrey = 200.0f, double noise = 2.0) {
  Scene s;
  testing::FlatRoofPair pair = testing::flatRoofPair(true, roofGrey, noise, 31, 4);
  s.left = pair.left;
  s.right = pair.right;
  s.roof = pair.roof;
  const cv::Size size = s.left.size();
  s.disparity = cv::Mat(size, CV_32F, cv::Scalar(kGround));
  const cv::Rect around(s.roof.x - 3, s.roof.y - 3, s.roof.width + 6, s.roof.height + 6);
  s.disparity(around).setTo(kNaN);
  s.disparity(cv::Rect(s.roof.x + 2, s.roof.y, s.roof.width - 4, 2)).setTo(kRoof);
  s.disparity(cv::Rect(s.roof.x + 2, s.roof.br().y - 2, s.roof.width - 4, 2)).setTo(kRoof);
  s.disparity(cv::Rect(s.roof.br().x - 1, s.roof.y + 10, 1, 10)).setTo(kGround);
  s.score = cv::Mat(size, CV_32F, cv::Scalar(0.9));
  return s;
}

// Rows (away from the roof's top and bottom) whose roof pixels all carry the roof's disparity.
int rowsFilledToTheOutline(const Scene& s) {
  int rows = 0;
  for (int y = s.roof.y + 3; y < s.roof.br().y - 3; ++y) {
    bool all = true;
    for (int x = s.roof.x; x < s.roof.br().x; ++x) {
      all = all && std::abs(s.disparity.at<float>(y, x) - kRoof) < 0.5f;
    }
    rows += all ? 1 : 0;
  }
  return rows;
}

// Pixels off the roof that took its disparity.
int spilledOntoTheGround(const Scene& s) {
  int spilled = 0;
  for (int y = 0; y < s.left.rows; ++y) {
    for (int x = 0; x < s.left.cols; ++x) {
      if (!s.roof.contains({x, y}) && std::abs(s.disparity.at<float>(y, x) - kRoof) < 1.5f) {
        ++spilled;
      }
    }
  }
  return spilled;
}

TEST(FillFlatRegions, ReachesTheImageContourAndStopsThere) {
  Scene grown = scene();
  fillFlatRegions(grown.left, grown.right, RegionFillSettings{}, 0, 32, 0.3f, grown.disparity,
                  grown.score);
  Scene plain = scene();
  RegionFillSettings noGrowth;
  noGrowth.growReach = 0;
  fillFlatRegions(plain.left, plain.right, noGrowth, 0, 32, 0.3f, plain.disparity, plain.score);
  const int rows = grown.roof.height - 6;
  // The flat region stops 2 px short of the outline (its 5x5 windows straddle it).
  EXPECT_EQ(rowsFilledToTheOutline(plain), 0);
  EXPECT_GE(rowsFilledToTheOutline(grown), rows * 9 / 10) << " of " << rows;
  // The ground's value carried onto the roof's last column is replaced (the grown pixels pass a
  // per-pixel noise test: a few may fail it).
  int replaced = 0;
  for (int y = grown.roof.y + 10; y < grown.roof.y + 20; ++y) {
    replaced += std::abs(grown.disparity.at<float>(y, grown.roof.br().x - 1) - kRoof) < 0.5f;
  }
  EXPECT_GE(replaced, 8);
  // No ground pixel takes the roof's disparity.
  EXPECT_EQ(spilledOntoTheGround(grown), 0);
}

TEST(FillFlatRegions, AScanOfTheRangeConfirmsAnUnclearCandidate) {
  // A roof of nearly the ground's grey under strong noise (grey 140, sigma 6): the outline error
  // of the roof's candidate is not half the ground's, but no other disparity of the range lines
  // the outline up as well.
  Scene scanned = scene(140.0f, 6.0);
  fillFlatRegions(scanned.left, scanned.right, RegionFillSettings{}, 0, 32, 0.3f, scanned.disparity,
                  scanned.score);
  Scene unscanned = scene(140.0f, 6.0);
  RegionFillSettings noScan;
  noScan.scanAgreement = 0;
  fillFlatRegions(unscanned.left, unscanned.right, noScan, 0, 32, 0.3f, unscanned.disparity,
                  unscanned.score);
  const int rows = scanned.roof.height - 6;
  EXPECT_EQ(rowsFilledToTheOutline(unscanned), 0);
  EXPECT_GE(rowsFilledToTheOutline(scanned), rows * 8 / 10) << " of " << rows;
  // With the roof's grey within 3 noise sigmas of parts of the ground, the flat region and its
  // growth take some ground along the outline: less than half a pixel per outline pixel.
  const int perimeter = 2 * (scanned.roof.width + scanned.roof.height);
  EXPECT_LT(spilledOntoTheGround(scanned), perimeter / 2);
}

}  // namespace
}  // namespace delineo::stereo::detail
