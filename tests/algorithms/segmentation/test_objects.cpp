// segmentation::classify, extractObjects, proposeBuildings: building vs vegetation on synthetic
// roofs and crowns (grey and colour), one object per class where a tree touches a building, the
// objects' measures on a case with known values, the proposals' attributes as `delineate --init`
// reads them, and the errors on bad inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <variant>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/core/nan_mask.hpp"
#include "delineo/segmentation/detect.hpp"
#include "delineo/segmentation/scene.hpp"
#include "delineo/io/vector.hpp"

using delineo::core::Error;
using delineo::core::ErrorCode;
using delineo::core::Progress;
using delineo::core::RunStatus;
using namespace delineo::segmentation;

namespace {

constexpr double kGsd = 0.25;

// A 240 x 200 scene: ground with mild noise; a flat roof [30, 100) x [40, 140) with membrane
// seams every 12 px (one direction) and a 10 m height; a dark, leafy crown of radius 28 px at
// (170, 100) as a dome up to 8 m.
struct Scene {
  cv::Mat grey, above, ndsm;
  cv::Rect roof{30, 40, 70, 100};
  cv::Point crown{170, 100};
  int radius = 28;
};

Scene roofAndCrown(cv::Point crown = {170, 100}) {
  Scene s;
  s.crown = crown;
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 2.0f);
  cv::Mat g(200, 240, CV_32F);
  for (int y = 0; y < g.rows; ++y) {
    for (int x = 0; x < g.cols; ++x) g.at<float>(y, x) = 110.0f + noise(rng);
  }
  s.above = cv::Mat::zeros(g.size(), CV_8U);
  s.ndsm = cv::Mat::zeros(g.size(), CV_32F);
  for (int y = s.roof.y; y < s.roof.y + s.roof.height; ++y) {
    for (int x = s.roof.x; x < s.roof.x + s.roof.width; ++x) {
      const bool seam = (x - s.roof.x) % 12 < 2;
      g.at<float>(y, x) = (seam ? 110.0f : 160.0f) + noise(rng);
      s.above.at<uchar>(y, x) = 255;
      s.ndsm.at<float>(y, x) = 10.0f;
    }
  }
  // Leaves: small random blobs (blurred noise), dark and textured.
  cv::Mat leaves(g.size(), CV_32F);
  cv::randn(leaves, 0.0, 60.0);
  cv::GaussianBlur(leaves, leaves, {0, 0}, 0.7);
  for (int y = 0; y < g.rows; ++y) {
    for (int x = 0; x < g.cols; ++x) {
      const double r = std::hypot(x - s.crown.x, y - s.crown.y);
      if (r >= s.radius || s.above.at<uchar>(y, x) != 0) continue;
      g.at<float>(y, x) = std::clamp(60.0f + leaves.at<float>(y, x), 0.0f, 255.0f);
      s.above.at<uchar>(y, x) = 255;
      s.ndsm.at<float>(y, x) = static_cast<float>(4.0 + 4.0 * std::sqrt(1.0 - r * r / (s.radius * s.radius)));
    }
  }
  g.convertTo(s.grey, CV_8U);
  return s;
}

double share(const cv::Mat& labels, const cv::Mat& where, ClassLabel cls) {
  return double(cv::countNonZero((labels == cls) & where)) / std::max(1, cv::countNonZero(where));
}

cv::Mat crownMask(const Scene& s) {
  cv::Mat m = cv::Mat::zeros(s.grey.size(), CV_8U);
  cv::circle(m, s.crown, s.radius - 1, 255, -1);
  return m & (s.above != 0);
}

}  // namespace

TEST(Classify, FlatRoofIsBuildingAndLeafyCrownIsVegetation) {
  const Scene s = roofAndCrown();
  const Classification c = classify(s.grey, s.above, s.ndsm, kGsd);
  ASSERT_EQ(c.status, RunStatus::Completed);
  cv::Mat roof = cv::Mat::zeros(s.grey.size(), CV_8U);
  roof(s.roof).setTo(255);
  EXPECT_EQ(share(c.labels, roof, kClassBuilding), 1.0);
  EXPECT_EQ(share(c.labels, crownMask(s), kClassVegetation), 1.0);
  EXPECT_EQ(cv::countNonZero((c.labels == kClassGround) & (s.above != 0)), 0);
  EXPECT_EQ(cv::countNonZero((c.labels != kClassGround) & (s.above == 0)), 0);
}

