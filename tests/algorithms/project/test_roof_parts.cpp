// A building's roof parts on synthetic DEMs: a ring roof around a lower inner roof, an L of two
// heights, a flat roof with noise, holes and a chimney; the parts tile the outline.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "delineo/io/polygon_sets.hpp"
#include "delineo/project/roof_parts.hpp"

using namespace delineo;
using project::RoofPart;

namespace {

constexpr double kGsd = 0.1;  // m per px: min-area 10 m² is 1000 px, clean-width 1 m is 10 px

core::Polygon rectangle(double x0, double y0, double x1, double y1) { return {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, {}}; }

// Heights (m) of a 200 x 200 px scene at ground 0 with `roof` (m) inside each rectangle, later ones on top.
cv::Mat sceneWith(const std::vector<std::pair<cv::Rect, float>>& roofs) {
  cv::Mat heights(200, 200, CV_32F, cv::Scalar(0.0f));
  for (const auto& [box, roof] : roofs) heights(box).setTo(roof);
  return heights;
}

void addNoise(cv::Mat& heights, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(sigma));
  for (int y = 0; y < heights.rows; ++y) {
    for (int x = 0; x < heights.cols; ++x) heights.at<float>(y, x) += noise(rng);
  }
}

std::vector<RoofPart> partsOf(const cv::Mat& heights, const core::Polygon& outline,
                              segmentation::RoofLevelParams params = {}) {
  return project::partitionRoof(heights, outline, kGsd, params, delineation::RegularizationParams{});
}

// The parts cover the outline without overlapping: their areas add up to the outline's, their
// union is the outline and no two share more than a sliver of 1e-6 px².
void expectTiling(const std::vector<RoofPart>& parts, const core::Polygon& outline) {
  double sum = 0.0;
  io::PolygonSet all;
  for (size_t i = 0; i < parts.size(); ++i) {
    sum += core::area(parts[i].polygon);
    for (size_t j = i + 1; j < parts.size(); ++j) {
      double overlap = 0.0;
      for (const auto& p : io::intersectionOf({parts[i].polygon}, {parts[j].polygon})) overlap += core::area(p);
      EXPECT_LT(overlap, 1e-6) << "parts " << i << " and " << j << " overlap";
    }
    all = io::unionOf(all, {parts[i].polygon});
  }
  EXPECT_NEAR(sum, core::area(outline), 1e-6 * core::area(outline));
  double outside = 0.0;
  for (const auto& p : io::differenceOf(all, {outline})) outside += core::area(p);
  for (const auto& p : io::differenceOf({outline}, all)) outside += core::area(p);
  EXPECT_LT(outside, 1e-6);
}

// The part whose height is nearest `height`.
const RoofPart& partAt(const std::vector<RoofPart>& parts, double height) {
  size_t best = 0;
  for (size_t i = 1; i < parts.size(); ++i) {
    if (std::abs(parts[i].height - height) < std::abs(parts[best].height - height)) best = i;
  }
  return parts[best];
}

TEST(RoofParts, ARingRoofAroundALowerInnerRoofGivesTwoPartsTilingTheOutline) {
  // Outline 40..160 px; the ring 25 px wide at 18 m around a 70 x 70 px inner roof at 16 m.
  cv::Mat heights = sceneWith({{cv::Rect(40, 40, 120, 120), 18.0f}, {cv::Rect(65, 65, 70, 70), 16.0f}});
  addNoise(heights, 0.2, 1);
  const core::Polygon outline = rectangle(40, 40, 160, 160);
  const std::vector<RoofPart> parts = partsOf(heights, outline);
  ASSERT_EQ(parts.size(), 2u);
  const RoofPart& inner = partAt(parts, 16.0);
  const RoofPart& ring = partAt(parts, 18.0);
  EXPECT_NEAR(inner.height, 16.0, 0.1);
  EXPECT_NEAR(ring.height, 18.0, 0.1);
  // Within a pixel band along the inner roof's 280 px border.
  EXPECT_NEAR(core::area(inner.polygon), 70.0 * 70.0, 280.0);
  EXPECT_NEAR(core::area(ring.polygon), 120.0 * 120.0 - 70.0 * 70.0, 280.0);
  EXPECT_EQ(ring.polygon.holes.size(), 1u) << "the ring goes round the inner roof";
  EXPECT_LE(inner.polygon.outer.size(), 6u) << "the inner roof is squared";
  expectTiling(parts, outline);
}

TEST(RoofParts, AFlatRoofIsOnePartEqualToTheOutline) {
  const cv::Mat heights = sceneWith({{cv::Rect(40, 40, 120, 120), 12.0f}});
  const core::Polygon outline = rectangle(40, 40, 160, 160);
  const std::vector<RoofPart> parts = partsOf(heights, outline);
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_EQ(parts[0].polygon.outer, outline.outer);
  EXPECT_NEAR(parts[0].height, 12.0, 1e-6);
}

TEST(RoofParts, NoiseAndHolesWithoutHeightDoNotMakeParts) {
  cv::Mat heights = sceneWith({{cv::Rect(40, 40, 120, 120), 12.0f}});
  addNoise(heights, 0.4, 2);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> at(40, 150);
  for (int hole = 0; hole < 12; ++hole) heights(cv::Rect(at(rng), at(rng), 10, 10)).setTo(std::nanf(""));
  for (int speck = 0; speck < 2000; ++speck) heights.at<float>(at(rng), at(rng)) = std::nanf("");
  const core::Polygon outline = rectangle(40, 40, 160, 160);
  const std::vector<RoofPart> parts = partsOf(heights, outline);
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_EQ(parts[0].polygon.outer, outline.outer);
  EXPECT_NEAR(parts[0].height, 12.0, 0.1);
}

