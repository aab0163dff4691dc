#include "delineo/eval/polygon_measures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace delineo::eval {

namespace {

using core::Polygon;
using core::Ring;

double cross(const cv::Point2d& a, const cv::Point2d& b) { return a.x * b.y - a.y * b.x; }

struct Segment {
  cv::Point2d from, to;
};

// Ring without consecutive repeated vertices (and without a closing copy of the first one).
Ring withoutRepeats(const Ring& ring) {
  Ring out;
  out.reserve(ring.size());
  for (const auto& p : ring) {
    if (out.empty() || out.back() != p) out.push_back(p);
  }
  while (out.size() > 1 && out.front() == out.back()) out.pop_back();
  return out;
}

// Rings oriented so that the polygon's interior is on the left of every edge in the frame where
// core::signedArea is positive: outer ring positive, holes negative.
std::vector<Ring> orientedRings(const Polygon& polygon) {
  std::vector<Ring> rings;
  auto add = [&](const Ring& ring, bool outer) {
    Ring r = withoutRepeats(ring);
    if (r.size() < 3) return;
    const double s = core::signedArea(r);
    if ((outer && s < 0) || (!outer && s > 0)) std::reverse(r.begin(), r.end());
    rings.push_back(std::move(r));
  };
  add(polygon.outer, true);
  for (const auto& h : polygon.holes) add(h, false);
  return rings;
}

std::vector<Segment> edgesOf(const std::vector<Ring>& rings) {
  std::vector<Segment> edges;
  for (const auto& r : rings) {
    for (size_t i = 0; i < r.size(); ++i) edges.push_back({r[i], r[(i + 1) % r.size()]});
  }
  return edges;
}

double pointSegmentDistance(const cv::Point2d& p, const Segment& s) {
  const cv::Point2d d = s.to - s.from;
  const double len2 = d.dot(d);
  double t = len2 > 0 ? (p - s.from).dot(d) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const cv::Point2d q = s.from + t * d;
  return std::hypot(p.x - q.x, p.y - q.y);
}

double distanceToEdges(const cv::Point2d& p, const std::vector<Segment>& edges) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& e : edges) best = std::min(best, pointSegmentDistance(p, e));
  return best;
}

// Even-odd rule over all rings, half-open in y so that a point is counted once.
bool insideRings(const cv::Point2d& p, const std::vector<Ring>& rings) {
  bool inside = false;
  for (const auto& r : rings) {
    const size_t n = r.size();
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
      const auto& a = r[i];
      const auto& b = r[j];
      if ((a.y > p.y) != (b.y > p.y)) {
        const double x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
        if (p.x < x) inside = !inside;
      }
    }
  }
  return inside;
}

double extentOf(const std::vector<Ring>& a, const std::vector<Ring>& b) {
  double m = 1.0;
  for (const auto* rings : {&a, &b}) {
    for (const auto& r : *rings) {
      for (const auto& p : r) m = std::max({m, std::abs(p.x), std::abs(p.y)});
    }
  }
  return m;
}

enum class Location { Outside, Inside, OnBoundarySameSide, OnBoundaryOppositeSide };

// Where the midpoint `m` of a boundary piece running in `direction` lies relative to a polygon.
Location locate(const cv::Point2d& m, const cv::Point2d& direction, const std::vector<Ring>& rings,
                const std::vector<Segment>& edges, double tolerance) {
  for (const auto& e : edges) {
    if (pointSegmentDistance(m, e) <= tolerance) {
      // Both rings have their interior on the left: same direction means same side.
      return direction.dot(e.to - e.from) > 0 ? Location::OnBoundarySameSide
                                              : Location::OnBoundaryOppositeSide;
    }
  }
  return insideRings(m, rings) ? Location::Inside : Location::Outside;
}

// Shoelace contribution of the pieces of `ring`'s edges that belong to the boundary of the
// intersection with the polygon `other`.
double boundaryContribution(const std::vector<Ring>& rings, const std::vector<Ring>& otherRings,
                            const std::vector<Segment>& otherEdges, bool countSharedPieces,
                            double tolerance) {
  double sum = 0.0;
  std::vector<double> cuts;
  for (const auto& e : edgesOf(rings)) {
    const cv::Point2d d = e.to - e.from;
    const double len = std::sqrt(d.dot(d));
    if (len <= 0) continue;
    cuts.assign({0.0, 1.0});
    for (const auto& o : otherEdges) {
      const cv::Point2d f = o.to - o.from;
      const cv::Point2d w = o.from - e.from;
      const double denom = cross(d, f);
      const double flen = std::sqrt(f.dot(f));
      if (std::abs(denom) > 1e-12 * len * flen) {
        const double t = cross(w, f) / denom;
        const double u = cross(w, d) / denom;
        const double slack = tolerance / std::max(flen, 1e-300);
        if (t > 0 && t < 1 && u >= -slack && u <= 1 + slack) cuts.push_back(t);
      } else if (std::abs(cross(w, d)) / len <= tolerance) {
        // Collinear: the other edge's ends split this edge where they fall on it.
        for (const auto& p : {o.from, o.to}) {
          const double t = (p - e.from).dot(d) / (len * len);
          if (t > 0 && t < 1) cuts.push_back(t);
        }
      }
    }
    std::sort(cuts.begin(), cuts.end());
    for (size_t k = 0; k + 1 < cuts.size(); ++k) {
      if ((cuts[k + 1] - cuts[k]) * len <= tolerance) continue;
      const cv::Point2d p0 = e.from + cuts[k] * d;
      const cv::Point2d p1 = e.from + cuts[k + 1] * d;
      const Location where = locate(0.5 * (p0 + p1), d, otherRings, otherEdges, tolerance);
      if (where == Location::Inside ||
          (countSharedPieces && where == Location::OnBoundarySameSide)) {
        sum += 0.5 * cross(p0, p1);
      }
    }
  }
  return sum;
}

