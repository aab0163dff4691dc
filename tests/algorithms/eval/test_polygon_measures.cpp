#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/eval/polygon_measures.hpp"

using delineo::core::Polygon;
using delineo::core::Ring;
namespace eval = delineo::eval;

namespace {

Ring box(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}
Polygon square(double x0, double y0, double side) { return {box(x0, y0, x0 + side, y0 + side), {}}; }

Polygon scaled(const Polygon& p, double s) {
  Polygon out = p;
  for (auto& v : out.outer) v *= s;
  for (auto& h : out.holes) {
    for (auto& v : h) v *= s;
  }
  return out;
}

// Reference intersection area by rasterising at `scale` samples per unit.
double rasterIntersection(const Polygon& a, const Polygon& b, double scale, cv::Size size) {
  const cv::Size big(static_cast<int>(size.width * scale), static_cast<int>(size.height * scale));
  const cv::Mat ma = delineo::core::rasterize(scaled(a, scale), big);
  const cv::Mat mb = delineo::core::rasterize(scaled(b, scale), big);
  return cv::countNonZero(ma & mb) / (scale * scale);
}

// Non-convex star-shaped polygon around `centre`, optionally with a square hole at the centre.
Polygon randomStar(std::mt19937& rng, cv::Point2d centre, bool withHole) {
  std::uniform_real_distribution<double> radius(6.0, 14.0);
  const int n = 7 + static_cast<int>(rng() % 6);
  Polygon p;
  for (int k = 0; k < n; ++k) {
    const double angle = 2 * M_PI * k / n;
    const double r = radius(rng);
    p.outer.push_back(centre + cv::Point2d(r * std::cos(angle), r * std::sin(angle)));
  }
  if (withHole) p.holes.push_back(box(centre.x - 2.5, centre.y - 2.5, centre.x + 2.5, centre.y + 2.5));
  return p;
}

}  // namespace

TEST(PolygonMeasures, SquaresOffsetByHalfHaveIouOneThird) {
  const Polygon a = square(0, 0, 10);
  const Polygon b = square(5, 0, 10);
  EXPECT_NEAR(eval::intersectionArea(a, b), 50.0, 1e-9);
  EXPECT_NEAR(eval::intersectionOverUnion(a, b), 1.0 / 3.0, 1e-12);
  // Diagonal offset: 5 x 5 overlap.
  EXPECT_NEAR(eval::intersectionOverUnion(a, square(5, 5, 10)), 25.0 / 175.0, 1e-12);
}

TEST(PolygonMeasures, IdenticalPolygonsScorePerfectly) {
  Polygon a = square(3, 4, 10);
  a.holes.push_back(box(5, 6, 7, 9));
  Polygon b = a;
  std::reverse(b.outer.begin(), b.outer.end());  // orientation and start vertex do not matter
  std::rotate(b.outer.begin(), b.outer.begin() + 1, b.outer.end());
  EXPECT_NEAR(eval::intersectionOverUnion(a, b), 1.0, 1e-12);
  EXPECT_NEAR(eval::shapeErrorP1(b, a), 0.0, 1e-9);
  EXPECT_NEAR(eval::polisDistance(a, b), 0.0, 1e-12);
  EXPECT_NEAR(eval::hausdorffDistance(a, b, 0.1), 0.0, 1e-12);
}

TEST(PolygonMeasures, DisjointTouchingAndNestedPolygons) {
  EXPECT_EQ(eval::intersectionArea(square(0, 0, 10), square(20, 0, 5)), 0.0);
  EXPECT_NEAR(eval::intersectionArea(square(0, 0, 10), square(10, 0, 10)), 0.0, 1e-9);  // share an edge
  EXPECT_NEAR(eval::intersectionArea(square(0, 0, 10), square(2, 3, 4)), 16.0, 1e-9);
  EXPECT_NEAR(eval::intersectionArea(square(2, 3, 4), square(0, 0, 10)), 16.0, 1e-9);
}

TEST(PolygonMeasures, HolesAreExcludedFromTheOverlap) {
  Polygon courtyard = square(0, 0, 10);
  courtyard.holes.push_back(box(2, 2, 8, 8));  // area 100 - 36 = 64
  EXPECT_NEAR(eval::intersectionArea(courtyard, square(0, 0, 10)), 64.0, 1e-9);
  EXPECT_NEAR(eval::intersectionOverUnion(courtyard, square(0, 0, 10)), 0.64, 1e-12);
  EXPECT_NEAR(eval::intersectionArea(courtyard, square(4, 4, 2)), 0.0, 1e-9);  // inside the hole
  // Left half: 50 minus the hole's part [2,5] x [2,8] = 18.
  EXPECT_NEAR(eval::intersectionArea(courtyard, Polygon{box(0, 0, 5, 10), {}}), 32.0, 1e-9);
  // Two courtyards with the same hole.
  EXPECT_NEAR(eval::intersectionOverUnion(courtyard, courtyard), 1.0, 1e-12);
}

