#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "delineo/core/error.hpp"
#include "delineo/dem/enhance.hpp"

using delineo::core::Error;
using delineo::core::ErrorCode;
using delineo::core::Polygon;
using delineo::core::Progress;
using delineo::core::RunStatus;
using namespace delineo::dem;

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kRoof = 10.0f;  // m

Polygon square(double x0, double y0, double x1, double y1) {
  Polygon p;
  p.outer = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  return p;
}

// Distance in px from pixel (x, y) to the pixel-aligned box [x0, x1) x [y0, y1) (Chebyshev):
// 0 inside, 1 for the first ring outside.
int ringOutside(int x, int y, int x0, int y0, int x1, int y1) {
  return std::max({x0 - x, x - (x1 - 1), y0 - y, y - (y1 - 1), 0});
}
int ringInside(int x, int y, int x0, int y0, int x1, int y1) {
  return std::min({x - x0, x1 - 1 - x, y - y0, y1 - 1 - y}) + 1;
}

// A flat 10 m box on flat 0 m ground whose walls are ramps: 2 px outside at 2/3 and 1/3 of the
// roof, and the roof's first pixel at 0.7 of it (what a matcher's smoothing leaves).
cv::Mat rampedBox(int size, int x0, int y0, int x1, int y1) {
  cv::Mat dem(size, size, CV_32F, cv::Scalar(0.0f));
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const int out = ringOutside(x, y, x0, y0, x1, y1);
      float& h = dem.at<float>(y, x);
      if (out == 0) h = ringInside(x, y, x0, y0, x1, y1) == 1 ? 0.7f * kRoof : kRoof;
      else if (out <= 2) h = kRoof * (3 - out) / 3.0f;
    }
  }
  return dem;
}

double rmsOver(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < a.rows; ++y) {
    for (int x = 0; x < a.cols; ++x) {
      if (mask.at<uchar>(y, x) == 0) continue;
      const double d = a.at<float>(y, x) - b.at<float>(y, x);
      sum += d * d;
      ++n;
    }
  }
  return std::sqrt(sum / std::max(n, 1));
}
}  // namespace

TEST(DemEnhance, RampedEdgeBecomesAVerticalWall) {
  const cv::Mat dem = rampedBox(80, 20, 20, 60, 60);
  const auto r = enhanceDem(dem, {square(20, 20, 60, 60)}, EnhanceParams{});
  ASSERT_EQ(r.status, RunStatus::Completed);
  // Across the west wall on row 40: ground up to x 19, roof from x 20, no ramp between.
  EXPECT_FLOAT_EQ(dem.at<float>(40, 19), kRoof * 2 / 3.0f);  // the input's ramp
  for (int x = 10; x < 20; ++x) EXPECT_FLOAT_EQ(r.dem.at<float>(40, x), 0.0f) << "x " << x;
  for (int x = 20; x < 60; ++x) EXPECT_FLOAT_EQ(r.dem.at<float>(40, x), kRoof) << "x " << x;
  // Every pixel of the image now is either ground or roof.
  for (int y = 0; y < 80; ++y) {
    for (int x = 0; x < 80; ++x) {
      const float expected = ringOutside(x, y, 20, 20, 60, 60) == 0 ? kRoof : 0.0f;
      ASSERT_FLOAT_EQ(r.dem.at<float>(y, x), expected) << "(" << x << ", " << y << ")";
    }
  }
  ASSERT_EQ(r.footprints.size(), 1u);
  EXPECT_EQ(r.footprints[0].pixels, 40 * 40);
  EXPECT_EQ(r.footprints[0].band, 3);
  EXPECT_EQ(r.footprints[0].window, 9);  // a plain roof
}

TEST(DemEnhance, ABandTooNarrowForTheRampLeavesPartOfIt) {
  // The band is what removes the ramp: with 1 px the second ramp pixel outside stays.
  EnhanceParams params;
  params.wallBand = 1;
  const auto r = enhanceDem(rampedBox(80, 20, 20, 60, 60), {square(20, 20, 60, 60)}, params);
  EXPECT_FLOAT_EQ(r.dem.at<float>(40, 19), 0.0f);
  EXPECT_FLOAT_EQ(r.dem.at<float>(40, 18), kRoof / 3.0f);
}

