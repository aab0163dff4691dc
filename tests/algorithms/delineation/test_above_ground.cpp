// delineation::aboveGroundObjectAt: the connected region above the local ground under a click,
// with the ground of estimateGroundLevel() (the histogram's ground line) next to its outline.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "delineo/core/error.hpp"
#include "delineo/delineation/above_ground.hpp"
#include "delineo/delineation/roof_interval.hpp"

using delineo::core::Error;
using delineo::core::ErrorCode;
using namespace delineo::delineation;

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr double kMetresPerPixel = 0.5;  // a 6 px box is 3 m high, above the 2.5 m margin

// Ground at `ground + slope * x`, plus `height` px of disparity on `box`.
cv::Mat groundWith(cv::Size size, float ground, float slope, const cv::Rect& box, float height) {
  cv::Mat d(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      d.at<float>(y, x) = ground + slope * static_cast<float>(x) + (box.contains({x, y}) ? height : 0.0f);
    }
  }
  return d;
}

int overlap(const cv::Mat& mask, const cv::Rect& box) { return cv::countNonZero(mask(box)); }
}  // namespace

TEST(AboveGround, FlatGroundGivesTheBoxAndTheHistogramsGround) {
  const cv::Rect box(30, 40, 40, 40);
  const cv::Mat d = groundWith({200, 200}, 4.0f, 0.0f, box, 20.0f);
  const AboveGroundObject o = aboveGroundObjectAt(d, {50.5, 60.5}, kMetresPerPixel);
  ASSERT_EQ(o.outcome, PickOutcome::Found);
  EXPECT_EQ(o.pixels, box.area());
  EXPECT_EQ(overlap(o.mask, box), box.area());
  EXPECT_NEAR(o.groundLevel, 4.0, 0.01);
  // The ground is the one the histogram shows for the picked outline: the same function.
  EXPECT_EQ(o.groundLevel, estimateGroundLevel(d, o.outline));
  EXPECT_GE(o.outline.outer.size(), 4u);
  const cv::Rect2d b = delineo::core::boundingBox(o.outline.outer);
  EXPECT_NEAR(b.x, 30.5, 0.01);
  EXPECT_NEAR(b.width, 39.0, 0.01);
}

TEST(AboveGround, AClickFarInsideALargeRoofWidensTheGroundSearch) {
  // The first 120 px band around the centre is all roof; the ground lies 180 px away.
  const cv::Rect roof(20, 20, 360, 360);
  const cv::Mat d = groundWith({400, 400}, 0.0f, 0.0f, roof, 30.0f);
  const AboveGroundObject o = aboveGroundObjectAt(d, {200, 200}, kMetresPerPixel);
  ASSERT_EQ(o.outcome, PickOutcome::Found);
  EXPECT_EQ(o.pixels, roof.area());
  EXPECT_NEAR(o.groundLevel, 0.0, 0.01);
  // With the search limited to the first band, the click finds no ground under it.
  AboveGroundParams narrow;
  narrow.maxSearchRadius = narrow.searchRadius;
  EXPECT_EQ(aboveGroundObjectAt(d, {200, 200}, kMetresPerPixel, narrow).outcome, PickOutcome::NotAboveGround);
}

TEST(AboveGround, ASlopedGroundIsReadNextToTheObject) {
  // 0.08 px of disparity per px: across the 300 px map the ground rises 24 px (12 m); the box
  // stands 8 px (4 m) above the ground beside it.
  const cv::Rect box(200, 100, 50, 40);
  const cv::Mat d = groundWith({300, 240}, 0.0f, 0.08f, box, 8.0f);
  const AboveGroundObject o = aboveGroundObjectAt(d, {225, 120}, kMetresPerPixel);
  ASSERT_EQ(o.outcome, PickOutcome::Found);
  EXPECT_GE(overlap(o.mask, box), box.area() * 95 / 100);
  EXPECT_LE(o.pixels - overlap(o.mask, box), box.area() / 20);  // little ground taken in
  EXPECT_NEAR(o.groundLevel, 0.08 * 225, 1.5);
}

TEST(AboveGround, HolesAlongWallsAndAtTheClickDoNotStopThePick) {
  const cv::Rect box(60, 60, 50, 50);
  cv::Mat d = groundWith({200, 200}, 0.0f, 0.0f, box, 16.0f);
  d(cv::Rect(55, 60, 5, 50)).setTo(kNaN);  // occlusion beside the left wall
  d(cv::Rect(83, 83, 4, 4)).setTo(kNaN);   // no data under the click
  const AboveGroundObject o = aboveGroundObjectAt(d, {85, 85}, kMetresPerPixel);
  ASSERT_EQ(o.outcome, PickOutcome::Found);
  // The object is its outer border: the hole under the click is inside it.
  EXPECT_EQ(overlap(o.mask, box), box.area());
  EXPECT_EQ(o.pixels, box.area());
}

