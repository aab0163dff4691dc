#include "delineo/io/polygon_sets.hpp"

#include <algorithm>
#include <limits>
#include <memory>

#include <ogr_geometry.h>

#include "delineo/core/error.hpp"
#include "gdal_support.hpp"

namespace delineo::io {

namespace {

using GeometryPtr = std::unique_ptr<OGRGeometry>;

OGRLinearRing* ogrRing(const core::Ring& ring) {
  auto* out = new OGRLinearRing();
  for (const auto& p : ring) out->addPoint(p.x, p.y);
  if (!ring.empty()) out->addPoint(ring.front().x, ring.front().y);
  return out;
}

GeometryPtr ogrSet(const PolygonSet& set) {
  auto multi = std::make_unique<OGRMultiPolygon>();
  for (const auto& polygon : set) {
    auto* p = new OGRPolygon();
    p->addRingDirectly(ogrRing(polygon.outer));
    for (const auto& hole : polygon.holes) p->addRingDirectly(ogrRing(hole));
    multi->addGeometryDirectly(p);
  }
  if (multi->IsValid()) return multi;
  GeometryPtr valid(multi->MakeValid());
  if (!valid) throw core::Error(core::ErrorCode::ProcessingFailed, "a polygon could not be made valid (GDAL without GEOS?)");
  return valid;
}

core::Ring ringOf(const OGRLinearRing& ring) {
  core::Ring out;
  for (int i = 0; i + 1 < ring.getNumPoints(); ++i) out.emplace_back(ring.getX(i), ring.getY(i));  // last repeats the first
  return out;
}

void collectPolygons(const OGRGeometry* geometry, PolygonSet& out) {
  if (geometry == nullptr) return;
  const auto type = wkbFlatten(geometry->getGeometryType());
  if (type == wkbPolygon) {
    const auto* p = geometry->toPolygon();
    if (p->getExteriorRing() == nullptr || p->getExteriorRing()->getNumPoints() < 4) return;
    core::Polygon polygon{ringOf(*p->getExteriorRing()), {}};
    for (int h = 0; h < p->getNumInteriorRings(); ++h) polygon.holes.push_back(ringOf(*p->getInteriorRing(h)));
    out.push_back(std::move(polygon));
  } else if (type == wkbMultiPolygon || type == wkbGeometryCollection) {
    for (const auto* part : *geometry->toGeometryCollection()) collectPolygons(part, out);
  }
}

PolygonSet setOf(OGRGeometry* result) {
  const GeometryPtr owned(result);
  if (!owned) throw core::Error(core::ErrorCode::ProcessingFailed, "a polygon operation failed (GDAL without GEOS?)");
  PolygonSet out;
  collectPolygons(owned.get(), out);
  return out;
}

}  // namespace

PolygonSet intersectionOf(const PolygonSet& a, const PolygonSet& b) {
  if (a.empty() || b.empty()) return {};
  detail::ScopedGdalErrors quiet;
  return setOf(ogrSet(a)->Intersection(ogrSet(b).get()));
}

PolygonSet differenceOf(const PolygonSet& a, const PolygonSet& b) {
  if (a.empty() || b.empty()) return a;
  detail::ScopedGdalErrors quiet;
  return setOf(ogrSet(a)->Difference(ogrSet(b).get()));
}

PolygonSet unionOf(const PolygonSet& a, const PolygonSet& b) {
  detail::ScopedGdalErrors quiet;
  if (a.empty() && b.empty()) return {};
  if (a.empty()) return setOf(ogrSet(b)->UnionCascaded());
  return setOf(ogrSet(a)->Union(ogrSet(b).get()));
}

PolygonSet splitAlong(const core::Polygon& polygon, cv::Point2d from, cv::Point2d to) {
  if (polygon.outer.size() < 3 || cv::norm(to - from) <= 0.0) return {};
  detail::ScopedGdalErrors quiet;
  OGRLineString line;
  line.addPoint(from.x, from.y);
  line.addPoint(to.x, to.y);
  const GeometryPtr blade(line.Buffer(kSplitWidth / 2.0, 1));
  if (!blade) throw core::Error(core::ErrorCode::ProcessingFailed, "a polygon operation failed (GDAL without GEOS?)");
  PolygonSet pieces = setOf(ogrSet({polygon})->Difference(blade.get()));
  if (pieces.size() < 2) return {};
  std::sort(pieces.begin(), pieces.end(), [](const auto& x, const auto& y) { return core::area(x) > core::area(y); });
  return pieces;
}

namespace {
cv::Point2d nearestOnSegment(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d ab = b - a;
  const double length2 = ab.dot(ab);
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return a + t * ab;
}

// `polygon` with each vertex within `reach` of a ring of `onto` moved to the nearest point there.
core::Polygon snappedOnto(core::Polygon polygon, const core::Polygon& onto, double reach) {
  std::vector<const core::Ring*> rings{&onto.outer};
  for (const auto& hole : onto.holes) rings.push_back(&hole);
  auto snap = [&](cv::Point2d& p) {
    double best = reach;
    cv::Point2d to = p;
    for (const core::Ring* ring : rings) {
      for (size_t i = 0; i < ring->size(); ++i) {
        const cv::Point2d q = nearestOnSegment(p, (*ring)[i], (*ring)[(i + 1) % ring->size()]);
        if (const double d = cv::norm(q - p); d <= best) best = d, to = q;
      }
    }
    p = to;
  };
  for (auto& p : polygon.outer) snap(p);
  for (auto& hole : polygon.holes) {
    for (auto& p : hole) snap(p);
  }
  return polygon;
}

// The one polygon of `set` without the holes that are no courtyard of `a` or `b` (the pockets a
// union leaves where two outlines do not quite meet); nullopt when `set` is not one polygon.
std::optional<core::Polygon> singlePolygon(const PolygonSet& set, const core::Polygon& a, const core::Polygon& b) {
  if (set.size() != 1) return std::nullopt;
  PolygonSet courtyards;
  for (const core::Polygon* p : {&a, &b}) {
    for (const auto& hole : p->holes) courtyards.push_back({hole, {}});
  }
  core::Polygon merged = set.front();
  std::erase_if(merged.holes, [&](const core::Ring& hole) {
    return courtyards.empty() || intersectionOf({core::Polygon{hole, {}}}, courtyards).empty();
  });
  return merged;
}
}  // namespace

std::optional<core::Polygon> mergedOutline(const core::Polygon& a, const core::Polygon& b, double maxGap) {
  if (a.outer.size() < 3 || b.outer.size() < 3) return std::nullopt;
  if (auto merged = singlePolygon(unionOf({a}, {b}), a, b)) return merged;
  if (!(maxGap > 0.0)) return std::nullopt;
  const core::Polygon bOnA = snappedOnto(b, a, maxGap);
  if (auto merged = singlePolygon(unionOf({a}, {bOnA}), a, b)) return merged;
  return singlePolygon(unionOf({snappedOnto(a, bOnA, maxGap)}, {bOnA}), a, b);
}

double sharedBorderLength(const core::Polygon& a, const core::Polygon& b, double tolerance) {
  detail::ScopedGdalErrors quiet;
  const GeometryPtr borderA(ogrSet({a})->Boundary());
  const GeometryPtr borderB(ogrSet({b})->Boundary());
  if (!borderA || !borderB) return 0.0;
  const GeometryPtr near(borderB->Buffer(tolerance, 2));
  if (!near) return 0.0;
  const GeometryPtr shared(borderA->Intersection(near.get()));
  if (!shared) return 0.0;
  const auto type = wkbFlatten(shared->getGeometryType());
  if (type == wkbLineString) return shared->toLineString()->get_Length();
  if (type == wkbMultiLineString) return shared->toMultiLineString()->get_Length();
  if (type == wkbGeometryCollection) {
    double length = 0.0;
    for (const auto* part : *shared->toGeometryCollection()) {
      if (wkbFlatten(part->getGeometryType()) == wkbLineString) length += part->toLineString()->get_Length();
    }
    return length;
  }
  return 0.0;
}

double perimeter(const core::Polygon& polygon) {
  auto ringLength = [](const core::Ring& ring) {
    double length = 0.0;
    for (size_t i = 0; i < ring.size(); ++i) length += cv::norm(ring[(i + 1) % ring.size()] - ring[i]);
    return length;
  };
  double length = ringLength(polygon.outer);
  for (const auto& hole : polygon.holes) length += ringLength(hole);
  return length;
}

}  // namespace delineo::io
