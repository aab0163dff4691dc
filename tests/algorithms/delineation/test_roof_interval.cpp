// Roof interval and ground level proposal on synthetic disparity maps.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "delineo/core/error.hpp"
#include "delineo/delineation/roof_interval.hpp"

namespace {

using delineo::core::Polygon;
using delineo::delineation::estimateGroundLevel;
using delineo::delineation::proposeRoofInterval;
using delineo::delineation::RoofIntervalParams;

Polygon rectangle(double x0, double y0, double x1, double y1) {
  Polygon p;
  p.outer = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  return p;
}

// Deterministic noise of about ±0.4 px.
void addNoise(cv::Mat& map) {
  cv::Mat noise(map.size(), CV_32F);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, -0.4, 0.4);
  map += noise;
}

// The scene of the real case that motivated the proposal: a large flat roof at 71.5 px with a
// 4 px parapet at 75 px, a neighbouring roof at 59.5 px along its whole north side, ground at 8 px.
cv::Mat bigRoofScene() {
  cv::Mat map(400, 400, CV_32F, cv::Scalar(8.0f));
  map(cv::Rect(0, 0, 400, 100)).setTo(59.5f);              // neighbour north of the roof
  map(cv::Rect(100, 100, 220, 200)).setTo(75.0f);          // parapet
  map(cv::Rect(104, 104, 212, 192)).setTo(71.5f);          // roof
  addNoise(map);
  return map;
}

TEST(RoofInterval, ContainsTheMainPeakOfARoofWithParapetsAndFindsTheGroundBesideTheNeighbour) {
  const cv::Mat map = bigRoofScene();
  // A rough rectangle 10 px larger than the roof on each side, except on the north where it
  // stops at the neighbour.
  const auto p = proposeRoofInterval(map, rectangle(90, 100, 330, 310));
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.peak, 71.5, 0.5);
  EXPECT_LE(p.low, 71);
  EXPECT_GE(p.high, 72);
  EXPECT_LT(p.high - p.low, 8);
  EXPECT_GT(p.low, 60);  // the neighbour's level is not roof
  EXPECT_NEAR(p.groundLevel, 8.0, 1.0);  // not the neighbour at 59.5, which the north band holds
}

TEST(RoofInterval, TightPolygonStillFindsTheRoofPeakAndNotTheParapet) {
  const cv::Mat map = bigRoofScene();
  const auto p = proposeRoofInterval(map, rectangle(100, 100, 320, 300));
  ASSERT_TRUE(p.found);
  EXPECT_LE(p.low, 71);
  EXPECT_GE(p.high, 72);
}

TEST(RoofInterval, RoughRectangleMostlyOverGroundStillProposesTheRoof) {
  cv::Mat map(300, 300, CV_32F, cv::Scalar(-4.0f));
  map(cv::Rect(120, 120, 40, 40)).setTo(30.0f);
  addNoise(map);
  // 30 px larger than the roof on each side: ground is 80 % of the rectangle.
  const auto p = proposeRoofInterval(map, rectangle(90, 90, 190, 190));
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.peak, 30.0, 0.5);
  EXPECT_LE(p.low, 30);
  EXPECT_GE(p.high, 30);
  EXPECT_GT(p.low, 0);
  EXPECT_NEAR(p.groundLevel, -4.0, 0.5);
}

TEST(RoofInterval, SlopedRoofGetsAnIntervalAsWideAsItsSpread) {
  cv::Mat map(300, 300, CV_32F, cv::Scalar(5.0f));
  for (int y = 100; y < 200; ++y) {
    for (int x = 100; x < 200; ++x) map.at<float>(y, x) = 40.0f + 0.1f * static_cast<float>(x - 100);  // 40..50
  }
  const auto p = proposeRoofInterval(map, rectangle(95, 95, 205, 205));
  ASSERT_TRUE(p.found);
  EXPECT_LE(p.low, 42);
  EXPECT_GE(p.high, 48);
}