TEST(DemEnhance, NoiseOnAFlatRoofShrinks) {
  cv::Mat dem = rampedBox(96, 16, 16, 80, 80);
  cv::Mat noise(dem.size(), CV_32F);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.5);
  const cv::Mat roofMask = cv::Mat::zeros(dem.size(), CV_8U);
  roofMask(cv::Rect(16, 16, 64, 64)).setTo(255);
  noise.setTo(0.0f, roofMask == 0);
  const cv::Mat truth = rampedBox(96, 16, 16, 80, 80);
  truth(cv::Rect(16, 16, 64, 64)).setTo(kRoof);
  dem += noise;
  const auto r = enhanceDem(dem, {square(16, 16, 80, 80)}, EnhanceParams{});
  const double before = rmsOver(dem, truth, roofMask);
  const double after = rmsOver(r.dem, truth, roofMask);
  EXPECT_GT(before, 0.5);  // the noise and the roof's ramped first ring
  EXPECT_LT(after, 0.15 * before) << "before " << before << " after " << after;
  EXPECT_EQ(r.footprints[0].window, 9);
  // The paper's rule (one pixel above the threshold) takes isolated noise for an object.
  EnhanceParams paper;
  paper.minObjectPixels = 1;
  EXPECT_EQ(enhanceDem(dem, {square(16, 16, 80, 80)}, paper).footprints[0].window, 3);
}

TEST(DemEnhance, AnObjectOnTheRoofChoosesTheSmallWindowAndSurvives) {
  cv::Mat dem = rampedBox(100, 10, 10, 90, 90);
  dem(cv::Rect(40, 40, 5, 5)).setTo(kRoof + 3.0f);  // a 5 x 5 px superstructure
  const auto r = enhanceDem(dem, {square(10, 10, 90, 90)}, EnhanceParams{});
  EXPECT_GT(r.gradientThreshold, 0.0);
  EXPECT_GT(r.footprints[0].objectPixels, 0);
  EXPECT_EQ(r.footprints[0].window, 3);
  EXPECT_FLOAT_EQ(r.dem.at<float>(42, 42), kRoof + 3.0f);
  // A 9 x 9 median would have erased it (25 of 81 pixels).
  EnhanceParams large;
  large.smallWindow = 9;
  EXPECT_FLOAT_EQ(enhanceDem(dem, {square(10, 10, 90, 90)}, large).dem.at<float>(42, 42), kRoof);
}

TEST(DemEnhance, GroundBeyondTheBandIsUntouched) {
  cv::Mat dem = rampedBox(80, 20, 20, 60, 60);
  cv::Mat noise(dem.size(), CV_32F);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.3);
  for (int y = 0; y < 80; ++y) {
    for (int x = 0; x < 80; ++x) dem.at<float>(y, x) += 0.05f * x + noise.at<float>(y, x);
  }
  dem.at<float>(5, 5) = kNaN;
  EnhanceParams params;
  const auto r = enhanceDem(dem, {square(20, 20, 60, 60)}, params);
  int checked = 0;
  for (int y = 0; y < 80; ++y) {
    for (int x = 0; x < 80; ++x) {
      if (ringOutside(x, y, 20, 20, 60, 60) <= params.wallBand) continue;
      const float a = dem.at<float>(y, x), b = r.dem.at<float>(y, x);
      ASSERT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << "(" << x << ", " << y << ")";
      ++checked;
    }
  }
  EXPECT_GT(checked, 2000);
  // The band takes the ground's level beside it (the slope's 0.05 m/px, the noise).
  EXPECT_NEAR(r.dem.at<float>(40, 18), 0.05f * 18, 0.5);
}

TEST(DemEnhance, ACourtyardIsGroundWithVerticalWalls) {
  // A 60 x 60 building with a 20 x 20 courtyard in its middle; ramps at every outline.
  cv::Mat dem(80, 80, CV_32F, cv::Scalar(0.0f));
  for (int y = 0; y < 80; ++y) {
    for (int x = 0; x < 80; ++x) {
      const int outer = ringOutside(x, y, 10, 10, 70, 70);
      const int court = ringInside(x, y, 30, 30, 50, 50);  // > 0 inside the courtyard
      float& h = dem.at<float>(y, x);
      if (outer > 0) h = outer <= 2 ? kRoof * (3 - outer) / 3.0f : 0.0f;
      else if (court > 0 && ringOutside(x, y, 30, 30, 50, 50) == 0) h = court <= 2 ? kRoof * (3 - court) / 3.0f : 0.0f;
      else h = kRoof;
    }
  }
  Polygon building = square(10, 10, 70, 70);
  building.holes.push_back({{30, 30}, {30, 50}, {50, 50}, {50, 30}});
  const auto r = enhanceDem(dem, {building}, EnhanceParams{});
  // Row 40 crosses roof, courtyard, roof.
  for (int x = 10; x < 30; ++x) EXPECT_FLOAT_EQ(r.dem.at<float>(40, x), kRoof) << "x " << x;
  for (int x = 30; x < 50; ++x) EXPECT_FLOAT_EQ(r.dem.at<float>(40, x), 0.0f) << "x " << x;
  for (int x = 50; x < 70; ++x) EXPECT_FLOAT_EQ(r.dem.at<float>(40, x), kRoof) << "x " << x;
  EXPECT_EQ(r.footprints[0].pixels, 60 * 60 - 20 * 20);
}

