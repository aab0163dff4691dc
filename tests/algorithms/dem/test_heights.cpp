// dem::heightsFromDisparity, dem::handleGaps, dem::demFromDisparity: the linear height model and
// the elevation gaps (merged when their border is one surface, kept at discontinuities, filled on
// request from their lower side).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "delineo/core/error.hpp"
#include "delineo/dem/heights.hpp"

using delineo::core::Error;
using delineo::core::ErrorCode;
using delineo::core::Progress;
using delineo::core::RunStatus;
using namespace delineo::dem;

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

HeightModel model(double k, double ground, double reference = 0.0) {
  HeightModel m;
  m.metresPerPixel = k;
  m.groundDisparity = ground;
  m.referenceHeight = reference;
  return m;
}

// Ground disparity 5 + 0.05 x (a 10 % slope at 0.5 m/px... of disparity), a box 20 px of
// disparity higher on [20, 40) x [20, 40).
constexpr int kSize = 80;
float groundDisparity(int x) { return 5.0f + 0.05f * static_cast<float>(x); }
bool inBox(int x, int y) { return x >= 20 && x < 40 && y >= 20 && y < 40; }
cv::Mat slopeWithBox() {
  cv::Mat d(kSize, kSize, CV_32F);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) d.at<float>(y, x) = groundDisparity(x) + (inBox(x, y) ? 20.0f : 0.0f);
  }
  return d;
}
void punch(cv::Mat& m, const cv::Rect& r) { m(r).setTo(kNaN); }

int finiteCount(const cv::Mat& m) {
  int n = 0;
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) n += std::isfinite(m.at<float>(y, x)) ? 1 : 0;
  }
  return n;
}

// Largest |a - b| over `r`.
double maxError(const cv::Mat& a, const cv::Mat& b, const cv::Rect& r) {
  double worst = 0.0;
  for (int y = r.y; y < r.y + r.height; ++y) {
    for (int x = r.x; x < r.x + r.width; ++x) {
      worst = std::max(worst, static_cast<double>(std::abs(a.at<float>(y, x) - b.at<float>(y, x))));
    }
  }
  return worst;
}
}  // namespace

TEST(Heights, FlatPlaneFollowsTheLinearModel) {
  const cv::Mat disparity(30, 40, CV_32F, cv::Scalar(10.0f));
  const GapResult r = demFromDisparity(disparity, model(0.5, 8.0, 100.0), GapParams{});
  ASSERT_EQ(r.status, RunStatus::Completed);
  EXPECT_TRUE(r.gaps.empty());
  EXPECT_EQ(finiteCount(r.dem), 30 * 40);
  EXPECT_FLOAT_EQ(r.dem.at<float>(7, 9), 101.0f);  // 100 + (10 - 8) * 0.5
  EXPECT_DOUBLE_EQ(model(0.5, 8.0, 100.0).disparityAt(101.0), 10.0);
}

TEST(Heights, NoDataStaysNoDataInTheConversion) {
  cv::Mat disparity(4, 4, CV_32F, cv::Scalar(3.0f));
  disparity.at<float>(1, 2) = kNaN;
  const cv::Mat h = heightsFromDisparity(disparity, model(-2.0, 1.0));
  EXPECT_TRUE(std::isnan(h.at<float>(1, 2)));
  EXPECT_FLOAT_EQ(h.at<float>(0, 0), -4.0f);  // a negative scale is allowed
}

TEST(Heights, GapsInsideOneSurfaceAreMergedAndFollowTheSlope) {
  cv::Mat disparity = slopeWithBox();
  const cv::Mat truth = heightsFromDisparity(disparity, model(0.5, 5.0));
  punch(disparity, {55, 50, 9, 7});  // on the sloping ground
  punch(disparity, {26, 26, 6, 6});  // on the roof
  const GapResult r = demFromDisparity(disparity, model(0.5, 5.0), GapParams{});
  ASSERT_EQ(r.gaps.size(), 2u);
  for (const DemGap& gap : r.gaps) {
    EXPECT_TRUE(gap.merged) << "border spread " << gap.borderSpread;
    EXPECT_LT(gap.borderSpread, 0.2);
    EXPECT_FALSE(gap.touchesEdge);
  }
  EXPECT_EQ(r.mergedPixels, 9 * 7 + 6 * 6);
  EXPECT_EQ(r.keptPixels, 0);
  EXPECT_EQ(finiteCount(r.dem), kSize * kSize);
  // The ground rises 0.25 m across the gap: the interpolation follows it.
  EXPECT_LT(maxError(r.dem, truth, {55, 50, 9, 7}), 0.1);
  EXPECT_LT(maxError(r.dem, truth, {26, 26, 6, 6}), 0.1);
  // Labels: 0 on measured heights, the gap's index + 1 on its pixels.
  EXPECT_EQ(r.gapLabels.at<int>(0, 0), 0);
  EXPECT_GT(r.gapLabels.at<int>(52, 58), 0);
}

