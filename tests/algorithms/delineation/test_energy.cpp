#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <opencv2/core.hpp>

#include "delineo/delineation/energy.hpp"

using namespace delineo::delineation;

namespace {

constexpr double kPi = 3.14159265358979323846;

EnergyImages flatImages(cv::Size size, float roof, float ground, float noMatch) {
  EnergyImages im;
  im.roofCost = cv::Mat(size, CV_32F, cv::Scalar(roof));
  im.groundCost = cv::Mat(size, CV_32F, cv::Scalar(ground));
  im.noMatchCost = noMatch;
  return im;
}

IntPolygon rect(int x, int y, int w, int h) {
  IntPolygon p;
  p.outer = {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}};
  return p;
}

}  // namespace

TEST(AnglePrior, PaperValues) {
  EXPECT_NEAR(anglePrior(0.0), 2.0, 1e-12);
  EXPECT_NEAR(anglePrior(kPi / 4), 1.0, 1e-9);
  EXPECT_NEAR(anglePrior(kPi / 2), 0.0, 1e-12);
  EXPECT_NEAR(anglePrior(kPi), 0.0, 1e-12);
  EXPECT_NEAR(anglePrior(3 * kPi / 2), 0.0, 1e-12);
  EXPECT_NEAR(anglePrior(3 * kPi / 4), 1.0, 1e-9);
  // Concave around its minima: 170° costs more than half of what 135° costs.
  EXPECT_GT(anglePrior(170 * kPi / 180), 0.3);
}

TEST(AnglePrior, VertexAngles) {
  EXPECT_NEAR(vertexAngle({0, 10}, {0, 0}, {10, 0}), kPi / 2, 1e-12);
  EXPECT_NEAR(vertexAngle({-10, 0}, {0, 0}, {10, 0}), kPi, 1e-12);
  EXPECT_NEAR(vertexAngle({10, 10}, {0, 0}, {10, 0}), kPi / 4, 1e-12);
}

TEST(Energy, RoofAndGroundTerms) {
  const auto im = flatImages({30, 20}, 1.0f, 0.5f, 0.8f);
  const auto p = rect(2, 3, 10, 5);
  PolygonEnergy e(im, {5.0, 15.0});
  e.setPolygon(p);
  const auto t = e.terms();
  EXPECT_NEAR(t.term[0], 50.0, 1e-9);
  EXPECT_NEAR(t.term[1], 0.5 * (600 - 50), 1e-9);
  EXPECT_NEAR(t.term[2], 0.0, 1e-12);
  EXPECT_NEAR(t.term[5], 0.0, 1e-9);  // four right angles
}

TEST(Energy, OcclusionBandFollowsTheSide) {
  auto im = flatImages({30, 20}, 1.0f, 0.5f, 0.8f);
  im.occlusionWidth = cv::Mat(im.roofCost.size(), CV_32S, cv::Scalar(3));
  const auto p = rect(2, 3, 10, 5);
  PolygonEnergy e(im, {5.0, 15.0});
  // Left side: band [max(2-3, 0), 2) = 2 px per row (clipped by the ROI border).
  im.occlusionSide = -1;
  e = PolygonEnergy(im, {5.0, 15.0});
  e.setPolygon(p);
  EXPECT_NEAR(e.terms().term[2], 0.8 * 2 * 5, 1e-5);
  EXPECT_NEAR(e.terms().term[1], 0.5 * (600 - 50 - 10), 1e-9);
  // Right side: band [12, 15) = 3 px per row.
  im.occlusionSide = +1;
  e = PolygonEnergy(im, {5.0, 15.0});
  e.setPolygon(p);
  EXPECT_NEAR(e.terms().term[2], 0.8 * 3 * 5, 1e-5);
  EXPECT_NEAR(e.terms().term[1], 0.5 * (600 - 50 - 15), 1e-9);
  EXPECT_NEAR(referenceEnergy(im, {5.0, 15.0}, p).term[2], 0.8 * 15, 1e-5);
}