TEST(Classify, EachRegionTakesItsMajority) {
  const Scene s = roofAndCrown();
  const Classification c = classify(s.grey, s.above, s.ndsm, kGsd);
  // Per pixel, some roof pixels near the crown or the seams may read as vegetation; per region, none.
  cv::Mat roof = cv::Mat::zeros(s.grey.size(), CV_8U);
  roof(s.roof).setTo(255);
  EXPECT_GE(share(c.pixelLabels, roof, kClassBuilding), 0.5);
  EXPECT_EQ(share(c.labels, roof, kClassBuilding), 1.0);
  // A region map given by the caller decides: one region over both objects makes one class.
  cv::Mat one(s.grey.size(), CV_32S, cv::Scalar(-1));
  one.setTo(0, s.above);
  const Classification merged = classify(s.grey, s.above, s.ndsm, kGsd, {}, one);
  const bool allBuilding = cv::countNonZero(merged.labels == kClassVegetation) == 0;
  const bool allVegetation = cv::countNonZero(merged.labels == kClassBuilding) == 0;
  EXPECT_TRUE(allBuilding || allVegetation);
}

TEST(Classify, GreennessDecidesOnColour) {
  // Two smooth, bright, identical patches: the grey rules call both buildings; one is green.
  cv::Mat bgr(120, 200, CV_8UC3, cv::Scalar(120, 120, 120));
  cv::Mat above = cv::Mat::zeros(bgr.size(), CV_8U);
  const cv::Rect grey(20, 30, 60, 60), green(120, 30, 60, 60);
  bgr(grey).setTo(cv::Scalar(150, 150, 150));
  bgr(green).setTo(cv::Scalar(110, 170, 130));  // BGR: more green than red, same brightness
  above(grey).setTo(255);
  above(green).setTo(255);
  const cv::Mat ndsm(bgr.size(), CV_32F, cv::Scalar(6.0f));
  cv::Mat greyMask = cv::Mat::zeros(bgr.size(), CV_8U), greenMask = greyMask.clone();
  greyMask(grey).setTo(255);
  greenMask(green).setTo(255);
  const Classification c = classify(bgr, above, ndsm, kGsd);
  ASSERT_FALSE(c.greenness.empty());
  EXPECT_EQ(share(c.labels, greyMask, kClassBuilding), 1.0);
  EXPECT_EQ(share(c.labels, greenMask, kClassVegetation), 1.0);
  // Without the greenness rule the green patch is a roof like the other.
  ClassifyParams off;
  off.greenThreshold = 1.0;
  const Classification blind = classify(bgr, above, ndsm, kGsd, off);
  EXPECT_EQ(share(blind.labels, greenMask, kClassBuilding), 1.0);
}

TEST(Objects, AdjacentBuildingAndTreeStayTwoObjects) {
  // The crown touches the roof's east wall.
  const Scene s = roofAndCrown({100 + 26, 90});
  const Classification c = classify(s.grey, s.above, s.ndsm, kGsd);
  cv::Mat pieces;
  ASSERT_EQ(cv::connectedComponents(s.above, pieces, 8), 2);  // one above-ground piece (and the ground)
  const ObjectSet set = extractObjects(c.labels, s.ndsm, kGsd);
  ASSERT_EQ(set.objects.size(), 2u);
  int buildings = 0, trees = 0;
  for (const auto& o : set.objects) {
    (o.cls == kClassBuilding ? buildings : trees)++;
    if (o.cls == kClassBuilding) {
      const double expected = s.roof.area() * kGsd * kGsd;
      EXPECT_NEAR(o.areaM2, expected, 0.05 * expected);
    }
  }
  EXPECT_EQ(buildings, 1);
  EXPECT_EQ(trees, 1);
}

