// Flat regions filled from their outline (internal fillFlatRegions): the fill reaches the image
// contour.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <opencv2/core.hpp>

#include "match_fill.hpp"
#include "synthetic.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kRoof = 20.0f, kGround = 4.0f;

// A textureless roof (grey 200, 50x40 px) at disparity 20 on textured ground at disparity 4,
// noise sigma 2 in each view; and the map a window matcher leaves there: ground matched up to
// 3 px from the roof, the roof's top and bottom 2 rows matched (their windows reach the
// outline), the rest of the roof unmatched, except 10 rows of its last column that carry the
// ground's value over the outline.
struct Scene {
  cv::Mat left, right, disparity, score;
  cv::Rect roof{60, 40, 50, 40};
};

Scene scene(float roofGrey = 200.0f, double noise = 2.0) {
  Scene s;
  testing::FlatRoofPair pair = testing::flatRoofPair(true, roofGrey, noise, 31, 4);
  s.left = pair.left;
  s.right = pair.right;
  s.roof = pair.roof;
  const cv::Size size = s.left.size();
  s.disparity = cv::Mat(size, CV_32F, cv::Scalar(kGround));
  const cv::Rect around(s.roof.x - 3, s.roof.y - 3, s.roof.width + 6, s.roof.height + 6);
  s.disparity(around).setTo(kNaN);
  s.disparity(cv::Rect(s.roof.x + 2, s.roof.y, s.roof.width - 4, 2)).setTo(kRoof);
  s.disparity(cv::Rect(s.roof.x + 2, s.roof.br().y - 2, s.roof.width - 4, 2)).setTo(kRoof);
  s.disparity(cv::Rect(s.roof.br().x - 1, s.roof.y + 10, 1, 10)).setTo(kGround);
  s.score = cv::Mat(size, CV_32F, cv::Scalar(0.9));
  return s;
}

// Rows (away from the roof's top and bottom) whose roof pixels all carry the roof's disparity.
int rowsFilledToTheOutline(const Scene& s) {
  int rows = 0;
  for (int y = s.roof.y + 3; y < s.roof.br().y - 3; ++y) {
    bool all = true;
    for (int x = s.roof.x; x < s.roof.br().x; ++x) {
      all = all && std::abs(s.disparity.at<float>(y, x) - kRoof) < 0.5f;
    }
    rows += all ? 1 : 0;
  }
  return rows;
}

// Pixels off the roof that took its disparity.
int spilledOntoTheGround(const Scene& s) {
  int spilled = 0;
  for (int y = 0; y < s.left.rows; ++y) {
    for (int x = 0; x < s.left.cols; ++x) {
      if (!s.roof.contains({x, y}) && std::abs(s.disparity.at<float>(y, x) - kRoof) < 1.5f) {
        ++spilled;
      }
    }
  }
  return spilled;
}

// The fill on a test scene (range 0..dmax, fill score 0.3).
template <class SceneT>
void fill(SceneT& s, const RegionFillSettings& settings, int dmax) {
  fillFlatRegions(s.left, s.right, settings, 0, dmax, 0.3f, s.disparity, s.score);
}

// Pixels of `area` whose disparity is within `tolerance` px (exclusive) of expected(x, y).
template <class Expected>
int pixelsWithin(const cv::Mat& disparity, const cv::Rect& area, Expected&& expected,
                 double tolerance) {
  int n = 0;
  for (int y = area.y; y < area.br().y; ++y) {
    for (int x = area.x; x < area.br().x; ++x) {
      n += std::abs(disparity.at<float>(y, x) - expected(x, y)) < tolerance ? 1 : 0;
    }
  }
  return n;
}

// Pixels of `area` that hold the roof's disparity (within 0.5 px).
// The roof without its 5 px nearest the outline: where the value filled is checked.
cv::Rect innerRoof(const Scene& s) {
  return {s.roof.x + 5, s.roof.y + 5, s.roof.width - 10, s.roof.height - 10};
}

// Pixels of `area` holding `value` within `tolerance` px (exclusive).
int pixelsAt(const cv::Mat& disparity, const cv::Rect& area, float value, double tolerance) {
  return pixelsWithin(
      disparity, area, [value](int, int) { return value; }, tolerance);
}

int roofPixelsIn(const Scene& s, const cv::Rect& area) {
  return pixelsWithin(
      s.disparity, area, [](int, int) { return kRoof; }, 0.5);
}

int roofPixelsWithTheRoofsDisparity(const Scene& s) {
  return roofPixelsIn(s, s.roof);
}

TEST(PlainPixels, AreThePlainRoofNotTheTexturedGround) {
  const Scene s = scene();
  const cv::Mat plain = plainPixels(s.left, 3.0);
  const cv::Rect inner(s.roof.x + 3, s.roof.y + 3, s.roof.width - 6, s.roof.height - 6);
  EXPECT_EQ(cv::countNonZero(plain(inner)), inner.area());
  const cv::Rect ground(0, 0, s.roof.x - 3, s.left.rows);
  // (The ground's texture: a few of its 5x5 windows may be about as plain as noise.)
  EXPECT_LT(cv::countNonZero(plain(ground)), ground.area() / 20);
  // A lower threshold keeps fewer of the roof's pixels, never more.
  EXPECT_LE(cv::countNonZero(plainPixels(s.left, 1.0)(inner)), cv::countNonZero(plain(inner)));
  // The image's moments made beforehand (as the matcher does, once for three steps) give the
  // same pixels, nodata included.
  cv::Mat withNodata = s.left.clone();
  withNodata(cv::Rect(5, 5, 20, 10)).setTo(kNaN);
  const LocalMoments moments = localMoments(withNodata);
  EXPECT_GT(moments.noise, 0.0);
  for (const double sigmas : {1.0, 3.0}) {
    EXPECT_EQ(cv::countNonZero(plainPixels(withNodata, sigmas, &moments) !=
                               plainPixels(withNodata, sigmas)),
              0)
        << sigmas;
  }
}

TEST(FillFlatRegions, ReachesTheImageContourAndStopsThere) {
  Scene grown = scene();
  fill(grown, RegionFillSettings{}, 32);
  Scene plain = scene();
  RegionFillSettings noGrowth;
  noGrowth.growReach = 0;
  fill(plain, noGrowth, 32);
  const int rows = grown.roof.height - 6;
  // The flat region stops 2 px short of the outline (its 5x5 windows straddle it).
  EXPECT_EQ(rowsFilledToTheOutline(plain), 0);
  EXPECT_GE(rowsFilledToTheOutline(grown), rows * 9 / 10) << " of " << rows;
  // The ground's value carried onto the roof's last column is replaced (the grown pixels pass a
  // per-pixel noise test: a few may fail it).
  int replaced = 0;
  for (int y = grown.roof.y + 10; y < grown.roof.y + 20; ++y) {
    replaced += std::abs(grown.disparity.at<float>(y, grown.roof.br().x - 1) - kRoof) < 0.5f;
  }
  EXPECT_GE(replaced, 8);
  // No ground pixel takes the roof's disparity.
  EXPECT_EQ(spilledOntoTheGround(grown), 0);
}

TEST(FillFlatRegions, FillsTheMedianOfTheOutlinesMatchesNotTheirMean) {
  // A third of the bottom strip's matches 1.2 px too far (windows along an outline that runs
  // with the rows, not fixed in x): within the cluster's 1.5 px, they would pull a mean 0.2 px
  // off; the median stays at the roof's disparity.
  Scene s = scene();
  s.disparity(cv::Rect(s.roof.x + 2, s.roof.br().y - 2, 30, 2)).setTo(kRoof + 1.2f);
  fill(s, RegionFillSettings{}, 32);
  const cv::Rect inner = innerRoof(s);
  // (Measured: all 1 200 inner pixels within 0.01 px; 0 with the cluster's mean.)
  EXPECT_EQ(pixelsAt(s.disparity, inner, kRoof, 0.01), inner.area());
}