TEST(RoofParts, AChimneySmallerThanTheMinimumAreaIsAbsorbed) {
  // 15 x 15 px = 2.25 m², 3 m above the roof: absorbed; with a 1 m² minimum area it is a part.
  const cv::Mat heights = sceneWith({{cv::Rect(40, 40, 120, 120), 12.0f}, {cv::Rect(90, 90, 15, 15), 15.0f}});
  const core::Polygon outline = rectangle(40, 40, 160, 160);
  ASSERT_EQ(partsOf(heights, outline).size(), 1u);
  segmentation::RoofLevelParams small;
  small.minArea = 1.0;
  const std::vector<RoofPart> parts = partsOf(heights, outline, small);
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_NEAR(core::area(partAt(parts, 15.0).polygon), 15.0 * 15.0, 60.0 + 1.0);
  expectTiling(parts, outline);
}

TEST(RoofParts, AnLOfTwoHeightsGivesItsTwoWings) {
  // Wing A: x 20..180, y 20..80 at 12 m; wing B: x 20..80, y 80..180 at 6 m.
  cv::Mat heights = sceneWith({{cv::Rect(20, 20, 160, 60), 12.0f}, {cv::Rect(20, 80, 60, 100), 6.0f}});
  addNoise(heights, 0.2, 4);
  const core::Polygon outline{{{20, 20}, {180, 20}, {180, 80}, {80, 80}, {80, 180}, {20, 180}}, {}};
  const std::vector<RoofPart> parts = partsOf(heights, outline);
  ASSERT_EQ(parts.size(), 2u);
  const RoofPart& high = partAt(parts, 12.0);
  const RoofPart& low = partAt(parts, 6.0);
  EXPECT_NEAR(high.height, 12.0, 0.1);
  EXPECT_NEAR(low.height, 6.0, 0.1);
  EXPECT_NEAR(core::area(high.polygon), 160.0 * 60.0, 60.0);  // the 60 px border between them, a pixel each way
  EXPECT_NEAR(core::area(low.polygon), 60.0 * 100.0, 60.0);
  expectTiling(parts, outline);
}

TEST(RoofParts, AnObliqueRingRoofIsSquaredInTheBuildingsOrientation) {
  // The ring scene turned by 30° about the image centre.
  const cv::Mat flat = sceneWith({{cv::Rect(40, 40, 120, 120), 18.0f}, {cv::Rect(65, 65, 70, 70), 16.0f}});
  const cv::Matx23d turn(cv::getRotationMatrix2D(cv::Point2f(100.0f, 100.0f), 30.0, 1.0));
  cv::Mat heights;
  cv::warpAffine(flat, heights, turn, flat.size(), cv::INTER_NEAREST);
  core::Polygon outline;
  for (const cv::Point2d corner : {cv::Point2d(40, 40), cv::Point2d(160, 40), cv::Point2d(160, 160), cv::Point2d(40, 160)}) {
    const cv::Point2d c = corner - cv::Point2d(0.5, 0.5);  // pixel centres turn about the centre of pixel 100
    outline.outer.emplace_back(turn(0, 0) * c.x + turn(0, 1) * c.y + turn(0, 2) + 0.5,
                               turn(1, 0) * c.x + turn(1, 1) * c.y + turn(1, 2) + 0.5);
  }
  const std::vector<RoofPart> parts = partsOf(heights, outline);
  ASSERT_EQ(parts.size(), 2u);
  const RoofPart& inner = partAt(parts, 16.0);
  EXPECT_NEAR(core::area(inner.polygon), 70.0 * 70.0, 280.0);
  ASSERT_EQ(inner.polygon.outer.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {  // every edge at 30° modulo 90°
    const cv::Point2d d = inner.polygon.outer[(i + 1) % 4] - inner.polygon.outer[i];
    const double angle = std::fmod(std::atan2(d.y, d.x) * 180.0 / CV_PI + 360.0, 90.0);
    EXPECT_NEAR(std::min(std::abs(angle - 60.0), std::abs(angle - 30.0)), 0.0, 0.5) << "edge " << i;
  }
  expectTiling(parts, outline);
}

TEST(RoofParts, OffOrWithoutHeightsTheOutlineIsOnePart) {
  const cv::Mat heights = sceneWith({{cv::Rect(40, 40, 120, 120), 18.0f}, {cv::Rect(65, 65, 70, 70), 12.0f}});
  const core::Polygon outline = rectangle(40, 40, 160, 160);
  segmentation::RoofLevelParams off;
  off.mode = "off";
  ASSERT_EQ(partsOf(heights, outline, off).size(), 1u);
  EXPECT_EQ(partsOf(heights, outline, off)[0].polygon.outer, outline.outer);
  ASSERT_EQ(partsOf(cv::Mat(), outline).size(), 1u);
  ASSERT_EQ(partsOf(cv::Mat(200, 200, CV_32F, cv::Scalar(std::nanf(""))), outline).size(), 1u);
  ASSERT_EQ(partsOf(heights, outline).size(), 2u);
}

}  // namespace