namespace {

// A 240 x 160 DEM at 0.25 m/px: flat ground at 100 m with 5 cm noise and the given flat boxes
// (rectangle, height above the ground) drawn in order; a bright, smooth grey image.
struct Box {
  cv::Rect rect;
  float height;
};

SceneAnalysis analyseBoxes(std::initializer_list<Box> boxes) {
  cv::Mat dem(160, 240, CV_32F);
  cv::randn(dem, 100.0, 0.05);
  for (const Box& b : boxes) dem(b.rect) += b.height;
  cv::Mat image(dem.size(), CV_8U);
  cv::randn(image, 170.0, 3.0);
  return analyseScene(dem, image, kGsd, SceneParams{});
}

int buildingObjects(const SceneAnalysis& a) {
  int n = 0;
  for (const auto& o : a.detection.objects.objects) n += o.cls == kClassBuilding;
  return n;
}

}  // namespace

TEST(Objects, TouchingBuildingsOfDifferentHeightsAreTwoObjects) {
  // 400 m² at 8 m against 400 m² at 14 m: one above-ground piece, two levels 6 m apart.
  const SceneAnalysis a = analyseBoxes({{{40, 40, 80, 80}, 8.0f}, {{120, 40, 80, 80}, 14.0f}});
  ASSERT_EQ(a.status, RunStatus::Completed);
  ASSERT_EQ(buildingObjects(a), 2);
  ASSERT_EQ(a.detection.proposals.size(), 2u);
  for (const auto& o : a.detection.objects.objects) {
    EXPECT_NEAR(o.areaM2, 400.0, 40.0);
    EXPECT_TRUE(std::abs(o.meanHeight - 8.0) < 1.0 || std::abs(o.meanHeight - 14.0) < 1.0) << o.meanHeight;
  }
}

TEST(Objects, SuperstructuresStayPartOfTheirRoof) {
  // 500 m² at 10 m with a 4 m² structure 1.5 m higher (under δ_0) and another 3 m higher (over
  // δ_0, but under min-building-area and inside the roof): one object, one proposal.
  const SceneAnalysis a = analyseBoxes(
      {{{40, 40, 100, 80}, 10.0f}, {{60, 60, 8, 8}, 1.5f}, {{100, 80, 8, 8}, 3.0f}});
  ASSERT_EQ(a.status, RunStatus::Completed);
  EXPECT_EQ(buildingObjects(a), 1);
  EXPECT_EQ(a.detection.proposals.size(), 1u);
}

namespace {

// Labels with one building [20, 80) x [30, 70) (2400 px) on a 120 x 100 grid at 0.5 m: nDSM 12 m
// with one 15 m pixel; disparity 10 on the ground and 30 + 4 (x - 20) / 59 on the roof.
struct KnownCase {
  cv::Mat labels, ndsm, disparity;
  cv::Rect box{20, 30, 60, 40};
};

KnownCase knownCase() {
  KnownCase k;
  k.labels = cv::Mat::zeros(100, 120, CV_8U);
  k.ndsm = cv::Mat::zeros(k.labels.size(), CV_32F);
  k.disparity = cv::Mat(k.labels.size(), CV_32F, cv::Scalar(10.0f));
  k.labels(k.box).setTo(kClassBuilding);
  k.ndsm(k.box).setTo(12.0f);
  k.ndsm.at<float>(50, 50) = 15.0f;
  for (int y = k.box.y; y < k.box.br().y; ++y) {
    for (int x = k.box.x; x < k.box.br().x; ++x) k.disparity.at<float>(y, x) = 30.0f + 4.0f * (x - 20) / 59.0f;
  }
  return k;
}

}  // namespace