TEST(FillFlatRegions, AScanOfTheRangeConfirmsAnUnclearCandidate) {
  // A roof of nearly the ground's grey under strong noise (grey 140, sigma 6): the outline error
  // of the roof's candidate is not half the ground's, but no other disparity of the range lines
  // the outline up as well.
  Scene scanned = scene(140.0f, 6.0);
  fill(scanned, RegionFillSettings{}, 32);
  Scene unscanned = scene(140.0f, 6.0);
  RegionFillSettings noScan;
  noScan.scanAgreement = 0;
  noScan.coreOpening = 0;  // the core (without the thin parts along the ground) lines up better
  noScan.edgeDecideShare = 0;  // where the scan does not confirm, the roof's edges would decide
  fill(unscanned, noScan, 32);
  const int rows = scanned.roof.height - 6;
  EXPECT_EQ(rowsFilledToTheOutline(unscanned), 0);
  EXPECT_GE(rowsFilledToTheOutline(scanned), rows * 8 / 10) << " of " << rows;
  // With the roof's grey within 3 noise sigmas of parts of the ground, the flat region and its
  // growth take some ground along the outline: less than half a pixel per outline pixel.
  const int perimeter = 2 * (scanned.roof.width + scanned.roof.height);
  EXPECT_LT(spilledOntoTheGround(scanned), perimeter / 2);
}

TEST(FillFlatRegions, TheScanReadsTheRightViewThroughTheMatchesGreyMap) {
  // The scan's scene (grey 140 roof, noise 6), the right view seen with gain 0.9 and offset 8,
  // and a bright band (grey 210) along its last 24 columns that the left view does not show (a
  // surface only one view sees; the left pixels that would pair with it are unmatched). The band
  // skews the images' grey moments: their map is gain 0.74 and offset 24 against the matches'
  // 1.09 and -6.5, several grey levels off at the roof's grey, the same at every disparity.
  Scene s = scene(140.0f, 6.0);
  cv::RNG rng(11);
  const int bandStart = s.right.cols - 24;
  for (int y = 0; y < s.right.rows; ++y) {
    for (int x = 0; x < s.right.cols; ++x) {
      float& v = s.right.at<float>(y, x);
      v = x >= bandStart ? 210.0f + static_cast<float>(rng.gaussian(6.0)) : 0.9f * v + 8.0f;
    }
  }
  const int firstUnmatched = bandStart + static_cast<int>(kGround);
  s.disparity(cv::Rect(firstUnmatched, 0, s.disparity.cols - firstUnmatched, s.disparity.rows))
      .setTo(kNaN);
  fill(s, RegionFillSettings{}, 32);
  // (Measured: all 1 200 inner pixels, and 0 with the scan through the images' map.)
  const cv::Rect inner = innerRoof(s);
  EXPECT_EQ(roofPixelsIn(s, inner), inner.area());
  const int perimeter = 2 * (s.roof.width + s.roof.height);
  EXPECT_LT(spilledOntoTheGround(s), perimeter / 2);
}

// The scene with the right view `offset` grey levels off over the roof and 10 px around it, and
// the roof's last column matched at the roof's disparity (the matches beside the region on its
// rows agree with it) unless `carriedGround`.
Scene seenInOtherLight(float roofGrey, float offset, bool carriedGround = false) {
  Scene s = scene(roofGrey);
  const cv::Rect seen(s.roof.x - static_cast<int>(kRoof) - 10, s.roof.y - 10, s.roof.width + 20,
                      s.roof.height + 20);
  s.right(seen) += offset;
  if (!carriedGround) s.disparity(cv::Rect(s.roof.br().x - 1, s.roof.y + 10, 1, 10)).setTo(kRoof);
  return s;
}

TEST(FillFlatRegions, AShadedRoofIsDecidedInItsOwnLight) {
  // A dark plain roof (grey 60, under the left image's median) in a shadow that the right view
  // sees 20 grey levels brighter than the images' grey map says: through the map no candidate
  // lines the outline up; with the ring's own brightness offset removed, the roof's does.
  Scene ownLight = seenInOtherLight(60.0f, 20.0f);
  fill(ownLight, RegionFillSettings{}, 32);
  Scene mapOnly = seenInOtherLight(60.0f, 20.0f);
  RegionFillSettings noOwnLight;
  noOwnLight.shadowOwnLight = false;
  fill(mapOnly, noOwnLight, 32);
  const cv::Rect inner = innerRoof(ownLight);
  EXPECT_EQ(roofPixelsIn(mapOnly, inner), 0);
  EXPECT_EQ(roofPixelsIn(ownLight, inner), inner.area());
  EXPECT_LE(spilledOntoTheGround(ownLight), 2);  // (measured: 1)
  // Where the matches beside it on its rows carry another disparity (the ground's, on the roof's
  // last column), the value found in its own light is not trusted.
  Scene disagreeing = seenInOtherLight(60.0f, 20.0f, true);
  fill(disagreeing, RegionFillSettings{}, 32);
  EXPECT_EQ(roofPixelsIn(disagreeing, innerRoof(disagreeing)), 0);
  // A bright roof (grey 200) seen 40 levels darker is not retried: brighter than most of the
  // scene, it is no shadow (without the median test its 1 200 inner pixels were filled).
  Scene sunlit = seenInOtherLight(200.0f, -40.0f);
  fill(sunlit, RegionFillSettings{}, 32);
  EXPECT_EQ(roofPixelsIn(sunlit, innerRoof(sunlit)), 0);
}

TEST(FillFlatRegions, ThinFlatPartsJoinedToARoofDoNotDecideItsFill) {
  // Three plain 6-row bands of the roof's grey at the ground's disparity (a facade's bands
  // between its window rows) touch the roof's left side: their flat middles join the roof's flat
  // region, and their outline does not line up at the roof's disparity.
  auto withBands = [](Scene s) {
    cv::RNG rng(7);
    for (int band = 0; band < 3; ++band) {
      const int y0 = s.roof.y + 6 + 12 * band;
      for (int y = y0; y < y0 + 6; ++y) {
        for (int x = s.roof.x - 30; x < s.roof.x; ++x) {
          s.left.at<float>(y, x) = 200.0f + static_cast<float>(rng.gaussian(2.0));
          s.right.at<float>(y, x - static_cast<int>(kGround)) =
              200.0f + static_cast<float>(rng.gaussian(2.0));
        }
      }
    }
    return s;
  };
  Scene withCore = withBands(scene());
  fill(withCore, RegionFillSettings{}, 32);
  Scene wholeRegion = withBands(scene());
  RegionFillSettings noCore;
  noCore.coreOpening = 0;
  fill(wholeRegion, noCore, 32);
  // Without the core the bands' outline keeps the roof unfilled; with it the roof is filled
  // (the growth back to its contour leaves a few single pixels out, as in the tests above).
  EXPECT_EQ(rowsFilledToTheOutline(wholeRegion), 0);
  const int roofArea = withCore.roof.area();
  EXPECT_GE(roofPixelsWithTheRoofsDisparity(withCore), roofArea * 95 / 100) << " of " << roofArea;
  // The bands keep their own disparity, but for the pixel next to the roof on some of their
  // rows, which the growth reaches: it looks like the roof and matches at its disparity.
  EXPECT_LE(spilledOntoTheGround(withCore), 3 * 6);
}