// A low wing (31 px, 240 x 40 px) in the shadow of a taller block (80 px, its parapet 82.5 px)
// along its north side: the matcher keeps every pixel of the sunlit block but only half of the
// wing's, as in Toulouse.
cv::Mat wingInTheShadowOfABlockScene() {
  cv::Mat map(320, 440, CV_32F, cv::Scalar(6.0f));
  map(cv::Rect(0, 0, 440, 140)).setTo(80.0f);
  map(cv::Rect(0, 136, 440, 4)).setTo(82.5f);
  const cv::Rect wing(100, 140, 240, 40);
  map(wing).setTo(31.0f);
  addNoise(map);
  cv::Mat draw(wing.size(), CV_32F);
  cv::RNG rng(11);
  rng.fill(draw, cv::RNG::UNIFORM, 0.0, 1.0);
  map(wing).setTo(std::numeric_limits<float>::quiet_NaN(), draw > 0.5);
  return map;
}

TEST(RoofInterval, ANeighboursTallerBlockFillingAThirdOfTheRectangleDoesNotTakeThePeak) {
  const cv::Mat map = wingInTheShadowOfABlockScene();
  // The operator's rectangle is centred on the wing, 30-35 px larger on each side, and its north
  // third lies on the block: the block's matched pixels outnumber the wing's.
  const auto p = proposeRoofInterval(map, rectangle(70, 105, 370, 215));
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.peak, 31.0, 0.5);
  EXPECT_LE(p.low, 31);
  EXPECT_GE(p.high, 31);
  EXPECT_LT(p.high, 60);
  EXPECT_NEAR(p.groundLevel, 6.0, 0.5);
  RoofIntervalParams noEntryTest;
  noEntryTest.entryReach = 0.0;
  EXPECT_NEAR(proposeRoofInterval(map, rectangle(70, 105, 370, 215), noEntryTest).peak, 80.0, 1.0);
}

TEST(RoofInterval, ADelineatedRingRoofKeepsItsRingNotTheLowerPartAtItsCentre) {
  // A raised ring (80 px) around a lower inner roof (72 px) at the polygon's centre, as the
  // delineated outline of Toulouse's raised block: weighting pixels by their distance to the
  // border would give the inner roof.
  cv::Mat map(360, 400, CV_32F, cv::Scalar(6.0f));
  map(cv::Rect(100, 100, 200, 160)).setTo(80.0f);
  map(cv::Rect(140, 140, 120, 80)).setTo(72.0f);
  addNoise(map);
  const auto p = proposeRoofInterval(map, rectangle(100, 100, 300, 260));
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.peak, 80.0, 0.5);
}

TEST(RoofInterval, ALowerRoofOfTheBuildingJoinsTheIntervalButACourtyardOrAStructureBesideItDoesNot) {
  // Toulouse's raised block from a rough rectangle: the ring (80 px) is the roof peak, the inner
  // roof (72 px) it encloses is part of the building: the interval reaches down to it.
  cv::Mat map(360, 440, CV_32F, cv::Scalar(6.0f));
  map(cv::Rect(100, 100, 200, 160)).setTo(80.0f);
  map(cv::Rect(140, 140, 120, 80)).setTo(72.0f);
  cv::Mat recessed = map.clone();
  addNoise(recessed);
  const Polygon rough = rectangle(70, 70, 330, 290);
  const auto p = proposeRoofInterval(recessed, rough);
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.peak, 80.0, 0.5);
  EXPECT_LE(p.low, 71);
  EXPECT_GE(p.high, 81);
  // A courtyard at the ground inside the ring is not roof.
  cv::Mat courtyard = map.clone();
  courtyard(cv::Rect(140, 140, 120, 80)).setTo(6.0f);
  addNoise(courtyard);
  const auto c = proposeRoofInterval(courtyard, rough);
  ASSERT_TRUE(c.found);
  EXPECT_GE(c.low, 76);
  // Neither is a lower structure of the same size beside the building, inside the rectangle but
  // apart from the roof (the street between them), nor one crossing the rectangle's side.
  cv::Mat beside(360, 440, CV_32F, cv::Scalar(6.0f));
  beside(cv::Rect(100, 100, 150, 160)).setTo(80.0f);
  beside(cv::Rect(260, 110, 60, 140)).setTo(72.0f);
  cv::Mat crossing = beside.clone();
  crossing(cv::Rect(260, 110, 60, 140)).setTo(6.0f);
  crossing(cv::Rect(250, 110, 190, 140)).setTo(72.0f);
  for (cv::Mat* m : {&beside, &crossing}) {
    addNoise(*m);
    const auto b = proposeRoofInterval(*m, rough);
    ASSERT_TRUE(b.found);
    EXPECT_NEAR(b.peak, 80.0, 0.5);
    EXPECT_GE(b.low, 76);
  }
}