Polygon translated(const Polygon& polygon, const cv::Point2d& shift) {
  Polygon out = polygon;
  for (auto& p : out.outer) p += shift;
  for (auto& hole : out.holes) {
    for (auto& p : hole) p += shift;
  }
  return out;
}

bool isSimplePolygon(const Polygon& polygon) {
  if (!core::isSimple(withoutRepeats(polygon.outer))) return false;
  for (const auto& hole : polygon.holes) {
    if (!core::isSimple(withoutRepeats(hole))) return false;
  }
  return true;
}

// Even-odd areas measured on a common supersampled raster (see overlapAreas).
OverlapAreas rasterOverlap(const Polygon& a, const Polygon& b) {
  constexpr double kMaxSamplesPerUnit = 16.0;
  constexpr double kMaxSamplesAcross = 2048.0;
  cv::Rect2d box = core::boundingBox(a.outer) | core::boundingBox(b.outer);
  const double extent = std::max({box.width, box.height, 1e-12});
  const double scale = std::min(kMaxSamplesPerUnit, kMaxSamplesAcross / extent);
  auto toRaster = [&](const Polygon& p) {
    Polygon out = translated(p, -box.tl());
    for (auto& v : out.outer) v *= scale;
    for (auto& hole : out.holes) {
      for (auto& v : hole) v *= scale;
    }
    return out;
  };
  const cv::Size size(static_cast<int>(std::ceil(box.width * scale)) + 1,
                      static_cast<int>(std::ceil(box.height * scale)) + 1);
  const cv::Mat maskA = core::rasterize(toRaster(a), size);
  const cv::Mat maskB = core::rasterize(toRaster(b), size);
  const double pixelArea = 1.0 / (scale * scale);
  OverlapAreas result;
  result.exact = false;
  result.a = cv::countNonZero(maskA) * pixelArea;
  result.b = cv::countNonZero(maskB) * pixelArea;
  result.intersection = cv::countNonZero(maskA & maskB) * pixelArea;
  return result;
}

std::vector<cv::Point2d> verticesOf(const std::vector<Ring>& rings) {
  std::vector<cv::Point2d> v;
  for (const auto& r : rings) v.insert(v.end(), r.begin(), r.end());
  return v;
}

double directedHausdorff(const std::vector<Segment>& from, const std::vector<Segment>& to,
                         double step) {
  double worst = 0.0;
  for (const auto& e : from) {
    const cv::Point2d d = e.to - e.from;
    const int pieces = std::max(1, static_cast<int>(std::ceil(std::sqrt(d.dot(d)) / step)));
    // The edge's end is the next edge's start: sample [0, pieces) here.
    for (int k = 0; k < pieces; ++k) {
      const cv::Point2d p = e.from + (static_cast<double>(k) / pieces) * d;
      worst = std::max(worst, distanceToEdges(p, to));
    }
  }
  return worst;
}

}  // namespace

OverlapAreas overlapAreas(const core::Polygon& a, const core::Polygon& b) {
  // Work around a local origin: map coordinates (UTM metres ~1e6) would otherwise lose
  // significant digits in the shoelace products.
  const cv::Point2d origin = a.outer.empty() ? cv::Point2d() : a.outer.front();
  const Polygon localA = translated(a, -origin);
  const Polygon localB = translated(b, -origin);
  if (!isSimplePolygon(localA) || !isSimplePolygon(localB)) {
    return rasterOverlap(localA, localB);
  }
  OverlapAreas result;
  result.a = core::area(localA);
  result.b = core::area(localB);
  const auto ringsA = orientedRings(localA);
  const auto ringsB = orientedRings(localB);
  if (ringsA.empty() || ringsB.empty()) return result;
  const cv::Rect2d boxA = core::boundingBox(ringsA.front());
  const cv::Rect2d boxB = core::boundingBox(ringsB.front());
  if (boxA.x > boxB.x + boxB.width || boxB.x > boxA.x + boxA.width ||
      boxA.y > boxB.y + boxB.height || boxB.y > boxA.y + boxA.height) {
    return result;
  }
  const double tolerance = 1e-9 * extentOf(ringsA, ringsB);
  const auto edgesA = edgesOf(ringsA);
  const auto edgesB = edgesOf(ringsB);
  // Shared pieces are taken from a's pass only, so they count once.
  const double s = boundaryContribution(ringsA, ringsB, edgesB, true, tolerance) +
                   boundaryContribution(ringsB, ringsA, edgesA, false, tolerance);
  result.intersection = std::clamp(s, 0.0, std::min(result.a, result.b));
  return result;
}