// A plain sloped facet (a roof's side: grey 180, noise sigma 2, 70x60 px at (60, 30)) whose
// disparity is 20 px at its top-left corner and changes by `perColumn` and `perRow` px per
// column and row, on textured ground at disparity 4; the facet's pixels unmatched, the ground
// matched up to 3 px from it (as a window matcher leaves them). `edgeRowsMatched`: the facet's
// top and bottom 2 rows carry their true disparity (their windows reach the outline).
// The share of pixel x (covering [x - 0.5, x + 0.5)) that the interval [from, to) covers.
double coveredShare(int x, double from, double to) {
  return std::clamp(std::min(x + 0.5, to) - std::max(x - 0.5, from), 0.0, 1.0);
}

struct FacetScene {
  cv::Mat left, right, disparity, score;
  cv::Rect facet{60, 30, 70, 60};
  double perColumn = 0, perRow = 0;
  double truth(int x, int y) const {
    return 20.0 + perColumn * (x - facet.x) + perRow * (y - facet.y);
  }
};

// `mixedEdges`: each right pixel blends the facet's grey and the ground's by the share of it the
// facet covers (as a camera integrates it), instead of showing the one at its centre.
FacetScene slopedFacet(double perColumn = 0.15, double perRow = -0.05, bool edgeRowsMatched = false,
                       bool mixedEdges = false) {
  FacetScene s;
  s.perColumn = perColumn;
  s.perRow = perRow;
  const cv::Size size(200, 120);
  const cv::Mat ground = testing::texture(cv::Size(size.width + 64, size.height), 31) * 0.6 + 20.0;
  s.left.create(size, CV_32F);
  s.right.create(size, CV_32F);
  cv::RNG rng(4);
  // d(x, y) = c + perColumn x + perRow y.
  const double c = 20.0 - perColumn * s.facet.x - perRow * s.facet.y;
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      s.left.at<float>(y, x) = (s.facet.contains({x, y}) ? 180.0f : ground.at<float>(y, x + 32)) +
                               static_cast<float>(rng.gaussian(2.0));
      // The facet point seen at right column x: x = xf − d(xf, y). The facet spans
      // [facet.x − 0.5, facet.br().x − 0.5) in both views, sampled at pixel centres.
      const double xf = (x + c + perRow * y) / (1.0 - perColumn);
      const bool facetRow = y >= s.facet.y && y < s.facet.br().y;
      const bool seesFacet = facetRow && xf >= s.facet.x - 0.5 && xf < s.facet.br().x - 0.5;
      double share = seesFacet ? 1.0 : 0.0;
      if (mixedEdges) {
        // The facet's ends in the right view: x = xf (1 − perColumn) − c − perRow y.
        const double from = (s.facet.x - 0.5) * (1.0 - perColumn) - c - perRow * y;
        const double to = (s.facet.br().x - 0.5) * (1.0 - perColumn) - c - perRow * y;
        share = facetRow ? coveredShare(x, from, to) : 0.0;
      }
      s.right.at<float>(y, x) = static_cast<float>(
          share * 180.0 + (1.0 - share) * ground.at<float>(y, x + 4 + 32) + rng.gaussian(2.0));
    }
  }
  s.disparity = cv::Mat(size, CV_32F, cv::Scalar(kGround));
  const cv::Rect around(s.facet.x - 3, s.facet.y - 3, s.facet.width + 6, s.facet.height + 6);
  s.disparity(around).setTo(kNaN);
  if (edgeRowsMatched) {
    for (const int y0 : {s.facet.y, s.facet.br().y - 2}) {
      for (int y = y0; y < y0 + 2; ++y) {
        for (int x = s.facet.x + 2; x < s.facet.br().x - 2; ++x) {
          s.disparity.at<float>(y, x) = static_cast<float>(s.truth(x, y));
        }
      }
    }
  }
  s.score = cv::Mat(size, CV_32F, cv::Scalar(0.9));
  return s;
}

// Facet pixels whose disparity is within `tolerance` px of the facet's plane.
int facetPixelsOnItsPlane(const FacetScene& s, double tolerance) {
  return pixelsWithin(
      s.disparity, s.facet, [&](int x, int y) { return s.truth(x, y); }, tolerance);
}

TEST(FillFlatRegions, APlainSlopedFacetTakesThePlaneOfItsRowEndsInBothViews) {
  FacetScene sloped = slopedFacet();
  fill(sloped, RegionFillSettings{}, 40);
  FacetScene constantOnly = slopedFacet();
  RegionFillSettings noPlanes;
  noPlanes.planeMinRows = 0;
  fill(constantOnly, noPlanes, 40);
  // No constant lines the facet's outline up (its disparity spans 20..27.9 px): unfilled.
  EXPECT_EQ(facetPixelsOnItsPlane(constantOnly, 0.5), 0);
  // The plane fills it to its contour, within half a pixel.
  const int area = sloped.facet.area();
  EXPECT_GE(facetPixelsOnItsPlane(sloped, 0.5), area * 95 / 100) << " of " << area;
  // The ground keeps its disparity.
  int spilled = 0;
  for (int y = 0; y < sloped.left.rows; ++y) {
    for (int x = 0; x < sloped.left.cols; ++x) {
      const float d = sloped.disparity.at<float>(y, x);
      spilled += !sloped.facet.contains({x, y}) && std::isfinite(d) && d > kGround + 1.0f ? 1 : 0;
    }
  }
  EXPECT_LE(spilled, 2 * (sloped.facet.width + sloped.facet.height) / 10);
}

TEST(FillFlatRegions, APlainFacetsPlaneGoesThroughItsRowEndsSubpixelEdges) {
  // The facet of the test above, its right view blending the facet and the ground at its ends.
  const auto mixed = [] { return slopedFacet(0.15, -0.05, false, true); };
  FacetScene edges = mixed();
  fill(edges, RegionFillSettings{}, 40);
  FacetScene wholePixels = mixed();
  RegionFillSettings wholePixelEnds;
  wholePixelEnds.planeEdgeEnds = false;
  fill(wholePixels, wholePixelEnds, 40);
  const int area = edges.facet.area();
  // (Measured: 4 080 of its 4 200 pixels within 0.1 px of the plane; 786 through the whole-pixel
  // ends, 3 924 of them within 0.5 px.)
  EXPECT_GE(facetPixelsOnItsPlane(edges, 0.1), area * 9 / 10) << " of " << area;
  EXPECT_LT(facetPixelsOnItsPlane(wholePixels, 0.1), area / 2) << " of " << area;
  EXPECT_GE(facetPixelsOnItsPlane(wholePixels, 0.5), area * 9 / 10) << " of " << area;
}

TEST(FillFlatRegions, APlaneThatWouldHideManyMatchesInTheRightViewIsNotFilled) {
  // Filled, the facet (17-20 px at its left side) would hide in the right view the ground
  // matches (disparity 4) up to about 15 px left of it: between 0.1 and 0.14 × its flat region's
  // area (kept at 0.14). Kept at the default ratio (4); refused at 0.1; kept again at 0.1
  // when those ground pixels are unmatched, as a matcher leaves the ground the right view does
  // not see. (On the 2000² scene a plain rooftop box at 23 px took a copy of itself 126 px away
  // and would have hidden 14 × its area.)
  RegionFillSettings strict;
  strict.planeHiddenRatio = 0.1;
  FacetScene kept = slopedFacet();
  fill(kept, RegionFillSettings{}, 40);
  FacetScene refused = slopedFacet();
  fill(refused, strict, 40);
  const int area = kept.facet.area();
  EXPECT_GE(facetPixelsOnItsPlane(kept, 0.5), area * 95 / 100) << " of " << area;
  EXPECT_EQ(facetPixelsOnItsPlane(refused, 0.5), 0);
  FacetScene occluded = slopedFacet();
  occluded.disparity(cv::Rect(occluded.facet.x - 20, occluded.facet.y - 3, 20,
                              occluded.facet.height + 6))
      .setTo(kNaN);
  fill(occluded, strict, 40);
  EXPECT_GE(facetPixelsOnItsPlane(occluded, 0.5), area * 95 / 100) << " of " << area;
}

