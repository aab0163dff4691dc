#include "delineo/core/geometry.hpp"

#include <string>

#include "delineo/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>


namespace delineo::core {

std::optional<double> numberProperty(const Feature& feature, const std::string& key, double limit) {
  const auto it = feature.attributes.find(key);
  if (it == feature.attributes.end() || std::holds_alternative<std::monostate>(it->second)) return std::nullopt;
  std::optional<double> value;
  if (const auto* i = std::get_if<long long>(&it->second)) value = static_cast<double>(*i);
  if (const auto* d = std::get_if<double>(&it->second)) value = *d;
  if (const auto* s = std::get_if<std::string>(&it->second)) {
    try {
      size_t used = 0;
      value = std::stod(*s, &used);
      if (used != s->size()) value.reset();
    } catch (const std::exception&) {
    }
  }
  if (!value || !std::isfinite(*value) || std::abs(*value) > limit) {
    throw Error(ErrorCode::InvalidParameter, "property " + key + " must be a finite number within +-" +
                                                 std::to_string(static_cast<long long>(limit)));
  }
  return value;
}

double signedArea(const Ring& ring) {
  double a = 0.0;
  const size_t n = ring.size();
  for (size_t i = 0; i < n; ++i) {
    const auto& p = ring[i];
    const auto& q = ring[(i + 1) % n];
    a += p.x * q.y - q.x * p.y;
  }
  return 0.5 * a;
}

double area(const Polygon& polygon) {
  double a = std::abs(signedArea(polygon.outer));
  for (const auto& h : polygon.holes) a -= std::abs(signedArea(h));
  return std::max(0.0, a);
}

cv::Rect2d boundingBox(const Ring& ring) {
  if (ring.empty()) return {};
  double x0 = std::numeric_limits<double>::max(), y0 = x0;
  double x1 = std::numeric_limits<double>::lowest(), y1 = x1;
  for (const auto& p : ring) {
    x0 = std::min(x0, p.x);
    y0 = std::min(y0, p.y);
    x1 = std::max(x1, p.x);
    y1 = std::max(y1, p.y);
  }
  return {x0, y0, x1 - x0, y1 - y0};
}

namespace {
double cross(const cv::Point2d& o, const cv::Point2d& a, const cv::Point2d& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}
bool onSegment(const cv::Point2d& p, const cv::Point2d& q, const cv::Point2d& r) {
  return std::min(p.x, r.x) <= q.x && q.x <= std::max(p.x, r.x) && std::min(p.y, r.y) <= q.y &&
         q.y <= std::max(p.y, r.y);
}
int sign(double v) { return (v > 1e-12) - (v < -1e-12); }
}  // namespace

bool segmentsIntersect(const cv::Point2d& p1, const cv::Point2d& p2, const cv::Point2d& p3,
                       const cv::Point2d& p4) {
  const int d1 = sign(cross(p3, p4, p1)), d2 = sign(cross(p3, p4, p2));
  const int d3 = sign(cross(p1, p2, p3)), d4 = sign(cross(p1, p2, p4));
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  if (d1 == 0 && onSegment(p3, p1, p4)) return true;
  if (d2 == 0 && onSegment(p3, p2, p4)) return true;
  if (d3 == 0 && onSegment(p1, p3, p2)) return true;
  if (d4 == 0 && onSegment(p1, p4, p2)) return true;
  return false;
}

namespace {

// Whether edges i and j (j > i) of the ring of n vertices cross; adjacent edges share a vertex.
bool edgesCross(const Ring& ring, size_t i, size_t j) {
  const size_t n = ring.size();
  if ((j + 1) % n == i || (i + 1) % n == j) return false;
  return segmentsIntersect(ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n]);
}

// Every pair of edges sharing a cell of a square grid (about two edges a cell along the ring),
// so that a ring of many vertices is checked in near linear time.
bool anyEdgesCrossInGrid(const Ring& ring) {
  const size_t n = ring.size();
  const cv::Rect2d box = boundingBox(ring);
  double length = 0;
  for (size_t i = 0; i < n; ++i) length += cv::norm(ring[(i + 1) % n] - ring[i]);
  // At most about 4n cells.
  const double cell = std::max({2.0 * length / static_cast<double>(n), std::sqrt(box.width * box.height / (4.0 * n)),
                                std::max(box.width, box.height) / (4.0 * n), 1e-9});
  const auto cols = static_cast<size_t>(box.width / cell) + 1, rows = static_cast<size_t>(box.height / cell) + 1;
  std::vector<std::vector<size_t>> cells(cols * rows);
  for (size_t i = 0; i < n; ++i) {
    const cv::Point2d& a = ring[i];
    const cv::Point2d& b = ring[(i + 1) % n];
    const auto x0 = static_cast<size_t>((std::min(a.x, b.x) - box.x) / cell), x1 = static_cast<size_t>((std::max(a.x, b.x) - box.x) / cell);
    const auto y0 = static_cast<size_t>((std::min(a.y, b.y) - box.y) / cell), y1 = static_cast<size_t>((std::max(a.y, b.y) - box.y) / cell);
    for (size_t y = y0; y <= std::min(y1, rows - 1); ++y) {
      for (size_t x = x0; x <= std::min(x1, cols - 1); ++x) cells[y * cols + x].push_back(i);
    }
  }
  for (const auto& list : cells) {
    for (size_t p = 0; p < list.size(); ++p) {
      for (size_t q = p + 1; q < list.size(); ++q) {
        if (edgesCross(ring, list[p], list[q])) return true;
      }
    }
  }
  return false;
}

}  // namespace