double intersectionArea(const core::Polygon& a, const core::Polygon& b) {
  return overlapAreas(a, b).intersection;
}

double intersectionOverUnion(const core::Polygon& a, const core::Polygon& b) {
  const OverlapAreas areas = overlapAreas(a, b);
  const double uni = areas.a + areas.b - areas.intersection;
  return uni > 0 ? areas.intersection / uni : 0.0;
}

double shapeErrorP1(const core::Polygon& predicted, const core::Polygon& truth) {
  const OverlapAreas areas = overlapAreas(predicted, truth);
  if (areas.b <= 0) return std::numeric_limits<double>::quiet_NaN();
  const double symmetricDifference = areas.a + areas.b - 2.0 * areas.intersection;
  return 100.0 * std::max(0.0, symmetricDifference) / areas.b;
}

double distanceToBoundary(const cv::Point2d& point, const core::Polygon& polygon) {
  return distanceToEdges(point, edgesOf(orientedRings(polygon)));
}

double polisDistance(const core::Polygon& a, const core::Polygon& b) {
  const auto ringsA = orientedRings(a);
  const auto ringsB = orientedRings(b);
  const auto verticesA = verticesOf(ringsA);
  const auto verticesB = verticesOf(ringsB);
  if (verticesA.empty() || verticesB.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto edgesA = edgesOf(ringsA);
  const auto edgesB = edgesOf(ringsB);
  double sumA = 0.0, sumB = 0.0;
  for (const auto& v : verticesA) sumA += distanceToEdges(v, edgesB);
  for (const auto& v : verticesB) sumB += distanceToEdges(v, edgesA);
  return 0.5 * sumA / static_cast<double>(verticesA.size()) +
         0.5 * sumB / static_cast<double>(verticesB.size());
}

double hausdorffDistance(const core::Polygon& a, const core::Polygon& b, double step) {
  const auto edgesA = edgesOf(orientedRings(a));
  const auto edgesB = edgesOf(orientedRings(b));
  if (edgesA.empty() || edgesB.empty()) return std::numeric_limits<double>::quiet_NaN();
  return std::max(directedHausdorff(edgesA, edgesB, step), directedHausdorff(edgesB, edgesA, step));
}

std::vector<cv::Point2d> polygonCorners(const core::Polygon& polygon, double minTurnDegrees) {
  std::vector<cv::Point2d> corners;
  const double minTurn = minTurnDegrees * std::numbers::pi / 180.0;
  for (const auto& ring : orientedRings(polygon)) {
    const size_t n = ring.size();
    for (size_t i = 0; i < n; ++i) {
      const cv::Point2d in = ring[i] - ring[(i + n - 1) % n];
      const cv::Point2d out = ring[(i + 1) % n] - ring[i];
      const double turn = std::abs(std::atan2(cross(in, out), in.dot(out)));
      if (turn >= minTurn) corners.push_back(ring[i]);
    }
  }
  return corners;
}

CornerMatching matchCorners(const std::vector<cv::Point2d>& predicted,
                            const std::vector<cv::Point2d>& truth, double radius) {
  CornerMatching result;
  result.truthCorners = static_cast<int>(truth.size());
  result.predictedCorners = static_cast<int>(predicted.size());
  auto nearest = [](const cv::Point2d& p, const std::vector<cv::Point2d>& set) {
    size_t best = set.size();
    double bestDistance = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < set.size(); ++i) {
      const double d = std::hypot(p.x - set[i].x, p.y - set[i].y);
      if (d < bestDistance) {
        bestDistance = d;
        best = i;
      }
    }
    return std::pair{best, bestDistance};
  };
  double sumSquares = 0.0;
  for (size_t t = 0; t < truth.size(); ++t) {
    const auto [p, distance] = nearest(truth[t], predicted);
    if (p == predicted.size() || distance > radius) continue;
    if (nearest(predicted[p], truth).first != t) continue;
    sumSquares += distance * distance;
    ++result.matched;
  }
  result.rms = result.matched > 0 ? std::sqrt(sumSquares / result.matched)
                                  : std::numeric_limits<double>::quiet_NaN();
  return result;
}

}  // namespace delineo::eval