TEST(FillFlatRegions, AFacetAConstantLinesUpTakesItsPlaneWhenTheRowEndsDisagreeWithTheConstant) {
  // A facet sloping by 0.03 px per column (2.1 px across it) whose top and bottom rows are
  // matched: their values cluster, and the constant lines the outline up well enough to fill
  // it, with one value that misses both sides by up to 1 px. The row ends disagree with it.
  // (At 0.02 px per column the constant agrees with the row ends within 1 px and stays; at 0.04
  // no constant lines the outline up, the case of the test above.)
  FacetScene planar = slopedFacet(0.03, 0.0, true);
  fill(planar, RegionFillSettings{}, 40);
  FacetScene constant = slopedFacet(0.03, 0.0, true);
  RegionFillSettings noPlanes;
  noPlanes.planeMinRows = 0;
  fill(constant, noPlanes, 40);
  const int area = planar.facet.area();
  // Pixels of the facet holding the value filled at its centre.
  const auto withTheCentresValue = [](const FacetScene& f) {
    return cv::countNonZero(f.disparity(f.facet) ==
                            f.disparity.at<float>(f.facet.y + 30, f.facet.x + 35));
  };
  // Without planes the facet is filled, with one value.
  EXPECT_GE(withTheCentresValue(constant), area * 9 / 10);
  EXPECT_LT(facetPixelsOnItsPlane(constant, 0.5), area * 6 / 10) << " of " << area;
  EXPECT_GE(facetPixelsOnItsPlane(planar, 0.5), area * 95 / 100) << " of " << area;
  // Its plane spans about 2 px over the flat region: with planeMinSpan above that, the constant
  // stays (as for a flat roof whose row ends took a slope of noise); the default 1.5 px keeps
  // the plane (above).
  FacetScene tooFlat = slopedFacet(0.03, 0.0, true);
  RegionFillSettings wideSpan;
  wideSpan.planeMinSpan = 2.5;
  fill(tooFlat, wideSpan, 40);
  EXPECT_GE(withTheCentresValue(tooFlat), area * 9 / 10);
  // A flat facet keeps its constant (its plane's slope would be noise).
  FacetScene flat = slopedFacet(0.0, 0.0, true);
  fill(flat, RegionFillSettings{}, 40);
  int constantPixels = 0;
  for (int y = flat.facet.y + 2; y < flat.facet.br().y - 2; ++y) {
    for (int x = flat.facet.x; x < flat.facet.br().x; ++x) {
      constantPixels += flat.disparity.at<float>(y, x) ==
                                flat.disparity.at<float>(flat.facet.y + 30, flat.facet.x + 35)
                            ? 1
                            : 0;
    }
  }
  EXPECT_GE(constantPixels, (flat.facet.height - 4) * flat.facet.width * 95 / 100);
}

// The sloped facet of `slopedFacet()` seen in the right view with its eave side ragged from row
// 50 down (a hip facet beside which the right view sees the facade): 10 rows reach 4 px too far,
// the next 10 stop 3 px short, and so on. The hip-side row ends all agree with the facet's plane,
// the eave-side ones on 20 rows of the region's 56: 68 % of the row ends in all.
FacetScene facetWithARaggedEaveInTheRightView() {
  FacetScene s = slopedFacet();
  cv::RNG rng(9);
  const double c = 20.0 - s.perColumn * s.facet.x - s.perRow * s.facet.y;
  for (int y = 50; y < s.facet.br().y; ++y) {
    int last = -1;  // the right view's last facet column on the row
    for (int x = 0; x < s.right.cols; ++x) {
      const double xf = (x + c + s.perRow * y) / (1.0 - s.perColumn);
      if (xf >= s.facet.x - 0.5 && xf < s.facet.br().x - 0.5) last = x;
    }
    float* r = s.right.ptr<float>(y);
    if ((y - 50) / 10 % 2 == 0) {
      for (int k = 1; k <= 4; ++k) r[last + k] = 180.0f + static_cast<float>(rng.gaussian(2.0));
    } else {
      for (int k = 0; k < 3; ++k) r[last - k] = r[last + 6 + k];
    }
  }
  return s;
}

TEST(FillFlatRegions, AFacetWhoseHipSideRowEndsAgreeTakesTheirPlaneOverARaggedEave) {
  FacetScene hip = facetWithARaggedEaveInTheRightView();
  fill(hip, RegionFillSettings{}, 40);
  FacetScene bothSides = facetWithARaggedEaveInTheRightView();
  RegionFillSettings noOneSide;
  noOneSide.planeSideShare = 2.0;
  fill(bothSides, noOneSide, 40);
  const int area = hip.facet.area();
  // Too few row ends agree for the plane of both sides: unfilled.
  EXPECT_LT(facetPixelsOnItsPlane(bothSides, 0.5), area / 10) << " of " << area;
  // One side's ends agree and the other's fix the slope: the facet takes the plane.
  EXPECT_GE(facetPixelsOnItsPlane(hip, 0.5), area * 9 / 10) << " of " << area;
}

// The sloped facet of `slopedFacet()` with the right view exposed differently (right = 0.92 ·
// left + 6) and, over the left view's first 40 columns, a bright surface (grey 235) the right
// view does not see (it sees a dark one, grey 15, over its first 36): the images' moments then
// map the facet's grey 6+ levels off its counterpart's, the matched pixel pairs do not.
TEST(FillFlatRegions, ASlopedFacetFindsItsCounterpartUnderTheMatchedPairsGreyMap) {
  FacetScene s = slopedFacet();
  s.right = 0.92 * s.right + 6.0;
  cv::RNG rng(12);
  for (int y = 0; y < s.left.rows; ++y) {
    for (int x = 0; x < 40; ++x) {
      s.left.at<float>(y, x) = 235.0f + static_cast<float>(rng.gaussian(2.0));
      if (x < 36) s.right.at<float>(y, x) = 15.0f + static_cast<float>(rng.gaussian(2.0));
    }
  }
  s.disparity(cv::Rect(0, 0, 40, s.left.rows)).setTo(kNaN);
  fill(s, RegionFillSettings{}, 40);
  // Under the images' map no counterpart passes the grey test: the facet stays unfilled.
  const int area = s.facet.area();
  EXPECT_GE(facetPixelsOnItsPlane(s, 0.5), area * 9 / 10) << " of " << area;
}