TEST(Heights, HolesAlongWallsAreKeptAndFilledFromTheirLowerSideOnRequest) {
  cv::Mat disparity = slopeWithBox();
  const cv::Mat truth = heightsFromDisparity(disparity, model(0.5, 5.0));
  // Occlusions beside the walls: 3 px of ground left of the box, 2 px along its bottom half
  // reaching onto the roof's edge.
  const cv::Rect leftWall(17, 20, 3, 20), bottom(24, 38, 12, 4);
  punch(disparity, leftWall);
  punch(disparity, bottom);
  const GapResult kept = demFromDisparity(disparity, model(0.5, 5.0), GapParams{});
  ASSERT_EQ(kept.gaps.size(), 2u);
  for (const DemGap& gap : kept.gaps) {
    EXPECT_FALSE(gap.merged);
    EXPECT_FALSE(gap.filled);
    EXPECT_GT(gap.borderSpread, 3.0);  // ground and roof 10 m apart
  }
  EXPECT_EQ(kept.keptPixels, 3 * 20 + 12 * 4);
  EXPECT_EQ(finiteCount(kept.dem), kSize * kSize - kept.keptPixels);

  const GapResult filled = demFromDisparity(disparity, model(0.5, 5.0), GapParams{}, true);
  EXPECT_EQ(filled.filledPixels, kept.keptPixels);
  EXPECT_EQ(finiteCount(filled.dem), kSize * kSize);
  // Beside the left wall the hidden part is ground: filled at the ground's height, not a ramp.
  EXPECT_LT(maxError(filled.dem, truth, leftWall), 0.3);
  // Under the bottom wall, ground pixels get the ground's height.
  EXPECT_LT(maxError(filled.dem, truth, {24, 40, 12, 2}), 0.3);
}

TEST(Heights, AnAllNoDataMapIsOneKeptGapEvenWithTheFill) {
  const cv::Mat disparity(20, 30, CV_32F, cv::Scalar(kNaN));
  const GapResult r = demFromDisparity(disparity, model(0.5, 0.0), GapParams{}, true);
  ASSERT_EQ(r.gaps.size(), 1u);
  EXPECT_EQ(r.gaps[0].pixels, 600);
  EXPECT_EQ(r.gaps[0].borderPixels, 0);
  EXPECT_TRUE(r.gaps[0].touchesEdge);
  EXPECT_FALSE(r.gaps[0].merged);
  EXPECT_FALSE(r.gaps[0].filled);
  EXPECT_EQ(finiteCount(r.dem), 0);
}

TEST(Heights, ASingleValidPixelIsTooLittleToMergeButFillsOnRequest) {
  cv::Mat disparity(15, 15, CV_32F, cv::Scalar(kNaN));
  disparity.at<float>(7, 4) = 12.0f;
  const GapResult kept = demFromDisparity(disparity, model(1.0, 2.0), GapParams{});
  ASSERT_EQ(kept.gaps.size(), 1u);
  EXPECT_EQ(kept.gaps[0].borderPixels, 1);
  EXPECT_FALSE(kept.gaps[0].merged);
  EXPECT_EQ(finiteCount(kept.dem), 1);
  EXPECT_FLOAT_EQ(kept.dem.at<float>(7, 4), 10.0f);
  const GapResult filled = demFromDisparity(disparity, model(1.0, 2.0), GapParams{}, true);
  EXPECT_EQ(finiteCount(filled.dem), 15 * 15);
  EXPECT_NEAR(filled.dem.at<float>(0, 14), 10.0f, 1e-4);
}

TEST(Heights, BadInputsAndParametersGiveClearErrors) {
  const cv::Mat good(5, 5, CV_32F, cv::Scalar(1.0f));
  auto codeOf = [](auto&& call) {
    try {
      call();
    } catch (const Error& e) {
      return e.code();
    }
    ADD_FAILURE() << "no error";
    return ErrorCode::ProcessingFailed;
  };
  EXPECT_EQ(codeOf([&] { heightsFromDisparity(cv::Mat(), model(1, 0)); }), ErrorCode::UnsupportedInput);
  EXPECT_EQ(codeOf([&] { heightsFromDisparity(cv::Mat(5, 5, CV_64F, cv::Scalar(1)), model(1, 0)); }),
            ErrorCode::UnsupportedInput);
  EXPECT_EQ(codeOf([&] { heightsFromDisparity(cv::Mat(5, 5, CV_32FC3), model(1, 0)); }),
            ErrorCode::UnsupportedInput);
  EXPECT_EQ(codeOf([&] { heightsFromDisparity(good, model(0, 0)); }), ErrorCode::InvalidParameter);
  EXPECT_EQ(codeOf([&] { heightsFromDisparity(good, model(std::nan(""), 0)); }), ErrorCode::InvalidParameter);
  cv::Mat infinite = good.clone();
  infinite.at<float>(2, 3) = std::numeric_limits<float>::infinity();
  EXPECT_EQ(codeOf([&] { handleGaps(infinite, GapParams{}); }), ErrorCode::UnsupportedInput);
  try {
    handleGaps(infinite, GapParams{});
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("(3, 2)"), std::string::npos) << e.what();
  }
  GapParams bad;
  bad.maxBorderSpread = -1.0;
  EXPECT_EQ(codeOf([&] { handleGaps(good, bad); }), ErrorCode::InvalidParameter);
  bad = GapParams{};
  bad.minBorderPixels = 0;
  EXPECT_EQ(codeOf([&] { handleGaps(good, bad); }), ErrorCode::InvalidParameter);
}

TEST(Heights, CancelReturnsTheInputDem) {
  cv::Mat disparity = slopeWithBox();
  punch(disparity, {55, 50, 9, 7});
  const cv::Mat heights = heightsFromDisparity(disparity, model(0.5, 5.0));
  Progress progress;
  progress.cancelAfterReports(1);
  const GapResult r = handleGaps(heights, GapParams{}, &progress);
  EXPECT_EQ(r.status, RunStatus::Canceled);
  EXPECT_EQ(finiteCount(r.dem), finiteCount(heights));
}