TEST(Energy, BandStopsAtThePreviousRoofRun) {
  // U shape open at the top: rows 2..5 hold two roof runs [2,6) and [9,13); a left band of
  // width 5 next to the right run covers only the 3 ground pixels [6, 9) of the gap.
  auto im = flatImages({20, 10}, 1.0f, 0.0f, 1.0f);
  im.occlusionWidth = cv::Mat(im.roofCost.size(), CV_32S, cv::Scalar(5));
  IntPolygon u;
  u.outer = {{2, 2}, {6, 2}, {6, 6}, {9, 6}, {9, 2}, {13, 2}, {13, 8}, {2, 8}};
  PolygonEnergy e(im, {0.0, 0.0});
  e.setPolygon(u);
  // rows 2..5: band 2 (left of x=2) + 3 (gap); rows 6..7: band 2.
  EXPECT_NEAR(e.terms().term[2], 4 * (2 + 3) + 2 * 2, 1e-9);
  EXPECT_NEAR(referenceEnergy(im, {0.0, 0.0}, u).term[2], e.terms().term[2], 1e-9);
}

TEST(Energy, EdgeTermsUseTheNormalComponent) {
  auto im = flatImages({30, 20}, 0.0f, 0.0f, 0.0f);
  im.leftGradX = cv::Mat(im.roofCost.size(), CV_32F, cv::Scalar(1.0f));
  im.leftGradY = cv::Mat(im.roofCost.size(), CV_32F, cv::Scalar(0.0f));
  im.rightGradX = cv::Mat(im.roofCost.size(), CV_32F, cv::Scalar(0.0f));
  im.rightGradY = cv::Mat(im.roofCost.size(), CV_32F, cv::Scalar(0.5f));
  EnergyWeights plain{5.0, 15.0};
  plain.edgeContrast = 0;  // the paper's terms, without the roof/ground gate
  PolygonEnergy e(im, plain);
  e.setPolygon(rect(2, 3, 10, 5));
  // Left: only the two vertical edges (normal ±x) count, 5 px each.
  EXPECT_NEAR(e.terms().term[3], -5.0 * kEdgeUnit * 10, 1e-9);
  // Right: only the horizontal edges, 10 px each at 0.5.
  EXPECT_NEAR(e.terms().term[4], -5.0 * kEdgeUnit * 0.5 * 20, 1e-9);
}

TEST(Energy, ShapePriorOnATriangle) {
  const auto im = flatImages({30, 30}, 0.0f, 0.0f, 0.0f);
  IntPolygon tri;
  tri.outer = {{0, 0}, {10, 0}, {0, 10}};  // 90°, 45°, 45°
  PolygonEnergy e(im, {5.0, 15.0});
  e.setPolygon(tri);
  EXPECT_NEAR(e.terms().term[5], 15.0 * 2, 1e-9);
}

namespace {

EnergyImages randomImages(std::mt19937& rng, cv::Size size, int side) {
  EnergyImages im;
  im.roofCost.create(size, CV_32F);
  im.groundCost.create(size, CV_32F);
  cv::randu(im.roofCost, 0.0, 1.0);
  cv::randu(im.groundCost, 0.0, 1.0);
  im.noMatchCost = 0.7f;
  im.occlusionWidth.create(size, CV_32S);
  cv::randu(im.occlusionWidth, 0, 6);
  im.occlusionSide = side;
  for (cv::Mat* g : {&im.leftGradX, &im.leftGradY, &im.rightGradX, &im.rightGradY}) {
    g->create(size, CV_32F);
    cv::randu(*g, -1.5, 1.5);
  }
  (void)rng;
  return im;
}

// A star-shaped polygon around the centre: simple by construction.
IntPolygon randomStar(std::mt19937& rng, cv::Size size, int n) {
  std::uniform_real_distribution<double> radius(6.0, std::min(size.width, size.height) / 2.0 - 2);
  IntPolygon p;
  const cv::Point2d c(size.width / 2.0, size.height / 2.0);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * i / n;
    const double r = radius(rng);
    const cv::Point v(static_cast<int>(std::lround(c.x + r * std::cos(a))),
                      static_cast<int>(std::lround(c.y + r * std::sin(a))));
    if (p.outer.empty() || p.outer.back() != v) p.outer.push_back(v);
  }
  return p;
}

void expectTermsNear(const EnergyTerms& a, const EnergyTerms& b) {
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(a.term[k], b.term[k], 1e-6) << "term " << k + 1;
}

}  // namespace