// The sloped facet of `slopedFacet()` with, beyond its +x end on rows 66–89, a 12 px strip of
// ground of its grey (at the ground's disparity, 4 px, in both views) that the window matcher
// left unmatched: in the left view one flat region with the facet, in the right view apart from
// it (the facet is seen 26–31 px to the left, the strip 4 px). Those rows' +x ends lie 12 px
// past the facet's plane.
TEST(FillFlatRegions, AFacetJoinedToGroundOfItsGreyIsFilledOnlyWhereItsCounterpartMaps) {
  FacetScene s = slopedFacet();
  cv::RNG rng(11);
  const cv::Rect strip(s.facet.br().x, s.facet.y + 36, 12, 24);
  for (int y = strip.y; y < strip.br().y; ++y) {
    for (int x = strip.x; x < strip.br().x; ++x) {
      s.left.at<float>(y, x) = 180.0f + static_cast<float>(rng.gaussian(2.0));
      s.right.at<float>(y, x - 4) = 180.0f + static_cast<float>(rng.gaussian(2.0));
    }
  }
  s.disparity(cv::Rect(strip.x, strip.y, strip.width + 3, strip.height)).setTo(kNaN);
  fill(s, RegionFillSettings{}, 40);
  // The facet takes its plane (its −x ends agree with it, and the +x ends of the rows above).
  const int area = s.facet.area();
  EXPECT_GE(facetPixelsOnItsPlane(s, 0.5), area * 9 / 10) << " of " << area;
  // The strip beyond its counterpart's end does not (its first 2 px: the growth's reach).
  int onStrip = 0;
  for (int y = strip.y; y < strip.br().y; ++y) {
    for (int x = strip.x + 2; x < strip.br().x; ++x) {
      const float d = s.disparity.at<float>(y, x);
      onStrip += std::isfinite(d) && d > kGround + 2.0f ? 1 : 0;
    }
  }
  EXPECT_LE(onStrip, strip.height) << " of " << (strip.width - 2) * strip.height;
}

// The scene of `scene()` whose roof carries, along its right side, a 12 px band of weak random
// texture (a few grey levels: not flat, and left unmatched, as a window matcher that finds its
// NCC too weak would), and is seen 6 grey levels darker in the right view.
Scene stripedBandScene(double amplitude = 0.15) {
  Scene s = scene();
  const cv::Rect band(s.roof.br().x - 12, s.roof.y, 12, s.roof.height);
  const cv::Mat weak = (testing::texture(s.left.size(), 7, 0.7) - 128.0) * amplitude;
  for (int y = band.y; y < band.br().y; ++y) {
    for (int x = band.x; x < band.br().x; ++x) {
      // The roof point at left x is at right x − 20.
      s.left.at<float>(y, x) += weak.at<float>(y, x);
      s.right.at<float>(y, x - 20) += weak.at<float>(y, x);
    }
  }
  s.right(cv::Rect(s.roof.x - 20, s.roof.y, s.roof.width, s.roof.height)) -= 6.0f;
  s.disparity(band).setTo(kNaN);
  return s;
}

// stripedBandScene() with the band's first `columns` columns matched at the roof's disparity (a
// weakly textured roof's matched patch between the filled region and the band's unmatched rest).
Scene stripedBandWithMatchedColumns(int columns) {
  Scene s = stripedBandScene();
  s.disparity(cv::Rect(s.roof.br().x - 12, s.roof.y, columns, s.roof.height)).setTo(kRoof);
  return s;
}

// The scene `make()` builds, filled (range 0..32) with `settings` and, on a second copy, with
// `without`: the same settings with one rule turned off. Returns {with the rule, without it}.
template <class MakeScene>
std::pair<Scene, Scene> filledWithAndWithout(const MakeScene& make,
                                             const RegionFillSettings& settings,
                                             const RegionFillSettings& without) {
  std::pair<Scene, Scene> filled{make(), make()};
  fill(filled.first, settings, 32);
  fill(filled.second, without, 32);
  return filled;
}

// A rule's effect on `area`: without it, fewer than `withoutBelow` of the area's pixels hold the
// roof's disparity; with it, at least `withAtLeast`, and nothing spills onto the ground.
void expectTheRuleFills(const Scene& with, const Scene& without, const cv::Rect& area,
                        double withoutBelow, double withAtLeast) {
  const int filledWith = roofPixelsIn(with, area), filledWithout = roofPixelsIn(without, area);
  EXPECT_LT(filledWithout, withoutBelow * area.area()) << " of " << area.area();
  EXPECT_GE(filledWith, withAtLeast * area.area())
      << " of " << area.area() << ", without the rule " << filledWithout;
  EXPECT_EQ(spilledOntoTheGround(with), 0);
}

TEST(FillFlatRegions, GoesOnOverUnmatchedPixelsThatMatchAtItsDisparity) {
  RegionFillSettings noExtension;
  noExtension.extendReach = 0;
  const auto [extended, plain] =
      filledWithAndWithout([] { return stripedBandScene(); }, {}, noExtension);
  // The band's pixels left unmatched up to the outline (rows away from the top and bottom).
  const cv::Rect band(extended.roof.br().x - 12, extended.roof.y + 3, 12, extended.roof.height - 6);
  // Without the extension, the region's growth takes at most its first 3 columns. With it, most
  // of the band (not the last column, whose window meets the ground beyond the outline, nor the
  // pixels whose window the texture leaves ambiguous).
  expectTheRuleFills(extended, plain, band, 0.2, 0.6);
}

TEST(FillFlatRegions, AWiderWindowDecidesWhereTheSmallOneIsNotClearlyBest) {
  // The band's texture a little weaker (0.12 of the ground's): more of its 3x3 windows match
  // about as well 2 px or more along the row, at the noise's level; their 5x5 windows tell.
  RegionFillSettings smallOnly;
  smallOnly.extendWideWindow = 0;
  const auto [wide, small] =
      filledWithAndWithout([] { return stripedBandScene(0.12); }, {}, smallOnly);
  const cv::Rect band(wide.roof.br().x - 12, wide.roof.y + 3, 12, wide.roof.height - 6);
  // (Measured: 279 and 304 of 408.)
  expectTheRuleFills(wide, small, band, 0.70, 0.73);
}

TEST(FillFlatRegions, GoesOnOverMatchesThatAgreeWithIt) {
  // The band's first 5 columns matched at the roof's disparity (a weakly textured roof's matched
  // patch): between the filled region and the unmatched rest of the band.
  // The band's value is the constant of the matches around it, as the rule was measured with:
  // read from the band's edges (edgeMinSamples), the extension reaches 155 of the rest's 238
  // pixels even without passing over the matches.
  RegionFillSettings passing;
  passing.edgeMinSamples = 0;
  RegionFillSettings noPassing = passing;
  noPassing.extendAgree = -1;
  // (With the wider windows, the extension reaches 159 of the rest's pixels without passing over
  // the matches.)
  noPassing.extendWideWindow = 0;
  const auto [passed, stopped] =
      filledWithAndWithout([] { return stripedBandWithMatchedColumns(5); }, passing, noPassing);
  const cv::Rect rest(passed.roof.br().x - 7, passed.roof.y + 3, 7, passed.roof.height - 6);
  expectTheRuleFills(passed, stopped, rest, 1.0 / 3, 0.6);
}

TEST(FillFlatRegions, CountsItsReachFromTheMatchesOnItsSurfaceToo) {
  // The band's first 7 columns matched at the roof's disparity, the extension's reach 4 px: the
  // unmatched rest of the band lies farther than that from the filled pixels, not from the
  // matches on the roof.
  RegionFillSettings restarted;
  restarted.extendReach = 4;
  RegionFillSettings fromTheFillOnly = restarted;
  fromTheFillOnly.extendRestartAgree = -1;
  const auto [reached, stopped] = filledWithAndWithout(
      [] { return stripedBandWithMatchedColumns(7); }, restarted, fromTheFillOnly);
  const cv::Rect rest(reached.roof.br().x - 5, reached.roof.y + 3, 5, reached.roof.height - 6);
  expectTheRuleFills(reached, stopped, rest, 0.2, 0.5);
}