TEST(AboveGround, AThinLinkToANeighbourIsCut) {
  cv::Mat d = groundWith({200, 120}, 0.0f, 0.0f, {20, 30, 50, 50}, 12.0f);
  d(cv::Rect(100, 30, 50, 50)).setTo(20.0f);  // a higher neighbour
  d(cv::Rect(70, 50, 30, 2)).setTo(12.0f);   // a 2 px wall top between them
  const AboveGroundObject o = aboveGroundObjectAt(d, {40, 50}, kMetresPerPixel);
  ASSERT_EQ(o.outcome, PickOutcome::Found);
  EXPECT_EQ(o.pixels, 2500);
}

TEST(AboveGround, ANeighbourOfAnotherHeightStaysOutAndAParapetJoins) {
  // A roof at 20 px inside a 3 px parapet at 28 px (2 m higher at 0.25 m/px), beside a taller
  // neighbour at 40 px sharing its east wall.
  cv::Mat d = groundWith({220, 160}, 0.0f, 0.0f, {30, 30, 80, 80}, 28.0f);
  d(cv::Rect(33, 33, 74, 74)).setTo(20.0f);
  d(cv::Rect(110, 30, 60, 80)).setTo(40.0f);
  const AboveGroundObject o = aboveGroundObjectAt(d, {70, 70}, 0.25);
  ASSERT_EQ(o.outcome, PickOutcome::Found);
  EXPECT_EQ(o.pixels, 80 * 80);
  EXPECT_EQ(overlap(o.mask, {110, 30, 60, 80}), 0);
  // Without the step limit the neighbour joins; without the thin parts the parapet stays out.
  AboveGroundParams anyStep;
  anyStep.maxStep = 0.0;
  EXPECT_EQ(aboveGroundObjectAt(d, {70, 70}, 0.25, anyStep).pixels, 80 * 80 + 60 * 80);
  AboveGroundParams noThin;
  noThin.thinWidth = 1;
  EXPECT_EQ(aboveGroundObjectAt(d, {70, 70}, 0.25, noThin).pixels, 74 * 74);
}

TEST(AboveGround, GroundNoDataAndSinglePixelsAreNotObjects) {
  const cv::Mat d = groundWith({100, 100}, 2.0f, 0.0f, {40, 40, 20, 20}, 10.0f);
  EXPECT_EQ(aboveGroundObjectAt(d, {10, 10}, kMetresPerPixel).outcome, PickOutcome::NotAboveGround);
  const cv::Mat none(50, 50, CV_32F, cv::Scalar(kNaN));
  const AboveGroundObject empty = aboveGroundObjectAt(none, {25, 25}, kMetresPerPixel);
  EXPECT_EQ(empty.outcome, PickOutcome::NoGround);
  EXPECT_TRUE(std::isnan(empty.groundLevel));
  cv::Mat single = none.clone();
  single.at<float>(25, 25) = 30.0f;
  EXPECT_EQ(aboveGroundObjectAt(single, {25, 25}, kMetresPerPixel).outcome, PickOutcome::NoGround);
}

TEST(AboveGround, BadInputsGiveClearErrors) {
  const cv::Mat d(50, 50, CV_32F, cv::Scalar(1.0f));
  auto codeOf = [](auto&& call) {
    try {
      call();
    } catch (const Error& e) {
      return e.code();
    }
    ADD_FAILURE() << "no error";
    return ErrorCode::ProcessingFailed;
  };
  EXPECT_EQ(codeOf([&] { aboveGroundObjectAt(cv::Mat(), {1, 1}, 1.0); }), ErrorCode::UnsupportedInput);
  EXPECT_EQ(codeOf([&] { aboveGroundObjectAt(cv::Mat(5, 5, CV_8U), {1, 1}, 1.0); }), ErrorCode::UnsupportedInput);
  EXPECT_EQ(codeOf([&] { aboveGroundObjectAt(d, {1, 1}, 0.0); }), ErrorCode::InvalidParameter);
  EXPECT_EQ(codeOf([&] { aboveGroundObjectAt(d, {50, 1}, 1.0); }), ErrorCode::InvalidParameter);
  EXPECT_EQ(codeOf([&] { aboveGroundObjectAt(d, {-0.5, 1}, 1.0); }), ErrorCode::InvalidParameter);
  AboveGroundParams even;
  even.opening = 4;
  EXPECT_EQ(codeOf([&] { aboveGroundObjectAt(d, {1, 1}, 1.0, even); }), ErrorCode::InvalidParameter);
}
