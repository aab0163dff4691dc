// Buildings cut in two and merged (project::splitBuilding, project::mergeBuildings; io::splitAlong,
// io::mergedOutline underneath).
#include <gtest/gtest.h>

#include <cmath>

#include "delineo/io/polygon_sets.hpp"
#include "delineo/project/building_edits.hpp"

using namespace delineo;

namespace {
core::Polygon rectangle(double x0, double y0, double x1, double y1) {
  return core::Polygon{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, {}};
}

project::Building outlined(int id, const core::Polygon& polygon, int low, int high) {
  project::Building b;
  b.id = id;
  b.initial = b.outline = polygon;
  b.status = project::BuildingStatus::Automatic;
  b.roofInterval = project::DisparityInterval{low, high};
  b.energy = 12.0;
  return b;
}
}  // namespace

TEST(SplitAlong, ASegmentAcrossCutsAndOneEndingInsideDoesNot) {
  const core::Polygon r = rectangle(0, 0, 40, 20);
  const io::PolygonSet pieces = io::splitAlong(r, {30, -5}, {30, 25});
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_NEAR(core::area(pieces[0]), 600.0, 0.1);  // largest first
  EXPECT_NEAR(core::area(pieces[1]), 200.0, 0.1);
  EXPECT_TRUE(io::splitAlong(r, {30, -5}, {30, 10}).empty()) << "a cut ending inside leaves one piece";
  EXPECT_TRUE(io::splitAlong(r, {50, -5}, {50, 25}).empty()) << "a cut beside the building";
  // An L: a cut across its foot only leaves the upright whole.
  const core::Polygon l{{{0, 0}, {10, 0}, {10, 30}, {40, 30}, {40, 40}, {0, 40}}, {}};
  const io::PolygonSet lPieces = io::splitAlong(l, {25, 25}, {25, 45});
  ASSERT_EQ(lPieces.size(), 2u);
  EXPECT_NEAR(core::area(lPieces[1]), 150.0, 0.1);
}

TEST(MergedOutline, TouchingOrAFewPixelsApartMergeFartherApartDoNot) {
  const core::Polygon left = rectangle(0, 0, 20, 20);
  const auto touching = io::mergedOutline(left, rectangle(20, 0, 40, 20), 3.0);
  ASSERT_TRUE(touching.has_value());
  EXPECT_NEAR(core::area(*touching), 800.0, 1e-6);
  // Two outlines on either side of a wall, 2 px apart: the strip between them is filled.
  const auto wall = io::mergedOutline(left, rectangle(22, 0, 42, 20), 3.0);
  ASSERT_TRUE(wall.has_value());
  EXPECT_NEAR(core::area(*wall), 840.0, 1e-6);
  EXPECT_FALSE(io::mergedOutline(left, rectangle(30, 0, 50, 20), 3.0).has_value());
}

TEST(MergedOutline, APocketBetweenTheTwoIsFilledAndACourtyardKept) {
  // A U open to the right, closed by a bar 1 px beyond its arms: the pocket between them is no
  // courtyard of either.
  const core::Polygon u{{{0, 0}, {30, 0}, {30, 10}, {10, 10}, {10, 20}, {30, 20}, {30, 30}, {0, 30}}, {}};
  const auto closed = io::mergedOutline(u, rectangle(31, 0, 40, 30), 3.0);
  ASSERT_TRUE(closed.has_value());
  EXPECT_TRUE(closed->holes.empty());
  EXPECT_NEAR(core::area(*closed), 40.0 * 30.0, 1e-6);
  // A courtyard of one of them stays.
  core::Polygon yard = rectangle(0, 0, 20, 20);
  yard.holes = {{{5, 5}, {5, 15}, {15, 15}, {15, 5}}};
  const auto kept = io::mergedOutline(yard, rectangle(20, 0, 40, 20), 3.0);
  ASSERT_TRUE(kept.has_value());
  EXPECT_EQ(kept->holes.size(), 1u);
  EXPECT_NEAR(core::area(*kept), 800.0 - 100.0, 1e-6);
}

TEST(BuildingEdits, AnOutlinedBuildingSplitsIntoCorrectedPieces) {
  project::Project p;
  project::Building b = outlined(3, rectangle(10, 10, 70, 30), 40, 46);
  b.sourceId = "B-7";
  p.buildings = {b};
  const project::BuildingEdit edit = project::splitBuilding(p, 3, {50, 0}, {50, 40}, {}, "test");
  ASSERT_TRUE(edit.done()) << edit.refusal;
  ASSERT_EQ(edit.ids, (std::vector<int>{3, 4}));
  ASSERT_EQ(p.buildings.size(), 2u);
  for (const auto& piece : p.buildings) {
    EXPECT_EQ(piece.status, project::BuildingStatus::Corrected);
    EXPECT_EQ(piece.roofInterval, b.roofInterval) << "no disparity map: the interval stays";
    EXPECT_EQ(piece.sourceId, "B-7");
    EXPECT_TRUE(std::isnan(piece.energy)) << "an edited outline is scored again";
    EXPECT_EQ(piece.history.back().action, "split");
    EXPECT_EQ(piece.initial.outer, piece.outline.outer);
  }
  EXPECT_NEAR(core::area(p.find(3)->outline), 800.0, 0.1);
  EXPECT_NEAR(core::area(p.find(4)->outline), 400.0, 0.1);
  EXPECT_EQ(p.find(4)->history.size(), 1u) << "a new piece starts its own history";
}