TEST(FillFlatRegions, ReachedThroughItsMatchesStopsWhereTheSurfaceLeavesIt) {
  // As above, with every other row of the band's unmatched rest matched 0.8 px off the roof's
  // disparity (still passed over: the surface there leaves the fill's constant, as a gently
  // sloped facet does): the second walk adds no pixel beside those matches.
  const auto withOffMatches = [] {
    Scene s = stripedBandWithMatchedColumns(7);
    for (int y = s.roof.y + 3; y < s.roof.br().y - 3; y += 2) {
      s.disparity(cv::Rect(s.roof.br().x - 5, y, 5, 1)).setTo(kRoof + 0.8f);
    }
    return s;
  };
  const auto filledAtTheRoof = [](const Scene& s) {
    int n = 0;
    for (int y = s.roof.y + 4; y < s.roof.br().y - 3; y += 2) {
      for (int x = s.roof.br().x - 5; x < s.roof.br().x; ++x) {
        n += std::abs(s.disparity.at<float>(y, x) - kRoof) < 0.01f ? 1 : 0;
      }
    }
    return n;
  };
  RegionFillSettings restarted;
  restarted.extendReach = 4;
  RegionFillSettings firstOnly = restarted;
  firstOnly.extendRestartAgree = -1;
  const auto [second, first] = filledWithAndWithout(withOffMatches, restarted, firstOnly);
  EXPECT_EQ(filledAtTheRoof(second), filledAtTheRoof(first));
}

TEST(FillFlatRegions, AWiderWindowCrossesASeamAlongTheRoof) {
  // The roof's lower 18 rows carry weak random texture (left unmatched), cut off from its plain
  // upper part by a dark seam of 2 rows across the roof, in both views: a 3x3 window on the seam
  // matches at every disparity along it; a 5x5 one reaches the texture beside it.
  const auto withSeam = [] {
    Scene s = scene();
    const cv::Rect band(s.roof.x, s.roof.y + 22, s.roof.width, s.roof.height - 22);
    const cv::Mat weak = (testing::texture(s.left.size(), 7, 0.7) - 128.0) * 0.15;
    for (int y = band.y; y < band.br().y; ++y) {
      for (int x = band.x; x < band.br().x; ++x) {
        s.left.at<float>(y, x) += weak.at<float>(y, x);
        s.right.at<float>(y, x - 20) += weak.at<float>(y, x);
      }
    }
    const cv::Rect seam(s.roof.x, s.roof.y + 20, s.roof.width, 2);
    s.left(seam) -= 40.0f;
    s.right(seam - cv::Point(20, 0)) -= 40.0f;
    s.disparity(band).setTo(kNaN);
    return s;
  };
  // The extension reaches 12 px: the seam's ends, where it gives evidence along the row, are
  // 15 px or more from the pixels counted.
  RegionFillSettings wide;
  wide.extendReach = 12;
  RegionFillSettings smallOnly = wide;
  smallOnly.extendWideWindow = 0;
  const auto [crossed, stopped] = filledWithAndWithout(withSeam, wide, smallOnly);
  // The textured rows just below the seam, away from the roof's sides.
  const cv::Rect below(crossed.roof.x + 15, crossed.roof.y + 23, crossed.roof.width - 30, 6);
  expectTheRuleFills(crossed, stopped, below, 0.25, 0.6);
}

TEST(FillFlatRegions, ReplacesMatchesOfTheFarSurfaceWhereItsWindowIsClearlyBest) {
  // Columns 4-6 of the band matched at the ground's disparity (windows that met the ground beyond
  // the outline, or another surface of the right view as plain as the roof), beyond the reach of
  // the region's growth: they stand between the filled pixels and the band's unmatched rest.
  const auto withGroundColumns = [] {
    Scene s = stripedBandScene();
    s.disparity(cv::Rect(s.roof.br().x - 8, s.roof.y, 3, s.roof.height)).setTo(kGround);
    return s;
  };
  RegionFillSettings noReplacing;
  noReplacing.extendReplaceOff = 0;
  const auto [replaced, stopped] = filledWithAndWithout(withGroundColumns, {}, noReplacing);
  // The ground-valued columns and the rest beyond them.
  const cv::Rect beyond(replaced.roof.br().x - 8, replaced.roof.y + 3, 8, replaced.roof.height - 6);
  // (Measured: 2 and 186 of 272.) The ground beside the roof, matched at its own disparity, keeps
  // it.
  expectTheRuleFills(replaced, stopped, beyond, 0.2, 0.6);
}

TEST(FillFlatRegions, RefocusesTheMedianOnTheBulkOfTheOutlinesMatches) {
  // The top strip's 92 matches at the roof's disparity; the bottom strip's first row 0.6 px too
  // far and its second 1.7 px (a tail of windows along an outline that runs with the rows). All
  // lie within 1.5 px of the cluster's mean and the median falls on 20.6; within 1 px of it, the
  // median of the matches is the roof's. (The ring error's arbitration then moves it by the
  // grid's 0.025 px: measured 20.025 and, without the refocus, the mean 20.575.)
  const auto skewed = [] {
    Scene s = scene();
    s.disparity(cv::Rect(s.roof.x + 2, s.roof.br().y - 2, s.roof.width - 4, 1)).setTo(kRoof + 0.6f);
    s.disparity(cv::Rect(s.roof.x + 2, s.roof.br().y - 1, s.roof.width - 4, 1)).setTo(kRoof + 1.7f);
    return s;
  };
  RegionFillSettings plainMedian;
  plainMedian.refocusReach = 0;
  plainMedian.edgeMinSamples = 0;  // the roof's edges would give its 20 whatever the matches
  const auto [refocused, median] = filledWithAndWithout(skewed, {}, plainMedian);
  const cv::Rect inner = innerRoof(refocused);
  EXPECT_EQ(pixelsAt(refocused.disparity, inner, kRoof, 0.05), inner.area());
  EXPECT_EQ(pixelsAt(median.disparity, inner, kRoof + 0.6f, 0.05), inner.area());
}

// The roof's first and last two columns, away from its top and bottom 3 rows, matched at
// `value` (windows across its sides).
void matchTheSideColumnsAt(Scene& s, double value) {
  const int sideRows = s.roof.height - 6;
  s.disparity(cv::Rect(s.roof.x, s.roof.y + 3, 2, sideRows)).setTo(value);
  s.disparity(cv::Rect(s.roof.br().x - 2, s.roof.y + 3, 2, sideRows)).setTo(value);
}

TEST(FillFlatRegions, TheRingErrorArbitratesBetweenTheMatchesMedianAndTheirMean) {
  // The matches beside the roof on its rows (136, its side columns) all 0.8 px too far, as
  // beside a rooftop box; the strips along its top and bottom (184) 0.4 px short. The refocused
  // median of the matches beside is 20.8, the cluster's mean about 20.1, and the outline lines
  // up best at the roof's 20: the median of the three is the mean.
  const auto biased = [] {
    Scene s = scene();
    s.disparity(cv::Rect(s.roof.x + 2, s.roof.y, s.roof.width - 4, 2)).setTo(kRoof - 0.4f);
    s.disparity(cv::Rect(s.roof.x + 2, s.roof.br().y - 2, s.roof.width - 4, 2)).setTo(kRoof - 0.4f);
    matchTheSideColumnsAt(s, kRoof + 0.8f);
    return s;
  };
  RegionFillSettings medianOnly;
  medianOnly.ringArbiterReach = 0;
  medianOnly.edgeMinSamples = 0;  // the median alone: no edges either
  const auto [arbitrated, median] = filledWithAndWithout(biased, {}, medianOnly);
  const cv::Rect inner = innerRoof(arbitrated);
  // (Measured: every inner pixel at 20.110; 20.800 with the median alone.)
  EXPECT_EQ(pixelsAt(arbitrated.disparity, inner, kRoof, 0.2), inner.area());
  EXPECT_EQ(pixelsAt(median.disparity, inner, kRoof + 0.8f, 0.05), inner.area());
}

