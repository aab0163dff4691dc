#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "delineo/core/error.hpp"
#include "delineo/stereo/cost_service.hpp"
#include "synthetic.hpp"

namespace delineo::stereo {
namespace {

using testing::shiftedRight;
using testing::texture;

TEST(CostService, MinCostEqualsBruteForceMinimum) {
  const cv::Mat left = texture({120, 80}, 1);
  const cv::Mat right = shiftedRight(left, 7.0);
  const cv::Rect roi(30, 10, 50, 40);
  auto service = CorrelationCostService::compute(left, right, roi, -5, 40);
  ASSERT_NE(service, nullptr);
  EXPECT_EQ(service->roi(), roi);
  EXPECT_EQ(service->dmin(), -5);
  EXPECT_EQ(service->dmax(), 40);
  for (auto [a, b] : {std::pair{-5, 40}, std::pair{0, 3}, std::pair{-20, 2}, std::pair{17, 33},
                      std::pair{9, 9}, std::pair{-5, 26}, std::pair{38, 90}}) {
    const cv::Mat fast = service->minCost(a, b);
    ASSERT_EQ(fast.size(), roi.size());
    ASSERT_EQ(fast.type(), CV_32F);
    for (int y = roi.y; y < roi.br().y; y += 3) {
      for (int x = roi.x; x < roi.br().x; x += 2) {
        float brute = std::numeric_limits<float>::infinity();
        for (int d = std::max(a, -5); d <= std::min(b, 40); ++d) {
          brute = std::min(brute, service->cost(x, y, d));
        }
        ASSERT_EQ(fast.at<float>(y - roi.y, x - roi.x), brute) << a << ".." << b;
      }
    }
  }
}

TEST(CostService, TrueDisparityHasTheLowestCost) {
  const cv::Mat left = texture({120, 80}, 2);
  const cv::Mat right = shiftedRight(left, 12.0);
  const cv::Rect roi(40, 20, 40, 30);
  auto service = CorrelationCostService::compute(left, right, roi, 0, 30);
  ASSERT_NE(service, nullptr);
  const cv::Mat best = service->bestDisparity();
  const cv::Mat bestCost = service->bestCost();
  for (int y = 0; y < roi.height; ++y) {
    for (int x = 0; x < roi.width; ++x) {
      ASSERT_EQ(best.at<int>(y, x), 12);
      EXPECT_LT(bestCost.at<float>(y, x), 0.01F);
      EXPECT_NEAR(service->cost(x + roi.x, y + roi.y, 12), bestCost.at<float>(y, x), 1e-6);
    }
  }
}

TEST(CostService, UnmatchedCostWhereTheWindowLeavesTheImage) {
  const cv::Mat left = texture({60, 40}, 3);
  const cv::Mat right = shiftedRight(left, 3.0);
  CostParams params;
  params.window = 5;
  params.unmatchedCost = 0.75;
  // Left window leaves the image at x = 0..1; right window leaves it when x - d < 2.
  auto service =
      CorrelationCostService::compute(left, right, cv::Rect(0, 5, 20, 10), 0, 10, params);
  ASSERT_NE(service, nullptr);
  EXPECT_FLOAT_EQ(service->cost(0, 8, 0), 0.75F);
  EXPECT_FLOAT_EQ(service->cost(1, 8, 0), 0.75F);
  EXPECT_FLOAT_EQ(service->cost(5, 8, 4), 0.75F);  // x - d = 1: right window leaves
  EXPECT_LT(service->cost(5, 8, 3), 0.05F);        // x - d = 2: inside, true match
  EXPECT_FLOAT_EQ(service->minCost(11, 20).at<float>(0, 0), 0.75F);  // empty clipped range
  // NaN in the right image makes the windows covering it unmatched.
  cv::Mat holed = right.clone();
  holed.at<float>(8, 10) = std::numeric_limits<float>::quiet_NaN();
  auto withHole =
      CorrelationCostService::compute(left, holed, cv::Rect(0, 5, 20, 10), 0, 10, params);
  EXPECT_FLOAT_EQ(withHole->cost(13, 8, 3), 0.75F);
  EXPECT_LT(withHole->cost(16, 8, 3), 0.05F);
}

TEST(CostService, BadInputsThrow) {
  const cv::Mat left = texture({60, 40}, 4);
  const cv::Mat right = texture({61, 40}, 5);
  EXPECT_THROW(CorrelationCostService::compute(left, right, cv::Rect(0, 0, 10, 10), 0, 5),
               core::Error);
  EXPECT_THROW(CorrelationCostService::compute(left, left, cv::Rect(0, 0, 10, 10), 6, 5),
               core::Error);
  EXPECT_THROW(CorrelationCostService::compute(left, left, cv::Rect(55, 0, 10, 10), 0, 5),
               core::Error);
  CostParams even;
  even.window = 6;
  EXPECT_THROW(CorrelationCostService::compute(left, left, cv::Rect(0, 0, 10, 10), 0, 5, even),
               core::Error);
}

TEST(CostService, CancelReturnsNull) {
  const cv::Mat left = texture({100, 100}, 6);
  core::Progress progress;
  progress.cancel();
  EXPECT_EQ(
      CorrelationCostService::compute(left, left, cv::Rect(10, 10, 50, 50), 0, 40, {}, &progress),
      nullptr);
}

TEST(CostService, QueryIsFastFor300x300By256) {
  const cv::Mat left = texture({600, 340}, 7);
  const cv::Mat right = shiftedRight(left, 20.0);
  auto service =
      CorrelationCostService::compute(left, right, cv::Rect(280, 20, 300, 300), -20, 235);
  ASSERT_NE(service, nullptr);
  const auto start = std::chrono::steady_clock::now();
  const int queries = 10;
  for (int q = 0; q < queries; ++q) {
    const cv::Mat c = service->minCost(-20 + q, 235 - q);  // widest intervals: worst case
    ASSERT_FALSE(c.empty());
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() /
      queries;
  std::cout << "minCost over 300x300 x 256: " << ms << " ms per query\n";
  EXPECT_LT(ms, 20.0);
}

// A textureless roof (grey 200, disparity 40) on textured ground (disparity 3), noise 2 grey
// levels in both views, right view with gain 0.9 and offset 8. The roof is narrower than the
// disparity step, so that the ground's disparity never lands a roof pixel on the roof's image.
struct FlatRoofPair {
  cv::Mat left, right;
  cv::Rect roof{150, 30, 30, 40};
  int roofDisparity = 40, groundDisparity = 3;
};

FlatRoofPair flatRoofPair() {
  FlatRoofPair p;
  const cv::Mat ground = texture({320, 100}, 5);
  p.left.create(100, 260, CV_32F);
  p.right.create(100, 260, CV_32F);
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 260; ++x) {
      p.left.at<float>(y, x) = p.roof.contains({x, y}) ? 200.f : ground.at<float>(y, x);
      const bool onRoof = p.roof.contains({x + p.roofDisparity, y});
      const float v = onRoof ? 200.f : ground.at<float>(y, x + p.groundDisparity);
      p.right.at<float>(y, x) = 0.9f * v + 8.f;
    }
  }
  cv::RNG rng(7);
  testing::addSensorNoise(p.left, p.right, 2.0, rng);
  return p;
}

TEST(CostService, BrightnessTermSeparatesATexturelessRoofFromTheGround) {
  const FlatRoofPair p = flatRoofPair();
  const cv::Rect roi(90, 20, 150, 60);
  CostParams nccOnly;
  CostParams withBrightness;
  withBrightness.brightnessScale = 20;
  const auto plain = CorrelationCostService::compute(p.left, p.right, roi, 0, 44, nccOnly);
  const auto bright = CorrelationCostService::compute(p.left, p.right, roi, 0, 44, withBrightness);
  ASSERT_NE(plain, nullptr);
  ASSERT_NE(bright, nullptr);
  // Inside the roof, 3 px from its edges (flat windows): NCC cannot tell roof from ground; the
  // mean grey level, mapped through the fitted gain and offset, can.
  double plainGap = 0, roofCost = 0, groundCost = 0, count = 0;
  for (int y = p.roof.y + 3; y < p.roof.br().y - 3; ++y) {
    for (int x = p.roof.x + 3; x < p.roof.br().x - 3; ++x) {
      plainGap +=
          std::abs(plain->cost(x, y, p.roofDisparity) - plain->cost(x, y, p.groundDisparity));
      roofCost += bright->cost(x, y, p.roofDisparity);
      groundCost += bright->cost(x, y, p.groundDisparity);
      count += 1;
    }
  }
  EXPECT_LT(plainGap / count, 0.15);
  EXPECT_LT(roofCost / count, 0.1);  // 12 grey levels apart without the gain/offset map: 0.33
  EXPECT_GT(groundCost / count, 0.5);
  // Textured ground east of the roof (seen by both views): the term barely changes NCC's verdict.
  double nccGround = 0, brightGround = 0, n = 0;
  for (int y = roi.y; y < roi.br().y; ++y) {
    for (int x = p.roof.br().x + 5; x < roi.br().x; ++x) {
      nccGround += plain->cost(x, y, p.groundDisparity);
      brightGround += bright->cost(x, y, p.groundDisparity);
      n += 1;
    }
  }
  EXPECT_LT(brightGround / n, 0.05);
  EXPECT_NEAR(brightGround / n, nccGround / n, 0.02);
}

}  // namespace
}  // namespace delineo::stereo