TEST(PolygonMeasures, NonConvexOverlap) {
  const Polygon ell{{{0, 0}, {10, 0}, {10, 5}, {5, 5}, {5, 10}, {0, 10}}, {}};  // area 75
  EXPECT_NEAR(eval::intersectionArea(ell, square(5, 0, 10)), 25.0, 1e-9);
  EXPECT_NEAR(eval::intersectionArea(ell, square(3, 3, 4)), 16.0 - 4.0, 1e-9);
}

TEST(PolygonMeasures, ExactAreaAgreesWithFineRasterisation) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> offset(-8.0, 8.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Polygon a = randomStar(rng, {30, 30}, trial % 2 == 0);
    const Polygon b = randomStar(rng, {30 + offset(rng), 30 + offset(rng)}, trial % 3 == 0);
    const double exact = eval::intersectionArea(a, b);
    const double raster = rasterIntersection(a, b, 16.0, {60, 60});
    EXPECT_NEAR(exact, raster, 0.3) << "trial " << trial;
  }
}

TEST(PolygonMeasures, MapCoordinatesKeepFullPrecision) {
  // UTM-like coordinates: the shoelace products would lose digits without a local origin.
  const double x0 = 733900.25, y0 = 3725100.75;
  const auto areas = eval::overlapAreas(square(x0, y0, 10), square(x0 + 5, y0, 10));
  EXPECT_TRUE(areas.exact);
  EXPECT_NEAR(areas.intersection, 50.0, 1e-6);
  EXPECT_NEAR(eval::intersectionOverUnion(square(x0, y0, 10), square(x0 + 5, y0, 10)), 1.0 / 3.0,
              1e-9);
}

TEST(PolygonMeasures, SelfIntersectingOutlinesUseTheEvenOddRaster) {
  // Bow tie: two triangles of area 25 under the even-odd rule, both inside the square.
  const Polygon bowTie{{{0, 0}, {10, 10}, {10, 0}, {0, 10}}, {}};
  const auto areas = eval::overlapAreas(bowTie, square(0, 0, 10));
  EXPECT_FALSE(areas.exact);
  EXPECT_NEAR(areas.a, 50.0, 0.5);
  EXPECT_NEAR(areas.b, 100.0, 0.5);
  EXPECT_NEAR(areas.intersection, 50.0, 0.5);
  EXPECT_NEAR(eval::intersectionOverUnion(bowTie, square(0, 0, 10)), 0.5, 0.01);
  EXPECT_NEAR(eval::intersectionOverUnion(bowTie, bowTie), 1.0, 1e-12);
  EXPECT_NEAR(eval::shapeErrorP1(bowTie, square(0, 0, 10)), 50.0, 1.0);
}

TEST(PolygonMeasures, ShapeErrorP1MatchesTheMaskFormula) {
  const Polygon truth = square(10, 10, 20);
  const Polygon predicted{box(12, 10, 30, 34), {}};  // misses 2 x 20, adds 18 x 4
  // p1 = 100 * sum |B_f - B_gth| / sum B_gth on pixel masks (exact here: integer corners).
  const cv::Mat mf = delineo::core::rasterize(predicted, {50, 50}) / 255;
  const cv::Mat mg = delineo::core::rasterize(truth, {50, 50}) / 255;
  cv::Mat diff;
  cv::absdiff(mf, mg, diff);
  const double fromMasks = 100.0 * cv::sum(diff)[0] / cv::sum(mg)[0];
  EXPECT_NEAR(fromMasks, 100.0 * (40 + 72) / 400.0, 1e-9);
  EXPECT_NEAR(eval::shapeErrorP1(predicted, truth), fromMasks, 1e-9);
  EXPECT_NEAR(eval::shapeErrorP1(square(20, 10, 20), truth), 100.0, 1e-9);  // half shifted out
  EXPECT_TRUE(std::isnan(eval::shapeErrorP1(truth, Polygon{})));
}

TEST(PolygonMeasures, ShiftedSquareDistances) {
  const Polygon a = square(0, 0, 10);
  // Horizontal shift by 3: Hausdorff = 3; half the vertices lie on the other outline, so
  // PoLiS = (3 + 0 + 0 + 3) / 4 = 1.5.
  EXPECT_NEAR(eval::hausdorffDistance(a, square(3, 0, 10), 0.1), 3.0, 1e-9);
  EXPECT_NEAR(eval::polisDistance(a, square(3, 0, 10)), 1.5, 1e-12);
  // Shift (3, 4): Hausdorff = |shift| = 5 (corner to corner); vertex distances 5, 4, 3, 3 both
  // ways, PoLiS = 15 / 4.
  EXPECT_NEAR(eval::hausdorffDistance(a, Polygon{box(3, 4, 13, 14), {}}, 0.1), 5.0, 1e-9);
  EXPECT_NEAR(eval::polisDistance(a, Polygon{box(3, 4, 13, 14), {}}), 3.75, 1e-12);
}

