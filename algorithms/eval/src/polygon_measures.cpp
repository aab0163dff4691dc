#include "delineo/eval/polygon_measures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <unordered_map>
#include <vector>

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

// The edges of a polygon in a grid of square cells (only the cells an edge's bounding box
// touches are stored): nearest-edge and near-edge queries look at the cells around a point
// instead of every edge, so measures between polygons of many vertices stay near linear.
class EdgeIndex {
 public:
  explicit EdgeIndex(const std::vector<Segment>& edges) : edges_(edges), seen_(edges.size(), 0) {
    if (edges.empty()) return;
    double minX = 1e300, minY = 1e300, maxX = -1e300, maxY = -1e300, length = 0;
    for (const auto& e : edges) {
      minX = std::min({minX, e.from.x, e.to.x}), maxX = std::max({maxX, e.from.x, e.to.x});
      minY = std::min({minY, e.from.y, e.to.y}), maxY = std::max({maxY, e.from.y, e.to.y});
      length += std::hypot(e.to.x - e.from.x, e.to.y - e.from.y);
    }
    origin_ = {minX, minY};
    // About two edges a cell along the boundary, and at most 4096 cells a side.
    const double extent = std::max({maxX - minX, maxY - minY, 1e-9});
    cell_ = std::max({2.0 * length / static_cast<double>(edges.size()), extent / 4096.0, 1e-9});
    for (size_t i = 0; i < edges.size(); ++i) {
      const auto [x0, y0] = cellOf({std::min(edges[i].from.x, edges[i].to.x), std::min(edges[i].from.y, edges[i].to.y)});
      const auto [x1, y1] = cellOf({std::max(edges[i].from.x, edges[i].to.x), std::max(edges[i].from.y, edges[i].to.y)});
      for (std::int64_t y = y0; y <= y1; ++y) {
        for (std::int64_t x = x0; x <= x1; ++x) cells_[key(x, y)].push_back(static_cast<std::uint32_t>(i));
      }
    }
    for (const auto& [k, list] : cells_) {
      rows_[static_cast<std::int64_t>(static_cast<std::int32_t>(k & 0xffffffffu))].push_back(
          static_cast<std::int64_t>(static_cast<std::int32_t>(k >> 32)));
    }
    for (auto& [row, columns] : rows_) std::sort(columns.begin(), columns.end());
  }

  // Distance from `p` to the nearest edge: rings of cells around p's cell until no farther ring
  // can hold a nearer edge (every edge when that would visit more cells than there are edges).
  double nearest(const cv::Point2d& p) const {
    if (edges_.empty()) return std::numeric_limits<double>::infinity();
    const auto [cx, cy] = cellOf(p);
    double best = std::numeric_limits<double>::infinity();
    for (std::int64_t r = 0;; ++r) {
      if ((2 * r + 1) * (2 * r + 1) > static_cast<std::int64_t>(edges_.size()) + 64) return distanceToEdges(p, edges_);
      for (std::int64_t y = cy - r; y <= cy + r; ++y) {
        const bool edgeRow = y == cy - r || y == cy + r;
        for (std::int64_t x = cx - r; x <= cx + r; x += edgeRow ? 1 : 2 * std::max<std::int64_t>(r, 1)) {
          const auto it = cells_.find(key(x, y));
          if (it == cells_.end()) continue;
          for (const std::uint32_t i : it->second) best = std::min(best, pointSegmentDistance(p, edges_[i]));
        }
      }
      // Every cell beyond ring r lies at least r cells from p.
      if (best <= static_cast<double>(r) * cell_) return best;
    }
  }