TEST(BuildingEdits, APendingBuildingSplitsIntoPendingPiecesAndABadCutChangesNothing) {
  project::Project p;
  project::Building b;
  b.id = 1;
  b.initial = rectangle(0, 0, 40, 40);
  p.buildings = {b};
  const project::Project before = p;
  const project::BuildingEdit refused = project::splitBuilding(p, 1, {20, -5}, {20, 20});
  EXPECT_FALSE(refused.done());
  EXPECT_EQ(refused.why, project::EditRefusal::NotCutInTwo);
  EXPECT_NE(refused.refusal.find("from outside to outside"), std::string::npos);
  EXPECT_TRUE(p == before);
  ASSERT_TRUE(project::splitBuilding(p, 1, {20, -5}, {20, 45}).done());
  ASSERT_EQ(p.buildings.size(), 2u);
  for (const auto& piece : p.buildings) {
    EXPECT_EQ(piece.status, project::BuildingStatus::Pending);
    EXPECT_FALSE(piece.hasOutline());
  }
}

TEST(BuildingEdits, TwoBuildingsAcrossAWallMergeIntoOne) {
  project::Project p;
  project::Building a = outlined(2, rectangle(0, 0, 20, 20), 40, 44);
  project::Building b = outlined(5, rectangle(22, 0, 42, 20), 47, 50);
  a.sourceId = "A";
  b.sourceId = "B";
  p.buildings = {b, a};  // the one merged away comes first: ids, not positions, are kept
  const project::BuildingEdit edit = project::mergeBuildings(p, 2, 5, {}, "test");
  ASSERT_TRUE(edit.done()) << edit.refusal;
  ASSERT_EQ(p.buildings.size(), 1u);
  const project::Building& m = p.buildings.front();
  EXPECT_EQ(m.id, 2);
  EXPECT_EQ(m.status, project::BuildingStatus::Corrected);
  EXPECT_NEAR(core::area(m.outline), 840.0, 1e-6);
  EXPECT_EQ(m.roofInterval, (project::DisparityInterval{40, 50}));
  EXPECT_EQ(m.sourceId, "A;B");
  EXPECT_EQ(m.history.back().detail, "test: with building 5");
}

TEST(BuildingEdits, BuildingsFarApartOrOneWithItselfAreNotMerged) {
  project::Project p;
  p.buildings = {outlined(1, rectangle(0, 0, 20, 20), 40, 44), outlined(2, rectangle(40, 0, 60, 20), 40, 44)};
  const project::Project before = p;
  const project::BuildingEdit apart = project::mergeBuildings(p, 1, 2);
  EXPECT_FALSE(apart.done());
  EXPECT_EQ(apart.why, project::EditRefusal::TooFarApart);
  EXPECT_NE(apart.refusal.find("more than 3 px apart"), std::string::npos) << apart.refusal;
  EXPECT_EQ(project::mergeBuildings(p, 1, 1).why, project::EditRefusal::SameBuilding);
  EXPECT_EQ(project::mergeBuildings(p, 1, 9).why, project::EditRefusal::NoSuchBuilding);
  EXPECT_TRUE(p == before);
}

TEST(BuildingEdits, EachPieceTakesTheRoofIntervalOfItsOwnDisparities) {
  // Two roofs side by side, at 40 and 50 px over a ground at 10 px, under one outline.
  cv::Mat disparity(120, 160, CV_32F, cv::Scalar(10.0f));
  disparity(cv::Rect(30, 30, 40, 60)).setTo(40.0f);
  disparity(cv::Rect(70, 30, 50, 60)).setTo(50.0f);
  project::Project p;
  p.buildings = {outlined(1, rectangle(30, 30, 120, 90), 39, 51)};
  ASSERT_TRUE(project::splitBuilding(p, 1, {70, 20}, {70, 100}, disparity).done());
  const project::Building& right = *p.find(1);  // the larger piece keeps the id
  const project::Building& left = *p.find(2);
  ASSERT_TRUE(left.roofInterval && right.roofInterval);
  EXPECT_LE(left.roofInterval->low, 40);
  EXPECT_GE(left.roofInterval->high, 40);
  EXPECT_LT(left.roofInterval->high, 45);
  EXPECT_GT(right.roofInterval->low, 45);
  EXPECT_GE(right.roofInterval->high, 50);
  // Without a disparity map the pieces keep the building's interval.
  p.buildings = {outlined(1, rectangle(30, 30, 120, 90), 39, 51)};
  ASSERT_TRUE(project::splitBuilding(p, 1, {70, 20}, {70, 100}).done());
  EXPECT_EQ(p.find(2)->roofInterval, (project::DisparityInterval{39, 51}));
}
