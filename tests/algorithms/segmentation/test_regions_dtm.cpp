// Regions, region graph, DTM sampling and interpolation, and the labelling potentials.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "delineo/segmentation/dtm.hpp"
#include "delineo/segmentation/ground_model.hpp"
#include "delineo/segmentation/regions.hpp"

using namespace delineo::segmentation;

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
}

TEST(Regions, GrowingSplitsAtStepsAboveTheThresholdOnly) {
  cv::Mat dem(10, 20, CV_32F);
  for (int y = 0; y < dem.rows; ++y) {
    for (int x = 0; x < dem.cols; ++x) dem.at<float>(y, x) = static_cast<float>(0.5 * x);  // 0.5 m steps
  }
  dem.colRange(12, 20) += 3.0;  // a 3.5 m step between columns 11 and 12
  dem.at<float>(5, 5) = kNaN;
  int count = 0;
  const cv::Mat labels = growRegions(dem, 1.0, cv::Mat(), count);
  EXPECT_EQ(count, 2);
  EXPECT_EQ(labels.at<int>(5, 5), -1);
  EXPECT_EQ(labels.at<int>(0, 0), labels.at<int>(9, 11));
  EXPECT_NE(labels.at<int>(0, 11), labels.at<int>(0, 12));
}

TEST(Regions, SmallRegionsMergeIntoTheNeighbourOfClosestHeight) {
  cv::Mat dem(20, 30, CV_32F, cv::Scalar(0));
  dem.colRange(15, 30).setTo(10.0);
  dem(cv::Rect(14, 8, 2, 2)).setTo(7.0);  // 4 px speck on the border, nearer 10 m than 0 m
  int count = 0;
  cv::Mat labels = growRegions(dem, 1.0, cv::Mat(), count);
  ASSERT_EQ(count, 3);
  count = mergeSmallRegions(labels, dem, count, 5);
  EXPECT_EQ(count, 2);
  EXPECT_EQ(labels.at<int>(8, 14), labels.at<int>(0, 29));
}

TEST(Regions, GraphLinksNeighboursAndRegionsAcrossARowGap) {
  // Ground (0 m) | roof (10 m) | 6 px of no data | ground (0.2 m); the right ground touches the
  // roof only across the gap.
  cv::Mat dem(10, 40, CV_32F, cv::Scalar(0));
  dem.colRange(10, 20).setTo(10.0);
  dem.colRange(20, 26).setTo(kNaN);
  dem.colRange(26, 40).setTo(0.2);
  int count = 0;
  const cv::Mat labels = growRegions(dem, 1.0, cv::Mat(), count);
  ASSERT_EQ(count, 3);
  const RegionGraph g = buildRegionGraph(labels, dem, count, 4, 8);
  ASSERT_EQ(g.links.size(), 2u);
  const int roof = labels.at<int>(0, 15), right = labels.at<int>(0, 30);
  bool sawGapLink = false;
  for (const RegionLink& l : g.links) {
    const double roofMinusOther = l.a == roof ? l.step : -l.step;
    EXPECT_TRUE(l.a == roof || l.b == roof);
    if (l.a == right || l.b == right) {
      EXPECT_TRUE(l.acrossGap);
      EXPECT_NEAR(roofMinusOther, 9.8, 1e-4);
      EXPECT_EQ(l.contacts, 10);
      sawGapLink = true;
    } else {
      EXPECT_FALSE(l.acrossGap);
      EXPECT_NEAR(roofMinusOther, 10.0, 1e-4);
    }
  }
  EXPECT_TRUE(sawGapLink);
  EXPECT_EQ(g.gapLinks, 1);
  // A gap wider than the longest run links nothing.
  EXPECT_EQ(buildRegionGraph(labels, dem, count, 4, 5).links.size(), 1u);
}

TEST(Regions, StepIsReadInsideTheRegionsNotAtTheirMeans) {
  // A slope of 0.1 m/px with a 1.5 m step at column 60: two regions whose means differ by 6.5 m
  // but which meet with a 1.6 m step (2.2 m read 3 px further inside each: columns 56 and 63).
  cv::Mat dem(10, 100, CV_32F);
  for (int x = 0; x < 100; ++x) dem.col(x).setTo(0.1 * x + (x >= 60 ? 1.5 : 0.0));
  int count = 0;
  const cv::Mat labels = growRegions(dem, 1.0, cv::Mat(), count);
  ASSERT_EQ(count, 2);
  const RegionGraph g = buildRegionGraph(labels, dem, count, 3, 0);
  ASSERT_EQ(g.links.size(), 1u);
  EXPECT_NEAR(g.links[0].step, -2.2, 1e-4);  // region 0 (left) minus region 1
  EXPECT_NEAR(g.regions[1].meanHeight - g.regions[0].meanHeight, 6.5, 1e-4);
  EXPECT_EQ(g.links[0].contacts, 10);
}

TEST(Dtm, SamplingTakesTheMostFrequentGroundHeightNearTheCentre) {
  cv::Mat dem(40, 40, CV_32F, cv::Scalar(5.0));
  dem(cv::Rect(0, 0, 40, 10)).setTo(9.0);   // a quarter at another height
  cv::Mat ground(dem.size(), CV_8U, cv::Scalar(255));
  ground(cv::Rect(15, 15, 10, 10)).setTo(0);  // the centre is not ground
  const auto samples = sampleGround(dem, ground, 40, 1.0);
  ASSERT_EQ(samples.size(), 1u);
  EXPECT_FLOAT_EQ(samples[0].height, 5.0f);
  EXPECT_LT(cv::norm(cv::Point2f(samples[0].position) + cv::Point2f(0.5f, 0.5f) - cv::Point2f(20, 20)), 8.0);
  // Few ground pixels among many heights: no sample.
  cv::Mat speck(dem.size(), CV_8U, cv::Scalar(0));
  speck.at<unsigned char>(3, 3) = 255;
  EXPECT_TRUE(sampleGround(dem, speck, 40, 1.0).empty());
}