// The flat roof at a sub-pixel disparity, each pixel of both views the roof's grey and the
// ground's blended by the share of it the roof covers (as a camera integrates it): the roof
// spans [59.5, 109.5) in the left view (pixel x covers [x - 0.5, x + 0.5)) and
// [59.5 - d, 109.5 - d) in the right view. Ground at 4 px, noise sigma 2.
Scene subpixelRoofScene(double d) {
  Scene s = scene();
  const cv::Mat ground = testing::texture(cv::Size(s.left.cols + 64, s.left.rows), 31) * 0.6 + 20.0;
  cv::RNG rng(7);
  const double x0 = s.roof.x - 0.5, x1 = s.roof.br().x - 0.5;
  for (int y = 0; y < s.left.rows; ++y) {
    const bool roofRow = y >= s.roof.y && y < s.roof.br().y;
    for (int x = 0; x < s.left.cols; ++x) {
      const double inLeft = roofRow ? coveredShare(x, x0, x1) : 0.0;
      const double inRight = roofRow ? coveredShare(x, x0 - d, x1 - d) : 0.0;
      s.left.at<float>(y, x) = static_cast<float>(
          inLeft * 200.0 + (1 - inLeft) * ground.at<float>(y, x + 32) + rng.gaussian(2.0));
      s.right.at<float>(y, x) = static_cast<float>(
          inRight * 200.0 + (1 - inRight) * ground.at<float>(y, x + 4 + 32) + rng.gaussian(2.0));
    }
  }
  return s;
}

TEST(FillFlatRegions, APlainRoofsEdgesInBothViewsSetItsSubpixelValueOverBiasedMatches) {
  // The roof at 20.4; every match around it 0.7 px too far (21.1), as a ground of the roof's
  // grey beside its outline draws the windows across it. The three estimates of the matches
  // and the ring follow them; the roof's edges in the two views do not.
  constexpr double kTrue = 20.4;
  const auto biased = [] {
    Scene s = subpixelRoofScene(kTrue);
    cv::Mat matched = s.disparity == s.disparity;
    cv::Mat onRoof = cv::Mat::zeros(s.disparity.size(), CV_8U);
    onRoof(s.roof).setTo(255);
    s.disparity.setTo(kTrue + 0.7, matched & onRoof);
    matchTheSideColumnsAt(s, kTrue + 0.7);
    return s;
  };
  RegionFillSettings noEdges;
  noEdges.edgeMinSamples = 0;
  const auto [edges, matches] = filledWithAndWithout(biased, {}, noEdges);
  const cv::Rect inner = innerRoof(edges);
  EXPECT_EQ(pixelsAt(edges.disparity, inner, static_cast<float>(kTrue), 0.15), inner.area());
  EXPECT_EQ(pixelsAt(matches.disparity, inner, static_cast<float>(kTrue), 0.4), 0);
}

TEST(FillFlatRegions, APlainRoofWithNoMatchesAroundTakesTheConstantOfItsEdgesNotAPlane) {
  // The roof at 20.4 and nothing matched within 3 px of it: no constant can pass, and the
  // plane through its row ends (whole pixels, 20 or 21) has a slope of noise.
  constexpr double kTrue = 20.4;
  const auto unmatched = [] {
    Scene s = subpixelRoofScene(kTrue);
    const cv::Rect around(s.roof.x - 4, s.roof.y - 4, s.roof.width + 8, s.roof.height + 8);
    s.disparity(around).setTo(kNaN);
    return s;
  };
  RegionFillSettings keepsThePlane;
  keepsThePlane.planeMinSpan = 0;
  keepsThePlane.planeEdgeEnds = false;  // (through the ends' sub-pixel edges: a 0.10 px span)
  const auto [flat, plane] = filledWithAndWithout(unmatched, {}, keepsThePlane);
  const cv::Rect inner = innerRoof(flat);
  const auto spread = [&](const cv::Mat& d) {
    double lo = 1e9, hi = -1e9;
    for (int y = inner.y; y < inner.br().y; ++y) {
      for (int x = inner.x; x < inner.br().x; ++x) {
        lo = std::min(lo, static_cast<double>(d.at<float>(y, x)));
        hi = std::max(hi, static_cast<double>(d.at<float>(y, x)));
      }
    }
    return std::pair{lo, hi};
  };
  const auto [flatLo, flatHi] = spread(flat.disparity);
  const auto [planeLo, planeHi] = spread(plane.disparity);
  // (Measured: every inner pixel at 20.411; the plane 20.10 .. 20.90, 420 of 1 200 within
  // 0.15 px.)
  EXPECT_EQ(pixelsAt(flat.disparity, inner, static_cast<float>(kTrue), 0.15), inner.area());
  EXPECT_LT(flatHi - flatLo, 1e-3);
  EXPECT_GT(planeHi - planeLo, 0.5);
}

TEST(FillFlatRegions, TakesItsValueFromTheMatchesBesideTheRoofNotAboveOrBelowIt) {
  // The strips along the roof's top and bottom (windows across an outline that runs with the
  // rows) matched 1.2 px too far, 184 matches; the roof's first and last two columns (windows
  // across its sides) at its disparity, 136. The flat region's rows reach the side columns,
  // not the strips. Among all the matches around the region the strips' value is the median.
  Scene s = scene();
  s.disparity(cv::Rect(s.roof.x + 2, s.roof.y, s.roof.width - 4, 2)).setTo(kRoof + 1.2f);
  s.disparity(cv::Rect(s.roof.x + 2, s.roof.br().y - 2, s.roof.width - 4, 2)).setTo(kRoof + 1.2f);
  matchTheSideColumnsAt(s, kRoof);
  fill(s, RegionFillSettings{}, 32);
  const cv::Rect inner = innerRoof(s);
  // (Measured: all 1 200 inner pixels within 0.01 px; 0 with all the matches around.)
  EXPECT_EQ(pixelsAt(s.disparity, inner, kRoof, 0.01), inner.area());
}

// The band of 3 rows inside the flat roof, 4 px below its top, columns 4 .. 15: the 5x5 windows'
// counterparts in the right view at the roof's disparity (20) and at the ground's (4) both fall
// on the roof, and apart.
cv::Rect bandInsideTheRoof(const Scene& s) {
  return {s.roof.x + 4, s.roof.y + 4, 12, 3};
}

// scene() with that band matched at `value`: windows that reached another surface's texture
// across a gap of the outline.
Scene sceneWithABandInsideTheRoof(float value) {
  Scene s = scene();
  s.disparity(bandInsideTheRoof(s)).setTo(value);
  return s;
}

TEST(FillFlatRegions, ItsOwnMatchesFarOffTheFillTakeItWhereItExplainsThemAsWell) {
  RegionFillSettings keepingThem;
  keepingThem.inRegionReplaceOff = 0;
  const auto [replaced, kept] =
      filledWithAndWithout([] { return sceneWithABandInsideTheRoof(kGround); }, {}, keepingThem);
  const cv::Rect band = bandInsideTheRoof(replaced);
  // Plain roof in the right view at both disparities: the fill explains them as well, up to the
  // noise of a 5x5 window's mean error (measured: 36 of 36 replaced, 0 without the rule).
  expectTheRuleFills(replaced, kept, band, 0.01, 0.8);
}

TEST(FillFlatRegions, ItsOwnMatchesStayWhereTheirDisparityExplainsThemClearlyBetter) {
  // The band's counterparts at the fill's disparity 30 grey levels brighter in the right view
  // (the roof seen differently there): its own disparity explains it clearly better.
  Scene s = sceneWithABandInsideTheRoof(kGround);
  const cv::Rect band = bandInsideTheRoof(s);
  s.right(band - cv::Point(static_cast<int>(kRoof), 0)) += 30.0f;
  fill(s, RegionFillSettings{}, 32);
  EXPECT_EQ(pixelsWithin(
                s.disparity, band, [](int, int) { return kGround; }, 0.01),
            band.area());
}

