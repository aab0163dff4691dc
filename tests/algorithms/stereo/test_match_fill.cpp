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

int roofPixelsWithTheRoofsDisparity(const Scene& s) {
  int n = 0;
  for (int y = s.roof.y; y < s.roof.br().y; ++y) {
    for (int x = s.roof.x; x < s.roof.br().x; ++x) {
      n += std::abs(s.disparity.at<float>(y, x) - kRoof) < 0.5f ? 1 : 0;
    }
  }
  return n;
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
  noScan.coreOpening = 0;  // the core (without the thin parts along the ground) lines up better
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

TEST(FillFlatRegions, ThinFlatPartsJoinedToARoofDoNotDecideItsFill) {
  // Three plain 6-row bands of the roof's grey at the ground's disparity (a facade's bands
  // between its window rows) touch the roof's left side: their flat middles join the roof's flat
  // region, and their outline does not line up at the roof's disparity.
  auto withBands = [](Scene s) {
    cv::RNG rng(7);
    for (int band = 0; band < 3; ++band) {
      const int y0 = s.roof.y + 6 + 12 * band;
      for (int y = y0; y < y0 + 6; ++y) {
        for (int x = s.roof.x - 30; x < s.roof.x; ++x) {
          s.left.at<float>(y, x) = 200.0f + static_cast<float>(rng.gaussian(2.0));
          s.right.at<float>(y, x - static_cast<int>(kGround)) =
              200.0f + static_cast<float>(rng.gaussian(2.0));
        }
      }
    }
    return s;
  };
  Scene withCore = withBands(scene());
  fillFlatRegions(withCore.left, withCore.right, RegionFillSettings{}, 0, 32, 0.3f,
                  withCore.disparity, withCore.score);
  Scene wholeRegion = withBands(scene());
  RegionFillSettings noCore;
  noCore.coreOpening = 0;
  fillFlatRegions(wholeRegion.left, wholeRegion.right, noCore, 0, 32, 0.3f, wholeRegion.disparity,
                  wholeRegion.score);
  // Without the core the bands' outline keeps the roof unfilled; with it the roof is filled
  // (the growth back to its contour leaves a few single pixels out, as in the tests above).
  EXPECT_EQ(rowsFilledToTheOutline(wholeRegion), 0);
  const int roofArea = withCore.roof.area();
  EXPECT_GE(roofPixelsWithTheRoofsDisparity(withCore), roofArea * 95 / 100) << " of " << roofArea;
  // The bands keep their own disparity, but for the pixel next to the roof on some of their
  // rows, which the growth reaches: it looks like the roof and matches at its disparity.
  EXPECT_LE(spilledOntoTheGround(withCore), 3 * 6);
}

}  // namespace
}  // namespace delineo::stereo::detail