TEST(DemEnhance, NoDataOnTheRoofIsFilledAndOnTheGroundKept) {
  cv::Mat dem = rampedBox(80, 20, 20, 60, 60);
  dem(cv::Rect(30, 30, 12, 12)).setTo(kNaN);  // a hole in the roof's matches
  dem(cv::Rect(2, 2, 6, 6)).setTo(kNaN);      // no data on the ground, far from the building
  dem.at<float>(40, 19) = kNaN;               // no data in the outer band
  const auto r = enhanceDem(dem, {square(20, 20, 60, 60)}, EnhanceParams{});
  for (int y = 30; y < 42; ++y) {
    for (int x = 30; x < 42; ++x) ASSERT_FLOAT_EQ(r.dem.at<float>(y, x), kRoof);
  }
  EXPECT_EQ(r.footprints[0].filledPixels, 144);
  EXPECT_TRUE(std::isnan(r.dem.at<float>(4, 4)));
  EXPECT_FLOAT_EQ(r.dem.at<float>(40, 19), 0.0f);
}

TEST(DemEnhance, AFootprintWithoutAnyHeightIsLeftAlone) {
  cv::Mat dem(60, 60, CV_32F, cv::Scalar(1.0f));
  dem(cv::Rect(20, 20, 20, 20)).setTo(kNaN);
  const auto r = enhanceDem(dem, {square(20, 20, 40, 40)}, EnhanceParams{});
  EXPECT_EQ(r.footprints[0].window, 0);
  EXPECT_TRUE(std::isnan(r.dem.at<float>(30, 30)));
  EXPECT_FLOAT_EQ(r.dem.at<float>(30, 18), 1.0f);
}

TEST(DemEnhance, AdjacentBuildingsMeetAtAVerticalWall) {
  // Two roofs, 10 m and 16 m, sharing the wall at x 40, with a ramp across it.
  cv::Mat dem(60, 80, CV_32F, cv::Scalar(0.0f));
  dem(cv::Rect(10, 10, 30, 40)).setTo(10.0f);
  dem(cv::Rect(40, 10, 30, 40)).setTo(16.0f);
  dem.col(39).rowRange(10, 50).setTo(12.0f);
  dem.col(40).rowRange(10, 50).setTo(14.0f);
  const auto r = enhanceDem(dem, {square(10, 10, 40, 50), square(40, 10, 70, 50)}, EnhanceParams{});
  EXPECT_FLOAT_EQ(r.dem.at<float>(30, 39), 10.0f);
  EXPECT_FLOAT_EQ(r.dem.at<float>(30, 40), 16.0f);
}

TEST(DemEnhance, AFootprintRunningOffTheImageIsClipped) {
  cv::Mat dem = rampedBox(60, 30, 20, 60, 40);
  dem.col(59).rowRange(21, 39).setTo(kRoof);  // no ramp where the image cuts the roof
  const auto r = enhanceDem(dem, {square(30, 20, 75, 40)}, EnhanceParams{});
  EXPECT_EQ(r.footprints[0].pixels, 30 * 20);
  EXPECT_FLOAT_EQ(r.dem.at<float>(30, 59), kRoof);  // at the image border: roof, not a wall
  EXPECT_FLOAT_EQ(r.dem.at<float>(30, 29), 0.0f);
}

