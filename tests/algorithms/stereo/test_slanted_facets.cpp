// Steep facets matched on slanted planes (internal recoverSlantedFacets).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "slanted_facets.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A gable roof on textured ground: ground at 5 px, a facet rising 0.35 px/px from 20 px at x = 30
// to its ridge at x = 60, and the other facet falling as steeply to x = 90. The left view is
// the right one sampled at x − d (linear interpolation, as the matcher reads it). The disparity
// map holds the truth, except the first facet's inside, left unmatched, between contours at
// x = 30 and x = 60.
struct GableScene {
  static constexpr int kWidth = 120, kHeight = 80;
  cv::Mat left, right, truth, disparity, score, edges;
  const cv::Rect facet{31, 10, 29, 60};

  static double truthAt(int x) {
    if (x >= 30 && x < 60) return 20 + 0.35 * (x - 30);
    if (x >= 60 && x < 90) return 30.5 - 0.35 * (x - 60);
    return 5;
  }

  GableScene() {
    right.create(kHeight, kWidth, CV_32F);
    cv::RNG rng(7);
    rng.fill(right, cv::RNG::UNIFORM, 0.0, 255.0);
    cv::GaussianBlur(right, right, {0, 0}, 1.2);
    left.create(right.size(), CV_32F);
    truth.create(right.size(), CV_32F);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const double d = truthAt(x);
        truth.at<float>(y, x) = static_cast<float>(d);
        const double xr = x - d;
        const int x0 = static_cast<int>(std::floor(xr));
        const double t = xr - x0;
        left.at<float>(y, x) = x0 < 0 ? 0.0F
                                      : static_cast<float>((1 - t) * right.at<float>(y, x0) +
                                                           t * right.at<float>(y, x0 + 1));
      }
    }
    disparity = truth.clone();
    disparity(facet).setTo(kNaN);
    score = cv::Mat(right.size(), CV_32F, cv::Scalar(0.9));
    score(facet).setTo(kNaN);
    edges = cv::Mat::zeros(right.size(), CV_8U);
    edges(cv::Rect(30, 0, 1, kHeight)).setTo(255);
    edges(cv::Rect(60, 0, 1, kHeight)).setTo(255);
  }
};

TEST(RecoverSlantedFacets, MatchesAnUnmatchedSteepFacetOnItsPlane) {
  GableScene s;
  SlantedFacetSettings settings;
  const int matched =
      recoverSlantedFacets(s.left, s.right, s.edges, settings, 0, 40, s.disparity, s.score);
  EXPECT_GE(matched, 0.9 * s.facet.area());
  int close = 0;
  for (int y = s.facet.y; y < s.facet.y + s.facet.height; ++y) {
    for (int x = s.facet.x; x < s.facet.x + s.facet.width; ++x) {
      const float d = s.disparity.at<float>(y, x);
      if (std::isnan(d)) continue;
      EXPECT_NEAR(d, s.truth.at<float>(y, x), 0.25) << "at " << x << "," << y;
      EXPECT_GE(s.score.at<float>(y, x), settings.minPixelScore);
      close += std::abs(d - s.truth.at<float>(y, x)) <= 0.1F ? 1 : 0;
    }
  }
  EXPECT_GE(close, 0.9 * matched);
  // Outside the region nothing changed.
  EXPECT_EQ(s.disparity.at<float>(5, 40), s.truth.at<float>(5, 40));
}

TEST(RecoverSlantedFacets, AStripOfAnotherSurfaceInTheRegionDoesNotHideTheFacet) {
  GableScene s;
  // Over 10 rows the contour at the ridge is missing and the region runs on into 6 unmatched
  // columns of the other side, whose left view there is unrelated, high-contrast texture.
  const cv::Rect strip(60, 55, 7, 10);
  s.edges(cv::Rect(60, 55, 1, 10)).setTo(0);
  s.disparity(strip).setTo(kNaN);
  cv::Mat other(strip.size(), CV_32F);
  cv::RNG rng(5);
  rng.fill(other, cv::RNG::UNIFORM, -400.0, 600.0);
  other.copyTo(s.left(strip));
  const int matched = recoverSlantedFacets(s.left, s.right, s.edges, SlantedFacetSettings{}, 0,
                                           40, s.disparity, s.score);
  EXPECT_GE(matched, 0.9 * s.facet.area());
  int close = 0;
  for (int y = s.facet.y; y < s.facet.y + s.facet.height; ++y) {
    for (int x = s.facet.x; x < s.facet.x + s.facet.width; ++x) {
      const float d = s.disparity.at<float>(y, x);
      close += !std::isnan(d) && std::abs(d - s.truth.at<float>(y, x)) <= 0.25F ? 1 : 0;
    }
  }
  EXPECT_GE(close, 0.9 * s.facet.area());
}

TEST(RecoverSlantedFacets, TheSameOnAnyNumberOfThreads) {
  GableScene one;
  // Both sides of the roof unmatched: two regions, one task each.
  const cv::Rect otherSide(61, 10, 28, 60);
  one.disparity(otherSide).setTo(kNaN);
  one.score(otherSide).setTo(kNaN);
  GableScene two;
  two.disparity = one.disparity.clone();
  two.score = one.score.clone();
  SlantedFacetSettings settings;
  settings.threads = 1;
  const int matchedOne = recoverSlantedFacets(one.left, one.right, one.edges, settings, 0, 40,
                                              one.disparity, one.score);
  settings.threads = 2;
  const int matchedTwo = recoverSlantedFacets(two.left, two.right, two.edges, settings, 0, 40,
                                              two.disparity, two.score);
  EXPECT_GE(matchedOne, 0.9 * (one.facet.area() + otherSide.area()));
  EXPECT_EQ(matchedOne, matchedTwo);
  const size_t bytes = one.disparity.total() * one.disparity.elemSize();
  EXPECT_EQ(std::memcmp(one.disparity.data, two.disparity.data, bytes), 0);
  EXPECT_EQ(std::memcmp(one.score.data, two.score.data, bytes), 0);
}

TEST(RecoverSlantedFacets, LeavesARegionNoPlaneLinesUpUnmatched) {
  GableScene s;
  // The facet's left view replaced by texture found nowhere in the right view.
  cv::Mat other(s.facet.size(), CV_32F);
  cv::RNG rng(11);
  rng.fill(other, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(other, other, {0, 0}, 1.2);
  other.copyTo(s.left(s.facet));
  EXPECT_EQ(recoverSlantedFacets(s.left, s.right, s.edges, SlantedFacetSettings{}, 0, 40,
                                 s.disparity, s.score),
            0);
  EXPECT_EQ(cv::countNonZero(s.disparity(s.facet) == s.disparity(s.facet)), 0);
}

TEST(RecoverSlantedFacets, LeavesSmallRegionsAndTheMapAloneWhenOff) {
  GableScene s;
  SlantedFacetSettings settings;
  settings.maxSlope = 0;
  EXPECT_EQ(recoverSlantedFacets(s.left, s.right, s.edges, settings, 0, 40, s.disparity, s.score),
            0);
  settings = SlantedFacetSettings{};
  settings.minArea = s.facet.area() + 1;
  EXPECT_EQ(recoverSlantedFacets(s.left, s.right, s.edges, settings, 0, 40, s.disparity, s.score),
            0);
  EXPECT_EQ(cv::countNonZero(s.disparity(s.facet) == s.disparity(s.facet)), 0);
}

}  // namespace
}  // namespace delineo::stereo::detail