TEST(FillFlatRegions, ItsOwnMatchesAFewPixelsOffTheFillTakeItWhereItExplainsThemAsWell) {
  // 3.5 px above the fill: a raised box's disparity carried onto the plain roof around it by
  // windows that reached the box's edges (seed 5 600²). Kept with an offset of 8 px.
  RegionFillSettings farOnly;
  farOnly.inRegionReplaceOff = 8.0;
  const auto [replaced, kept] =
      filledWithAndWithout([] { return sceneWithABandInsideTheRoof(kRoof + 3.5f); }, {}, farOnly);
  // (Measured: 26 of 36 replaced, 0 with the 8 px offset; the others' windows are explained a
  // little better at their own disparity by the noise.)
  expectTheRuleFills(replaced, kept, bandInsideTheRoof(replaced), 0.01, 0.6);
}

// The scene's roof (grey 140) with its matched top and bottom strips 3 px short of it: their
// cluster is the best candidate, and the ground's lines the outline up worse still, but the
// outline lines up clearly better at the roof's own disparity.
Scene sceneWithItsStripsThreePixelsShort() {
  Scene s = scene(140.0f);
  const float shortOfIt = kRoof - 3.0f;
  s.disparity(cv::Rect(s.roof.x + 2, s.roof.y, s.roof.width - 4, 2)).setTo(shortOfIt);
  s.disparity(cv::Rect(s.roof.x + 2, s.roof.br().y - 2, s.roof.width - 4, 2)).setTo(shortOfIt);
  return s;
}

TEST(FillFlatRegions, ACandidateTheOutlineLinesUpClearlyBetterElsewhereIsNotFilled) {
  RegionFillSettings noVeto;
  noVeto.scanVeto = 0;
  const auto [vetoed, unvetoed] =
      filledWithAndWithout(sceneWithItsStripsThreePixelsShort, {}, noVeto);
  const auto shortOfTheRoof = [&](const Scene& s) {
    return pixelsWithin(
        s.disparity, s.roof, [](int, int) { return kRoof - 3.0f; }, 0.5);
  };
  // (Measured: without the veto 1 920 of the 2 000 roof pixels 3 px short, none right; with it,
  // the constant is not filled and the plane through the row ends of the roof and of its
  // counterpart fills 1 901 at the roof's disparity, 91 of the strips' pixels keep theirs.)
  EXPECT_GE(shortOfTheRoof(unvetoed), 1800);
  EXPECT_EQ(roofPixelsWithTheRoofsDisparity(unvetoed), 0);
  EXPECT_LE(shortOfTheRoof(vetoed), 184);  // at most the strips
  EXPECT_GE(roofPixelsWithTheRoofsDisparity(vetoed), 1800);
}

TEST(FillFlatRegions, WhereNoConstantIsFilledAPlaneMustLineTheOutlineUpAboutAsWell) {
  // The roof's plane (through its row ends and its counterpart's, at the roof's disparity) lines
  // the outline up at 0.2-0.3 × the error of the strips' candidate: kept at the default ratio,
  // not when the plane must do five times better than the candidate. (On the 2000² scene a
  // plain roof strip between two seams took the plane of the next strip over in the right view,
  // 16 px off, whose outline error was 1.2 × the best candidate's.)
  RegionFillSettings demanding;
  demanding.planeCandidateRatio = 0.2;
  const auto [kept, refused] =
      filledWithAndWithout(sceneWithItsStripsThreePixelsShort, {}, demanding);
  EXPECT_GE(roofPixelsWithTheRoofsDisparity(kept), 1800);
  EXPECT_EQ(roofPixelsWithTheRoofsDisparity(refused), 0);
}

TEST(FillFlatRegions, ItsOwnMatchesCloseToTheFillStay) {
  // 2 px off the fill (a plain slanted surface's matches, right where a constant fill is not).
  Scene s = sceneWithABandInsideTheRoof(kRoof - 2.0f);
  fill(s, RegionFillSettings{}, 32);
  const cv::Rect band = bandInsideTheRoof(s);
  EXPECT_EQ(pixelsWithin(
                s.disparity, band, [](int, int) { return kRoof - 2.0f; }, 0.01),
            band.area());
}
}  // namespace
}  // namespace delineo::stereo::detail

namespace delineo::stereo::detail {
namespace {

bool shareACell(const ExtensionFootprints& f, size_t a, size_t b) {
  for (const int x : f.cells[a]) {
    for (const int y : f.cells[b]) {
      if (x == y) return true;
    }
  }
  return false;
}

// Two roofs on the same rows, 300 px apart in the image (their extensions' pixels far apart), with
// their candidates mapping to the same right-view columns (x − d about 200 for both): one's writes
// change what the other's test reads, so they must share a cell; a third whose candidates map far
// from both shares none with them; a fourth whose pixels hold a match mapping among the first's
// candidates (a value it may replace) shares one with the first.
TEST(ExtensionFootprints, ExtensionsShareACellWhereTheirRightViewPositionsMeet) {
  RegionFillSettings settings;  // extendReach 40, extendReplaceOff 4
  cv::Mat disparity(400, 1000, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  const std::vector<cv::Rect> boxes{{290, 100, 20, 20},   // d = 100: x − d in 150 .. 250
                                    {590, 100, 20, 20},   // d = 400: x − d in 150 .. 250
                                    {850, 100, 20, 20},   // d = 10: x − d in 800 .. 900
                                    {850, 300, 20, 20}};  // rows apart, but see below
  const std::vector<FillPlane> planes{{100, 0, 0}, {400, 0, 0}, {10, 0, 0}, {10, 0, 0}};
  // A match inside the fourth's box ± reach mapping to x − d = 200, on other rows than the first:
  // the fourth may replace it; nothing else ties them (rows apart).
  disparity.at<float>(300, 860) = 660.0F;
  const ExtensionFootprints f = extensionFootprints(boxes, planes, settings, 0, 700, disparity);
  ASSERT_EQ(f.cells.size(), 4U);
  EXPECT_TRUE(shareACell(f, 0, 1));
  EXPECT_FALSE(shareACell(f, 0, 2));
  EXPECT_FALSE(shareACell(f, 1, 2));
  // The fourth reads and writes right-view columns 800 .. 900 on rows 260 .. 360 and may replace
  // the match mapping to 200 there; the first reads 150 .. 250 on rows 60 .. 160: other rows.
  EXPECT_FALSE(shareACell(f, 0, 3));
  for (const auto& cells : f.cells) {
    for (const int c : cells) {
      EXPECT_GE(c, 0);
      EXPECT_LT(c, f.cellCount);
    }
  }
  // On the first's rows, the same match ties the fourth to the first.
  cv::Mat besideTheFirst = disparity.clone();
  besideTheFirst.at<float>(300, 860) = std::numeric_limits<float>::quiet_NaN();
  besideTheFirst.at<float>(110, 860) = 660.0F;
  std::vector<cv::Rect> sameRows = boxes;
  sameRows[3] = {850, 90, 20, 20};
  const ExtensionFootprints g =
      extensionFootprints(sameRows, planes, settings, 0, 700, besideTheFirst);
  EXPECT_TRUE(shareACell(g, 0, 3));
  EXPECT_TRUE(shareACell(g, 2, 3));  // the same image tiles
}

}  // namespace
}  // namespace delineo::stereo::detail