bool isSimple(const Ring& ring) {
  const size_t n = ring.size();
  if (n < 3) return false;
  if (std::abs(signedArea(ring)) < 1e-12) return false;
  for (size_t i = 0; i < n; ++i) {
    if (ring[i] == ring[(i + 1) % n]) return false;
  }
  if (n > 64) return !anyEdgesCrossInGrid(ring);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      if (edgesCross(ring, i, j)) return false;
    }
  }
  return true;
}

cv::Mat rasterize(const Polygon& polygon, cv::Size size) {
  // Exact even-odd scanline fill at pixel centres: a pixel is inside when its centre is, with
  // half-open edge rules so that adjacent polygons never share a pixel.
  cv::Mat mask(size, CV_8U, cv::Scalar(0));
  std::vector<const Ring*> rings{&polygon.outer};
  for (const auto& h : polygon.holes) rings.push_back(&h);
  std::vector<double> xs;
  for (int y = 0; y < size.height; ++y) {
    const double yc = y + 0.5;
    xs.clear();
    for (const Ring* ring : rings) {
      const size_t n = ring->size();
      for (size_t i = 0; i < n; ++i) {
        const auto& a = (*ring)[i];
        const auto& b = (*ring)[(i + 1) % n];
        if ((a.y <= yc) == (b.y <= yc)) continue;  // edge does not cross this scanline
        xs.push_back(a.x + (yc - a.y) * (b.x - a.x) / (b.y - a.y));
      }
    }
    std::sort(xs.begin(), xs.end());
    auto* row = mask.ptr<uchar>(y);
    for (size_t k = 0; k + 1 < xs.size(); k += 2) {
      // pixels whose centre x + 0.5 lies in [xs[k], xs[k+1])
      const int x0 = std::max(0, static_cast<int>(std::ceil(xs[k] - 0.5)));
      const int x1 = std::min(size.width, static_cast<int>(std::ceil(xs[k + 1] - 0.5)));
      for (int x = x0; x < x1; ++x) row[x] = 255;
    }
  }
  return mask;
}


namespace {

double crossProduct(cv::Point2d a, cv::Point2d b) { return a.x * b.y - a.y * b.x; }

bool lineIntersection(cv::Point2d a, cv::Point2d u, cv::Point2d b, cv::Point2d v,
                      cv::Point2d& out) {
  const double det = crossProduct(u, v);
  if (std::abs(det) < 1e-12 * std::max(1.0, cv::norm(u) * cv::norm(v))) return false;
  out = a + u * (crossProduct(b - a, v) / det);
  return true;
}

void requireRing(const Ring& ring, int index, size_t minVertices) {
  if (ring.size() < minVertices || index < 0 || static_cast<size_t>(index) >= ring.size()) {
    throw Error(ErrorCode::InvalidParameter, "cannot move vertex or edge " + std::to_string(index) +
                                                 " of a ring of " + std::to_string(ring.size()) +
                                                 " vertices (at least " +
                                                 std::to_string(minVertices) + " needed)");
  }
}

}  // namespace

Ring moveCornerKeepingAngles(const Ring& ring, int index, cv::Point2d to) {
  requireRing(ring, index, 4);
  const size_t n = ring.size(), i = static_cast<size_t>(index);
  const size_t ip = (i + n - 1) % n, ipp = (i + n - 2) % n, in = (i + 1) % n, inn = (i + 2) % n;
  Ring out = ring;
  out[i] = to;
  // The previous vertex stays on the edge arriving at it and on the line through `to` with the
  // direction of its edge to the moved vertex; likewise the next one.
  cv::Point2d p, q;
  if (lineIntersection(ring[ipp], ring[ip] - ring[ipp], to, ring[i] - ring[ip], p)) out[ip] = p;
  if (lineIntersection(ring[inn], ring[in] - ring[inn], to, ring[in] - ring[i], q)) out[in] = q;
  return out;
}

Ring moveEdgeKeepingAngles(const Ring& ring, int index, double offset) {
  requireRing(ring, index, 3);
  const size_t n = ring.size(), i = static_cast<size_t>(index);
  const size_t ip = (i + n - 1) % n, in = (i + 1) % n, inn = (i + 2) % n;
  const cv::Point2d e = ring[in] - ring[i];
  const double len = cv::norm(e);
  if (len < 1e-12) return ring;
  const cv::Point2d shift = cv::Point2d(e.y, -e.x) * (offset / len);  // left of e with y down
  Ring out = ring;
  cv::Point2d a, b;
  if (lineIntersection(ring[ip], ring[i] - ring[ip], ring[i] + shift, e, a)) out[i] = a;
  if (lineIntersection(ring[inn], ring[in] - ring[inn], ring[i] + shift, e, b)) out[in] = b;
  return out;
}

}  // namespace delineo::core