TEST(DemEnhance, BadInputsAreNamedErrors) {
  const cv::Mat dem = rampedBox(40, 10, 10, 30, 30);
  const std::vector<Polygon> box = {square(10, 10, 30, 30)};
  auto codeOf = [](auto&& call) {
    try {
      call();
    } catch (const Error& e) {
      return e.code();
    }
    ADD_FAILURE() << "no error";
    return ErrorCode::ProcessingFailed;
  };
  const EnhanceParams p;
  EXPECT_EQ(codeOf([&] { enhanceDem(cv::Mat(), box, p); }), ErrorCode::UnsupportedInput);
  EXPECT_EQ(codeOf([&] { enhanceDem(cv::Mat(40, 40, CV_8U, cv::Scalar(1)), box, p); }),
            ErrorCode::UnsupportedInput);
  cv::Mat infinite = dem.clone();
  infinite.at<float>(3, 4) = std::numeric_limits<float>::infinity();
  EXPECT_EQ(codeOf([&] { enhanceDem(infinite, box, p); }), ErrorCode::UnsupportedInput);
  EXPECT_EQ(codeOf([&] { enhanceDem(cv::Mat(40, 40, CV_32F, cv::Scalar(kNaN)), box, p); }),
            ErrorCode::UnsupportedInput);
  EXPECT_EQ(codeOf([&] { enhanceDem(dem, {square(50, 50, 60, 60)}, p); }),
            ErrorCode::MismatchedInputs);
  EXPECT_EQ(codeOf([&] { enhanceDem(dem, {square(-20, 5, -2, 20)}, p); }),
            ErrorCode::MismatchedInputs);
  Polygon two;
  two.outer = {{1, 1}, {5, 5}};
  EXPECT_EQ(codeOf([&] { enhanceDem(dem, {two}, p); }), ErrorCode::InvalidParameter);
  Polygon notFinite = square(10, 10, 30, 30);
  notFinite.outer[2].x = std::nan("");
  EXPECT_EQ(codeOf([&] { enhanceDem(dem, {notFinite}, p); }), ErrorCode::InvalidParameter);
  EnhanceParams even;
  even.largeWindow = 8;
  EXPECT_EQ(codeOf([&] { enhanceDem(dem, box, even); }), ErrorCode::InvalidParameter);
  EnhanceParams inverted;
  inverted.smallWindow = 11;
  EXPECT_EQ(codeOf([&] { enhanceDem(dem, box, inverted); }), ErrorCode::InvalidParameter);
  // The message names the footprint.
  try {
    enhanceDem(dem, {square(10, 10, 30, 30), square(50, 50, 60, 60)}, p);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("footprint 1"), std::string::npos) << e.what();
  }
}

TEST(DemEnhance, NoFootprintsKeepsTheDem) {
  const cv::Mat dem = rampedBox(40, 10, 10, 30, 30);
  const auto r = enhanceDem(dem, {}, EnhanceParams{});
  EXPECT_EQ(cv::norm(r.dem, dem, cv::NORM_INF), 0.0);
}

TEST(DemEnhance, CancelReturnsTheInputUnchanged) {
  const cv::Mat dem = rampedBox(80, 20, 20, 60, 60);
  Progress progress;
  progress.cancelAfterReports(1);
  const auto r = enhanceDem(dem, {square(20, 20, 60, 60), square(2, 2, 10, 10)}, EnhanceParams{},
                            &progress);
  EXPECT_EQ(r.status, RunStatus::Canceled);
  EXPECT_EQ(cv::norm(r.dem, dem, cv::NORM_INF), 0.0);
  // Without the cancel, the same call reports up to 1 and changes the ramp.
  Progress full;
  const auto done = enhanceDem(dem, {square(20, 20, 60, 60), square(2, 2, 10, 10)},
                               EnhanceParams{}, &full);
  EXPECT_EQ(done.status, RunStatus::Completed);
  EXPECT_DOUBLE_EQ(full.fraction(), 1.0);
  EXPECT_GT(cv::norm(done.dem, dem, cv::NORM_INF), 1.0);
}

TEST(DemEnhance, GradientOfAPlaneIsItsSlope) {
  cv::Mat plane(30, 30, CV_32F);
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 30; ++x) plane.at<float>(y, x) = 0.3f * x - 0.4f * y;
  }
  plane.at<float>(5, 5) = kNaN;
  for (double sigma : {0.5, 1.5}) {
    const cv::Mat g = gradientMagnitude(plane, sigma);
    EXPECT_NEAR(g.at<float>(15, 15), 0.5, 1e-4) << "sigma " << sigma;
    EXPECT_TRUE(std::isnan(g.at<float>(5, 6)));  // the filter reaches the no-data pixel
  }
}

TEST(DemEnhance, OtsuSplitsTwoModes) {
  cv::Mat v(1, 1000, CV_32F);
  std::mt19937 rng(1);
  std::normal_distribution<float> low(1.0f, 0.2f), high(6.0f, 0.5f);
  for (int i = 0; i < 1000; ++i) v.at<float>(0, i) = i < 800 ? low(rng) : high(rng);
  const double t = otsuThreshold(v);
  EXPECT_GT(t, 1.4);  // beyond two sigmas of the low mode
  EXPECT_LT(t, 4.5);
  EXPECT_EQ(otsuThreshold(cv::Mat(3, 3, CV_32F, cv::Scalar(2.0f))), 0.0);
}