TEST(RoofInterval, APolygonDrawnInsideItsRoofKeepsTheRoofNotASmallStructureOnIt) {
  // Every level of the polygon enters it from outside except a plant room (46 px, 30 x 30 px).
  cv::Mat map(300, 400, CV_32F, cv::Scalar(6.0f));
  map(cv::Rect(50, 50, 300, 200)).setTo(40.0f);
  map(cv::Rect(185, 135, 30, 30)).setTo(46.0f);
  addNoise(map);
  const auto p = proposeRoofInterval(map, rectangle(100, 100, 300, 200));
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.peak, 40.0, 0.5);
}

TEST(GroundLevel, IsTheLowestWellPopulatedLevelNotTheMostFrequentOne) {
  cv::Mat map(300, 300, CV_32F, cv::Scalar(20.0f));  // neighbouring roofs all around
  map(cv::Rect(0, 200, 300, 100)).setTo(6.0f);       // a street along the south side
  map(cv::Rect(0, 0, 20, 20)).setTo(-10.0f);         // a few stray low matches
  addNoise(map);
  const double g = estimateGroundLevel(map, rectangle(100, 100, 200, 180));
  EXPECT_NEAR(g, 6.0, 0.5);
}

// Ground sloping by 0.08 px per px along x (as across the Dublin tile), a tower at 90 px.
cv::Mat slopedGroundScene() {
  cv::Mat map(400, 700, CV_32F);
  for (int y = 0; y < map.rows; ++y) {
    for (int x = 0; x < map.cols; ++x) map.at<float>(y, x) = 10.0f + 0.08f * static_cast<float>(x);
  }
  map(cv::Rect(400, 170, 60, 60)).setTo(90.0f);
  addNoise(map);
  return map;
}

TEST(GroundLevel, OnASlopingGroundIsTheGroundNextToTheBuilding) {
  const cv::Mat map = slopedGroundScene();
  // The ground along the tower's sides averages 10 + 0.08 * 430 = 44.4 px; the 120 px band
  // around a rough rectangle spans 33..58 px. From rectangles 8 and 30 px larger than the tower.
  EXPECT_NEAR(estimateGroundLevel(map, rectangle(392, 162, 468, 238)), 44.4, 0.5);
  EXPECT_NEAR(estimateGroundLevel(map, rectangle(370, 140, 490, 260)), 44.4, 0.5);
  const auto p = proposeRoofInterval(map, rectangle(392, 162, 468, 238));
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.groundLevel, 44.4, 0.5);
  EXPECT_LE(p.low, 90);
  EXPECT_GE(p.high, 90);
}

TEST(GroundLevel, NaNWhenTheNeighbourhoodHasNoMatchedPixel) {
  cv::Mat map(100, 100, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  map(cv::Rect(40, 40, 20, 20)).setTo(30.0f);
  EXPECT_TRUE(std::isnan(estimateGroundLevel(map, rectangle(40, 40, 60, 60))));
  const auto p = proposeRoofInterval(map, rectangle(40, 40, 60, 60));
  ASSERT_TRUE(p.found);  // a roof without known ground: the most populated peak
  EXPECT_LE(p.low, 30);
  EXPECT_GE(p.high, 30);
}

TEST(RoofInterval, NotFoundWithTooFewMatchedPixels) {
  cv::Mat map(100, 100, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_FALSE(proposeRoofInterval(map, rectangle(40, 40, 60, 60)).found);
}

TEST(RoofInterval, RejectsAMapThatIsNotFloat) {
  const cv::Mat map(50, 50, CV_8U, cv::Scalar(3));
  try {
    proposeRoofInterval(map, rectangle(10, 10, 20, 20));
    FAIL() << "expected an error";
  } catch (const delineo::core::Error& e) {
    EXPECT_EQ(e.code(), delineo::core::ErrorCode::UnsupportedInput);
  }
}

TEST(RoofInterval, ParametersOutsideTheirDomainAreRejected) {
  RoofIntervalParams params;
  params.peakFraction = 1.5;
  EXPECT_THROW(params.validate(), delineo::core::Error);
  params = {};
  params.groundShare = 0.0;
  EXPECT_THROW(params.validate(), delineo::core::Error);
  EXPECT_NO_THROW(RoofIntervalParams{}.validate());
}

}  // namespace