TEST(PolygonMeasures, HausdorffFindsTheFarthestPointInsideAnEdge) {
  // The band's top edge is 4 from the frame at x in [4, 6] while its vertices touch the frame.
  const Polygon band{box(0, 4, 10, 6), {}};
  Polygon frame = square(-10, -10, 30);
  EXPECT_NEAR(eval::hausdorffDistance(band, Polygon{box(0, 0, 10, 10), {}}, 0.1), 4.0, 1e-9);
  // Coarse sampling can only under-estimate, by at most step / 2.
  const double coarse = eval::hausdorffDistance(band, Polygon{box(0, 0, 10, 10), {}}, 3.0);
  EXPECT_LE(coarse, 4.0 + 1e-12);
  EXPECT_GE(coarse, 4.0 - 1.5);
  // Holes are part of the boundary.
  frame.holes.push_back(box(0, 0, 10, 10));
  EXPECT_NEAR(eval::distanceToBoundary({5, 5}, frame), 5.0, 1e-12);
}

TEST(PolygonMeasures, CornersSkipCollinearVertices) {
  Polygon p{{{0, 0}, {5, 0}, {10, 0}, {10, 10}, {10, 10}, {0, 10}}, {}};
  const auto corners = eval::polygonCorners(p, 20.0);
  ASSERT_EQ(corners.size(), 4u);
  // A 10 degree kink is not a corner at 20 degrees, it is at 5.
  Polygon kink{{{0, 0}, {5, 0}, {10, 10 * std::tan(10 * M_PI / 180) / 2}, {10, 10}, {0, 10}}, {}};
  EXPECT_EQ(eval::polygonCorners(kink, 20.0).size(), 4u);
  EXPECT_EQ(eval::polygonCorners(kink, 5.0).size(), 5u);
}

TEST(PolygonMeasures, CornerRmsOnKnownJitter) {
  const std::vector<cv::Point2d> truth{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  // Offsets of length 0.5, 1, 0 and 1.
  const std::vector<cv::Point2d> predicted{{0.3, 0.4}, {9.4, 0.8}, {10, 10}, {1, 10}};
  const auto all = eval::matchCorners(predicted, truth, 3.0);
  EXPECT_EQ(all.matched, 4);
  EXPECT_NEAR(all.rms, 0.75, 1e-12);  // sqrt((0.25 + 1 + 0 + 1) / 4)
  const auto close = eval::matchCorners(predicted, truth, 0.9);
  EXPECT_EQ(close.matched, 2);
  EXPECT_NEAR(close.rms, std::sqrt(0.125), 1e-12);
  // Two predictions near one truth corner: only the nearer one is paired.
  const auto crowded = eval::matchCorners({{0.2, 0}, {0.5, 0}}, {{0, 0}}, 3.0);
  EXPECT_EQ(crowded.matched, 1);
  EXPECT_NEAR(crowded.rms, 0.2, 1e-12);
  EXPECT_TRUE(std::isnan(eval::matchCorners({}, truth, 3.0).rms));
}

TEST(PolygonMeasures, CirclesOfManyVerticesMatchTheirClosedForms) {
  // Two 30 000-vertex circles of radius 900 whose centres are 3 apart (the edge grid's paths):
  // the overlap of two discs (lens area), PoLiS and Hausdorff near the shift.
  const auto circle = [](double cx, int n) {
    delineo::core::Polygon p;
    for (int i = 0; i < n; ++i) {
      const double a = 2.0 * 3.14159265358979 * i / n;
      p.outer.emplace_back(cx + 900.0 * std::cos(a), 1000.0 + 900.0 * std::sin(a));
    }
    return p;
  };
  const delineo::core::Polygon a = circle(1000.0, 30000), b = circle(1003.0, 30000);
  const double r = 900.0, d = 3.0;
  const double lens = 2 * r * r * std::acos(d / (2 * r)) - 0.5 * d * std::sqrt(4 * r * r - d * d);
  const double disc = 3.14159265358979 * r * r;
  EXPECT_NEAR(eval::intersectionOverUnion(a, b), lens / (2 * disc - lens), 1e-4);
  EXPECT_NEAR(eval::hausdorffDistance(a, b, 1.0), 3.0, 0.01);
  EXPECT_NEAR(eval::polisDistance(a, b), 2.0 * 3.0 / 3.14159265358979, 0.02);  // mean |d cos θ|
}