TEST(Energy, IncrementalAgreesWithReference) {
  std::mt19937 rng(7);
  for (int side : {-1, 1}) {
    const cv::Size size(64, 48);
    const auto im = randomImages(rng, size, side);
    const EnergyWeights w{5.0, 15.0};
    for (int trial = 0; trial < 20; ++trial) {
      IntPolygon p = randomStar(rng, size, 12);
      if (!isValidPolygon(p)) continue;
      if (trial % 3 == 0) p.holes.push_back({{30, 22}, {30, 26}, {34, 26}, {34, 22}});
      if (!isValidPolygon(p)) p.holes.clear();
      PolygonEnergy e(im, w);
      e.setPolygon(p);
      expectTermsNear(e.terms(), referenceEnergy(im, w, p));
      // Deltas of local changes agree with the difference of reference energies.
      std::uniform_int_distribution<int> step(-3, 3);
      const double ref0 = referenceEnergy(im, w, p).total();
      for (int k = 0; k < 10; ++k) {
        const int i = static_cast<int>(rng() % p.outer.size());
        PolygonEnergy::Change c;
        c.first = i;
        if (k % 3 == 2) {
          c.removeCount = 1;  // deletion
        } else if (k % 3 == 1) {
          const cv::Point d(step(rng), step(rng));
          c.removeCount = 2;
          c.inserted = {p.outer[i] + d, p.outer[(i + 1) % p.outer.size()] + d};
        } else {
          c.inserted = {p.outer[i] + cv::Point(step(rng), step(rng))};
        }
        const double expected = referenceEnergy(im, w, e.changed(c)).total() - ref0;
        EXPECT_NEAR(e.delta(c), expected, 1e-6);
      }
    }
  }
}

TEST(Energy, ValidChangesNeverSelfIntersect) {
  std::mt19937 rng(11);
  const cv::Size size(60, 60);
  const auto im = randomImages(rng, size, -1);
  PolygonEnergy e(im, {5.0, 15.0});
  IntPolygon p = rect(10, 10, 40, 40);
  p.holes.push_back({{25, 25}, {25, 35}, {35, 35}, {35, 25}});
  // Densify so that vertices can fold over each other.
  IntPolygon dense;
  for (int i = 0; i <= 8; ++i) dense.outer.push_back({10 + 5 * i, 10});
  for (int i = 1; i <= 8; ++i) dense.outer.push_back({50, 10 + 5 * i});
  for (int i = 1; i <= 8; ++i) dense.outer.push_back({50 - 5 * i, 50});
  for (int i = 1; i < 8; ++i) dense.outer.push_back({10, 50 - 5 * i});
  dense.holes = p.holes;
  ASSERT_TRUE(isValidPolygon(dense));
  e.setPolygon(dense);
  std::uniform_int_distribution<int> step(-8, 8);
  int accepted = 0, rejected = 0;
  for (int k = 0; k < 3000; ++k) {
    PolygonEnergy::Change c;
    c.ring = (k % 5 == 0) ? 1 : 0;
    const auto& ring = e.polygon().ring(c.ring);
    c.first = static_cast<int>(rng() % ring.size());
    c.inserted = {ring[c.first] + cv::Point(step(rng), step(rng))};
    if (e.valid(c)) {
      e.apply(c);
      ++accepted;
      ASSERT_TRUE(isValidPolygon(e.polygon())) << "after change " << k;
    } else {
      ++rejected;
    }
  }
  EXPECT_GT(accepted, 100);
  EXPECT_GT(rejected, 100);
}

