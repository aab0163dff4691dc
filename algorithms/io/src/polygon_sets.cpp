#include "delineo/io/polygon_sets.hpp"

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