TEST(DemEnhance, ParametersRoundTripThroughJson) {
  EnhanceParams p;
  p.wallBand = 5;
  p.largeWindow = 7;
  EnhanceParams q;
  delineo::core::fromJson(q, delineo::core::toJson(p));
  EXPECT_EQ(q.wallBand, 5);
  EXPECT_EQ(q.largeWindow, 7);
}

TEST(DemEnhance, RoofOutsideAnOutlineTooSmallKeepsItsHeight) {
  // The outline lies 5 px inside a 40 x 40 roof: the 5 px strip around it is roof in the DEM,
  // thicker than the tolerance, so it joins the footprint instead of being flattened.
  const cv::Mat dem = rampedBox(80, 20, 20, 60, 60);
  const auto r = enhanceDem(dem, {square(25, 25, 55, 55)}, EnhanceParams{});
  for (int x = 20; x < 25; ++x) EXPECT_FLOAT_EQ(r.dem.at<float>(40, x), kRoof) << "x " << x;
  for (int x = 10; x < 18; ++x) EXPECT_FLOAT_EQ(r.dem.at<float>(40, x), 0.0f) << "x " << x;
  EXPECT_GT(r.footprints[0].addedPixels, 4 * 30 * 4);
  EXPECT_NEAR(r.footprints[0].roofHeight, kRoof, 1e-6);
  // Tolerance 0 takes the outline as given.
  EnhanceParams asGiven;
  asGiven.outlineTolerance = 0;
  EXPECT_EQ(enhanceDem(dem, {square(25, 25, 55, 55)}, asGiven).footprints[0].addedPixels, 0);
}

TEST(DemEnhance, GroundInsideAnOutlineTooLargeKeepsItsHeight) {
  // The outline lies 6 px outside the roof: the ground strip inside it stays ground.
  const cv::Mat dem = rampedBox(90, 25, 25, 65, 65);
  const auto r = enhanceDem(dem, {square(19, 19, 71, 71)}, EnhanceParams{});
  for (int x = 19; x < 23; ++x) EXPECT_FLOAT_EQ(r.dem.at<float>(45, x), 0.0f) << "x " << x;
  for (int x = 25; x < 65; ++x) EXPECT_FLOAT_EQ(r.dem.at<float>(45, x), kRoof) << "x " << x;
  EXPECT_GT(r.footprints[0].removedPixels, 4 * 46 * 4);
  EnhanceParams asGiven;
  asGiven.outlineTolerance = 0;
  EXPECT_EQ(enhanceDem(dem, {square(19, 19, 71, 71)}, asGiven).footprints[0].removedPixels, 0);
}

TEST(DemEnhance, AnOutlineOnePixelInsideKeepsTheRoofAndDropsTheRamp) {
  // The outline 1 px inside the roof: the roof pixel it misses keeps the roof's height (it is
  // 2 px from the ground in the DEM); the ramp beyond it is flattened.
  cv::Mat dem(80, 80, CV_32F, cv::Scalar(0.0f));
  dem(cv::Rect(20, 20, 40, 40)).setTo(kRoof);
  dem.col(19).rowRange(20, 60).setTo(kRoof);  // the matcher's fattening, 1 px
  const auto r = enhanceDem(dem, {square(21, 21, 59, 59)}, EnhanceParams{});
  EXPECT_FLOAT_EQ(r.dem.at<float>(40, 20), kRoof);
  EXPECT_FLOAT_EQ(r.dem.at<float>(40, 19), 0.0f);
}

TEST(DemEnhance, FatteningNextToHiddenGroundIsFlattened) {
  // West of the building the ground is hidden in the other view (no data) from x 4 to 17; the
  // two ramp pixels at x 18 and 19 are the matcher's fattening and take the ground's height.
  cv::Mat dem = rampedBox(80, 20, 20, 60, 60);
  dem(cv::Rect(4, 0, 14, 80)).setTo(kNaN);
  const auto r = enhanceDem(dem, {square(20, 20, 60, 60)}, EnhanceParams{});
  EXPECT_FLOAT_EQ(r.dem.at<float>(40, 19), 0.0f);
  EXPECT_FLOAT_EQ(r.dem.at<float>(40, 18), 0.0f);
  EXPECT_TRUE(std::isnan(r.dem.at<float>(40, 10)));
}