  // Even-odd rule over the indexed edges, half-open in y so that a point is counted once: only
  // the cells of p's row to its right can hold an edge that crosses the ray from p towards +x.
  bool inside(const cv::Point2d& p) const {
    if (edges_.empty()) return false;
    const auto [cx, cy] = cellOf(p);
    bool in = false;
    ++stamp_;
    const auto row = rows_.find(cy);
    if (row == rows_.end()) return false;
    for (auto column = std::lower_bound(row->second.begin(), row->second.end(), cx); column != row->second.end(); ++column) {
      const auto it = cells_.find(key(*column, cy));
      for (const std::uint32_t i : it->second) {
        if (seen_[i] == stamp_) continue;
        seen_[i] = stamp_;
        const cv::Point2d& a = edges_[i].from;
        const cv::Point2d& b = edges_[i].to;
        if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y)) in = !in;
      }
    }
    return in;
  }

  // Indices of the edges whose bounding box may come within `reach` of the box [lo, hi], each once.
  template <class Visit>
  void near(const cv::Point2d& lo, const cv::Point2d& hi, double reach, Visit&& visit) const {
    if (edges_.empty()) return;
    ++stamp_;
    const auto [x0, y0] = cellOf({lo.x - reach, lo.y - reach});
    const auto [x1, y1] = cellOf({hi.x + reach, hi.y + reach});
    if ((x1 - x0 + 1) * (y1 - y0 + 1) > static_cast<std::int64_t>(edges_.size()) + 64) {
      for (size_t i = 0; i < edges_.size(); ++i) visit(edges_[i]);
      return;
    }
    for (std::int64_t y = y0; y <= y1; ++y) {
      for (std::int64_t x = x0; x <= x1; ++x) {
        const auto it = cells_.find(key(x, y));
        if (it == cells_.end()) continue;
        for (const std::uint32_t i : it->second) {
          if (seen_[i] == stamp_) continue;
          seen_[i] = stamp_;
          visit(edges_[i]);
        }
      }
    }
  }

 private:
  std::pair<std::int64_t, std::int64_t> cellOf(const cv::Point2d& p) const {
    return {static_cast<std::int64_t>(std::floor((p.x - origin_.x) / cell_)),
            static_cast<std::int64_t>(std::floor((p.y - origin_.y) / cell_))};
  }
  static std::uint64_t key(std::int64_t x, std::int64_t y) {
    return (static_cast<std::uint64_t>(x) << 32) ^ (static_cast<std::uint64_t>(y) & 0xffffffffu);
  }

  const std::vector<Segment>& edges_;
  cv::Point2d origin_;
  double cell_ = 1.0;
  std::unordered_map<std::int64_t, std::vector<std::int64_t>> rows_;  // occupied columns a row, sorted
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
  mutable std::vector<std::uint32_t> seen_;
  mutable std::uint32_t stamp_ = 0;
};

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
Location locate(const cv::Point2d& m, const cv::Point2d& direction, const EdgeIndex& edges, double tolerance) {
  std::optional<Location> onBoundary;
  edges.near(m, m, tolerance, [&](const Segment& e) {
    if (!onBoundary && pointSegmentDistance(m, e) <= tolerance) {
      // Both rings have their interior on the left: same direction means same side.
      onBoundary = direction.dot(e.to - e.from) > 0 ? Location::OnBoundarySameSide : Location::OnBoundaryOppositeSide;
    }
  });
  if (onBoundary) return *onBoundary;
  return edges.inside(m) ? Location::Inside : Location::Outside;
}

// Shoelace contribution of the pieces of `ring`'s edges that belong to the boundary of the
// intersection with the polygon `other`.
double boundaryContribution(const std::vector<Ring>& rings, const EdgeIndex& otherEdges, bool countSharedPieces,
                            double tolerance) {
  double sum = 0.0;
  std::vector<double> cuts;
  for (const auto& e : edgesOf(rings)) {
    const cv::Point2d d = e.to - e.from;
    const double len = std::sqrt(d.dot(d));
    if (len <= 0) continue;
    cuts.assign({0.0, 1.0});
    const cv::Point2d lo(std::min(e.from.x, e.to.x), std::min(e.from.y, e.to.y));
    const cv::Point2d hi(std::max(e.from.x, e.to.x), std::max(e.from.y, e.to.y));
    otherEdges.near(lo, hi, tolerance, [&](const Segment& o) {
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
    });
    std::sort(cuts.begin(), cuts.end());
    for (size_t k = 0; k + 1 < cuts.size(); ++k) {
      if ((cuts[k + 1] - cuts[k]) * len <= tolerance) continue;
      const cv::Point2d p0 = e.from + cuts[k] * d;
      const cv::Point2d p1 = e.from + cuts[k + 1] * d;
      const Location where = locate(0.5 * (p0 + p1), d, otherEdges, tolerance);
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

double directedHausdorff(const std::vector<Segment>& from, const EdgeIndex& to, double step) {
  double worst = 0.0;
  for (const auto& e : from) {
    const cv::Point2d d = e.to - e.from;
    const int pieces = std::max(1, static_cast<int>(std::ceil(std::sqrt(d.dot(d)) / step)));
    // The edge's end is the next edge's start: sample [0, pieces) here.
    for (int k = 0; k < pieces; ++k) {
      const cv::Point2d p = e.from + (static_cast<double>(k) / pieces) * d;
      worst = std::max(worst, to.nearest(p));
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
  const double s = boundaryContribution(ringsA, EdgeIndex(edgesB), true, tolerance) +
                   boundaryContribution(ringsB, EdgeIndex(edgesA), false, tolerance);
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
  const EdgeIndex indexA(edgesA), indexB(edgesB);
  double sumA = 0.0, sumB = 0.0;
  for (const auto& v : verticesA) sumA += indexB.nearest(v);
  for (const auto& v : verticesB) sumB += indexA.nearest(v);
  return 0.5 * sumA / static_cast<double>(verticesA.size()) +
         0.5 * sumB / static_cast<double>(verticesB.size());
}

double hausdorffDistance(const core::Polygon& a, const core::Polygon& b, double step) {
  const auto edgesA = edgesOf(orientedRings(a));
  const auto edgesB = edgesOf(orientedRings(b));
  if (edgesA.empty() || edgesB.empty()) return std::numeric_limits<double>::quiet_NaN();
  return std::max(directedHausdorff(edgesA, EdgeIndex(edgesB), step), directedHausdorff(edgesB, EdgeIndex(edgesA), step));
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
