#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/boxfit/box_fitting.hpp"
#include "delineo/boxfit/stages.hpp"
#include "delineo/core/error.hpp"

using namespace delineo;
using namespace delineo::boxfit;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A scene of flat-roofed buildings: heights (m) on a gently sloping ground with a little noise,
// and a grey image where roofs are brighter than a textured ground.
struct Scene {
  cv::Mat heights, image;
};

Scene makeScene(cv::Size size, const std::vector<core::Polygon>& roofs, double roofHeight = 9.0, int seed = 1) {
  Scene s;
  cv::RNG rng(static_cast<uint64_t>(seed));
  s.heights.create(size, CV_32F);
  rng.fill(s.heights, cv::RNG::NORMAL, 0.0, 0.3);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) s.heights.at<float>(y, x) += static_cast<float>(0.01 * x + 0.005 * y);
  }
  cv::Mat texture(size, CV_32F);
  rng.fill(texture, cv::RNG::NORMAL, 0.0, 12.0);
  cv::GaussianBlur(texture, texture, {0, 0}, 1.0);
  s.image = texture + 90.0;
  for (const auto& roof : roofs) {
    const cv::Mat mask = core::rasterize(roof, size);
    cv::Mat raised = s.heights + roofHeight;
    raised.copyTo(s.heights, mask);
    cv::Mat bright = texture * 0.5 + 170.0;
    bright.copyTo(s.image, mask);
  }
  return s;
}