TEST(Dtm, InterpolationIsExactOnAPlaneInsideAndOutsideTheHull) {
  auto plane = [](double x, double y) { return 10.0 + 0.05 * x - 0.02 * y; };
  std::vector<GroundSample> samples;
  for (int y = 15; y < 100; y += 30) {
    for (int x = 20; x < 120; x += 33) {
      samples.push_back({cv::Point(x + (y % 7), y), static_cast<float>(plane(x + (y % 7) + 0.5, y + 0.5))});
    }
  }
  const cv::Mat dtm = interpolateDtm(samples, {130, 110});
  double worst = 0;
  for (int y = 0; y < dtm.rows; ++y) {
    for (int x = 0; x < dtm.cols; ++x) worst = std::max(worst, std::abs(dtm.at<float>(y, x) - plane(x + 0.5, y + 0.5)));
  }
  EXPECT_LT(worst, 1e-3);
}

TEST(Dtm, FewSamplesGiveTheirPlaneAndNoneGivesNaN) {
  EXPECT_TRUE(std::isnan(interpolateDtm({}, {10, 10}).at<float>(5, 5)));
  const cv::Mat one = interpolateDtm({{{3, 4}, 7.0f}}, {10, 10});
  EXPECT_FLOAT_EQ(one.at<float>(0, 9), 7.0f);
  // Three samples on one row: no triangle; the plane through them everywhere.
  const cv::Mat line = interpolateDtm({{{1, 5}, 1.0f}, {{5, 5}, 5.0f}, {{9, 5}, 9.0f}}, {12, 12});
  EXPECT_NEAR(line.at<float>(0, 3), 3.0f, 1e-4);
  EXPECT_NEAR(line.at<float>(11, 11), 11.0f, 1e-4);
}

TEST(Potentials, ContextualPotentialKeepsThePapersProperties) {
  const double d0 = 2.0;
  const GroundLabel g = GroundLabel::Ground, a = GroundLabel::Above;
  for (double delta = -20.0; delta <= 20.0; delta += 0.05) {
    // eq. 3: V(g,g) <= V(a,g) exactly when δ <= δ0 (equal at δ0).
    const double gg = contextualPotential(g, g, delta, d0), ag = contextualPotential(a, g, delta, d0);
    if (delta < d0 - 1e-9) {
      EXPECT_LE(gg, ag) << delta;
      if (delta > -3 * d0) {  // beyond, both are 1 to double precision
        EXPECT_LT(gg, ag) << delta;
      }
    } else if (delta > d0 + 1e-9) {
      EXPECT_GT(gg, ag) << delta;
    }
    // eq. 4: symmetry.
    EXPECT_DOUBLE_EQ(contextualPotential(g, a, delta, d0), contextualPotential(a, g, -delta, d0));
    EXPECT_DOUBLE_EQ(contextualPotential(a, a, delta, d0), -1.0);
    // Submodular, so that a minimum cut is the exact minimum.
    EXPECT_LE(gg + contextualPotential(a, a, delta, d0),
              contextualPotential(g, a, delta, d0) + ag + 1e-12) << delta;
  }
  EXPECT_NEAR(contextualPotential(g, g, d0, d0), contextualPotential(a, g, d0, d0), 1e-12);
}

TEST(Potentials, DataPotentialCrossesAtH0) {
  const GroundUnder under{100.0, 99.0, 101.0};
  const double d0 = 2.0;  // h0 = 102
  EXPECT_LT(dataPotential(GroundLabel::Ground, 100.0, under, d0), dataPotential(GroundLabel::Above, 100.0, under, d0));
  EXPECT_GT(dataPotential(GroundLabel::Ground, 104.0, under, d0), dataPotential(GroundLabel::Above, 104.0, under, d0));
  EXPECT_NEAR(dataPotential(GroundLabel::Ground, 102.0, under, d0), 0.0, 1e-12);
  double previous = -2.0;
  for (double h = 90.0; h < 120.0; h += 0.1) {
    const double v = dataPotential(GroundLabel::Ground, h, under, d0);
    EXPECT_GE(v, previous);
    previous = v;
  }
}

TEST(Dtm, SamplingTakesTheLowestWellPopulatedLevel) {
  // A window mostly covered by a roof (9 m) with a strip of street (5 m) on a third of it: the
  // most frequent height is the roof's, the lowest level holding 30 % of it is the street's.
  cv::Mat dem(40, 40, CV_32F, cv::Scalar(9.0));
  dem(cv::Rect(0, 0, 40, 12)).setTo(5.0);
  const cv::Mat ground(dem.size(), CV_8U, cv::Scalar(255));
  const auto low = sampleGround(dem, ground, 40, 1.0, 0.3);
  ASSERT_EQ(low.size(), 1u);
  EXPECT_FLOAT_EQ(low[0].height, 5.0f);
  const auto frequent = sampleGround(dem, ground, 40, 1.0, 1.0);
  ASSERT_EQ(frequent.size(), 1u);
  EXPECT_FLOAT_EQ(frequent[0].height, 9.0f);
  // A few low outliers (under 30 % of the peak) do not move it.
  dem(cv::Rect(0, 0, 40, 12)).setTo(9.0);
  dem(cv::Rect(0, 0, 10, 10)).setTo(2.0);
  EXPECT_FLOAT_EQ(sampleGround(dem, ground, 40, 1.0, 0.3)[0].height, 9.0f);
}
