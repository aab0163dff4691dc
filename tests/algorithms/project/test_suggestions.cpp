// project::suggestRoofInterval and project::suggestGroundLevel: the proposal the GUI's histogram
// and `delineo-cli run` share.
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "delineo/project/pipeline.hpp"

using namespace delineo;

namespace {

core::Polygon rectangle(double x0, double y0, double x1, double y1) {
  core::Polygon p;
  p.outer = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  return p;
}

// A flat roof at 71.5 px inside a 75 px parapet, a neighbour at 59.5 px north of it, ground at
// 8 px: the polygon percentiles used before proposed the parapet's [73, 76] and the ring around
// the polygon the neighbour's 59.5 px.
cv::Mat roofScene() {
  cv::Mat map(400, 400, CV_32F, cv::Scalar(8.0f));
  map(cv::Rect(0, 0, 400, 100)).setTo(59.5f);
  map(cv::Rect(100, 100, 220, 200)).setTo(75.0f);
  map(cv::Rect(104, 104, 212, 192)).setTo(71.5f);
  cv::Mat noise(map.size(), CV_32F);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, -0.4, 0.4);
  return map + noise;
}

}  // namespace

TEST(Suggestions, RoofIntervalHoldsTheRoofPeakAndGroundLevelIsTheStreet) {
  const cv::Mat map = roofScene();
  const core::Polygon picked = rectangle(96, 100, 324, 304);
  const auto interval = project::suggestRoofInterval(map, picked);
  ASSERT_TRUE(interval.has_value());
  EXPECT_LE(interval->low, 71);
  EXPECT_GE(interval->high, 72);
  const auto ground = project::suggestGroundLevel(map, picked);
  ASSERT_TRUE(ground.has_value());
  EXPECT_NEAR(*ground, 8.0, 1.0);
}

TEST(Suggestions, NothingWithoutADisparityMap) {
  EXPECT_FALSE(project::suggestRoofInterval(cv::Mat(), rectangle(0, 0, 10, 10)).has_value());
  EXPECT_FALSE(project::suggestGroundLevel(cv::Mat(), rectangle(0, 0, 10, 10)).has_value());
}

TEST(Suggestions, TheScenesGroundLevelIsTheStreetNotTheBiggestRoof) {
  const auto ground = project::suggestSceneGroundLevel(roofScene());
  ASSERT_TRUE(ground.has_value());
  EXPECT_NEAR(*ground, 8.0, 1.0);
  EXPECT_FALSE(project::suggestSceneGroundLevel(cv::Mat()).has_value());
}

// The GUI's "Pick an above-ground object" and the 3D view's block base read the same ground as
// the histogram's line: suggestGroundLevel of the picked outline, in px or in metres.
TEST(Suggestions, ThePickedObjectsGroundIsTheHistogramsGround) {
  const cv::Mat map = roofScene();
  project::Project p;
  p.height = {8.0, 0.25, 0.05};
  const cv::Mat dem = project::heightsFromDisparity(p, map);
  ASSERT_FALSE(dem.empty());
  EXPECT_NEAR(dem.at<float>(200, 200), (map.at<float>(200, 200) - 8.0f) * 0.25f, 1e-5);
  const project::ObjectPick pick = project::pickAboveGroundObject(p, map, dem, {210, 200});
  ASSERT_EQ(pick.outcome, project::ObjectPick::Outcome::Found);
  const cv::Rect2d box = core::boundingBox(pick.outline.outer);
  EXPECT_NEAR(box.x, 100.5, 1.0);
  EXPECT_NEAR(box.y, 100.5, 1.0);
  EXPECT_NEAR(box.width, 219.0, 1.0);
  EXPECT_NEAR(box.height, 199.0, 1.0);
  const auto histogramGround = project::suggestGroundLevel(map, pick.outline);
  ASSERT_TRUE(histogramGround.has_value());
  EXPECT_EQ(pick.groundLevel, *histogramGround);
  EXPECT_NEAR(pick.groundHeight, (*histogramGround - 8.0) * 0.25, 1e-9);
  const auto base = project::groundHeightNextTo(p, dem, pick.outline);
  ASSERT_TRUE(base.has_value());
  EXPECT_NEAR(*base, pick.groundHeight, 1e-3);
  // Without a disparity map the DEM is read; without either there is nothing to pick from.
  const project::ObjectPick fromDem = project::pickAboveGroundObject(p, cv::Mat(), dem, {210, 200});
  EXPECT_EQ(fromDem.outcome, project::ObjectPick::Outcome::Found);
  EXPECT_EQ(project::pickAboveGroundObject(p, cv::Mat(), cv::Mat(), {210, 200}).outcome,
            project::ObjectPick::Outcome::NoHeights);
  EXPECT_EQ(project::pickAboveGroundObject(p, map, dem, {20, 350}).outcome,
            project::ObjectPick::Outcome::NotAboveGround);
}
