// Disparity range estimation: simulated scenes (true range known), shifted textures, and the
// inputs it must refuse with a clear error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/error.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/disparity_range.hpp"
#include "synthetic.hpp"

namespace delineo::stereo {
namespace {

using core::ErrorCode;

struct FloatPair {
  cv::Mat left, right;
};

FloatPair views(const sim::Scene& scene) {
  FloatPair p;
  scene.left.convertTo(p.left, CV_32F);
  scene.right.convertTo(p.right, CV_32F);
  return p;
}

// Share of the scene's true disparities (every pixel with a surface) inside [dmin, dmax], and
// their 0.5th..99.5th percentile span.
struct Coverage {
  double inside = 0;
  double span = 0;
};

Coverage coverage(const cv::Mat& truth, int dmin, int dmax) {
  std::vector<float> v;
  for (int y = 0; y < truth.rows; ++y) {
    for (int x = 0; x < truth.cols; ++x) {
      const float d = truth.at<float>(y, x);
      if (std::isfinite(d)) v.push_back(d);
    }
  }
  std::sort(v.begin(), v.end());
  Coverage c;
  const auto in = std::count_if(v.begin(), v.end(), [&](float d) { return d >= dmin && d <= dmax; });
  c.inside = static_cast<double>(in) / static_cast<double>(v.size());
  c.span = v[static_cast<size_t>(0.995 * (v.size() - 1))] - v[static_cast<size_t>(0.005 * (v.size() - 1))];
  return c;
}

// Expects `call` to throw core::Error with `code` and `needle` in its message.
template <class F>
void expectError(F call, ErrorCode code, const std::string& needle) {
  try {
    call();
    FAIL() << "no error thrown, expected one containing '" << needle << "'";
  } catch (const core::Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(DisparityRange, SimulatedSceneRangeHoldsItsDisparitiesAndIsNotMuchWider) {
  for (int seed : {1, 2}) {
    const sim::Scene scene = sim::simulateScene(sim::squareSceneParams(500, seed));
    const FloatPair p = views(scene);
    const RangeEstimate r = estimateDisparityRange(p.left, p.right);
    ASSERT_EQ(r.status, core::RunStatus::Completed);
    const Coverage c = coverage(scene.disparity, r.dmin, r.dmax);
    EXPECT_GE(c.inside, 0.99) << "seed " << seed << ": [" << r.dmin << ", " << r.dmax << "]";
    EXPECT_LE(r.dmax - r.dmin, 1.5 * c.span) << "seed " << seed;
    EXPECT_GE(r.matches, 100);
    EXPECT_EQ(static_cast<int>(r.points.size()), r.matches);
    EXPECT_LE(r.low, r.median);
    EXPECT_LE(r.median, r.high);
  }
}

TEST(DisparityRange, NegativeGroundDisparityAndTallBuildings) {
  sim::SceneParams params = sim::squareSceneParams(500, 3);
  params.groundDisparity = -40;
  params.metresPerDisparity = 0.2;  // heights 2.5 times larger in disparity
  const sim::Scene scene = sim::simulateScene(params);
  const FloatPair p = views(scene);
  const RangeEstimate r = estimateDisparityRange(p.left, p.right);
  EXPECT_LT(r.dmin, -40);
  EXPECT_GE(coverage(scene.disparity, r.dmin, r.dmax).inside, 0.99);
}

TEST(DisparityRange, ConstantShiftGivesANarrowRangeAroundIt) {
  const cv::Mat left = testing::texture({400, 300}, 7);
  const cv::Mat right = testing::shiftedRight(left, 23.0);
  const RangeEstimate r = estimateDisparityRange(left, right);
  EXPECT_NEAR(r.median, 23.0, 0.5);
  EXPECT_LE(r.dmin, 23);
  EXPECT_GE(r.dmax, 23);
  EXPECT_LE(r.dmax - r.dmin, 10);
}

TEST(DisparityRange, GainAndOffsetBetweenTheViewsChangeNothing) {
  const cv::Mat left = testing::texture({400, 300}, 8);
  const cv::Mat right = testing::shiftedRight(left, -12.0);
  const RangeEstimate plain = estimateDisparityRange(left, right);
  const RangeEstimate scaled = estimateDisparityRange(left, right * 0.5 + 40.0);
  EXPECT_EQ(plain.dmin, scaled.dmin);
  EXPECT_EQ(plain.dmax, scaled.dmax);
  EXPECT_NEAR(scaled.median, -12.0, 0.5);
}

TEST(DisparityRange, NoDataPixelsAreLeftOut) {
  cv::Mat left = testing::texture({400, 300}, 9);
  cv::Mat right = testing::shiftedRight(left, 15.0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  left(cv::Rect(0, 0, 400, 60)).setTo(nan);
  right(cv::Rect(300, 0, 100, 300)).setTo(nan);
  const RangeEstimate r = estimateDisparityRange(left, right);
  EXPECT_NEAR(r.median, 15.0, 0.5);
  for (const cv::Point3f& m : r.points) EXPECT_GE(m.y, 60.0F);
}

// A plain roof (one grey plus noise, no keypoint inside) 36 px above textured ground: only its
// shape tells its disparity.
TEST(DisparityRange, PlainRoofIsFoundByItsShape) {
  const cv::Size size(400, 300);
  const cv::Mat ground = testing::texture(size, 17);
  cv::Mat left = ground.clone();
  cv::Mat right = testing::shiftedRight(ground, 4.0);
  cv::RNG rng(18);
  cv::Mat roof(100, 120, CV_32F);
  rng.fill(roof, cv::RNG::NORMAL, 200.0, 1.0);
  roof.copyTo(left(cv::Rect(150, 100, 120, 100)));
  roof.copyTo(right(cv::Rect(110, 100, 120, 100)));  // x_right = x_left - 40
  RangeEstimateParams params;
  params.plainRegions = false;
  const RangeEstimate features = estimateDisparityRange(left, right, params);
  EXPECT_LT(features.dmax, 40);
  const RangeEstimate both = estimateDisparityRange(left, right);
  EXPECT_GT(both.plainRegionSamples, 0);
  EXPECT_GE(both.dmax, 40);
  EXPECT_LE(both.dmax, 60);
  EXPECT_LE(both.dmin, 4);
}

TEST(DisparityRange, SameInputsSameRange) {
  const sim::Scene scene = sim::simulateScene(sim::squareSceneParams(400, 4));
  const FloatPair p = views(scene);
  const RangeEstimate a = estimateDisparityRange(p.left, p.right);
  const RangeEstimate b = estimateDisparityRange(p.left, p.right);
  EXPECT_EQ(a.dmin, b.dmin);
  EXPECT_EQ(a.dmax, b.dmax);
  EXPECT_EQ(a.matches, b.matches);
}

TEST(DisparityRange, LargeImagesAreDetectedOnAReducedCopy) {
  const cv::Mat left = testing::texture({1200, 900}, 10);
  const cv::Mat right = testing::shiftedRight(left, 31.0);
  RangeEstimateParams params;
  params.maxPixels = 270000;
  const RangeEstimate r = estimateDisparityRange(left, right, params);
  EXPECT_NEAR(r.scale, 0.5, 0.01);
  EXPECT_NEAR(r.median, 31.0, 1.0);  // full-resolution pixels
}

TEST(DisparityRange, BlankImagesAreAnError) {
  const cv::Mat grey(200, 300, CV_32F, cv::Scalar(128));
  const cv::Mat texture = testing::texture({300, 200}, 11);
  expectError([&] { estimateDisparityRange(grey, grey); }, ErrorCode::ProcessingFailed, "blank");
  expectError([&] { estimateDisparityRange(texture, grey); }, ErrorCode::ProcessingFailed,
              "right image is blank");
  const cv::Mat nodata(200, 300, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  expectError([&] { estimateDisparityRange(nodata, texture); }, ErrorCode::ProcessingFailed,
              "left image has no data");
}

TEST(DisparityRange, UnrelatedViewsGiveTooFewMatches) {
  const cv::Mat left = testing::texture({300, 200}, 12);
  const cv::Mat right = testing::texture({300, 200}, 13);
  expectError([&] { estimateDisparityRange(left, right); }, ErrorCode::ProcessingFailed,
              "feature matches");
}

TEST(DisparityRange, MismatchedOrUnsupportedInputsAreErrors) {
  const cv::Mat a = testing::texture({300, 200}, 14);
  const cv::Mat b = testing::texture({301, 200}, 14);
  expectError([&] { estimateDisparityRange(a, b); }, ErrorCode::MismatchedInputs, "300x200");
  cv::Mat bytes;
  a.convertTo(bytes, CV_8U);
  expectError([&] { estimateDisparityRange(bytes, bytes); }, ErrorCode::UnsupportedInput,
              "float32");
  expectError([&] { estimateDisparityRange(cv::Mat(), cv::Mat()); }, ErrorCode::UnsupportedInput,
              "float32");
}

TEST(DisparityRange, InvalidParametersAreRefused) {
  RangeEstimateParams p;
  p.lowPercentile = 40;
  p.highPercentile = 60;
  EXPECT_NO_THROW(p.validate());
  p.highPercentile = 50;
  p.lowPercentile = 50;
  expectError([&] { p.validate(); }, ErrorCode::InvalidParameter, "percentile");
  RangeEstimateParams q;
  q.detector = "surf";
  expectError([&] { q.validate(); }, ErrorCode::InvalidParameter, "detector");
  RangeEstimateParams r;
  r.ratio = 1.5;
  expectError([&] { r.validate(); }, ErrorCode::InvalidParameter, "ratio");
}

TEST(DisparityRange, OtherDetectorsWorkOnTexture) {
  const cv::Mat left = testing::texture({400, 300}, 15);
  const cv::Mat right = testing::shiftedRight(left, 9.0);
  for (const char* detector : {"akaze", "orb"}) {
    RangeEstimateParams p;
    p.detector = detector;
    const RangeEstimate r = estimateDisparityRange(left, right, p);
    EXPECT_NEAR(r.median, 9.0, 1.0) << detector;
  }
}

TEST(DisparityRange, CancelReturnsCanceled) {
  const cv::Mat left = testing::texture({300, 200}, 16);
  const cv::Mat right = testing::shiftedRight(left, 5.0);
  core::Progress progress;
  progress.cancelAfterReports(1);
  const RangeEstimate r = estimateDisparityRange(left, right, {}, &progress);
  EXPECT_EQ(r.status, core::RunStatus::Canceled);
}

}  // namespace
}  // namespace delineo::stereo