core::Polygon rectangle(double x, double y, double w, double h) {
  return {{{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, {}};
}

// The polygon's bounding box grown by `g` px: the operator's rough rectangle.
core::Polygon roughBox(const core::Polygon& p, double g) {
  const cv::Rect2d b = core::boundingBox(p.outer);
  return rectangle(b.x - g, b.y - g, b.width + 2 * g, b.height + 2 * g);
}

core::Polygon rotated(const core::Polygon& p, double degrees, cv::Point2d centre) {
  const double t = degrees * kPi / 180.0, c = std::cos(t), s = std::sin(t);
  core::Polygon out = p;
  for (auto& v : out.outer) {
    const cv::Point2d d = v - centre;
    v = centre + cv::Point2d(c * d.x - s * d.y, s * d.x + c * d.y);
  }
  return out;
}

double iou(const core::Polygon& a, const core::Polygon& b, cv::Size size) {
  if (a.outer.size() < 3) return 0.0;
  const cv::Mat ma = core::rasterize(a, size), mb = core::rasterize(b, size);
  const double inter = cv::countNonZero(ma & mb), uni = cv::countNonZero(ma | mb);
  return uni > 0 ? inter / uni : 0.0;
}

BoxFitBuilding fitOne(const Scene& s, const core::Polygon& init, const BoxFitParams& params = {}) {
  BoxFitRequest request;
  request.init = init;
  const BoxFitResult r = fitBoxes(s.heights, s.image, request, params);
  EXPECT_EQ(r.buildings.size(), 1u) << r.message;
  return r.buildings.empty() ? BoxFitBuilding{} : r.buildings.front();
}

const cv::Size kSize(220, 180);

}  // namespace

TEST(BoxFitting, RectangleGivesItsFourCorners) {
  const core::Polygon truth = rectangle(60, 50, 90, 60);
  const Scene s = makeScene(kSize, {truth});
  const BoxFitBuilding b = fitOne(s, roughBox(truth, 10));
  EXPECT_GT(iou(b.outline, truth, kSize), 0.95);
  EXPECT_EQ(b.outline.outer.size(), 4u);
  EXPECT_TRUE(b.outline.holes.empty());
  ASSERT_FALSE(b.boxes.empty());
  // Every box sits on the roof's walls: low energy, axis-aligned.
  for (const auto& box : b.boxes) {
    EXPECT_LT(box.energy, 1.0);
    const double a = std::fmod(box.angleDeg, 90.0);
    EXPECT_LT(std::min(a, 90.0 - a), 1.5) << box.angleDeg;
  }
  for (const auto& v : b.outline.outer) {
    const double dx = std::min(std::abs(v.x - 60), std::abs(v.x - 150));
    const double dy = std::min(std::abs(v.y - 50), std::abs(v.y - 110));
    EXPECT_LT(dx, 1.5) << v;
    EXPECT_LT(dy, 1.5) << v;
  }
}

TEST(BoxFitting, LShapeIsAChainOfBoxesWithSixCorners) {
  const core::Polygon truth{{{40, 30}, {170, 30}, {170, 80}, {95, 80}, {95, 150}, {40, 150}}, {}};
  const Scene s = makeScene(kSize, {truth});
  const BoxFitBuilding b = fitOne(s, roughBox(truth, 10));
  EXPECT_GT(iou(b.outline, truth, kSize), 0.93);
  EXPECT_EQ(b.outline.outer.size(), 6u);
  EXPECT_GE(b.boxes.size(), 2u);
  EXPECT_GE(b.diagnostics.junctions, 1);
  // The inner corner of the L is found, not filled in by a box.
  const cv::Point2d inner(95, 80);
  double nearest = 1e9;
  for (const auto& v : b.outline.outer) nearest = std::min(nearest, cv::norm(v - inner));
  EXPECT_LT(nearest, 2.0);
}

TEST(BoxFitting, RotatedBoxFollowsItsOrientation) {
  const cv::Point2d centre(110, 90);
  const core::Polygon truth = rotated(rectangle(65, 62, 90, 56), 27.0, centre);
  const Scene s = makeScene(kSize, {truth});
  const BoxFitBuilding b = fitOne(s, roughBox(truth, 8));
  EXPECT_GT(iou(b.outline, truth, kSize), 0.93);
  EXPECT_EQ(b.outline.outer.size(), 4u);
  ASSERT_FALSE(b.boxes.empty());
  // Boxes are stored modulo 90°: 27° or the same box at 117° both read 27.
  EXPECT_NEAR(b.diagnostics.mainOrientationDeg, 27.0, 2.0);
}

TEST(BoxFitting, AStreakOfRoofHeightsBeyondTheInitStaysOutOfTheOutline) {
  // A matcher spreads the roof's disparity along the rows past the wall (an occlusion filled
  // from the roof, a facade): heights at roof level 24 px beyond the east wall, where the image
  // shows ground. The segment stops at the operator's rectangle (10 px past the wall) and the
  // east side snaps back onto the wall's edge, within snap-inward.
  const core::Polygon truth = rectangle(50, 50, 90, 60);
  Scene s = makeScene(kSize, {truth});
  const cv::Mat streak = core::rasterize(rectangle(140, 50, 24, 60), kSize);
  cv::Mat raised = s.heights + 9.0;
  raised.copyTo(s.heights, streak);
  const BoxFitBuilding b = fitOne(s, roughBox(truth, 10));
  EXPECT_GT(iou(b.outline, truth, kSize), 0.93);
  double east = 0;
  for (const auto& v : b.outline.outer) east = std::max(east, v.x);
  EXPECT_LT(east, 145.0);  // the wall at 140 (158 when the segment reached 8 px past the init)
}

TEST(BoxFitting, TwoBuildingsInTheWholeImageWithoutAnInit) {
  const core::Polygon a = rectangle(20, 20, 70, 50), c = rectangle(120, 90, 70, 60);
  const Scene s = makeScene(kSize, {a, c});
  const BoxFitResult r = fitBoxes(s.heights, s.image, {});
  ASSERT_EQ(r.buildings.size(), 2u) << r.message;
  for (const auto& b : r.buildings) {
    EXPECT_GT(std::max(iou(b.outline, a, kSize), iou(b.outline, c, kSize)), 0.93);
  }
}

TEST(BoxFitting, NoDataDemGivesNoBuildingAndSaysWhy) {
  const core::Polygon truth = rectangle(60, 50, 90, 60);
  Scene s = makeScene(kSize, {truth});
  s.heights.setTo(std::numeric_limits<float>::quiet_NaN());
  BoxFitRequest request;
  request.init = roughBox(truth, 10);
  const BoxFitResult r = fitBoxes(s.heights, s.image, request);
  EXPECT_TRUE(r.buildings.empty());
  EXPECT_NE(r.message.find("no finite height"), std::string::npos) << r.message;
  EXPECT_EQ(r.status, core::RunStatus::Completed);
  const BoxFitResult whole = fitBoxes(s.heights, s.image, {});
  EXPECT_TRUE(whole.buildings.empty());
  EXPECT_FALSE(whole.message.empty());
}

TEST(BoxFitting, GapsInTheDemAreFilledFromTheGroundSide) {
  // A no-data strip west of the roof (ground hidden in the other view) and holes in the roof:
  // the outline is still the roof's.
  const core::Polygon truth = rectangle(60, 50, 90, 60);
  Scene s = makeScene(kSize, {truth});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  s.heights(cv::Rect(50, 50, 12, 60)).setTo(nan);
  s.heights(cv::Rect(90, 70, 15, 10)).setTo(nan);
  const BoxFitBuilding b = fitOne(s, roughBox(truth, 10));
  EXPECT_GT(iou(b.outline, truth, kSize), 0.94);
}

TEST(BoxFitting, FlatDemInsideTheInitSaysNothingStandsAboveTheGround) {
  const Scene s = makeScene(kSize, {});
  BoxFitRequest request;
  request.init = rectangle(60, 50, 90, 60);
  const BoxFitResult r = fitBoxes(s.heights, s.image, request);
  EXPECT_TRUE(r.buildings.empty());
  EXPECT_NE(r.message.find("above the ground"), std::string::npos) << r.message;
}

TEST(BoxFitting, BadInputsAreErrorsNamingTheProblem) {
  const core::Polygon truth = rectangle(60, 50, 90, 60);
  const Scene s = makeScene(kSize, {truth});
  BoxFitRequest request;
  request.init = roughBox(truth, 10);
  auto code = [](auto&& call) {
    try {
      call();
    } catch (const core::Error& e) {
      return e.code();
    }
    ADD_FAILURE() << "no error";
    return core::ErrorCode::ProcessingFailed;
  };
  EXPECT_EQ(code([&] { fitBoxes(cv::Mat(), s.image, request); }), core::ErrorCode::InvalidParameter);
  EXPECT_EQ(code([&] { fitBoxes(s.heights, cv::Mat(), request); }), core::ErrorCode::InvalidParameter);
  EXPECT_EQ(code([&] { fitBoxes(s.heights(cv::Rect(0, 0, 100, 100)), s.image, request); }),
            core::ErrorCode::MismatchedInputs);
  cv::Mat colour;
  cv::Mat image8;
  s.image.convertTo(image8, CV_8U);
  cv::cvtColor(image8, colour, cv::COLOR_GRAY2BGR);
  EXPECT_EQ(code([&] { fitBoxes(s.heights, colour, request); }), core::ErrorCode::UnsupportedInput);
  BoxFitRequest outside;
  outside.init = rectangle(500, 500, 30, 30);
  EXPECT_EQ(code([&] { fitBoxes(s.heights, s.image, outside); }), core::ErrorCode::InvalidParameter);
  BoxFitRequest twoVertices;
  twoVertices.init.outer = {{10, 10}, {50, 50}};
  EXPECT_EQ(code([&] { fitBoxes(s.heights, s.image, twoVertices); }), core::ErrorCode::InvalidParameter);
  BoxFitRequest flat;
  flat.init.outer = {{10, 10}, {50, 50}, {90, 90}};
  EXPECT_EQ(code([&] { fitBoxes(s.heights, s.image, flat); }), core::ErrorCode::InvalidParameter);
  BoxFitParams bad;
  bad.angleStep = 0;
  EXPECT_EQ(code([&] { fitBoxes(s.heights, s.image, request, bad); }), core::ErrorCode::InvalidParameter);
  // An 8-bit image works the same as float.
  EXPECT_NO_THROW(fitBoxes(s.heights, image8, request));
}

TEST(BoxFitting, ParametersAreValidatedAndRoundTripThroughJson) {
  BoxFitParams p;
  EXPECT_NO_THROW(p.validate());
  p.groundWindow = 300;
  EXPECT_THROW(p.validate(), core::Error);
  p = {};
  p.roiMargin = p.leash;
  EXPECT_THROW(p.validate(), core::Error);
  p = {};
  p.pieceLength = 33;
  p.skipCovered = true;
  BoxFitParams q;
  core::fromJson(q, core::toJson(p));
  EXPECT_EQ(q.pieceLength, 33);
  EXPECT_TRUE(q.skipCovered);
}

TEST(BoxFitting, CancelReturnsCanceledWithoutABuilding) {
  const core::Polygon truth{{{40, 30}, {170, 30}, {170, 80}, {95, 80}, {95, 150}, {40, 150}}, {}};
  const Scene s = makeScene(kSize, {truth});
  BoxFitRequest request;
  request.init = roughBox(truth, 10);
  core::Progress counting;
  const BoxFitResult full = fitBoxes(s.heights, s.image, request, {}, &counting);
  ASSERT_EQ(full.buildings.size(), 1u);
  ASSERT_GT(counting.reportCount(), 4);
  EXPECT_DOUBLE_EQ(counting.fraction(), 1.0);
  core::Progress progress;
  progress.cancelAfterReports(counting.reportCount() / 2);
  const BoxFitResult r = fitBoxes(s.heights, s.image, request, {}, &progress);
  EXPECT_EQ(r.status, core::RunStatus::Canceled);
  EXPECT_TRUE(r.buildings.empty());
}

TEST(BoxFitting, HeightsFromDisparityFollowTheHeightModel) {
  cv::Mat d = (cv::Mat_<float>(1, 3) << 10.0f, 14.0f, std::numeric_limits<float>::quiet_NaN());
  const cv::Mat h = heightsFromDisparity(d, 10.0, 0.5);
  EXPECT_FLOAT_EQ(h.at<float>(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(h.at<float>(0, 1), 2.0f);
  EXPECT_TRUE(std::isnan(h.at<float>(0, 2)));
}

// ---- Stages -----------------------------------------------------------------------------------

TEST(BoxFitStages, SegmentDropsSmallRaisedObjectsAndKeepsTheBuilding) {
  // A building and, within the leash, a 6x6 px tree at the same height: the tree is smaller than
  // min-area once eroded and is no part of the segment; the building is grown back whole after
  // the erosion (all but its four corners' few pixels).
  const core::Polygon truth = rectangle(60, 50, 90, 60);
  const core::Polygon tree = rectangle(156, 60, 6, 6);
  const Scene s = makeScene(kSize, {truth, tree});
  const cv::Mat initMask = core::rasterize(roughBox(truth, 10), kSize);
  const cv::Mat segment = buildingSegment(s.heights, initMask, 9.0, BoxFitParams{});
  const cv::Mat truthMask = core::rasterize(truth, kSize);
  EXPECT_EQ(cv::countNonZero(segment & core::rasterize(tree, kSize)), 0);
  EXPECT_GT(cv::countNonZero(segment & truthMask), cv::countNonZero(truthMask) - 20);
}

TEST(BoxFitStages, SkeletonOfAnLSplitsAtTheJunctionIntoSeedsInBothWings) {
  const core::Polygon truth{{{40, 30}, {170, 30}, {170, 80}, {95, 80}, {95, 150}, {40, 150}}, {}};
  const cv::Mat segment = core::rasterize(truth, kSize);
  const SkeletonSeeds seeds = skeletonSeeds(segment, BoxFitParams{});
  EXPECT_GE(seeds.junctions, 1);
  bool east = false, south = false;
  for (const auto& s : seeds.seeds) {
    east |= s.point.x > 110 && s.point.y < 80;
    south |= s.point.y > 95 && s.point.x < 95;
    EXPECT_GT(s.depth, 1.0);
  }
  EXPECT_TRUE(east);
  EXPECT_TRUE(south);
}

TEST(BoxFitStages, MergedBoxesOfAnLGiveOneStraightOutline) {
  // Two overlapping boxes that form an L: the union's outline has six corners at the boxes'.
  Box a, b;
  a.centre = {100, 50}, a.length = 120, a.width = 40, a.angleDeg = 0;
  b.centre = {60, 100}, b.length = 40, b.width = 120, b.angleDeg = 0;
  const core::Polygon outline = mergeBoxes({a, b}, {200, 200}, BoxFitParams{});
  ASSERT_EQ(outline.outer.size(), 6u);
  const core::Polygon truth{{{40, 30}, {160, 30}, {160, 70}, {80, 70}, {80, 160}, {40, 160}}, {}};
  EXPECT_GT(iou(outline, truth, {200, 200}), 0.98);
}

TEST(BoxFitStages, AWingNoBoxCoversGetsASeedOfItsOwn) {
  // An L whose boxes cover only the long arm: the short wing left over gets one seed inside it,
  // slivers along the box's sides none.
  const core::Polygon truth{{{40, 30}, {170, 30}, {170, 80}, {95, 80}, {95, 120}, {40, 120}}, {}};
  const cv::Mat segment = core::rasterize(truth, kSize);
  Box arm;
  arm.centre = {105, 55}, arm.length = 129, arm.width = 49, arm.angleDeg = 0;
  const std::vector<Seed> seeds = uncoveredSeeds(segment, {arm}, BoxFitParams{});
  ASSERT_EQ(seeds.size(), 1u);
  EXPECT_TRUE(cv::Rect(40, 80, 55, 40).contains(seeds[0].point)) << seeds[0].point;
  Box all;
  all.centre = {105, 55}, all.length = 130, all.width = 50;
  Box wing;
  wing.centre = {67.5, 100}, wing.length = 55, wing.width = 40;
  EXPECT_TRUE(uncoveredSeeds(segment, {all, wing}, BoxFitParams{}).empty());
}

TEST(BoxFitStages, BoxesOthersCoverAreLeftOutOfTheBuildingsBoxes) {
  // An L's two boxes, and six smaller boxes inside them (seeds along one arm's skeleton grow
  // boxes that the arm's box covers): only the two remain, in their input order.
  Box a, b;
  a.centre = {100, 50}, a.length = 120, a.width = 40, a.angleDeg = 0;
  b.centre = {60, 100}, b.length = 40, b.width = 120, b.angleDeg = 0;
  std::vector<Box> boxes;
  for (int i = 0; i < 6; ++i) {
    Box inner = a;
    inner.centre.x = 60 + 16 * i;
    inner.length = 30, inner.width = 36 - i;
    boxes.push_back(inner);
  }
  boxes.insert(boxes.begin() + 2, b);
  boxes.push_back(a);
  const std::vector<Box> kept = essentialBoxes(boxes, {200, 200});
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0].centre, b.centre);
  EXPECT_EQ(kept[1].centre, a.centre);
  // A box that adds a visible part of its own is kept.
  Box wing = a;
  wing.centre = {175, 50}, wing.length = 60;  // half of it beyond a's end
  EXPECT_EQ(essentialBoxes({a, b, wing}, {200, 200}).size(), 3u);
}

TEST(BoxFitStages, ABoxIsClippedToTheImage) {
  Box box;
  box.centre = {190, 50}, box.length = 40, box.width = 20, box.angleDeg = 0;
  const core::Ring inside = box.cornersWithin({200, 100});
  ASSERT_GE(inside.size(), 4u);
  for (const auto& p : inside) EXPECT_LE(p.x, 200.0);
  EXPECT_NEAR(std::abs(core::signedArea(inside)), 30.0 * 20.0, 1e-6);
  // Rotated and crossing a corner: still inside, and a box wholly outside has nothing left.
  box.centre = {5, 5}, box.angleDeg = 30;
  for (const auto& p : box.cornersWithin({200, 100})) EXPECT_TRUE(p.x >= 0 && p.y >= 0) << p;
  box.centre = {-100, -100};
  EXPECT_TRUE(box.cornersWithin({200, 100}).empty());
}

// The largest deviation from a right angle (degrees) among the ring's corners.
double worstCornerDeviation(const core::Ring& ring) {
  double worst = 0;
  for (size_t i = 0; i < ring.size(); ++i) {
    const cv::Point2d a = ring[(i + ring.size() - 1) % ring.size()] - ring[i];
    const cv::Point2d b = ring[(i + 1) % ring.size()] - ring[i];
    const double angle = std::acos(std::clamp(a.dot(b) / (cv::norm(a) * cv::norm(b)), -1.0, 1.0)) * 180.0 / kPi;
    worst = std::max(worst, std::abs(angle - 90.0));
  }
  return worst;
}

TEST(BoxFitting, ABuildingCutByTheImageBorderStaysRectilinear) {
  // An L-shaped flat roof whose east part runs past the image's right border, and an operator's
  // rectangle up to that border: the outline stops at the border with right angles only, and
  // no box leans (seeds along the border once grew boxes reaching past it at a slant).
  const core::Polygon truth{{{70, 40}, {260, 40}, {260, 120}, {130, 120}, {130, 160}, {70, 160}}, {}};
  const Scene s = makeScene(kSize, {truth});
  const core::Polygon init = rectangle(60, 30, kSize.width - 60, 140);
  const BoxFitBuilding b = fitOne(s, init);
  const core::Polygon visible{{{70, 40}, {220, 40}, {220, 120}, {130, 120}, {130, 160}, {70, 160}}, {}};
  EXPECT_GT(iou(b.outline, visible, kSize), 0.95);
  EXPECT_EQ(b.outline.outer.size(), 6u);
  EXPECT_LT(worstCornerDeviation(b.outline.outer), 2.0);
  for (const auto& box : b.boxes) {
    const double a = std::fmod(box.angleDeg, 90.0);
    EXPECT_LT(std::min(a, 90.0 - a), 1.5) << box.angleDeg;
    for (const auto& c : box.corners()) EXPECT_LE(c.x, kSize.width + 1.0) << "a box reaches past the image";
  }
}

TEST(BoxFitStages, SeedsOfASegmentCutByTheBorderAreNoDeeperThanTheirDistanceToIt) {
  // A segment running past the ROI's right side: the border is the segment's edge there, so no
  // skeleton along it and no seed deeper than its distance to it.
  cv::Mat segment = cv::Mat::zeros(120, 160, CV_8U);
  segment(cv::Rect(30, 20, 130, 80)).setTo(255);
  const SkeletonSeeds s = skeletonSeeds(segment, BoxFitParams{});
  EXPECT_EQ(cv::countNonZero(s.skeleton.col(segment.cols - 1)), 0);
  ASSERT_FALSE(s.seeds.empty());
  for (const Seed& seed : s.seeds) {
    EXPECT_LE(seed.depth, segment.cols - seed.point.x + 1.0) << seed.point;
    EXPECT_LE(seed.depth, 41.0) << seed.point;
  }
}