TEST(Objects, AreaHeightsAndIntervalsOfAKnownBuilding) {
  const KnownCase k = knownCase();
  const ObjectSet set = extractObjects(k.labels, k.ndsm, 0.5, {}, k.disparity);
  ASSERT_EQ(set.objects.size(), 1u);
  const SceneObject& o = set.objects[0];
  EXPECT_EQ(o.cls, kClassBuilding);
  EXPECT_EQ(o.pixels, 2400);
  EXPECT_DOUBLE_EQ(o.areaM2, 600.0);
  EXPECT_NEAR(o.meanHeight, (2399 * 12.0 + 15.0) / 2400, 1e-9);
  EXPECT_DOUBLE_EQ(o.maxHeight, 15.0);
  ASSERT_TRUE(o.hasRoofInterval);
  EXPECT_EQ(o.roofDisparityMin, 30);
  EXPECT_EQ(o.roofDisparityMax, 34);
  EXPECT_NEAR(o.groundDisparity, 10.0, 0.25);
  // The outline runs a quarter pixel inside the box's border and holds exactly its pixels.
  EXPECT_NEAR(delineo::core::area(o.outline), 59.5 * 39.5, 1e-6);
  cv::Mat box = cv::Mat::zeros(k.labels.size(), CV_8U);
  box(k.box).setTo(255);
  EXPECT_EQ(cv::countNonZero(delineo::core::rasterize(o.outline, box.size()) != box), 0);
  EXPECT_TRUE(delineo::core::isSimple(o.outline.outer));
  // Smaller than the minimum area: dropped.
  ObjectParams big;
  big.minArea = 601;
  EXPECT_TRUE(extractObjects(k.labels, k.ndsm, 0.5, big, k.disparity).objects.empty());
  // The GeoJSON attributes.
  const auto features = objectFeatures(set.objects);
  ASSERT_EQ(features.size(), 1u);
  EXPECT_EQ(std::get<std::string>(features[0].attributes.at("class")), "building");
  EXPECT_EQ(std::get<long long>(features[0].attributes.at("roof_disparity_min")), 30);
  EXPECT_DOUBLE_EQ(std::get<double>(features[0].attributes.at("area_m2")), 600.0);
}

TEST(Detect, ProposalsCarryWhatDelineateReads) {
  const KnownCase k = knownCase();
  cv::Mat labels = k.labels.clone();
  cv::Mat ndsm = k.ndsm.clone();
  labels(cv::Rect(90, 10, 20, 20)).setTo(kClassVegetation);  // a tree: never proposed
  ndsm(cv::Rect(90, 10, 20, 20)).setTo(6.0f);
  const ObjectSet set = extractObjects(labels, ndsm, 0.5, {}, k.disparity);
  ASSERT_EQ(set.objects.size(), 2u);
  const auto proposals = proposeBuildings(set.objects);
  ASSERT_EQ(proposals.size(), 1u);
  const auto& a = proposals[0].attributes;
  EXPECT_TRUE(std::holds_alternative<long long>(a.at("id")));
  EXPECT_EQ(std::get<long long>(a.at("roof_disparity_min")), 30);
  EXPECT_EQ(std::get<long long>(a.at("roof_disparity_max")), 34);
  EXPECT_EQ(std::get<long long>(a.at("ground_disparity")), 10);
  // delineate's check: the ground interval (±ground-tolerance) lies below the roof interval.
  EXPECT_LT(10 + DetectParams{}.groundTolerance, 30);
  // A ground too close to the roof for delineate's interval is left out (delineate estimates it).
  DetectParams wide;
  wide.groundTolerance = 20;
  EXPECT_EQ(proposeBuildings(set.objects, wide)[0].attributes.count("ground_disparity"), 0u);
  // Grown proposals hold the outline.
  DetectParams grow;
  grow.growth = 4;
  const auto grown = proposeBuildings(set.objects, grow);
  ASSERT_EQ(grown.size(), 1u);
  const cv::Rect2d b0 = delineo::core::boundingBox(proposals[0].polygon.outer);
  const cv::Rect2d b1 = delineo::core::boundingBox(grown[0].polygon.outer);
  EXPECT_NEAR(b1.x, b0.x - 4, 0.01);
  EXPECT_NEAR(b1.width, b0.width + 8, 0.01);
  EXPECT_NEAR(b1.height, b0.height + 8, 0.01);
  // Too small or too low: not proposed.
  DetectParams strict;
  strict.minBuildingArea = 700;
  EXPECT_TRUE(proposeBuildings(set.objects, strict).empty());
  strict = {};
  strict.minHeight = 13;
  EXPECT_TRUE(proposeBuildings(set.objects, strict).empty());
  // Round trip through the file delineate --init reads: the same integers come back.
  const std::string path = ::testing::TempDir() + "proposals_roundtrip.geojson";
  delineo::io::writeFeatures(path, proposals);
  const auto back = delineo::io::readFeatures(path);
  std::remove(path.c_str());
  ASSERT_EQ(back.size(), 1u);
  for (const char* key : {"id", "roof_disparity_min", "roof_disparity_max", "ground_disparity"}) {
    ASSERT_TRUE(back[0].attributes.count(key)) << key;
    EXPECT_EQ(std::get<long long>(back[0].attributes.at(key)), std::get<long long>(a.at(key))) << key;
  }
  EXPECT_EQ(back[0].polygon.outer.size(), proposals[0].polygon.outer.size());
}