TEST(Energy, EdgeGateRewardsOnlyContoursWithRoofInside) {
  // Roof-like pixels (c_roof < c_ground) on x < 15, ground-like on x >= 15; a vertical
  // gradient line everywhere (|∇I·n| = 1 across vertical edges).
  auto im = flatImages({40, 20}, 0.4f, 0.1f, 0.0f);
  im.roofCost(cv::Rect(0, 0, 15, 20)).setTo(0.1f);
  im.groundCost(cv::Rect(0, 0, 15, 20)).setTo(0.4f);
  im.leftGradX = cv::Mat(im.roofCost.size(), CV_32F, cv::Scalar(1.0f));
  im.leftGradY = cv::Mat(im.roofCost.size(), CV_32F, cv::Scalar(0.0f));
  const EnergyWeights w{5.0, 0.0};
  PolygonEnergy e(im, w);
  e.setPolygon(rect(2, 3, 10, 5));  // on the roof: both vertical edges count fully
  EXPECT_NEAR(e.terms().term[3], -5.0 * kEdgeUnit * 10, 1e-9);
  e.setPolygon(rect(20, 3, 10, 5));  // on the ground: nothing
  EXPECT_NEAR(e.terms().term[3], 0.0, 1e-9);
  // The interior side does not depend on the ring's orientation, and a hole's interior side is
  // the polygon around it: a hole in the ground part earns nothing, whichever way it turns.
  IntPolygon withHole = rect(1, 1, 38, 18);
  withHole.holes.push_back({{22, 6}, {28, 6}, {28, 12}, {22, 12}});
  e.setPolygon(withHole);
  const double clockwise = e.terms().term[3];
  std::reverse(withHole.holes[0].begin(), withHole.holes[0].end());
  std::reverse(withHole.outer.begin(), withHole.outer.end());
  e.setPolygon(withHole);
  EXPECT_NEAR(e.terms().term[3], clockwise, 1e-9);
  EXPECT_NEAR(referenceEnergy(im, w, withHole).term[3], clockwise, 1e-9);
  // Only the outer ring's left edge (roof inside) counts: 18 px.
  EXPECT_NEAR(clockwise, -5.0 * kEdgeUnit * 18, 1e-9);
}

TEST(Energy, ShapeLimitsRejectSpikeTipsAndFingers) {
  const auto im = flatImages({40, 40}, 0.0f, 0.0f, 0.0f);
  EnergyWeights limited{5.0, 15.0};
  EnergyWeights unlimited = limited;
  unlimited.minAngle = 0;
  unlimited.minGap = 0;
  IntPolygon p;
  p.outer = {{5, 10}, {13, 10}, {14, 10}, {15, 10}, {16, 10}, {25, 10}, {25, 20}, {5, 20}};
  PolygonEnergy a(im, limited), b(im, unlimited);
  a.setPolygon(p);
  b.setPolygon(p);
  // Spike: vertex (14, 10) pulled up to (14, 2): its angle is 2·atan(1/8) = 14°.
  const PolygonEnergy::Change spike{0, 2, 1, {{14, 2}}};
  EXPECT_FALSE(a.valid(spike));
  EXPECT_TRUE(b.valid(spike));
  // A blunter spike (vertex (15, 10) to (15, 6): 2·atan(2/4) = 53°) is allowed.
  EXPECT_TRUE(a.valid({0, 3, 1, {{15, 6}}}));
  // Finger: (14, 10) and (15, 10) moved together to (14, 2), (15, 2): its sides are 1 px apart.
  const PolygonEnergy::Change finger{0, 2, 2, {{14, 2}, {15, 2}}};
  EXPECT_FALSE(a.valid(finger));
  EXPECT_TRUE(b.valid(finger));
  // Parallel neighbours 1 px apart (a staircase) are not a finger.
  IntPolygon stairs;
  stairs.outer = {{5, 10}, {15, 10}, {15, 11}, {25, 11}, {25, 20}, {5, 20}};
  a.setPolygon(stairs);
  EXPECT_TRUE(a.valid({0, 4, 1, {{26, 20}}}));
}

TEST(Energy, VerticesStayInTheAllowedRegion) {
  auto im = flatImages({40, 40}, 0.0f, 0.0f, 0.0f);
  im.allowed = cv::Mat(im.roofCost.size(), CV_8U, cv::Scalar(0));
  im.allowed(cv::Rect(5, 5, 20, 20)).setTo(255);  // pixels 5..24: corners 5..25 allowed
  PolygonEnergy e(im, {5.0, 15.0});
  e.setPolygon(rect(10, 10, 10, 10));
  EXPECT_TRUE(e.valid({0, 0, 1, {{5, 5}}}));
  EXPECT_FALSE(e.valid({0, 0, 1, {{4, 5}}}));
  EXPECT_TRUE(e.valid({0, 2, 1, {{25, 25}}}));
  EXPECT_FALSE(e.valid({0, 2, 1, {{25, 26}}}));
}