TEST(Segmentation, BadInputsAreErrors) {
  const Scene s = roofAndCrown();
  auto code = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode::ProcessingFailed;  // no error thrown
  };
  EXPECT_EQ(code([&] { classify(cv::Mat(), s.above, s.ndsm, kGsd); }), ErrorCode::UnsupportedInput);
  cv::Mat floatImage;
  s.grey.convertTo(floatImage, CV_32F);
  EXPECT_EQ(code([&] { classify(floatImage, s.above, s.ndsm, kGsd); }), ErrorCode::UnsupportedInput);
  EXPECT_EQ(code([&] { classify(s.grey, s.ndsm, s.ndsm, kGsd); }), ErrorCode::UnsupportedInput);
  EXPECT_EQ(code([&] { classify(s.grey, s.above, s.above, kGsd); }), ErrorCode::UnsupportedInput);
  EXPECT_EQ(code([&] { classify(s.grey, s.above(cv::Rect(0, 0, 10, 10)), s.ndsm, kGsd); }),
            ErrorCode::MismatchedInputs);
  EXPECT_EQ(code([&] { classify(s.grey, s.above, s.ndsm, 0.0); }), ErrorCode::InvalidParameter);
  EXPECT_EQ(code([&] { classify(s.grey, s.above, s.ndsm, std::nan("")); }), ErrorCode::InvalidParameter);
  ClassifyParams bad;
  bad.window = 0;
  EXPECT_EQ(code([&] { classify(s.grey, s.above, s.ndsm, kGsd, bad); }), ErrorCode::InvalidParameter);
  EXPECT_EQ(code([&] { classify(s.grey, s.above, s.ndsm, kGsd, {}, cv::Mat(s.grey.size(), CV_8U)); }),
            ErrorCode::UnsupportedInput);
  const KnownCase k = knownCase();
  EXPECT_EQ(code([&] { extractObjects(cv::Mat(), k.ndsm, 0.5); }), ErrorCode::UnsupportedInput);
  EXPECT_EQ(code([&] { extractObjects(k.labels, k.ndsm(cv::Rect(0, 0, 5, 5)), 0.5); }), ErrorCode::MismatchedInputs);
  EXPECT_EQ(code([&] { extractObjects(k.labels, k.ndsm, 0.5, {}, k.labels); }), ErrorCode::UnsupportedInput);
  ObjectParams even;
  even.smoothing = 4;
  EXPECT_EQ(code([&] { extractObjects(k.labels, k.ndsm, 0.5, even); }), ErrorCode::InvalidParameter);
  DetectParams negative;
  negative.minBuildingArea = -1;
  EXPECT_EQ(code([&] { proposeBuildings({}, negative); }), ErrorCode::InvalidParameter);
}

TEST(Segmentation, CancelReturnsCanceled) {
  const Scene s = roofAndCrown();
  Progress progress;
  progress.cancelAfterReports(2);
  const Detection d = detectBuildings(s.grey, s.above, s.ndsm, kGsd, {}, {}, {}, {}, {}, &progress);
  EXPECT_EQ(d.status, RunStatus::Canceled);
  EXPECT_TRUE(d.proposals.empty());
}
