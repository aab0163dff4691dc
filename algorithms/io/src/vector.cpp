#include "delineo/io/vector.hpp"

#include <cmath>
#include <filesystem>
#include <memory>
#include <set>

#include <cpl_string.h>
#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "delineo/core/error.hpp"
#include "delineo/io/output_file.hpp"
#include "gdal_support.hpp"

namespace delineo::io {

using core::Error;
using core::ErrorCode;

namespace {

using DatasetPtr = std::unique_ptr<void, detail::DatasetCloser>;

struct FeatureDeleter {
  void operator()(OGRFeatureH feature) const { OGR_F_Destroy(feature); }
};
using FeaturePtr = std::unique_ptr<std::remove_pointer_t<OGRFeatureH>, FeatureDeleter>;

// OGR driver for a file extension, empty when the extension is not one of ours.
std::string driverForExtension(const std::string& path) {
  const std::string ext = detail::lowerExtension(path);
  if (ext == ".geojson" || ext == ".json") return "GeoJSON";
  if (ext == ".gpkg") return "GPKG";
  return {};
}

std::string describeFeature(long long index, GIntBig fid) {
  std::string text = "feature " + std::to_string(index);
  if (fid != OGRNullFID) text += " (id " + std::to_string(fid) + ")";
  return text;
}

bool samePoint(const cv::Point2d& a, const cv::Point2d& b) { return a.x == b.x && a.y == b.y; }

// Ring vertices in pixel coordinates, without the closing repeat and consecutive duplicates.
core::Ring readRing(OGRGeometryH ring, const GeoReference& geo) {
  core::Ring result;
  const int count = OGR_G_GetPointCount(ring);
  result.reserve(static_cast<size_t>(std::max(count, 0)));
  for (int i = 0; i < count; ++i) {
    cv::Point2d point(OGR_G_GetX(ring, i), OGR_G_GetY(ring, i));
    if (geo.valid()) point = geo.mapToPixel(point);
    if (!result.empty() && samePoint(result.back(), point)) continue;
    result.push_back(point);
  }
  while (result.size() > 1 && samePoint(result.front(), result.back())) result.pop_back();
  return result;
}

// A ring is degenerate with fewer than 3 distinct vertices or (numerically) zero area.
bool isDegenerate(const core::Ring& ring) {
  if (ring.size() < 3) return true;
  const cv::Rect2d box = core::boundingBox(ring);
  const double boxArea = box.width * box.height;
  if (!(boxArea > 0.0)) return true;
  // Relative to the bounding box so the test does not depend on the coordinate scale.
  return std::abs(core::signedArea(ring)) <= 1e-12 * boxArea;
}

// Vertices of one polygon, rings together: far beyond any building outline, and what the
// outline algorithms can take without running for minutes.
constexpr int kMaxPolygonVertices = 50000;

void requireFiniteRing(const core::Ring& ring, const std::string& where, const std::string& path) {
  for (const auto& p : ring) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      throw Error(ErrorCode::UnreadableFile, where + " has a vertex that is not a finite number", path);
    }
  }
}

core::Polygon readPolygon(OGRGeometryH polygon, const GeoReference& geo, const std::string& where,
                          const std::string& path) {
  const int rings = OGR_G_GetGeometryCount(polygon);
  if (OGR_G_IsEmpty(polygon) || rings == 0) {
    throw Error(ErrorCode::UnreadableFile, where + " has an empty polygon", path);
  }
  long long vertices = 0;
  for (int i = 0; i < rings; ++i) vertices += OGR_G_GetPointCount(OGR_G_GetGeometryRef(polygon, i));
  if (vertices > kMaxPolygonVertices) {
    throw Error(ErrorCode::UnsupportedInput,
                where + " has " + std::to_string(vertices) + " vertices; at most " +
                    std::to_string(kMaxPolygonVertices) + " are supported (simplify it first)",
                path);
  }
  core::Polygon result;
  result.outer = readRing(OGR_G_GetGeometryRef(polygon, 0), geo);
  requireFiniteRing(result.outer, where, path);
  if (isDegenerate(result.outer)) {
    throw Error(ErrorCode::UnreadableFile,
                where + " has a degenerate polygon (fewer than 3 distinct vertices or zero area)", path);
  }
  for (int i = 1; i < rings; ++i) {
    core::Ring hole = readRing(OGR_G_GetGeometryRef(polygon, i), geo);
    requireFiniteRing(hole, where, path);
    if (isDegenerate(hole)) {
      throw Error(ErrorCode::UnreadableFile, where + " has a degenerate hole (ring " + std::to_string(i) + ")",
                  path);
    }
    result.holes.push_back(std::move(hole));
  }
  return result;
}

std::map<std::string, core::AttributeValue> readAttributes(OGRFeatureH feature) {
  std::map<std::string, core::AttributeValue> attributes;
  const int fields = OGR_F_GetFieldCount(feature);
  for (int i = 0; i < fields; ++i) {
    OGRFieldDefnH field = OGR_F_GetFieldDefnRef(feature, i);
    const std::string name = OGR_Fld_GetNameRef(field);
    if (!OGR_F_IsFieldSetAndNotNull(feature, i)) {
      attributes[name] = std::monostate{};
      continue;
    }
    switch (OGR_Fld_GetType(field)) {
      case OFTInteger:
      case OFTInteger64: attributes[name] = static_cast<long long>(OGR_F_GetFieldAsInteger64(feature, i)); break;
      case OFTReal: attributes[name] = OGR_F_GetFieldAsDouble(feature, i); break;
      default: attributes[name] = std::string(OGR_F_GetFieldAsString(feature, i)); break;
    }
  }
  return attributes;
}

}  // namespace

std::vector<core::Feature> readFeatures(const std::string& path, const GeoReference& geo) {
  detail::ensureGdalRegistered();
  if (!detail::isVirtualPath(path)) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(ErrorCode::FileNotFound, "no such file", path);
    if (std::filesystem::is_directory(path, ec)) {
      throw Error(ErrorCode::UnreadableFile, "is a directory, not a vector file", path);
    }
  }
  detail::ScopedGdalErrors errors;
  // Restricting the driver to the one the extension names gives a precise error ("invalid
  // GeoJSON") instead of a generic one; other extensions may use any OGR driver.
  const std::string driverName = driverForExtension(path);
  CPLStringList allowedDrivers;
  if (!driverName.empty()) allowedDrivers.AddString(driverName.c_str());
  DatasetPtr dataset(GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR,
                                driverName.empty() ? nullptr : allowedDrivers.List(), nullptr, nullptr));
  if (!dataset) {
    const std::string what = driverName.empty() ? "not a readable vector file" : "not a valid " + driverName + " file";
    throw Error(ErrorCode::UnreadableFile, errors.describe(what), path);
  }
  GDALDatasetH ds = dataset.get();

  std::vector<core::Feature> features;
  long long index = 0;
  const int layers = GDALDatasetGetLayerCount(ds);
  for (int l = 0; l < layers; ++l) {
    OGRLayerH layer = GDALDatasetGetLayer(ds, l);
    OGR_L_ResetReading(layer);
    while (true) {
      errors.reset();
      FeaturePtr feature(OGR_L_GetNextFeature(layer));
      if (!feature) {
        if (errors.failed()) throw Error(ErrorCode::UnreadableFile, errors.describe("cannot read features"), path);
        break;
      }
      const std::string where = describeFeature(index, OGR_F_GetFID(feature.get()));
      ++index;
      OGRGeometryH geometry = OGR_F_GetGeometryRef(feature.get());
      if (geometry == nullptr) throw Error(ErrorCode::UnreadableFile, where + " has no geometry", path);
      const auto attributes = readAttributes(feature.get());
      const OGRwkbGeometryType type = wkbFlatten(OGR_G_GetGeometryType(geometry));
      if (type == wkbPolygon) {
        features.push_back({readPolygon(geometry, geo, where, path), attributes});
      } else if (type == wkbMultiPolygon) {
        const int parts = OGR_G_GetGeometryCount(geometry);
        if (parts == 0) throw Error(ErrorCode::UnreadableFile, where + " has an empty multipolygon", path);
        for (int p = 0; p < parts; ++p) {
          const std::string part = where + " part " + std::to_string(p);
          features.push_back({readPolygon(OGR_G_GetGeometryRef(geometry, p), geo, part, path), attributes});
        }
      } else {
        throw Error(ErrorCode::UnsupportedInput,
                    where + " has a " + OGRGeometryTypeToName(type) + " geometry; only polygons are supported",
                    path);
      }
    }
  }
  return features;
}

namespace {

enum class FieldKind { Integer, Real, String };

// One field type per attribute name over all features: integers widen to real when mixed with
// reals, and anything mixed with text becomes text.
std::map<std::string, FieldKind> fieldSchema(const std::vector<core::Feature>& features) {
  std::map<std::string, FieldKind> schema;
  std::set<std::string> seen;
  for (const auto& feature : features) {
    for (const auto& [name, value] : feature.attributes) {
      seen.insert(name);
      if (std::holds_alternative<std::monostate>(value)) continue;
      const FieldKind kind = std::holds_alternative<long long>(value) ? FieldKind::Integer
                             : std::holds_alternative<double>(value) ? FieldKind::Real
                                                                     : FieldKind::String;
      auto [it, inserted] = schema.emplace(name, kind);
      if (!inserted && it->second != kind) it->second = std::max(it->second, kind);
    }
  }
  for (const auto& name : seen) schema.emplace(name, FieldKind::String);  // only nulls: text
  return schema;
}

OGRGeometryH makeRing(const core::Ring& ring, const GeoReference& geo) {
  OGRGeometryH result = OGR_G_CreateGeometry(wkbLinearRing);
  for (const auto& vertex : ring) {
    const cv::Point2d point = geo.valid() ? geo.pixelToMap(vertex) : vertex;
    OGR_G_AddPoint_2D(result, point.x, point.y);
  }
  if (!ring.empty()) {
    const cv::Point2d first = geo.valid() ? geo.pixelToMap(ring.front()) : ring.front();
    OGR_G_AddPoint_2D(result, first.x, first.y);
  }
  return result;
}

// Writes the file at `path` itself; writeFeatures() points it at a temporary file.
void writeFeaturesAt(const std::string& path, const std::vector<core::Feature>& features,
                     const GeoReference& geo, const std::string& layerName) {
  detail::ensureGdalRegistered();
  const std::string driverName = driverForExtension(path);
  if (driverName.empty()) {
    throw Error(ErrorCode::WriteFailed, "unknown vector format: use .geojson, .json or .gpkg", path);
  }
  detail::ScopedGdalErrors errors;
  GDALDriverH driver = GDALGetDriverByName(driverName.c_str());
  if (driver == nullptr) throw Error(ErrorCode::WriteFailed, "GDAL has no " + driverName + " driver", path);

  if (!detail::isVirtualPath(path)) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw Error(ErrorCode::WriteFailed, "is a directory", path);
    // Both drivers refuse (GeoJSON) or append to (GPKG) an existing file; we overwrite.
    std::filesystem::remove(path, ec);
  }
  DatasetPtr dataset(GDALCreate(driver, path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  if (!dataset) throw Error(ErrorCode::WriteFailed, errors.describe("cannot create the file"), path);
  GDALDatasetH ds = dataset.get();

  auto fail = [&](const std::string& what) {
    const std::string message = errors.describe(what);
    dataset.reset();
    std::error_code ec;
    if (!detail::isVirtualPath(path)) std::filesystem::remove(path, ec);
    throw Error(ErrorCode::WriteFailed, message, path);
  };

  detail::SpatialReferencePtr srs;
  if (geo.valid() && !geo.crsWkt.empty()) {
    srs.reset(OSRNewSpatialReference(nullptr));
    if (OSRSetFromUserInput(srs.get(), geo.crsWkt.c_str()) != OGRERR_NONE) fail("the CRS is not valid WKT");
    // Coordinates are written x = easting / longitude, y = northing / latitude.
    OSRSetAxisMappingStrategy(srs.get(), OAMS_TRADITIONAL_GIS_ORDER);
  }
  OGRLayerH layer = GDALDatasetCreateLayer(ds, layerName.c_str(), srs.get(), wkbPolygon, nullptr);
  if (layer == nullptr) fail("cannot create layer '" + layerName + "'");

  const auto schema = fieldSchema(features);
  for (const auto& [name, kind] : schema) {
    const OGRFieldType type = kind == FieldKind::Integer ? OFTInteger64 : kind == FieldKind::Real ? OFTReal : OFTString;
    OGRFieldDefnH field = OGR_Fld_Create(name.c_str(), type);
    const OGRErr status = OGR_L_CreateField(layer, field, TRUE);
    OGR_Fld_Destroy(field);
    if (status != OGRERR_NONE) fail("cannot create field '" + name + "'");
  }

  // One transaction makes GeoPackage writes fast; GeoJSON ignores it.
  const bool inTransaction = GDALDatasetStartTransaction(ds, FALSE) == OGRERR_NONE;
  OGRFeatureDefnH definition = OGR_L_GetLayerDefn(layer);
  for (size_t i = 0; i < features.size(); ++i) {
    const core::Feature& source = features[i];
    FeaturePtr feature(OGR_F_Create(definition));
    for (const auto& [name, value] : source.attributes) {
      const int fieldIndex = OGR_F_GetFieldIndex(feature.get(), name.c_str());
      if (fieldIndex < 0) continue;
      if (std::holds_alternative<std::monostate>(value)) {
        OGR_F_SetFieldNull(feature.get(), fieldIndex);
      } else if (const auto* integer = std::get_if<long long>(&value)) {
        OGR_F_SetFieldInteger64(feature.get(), fieldIndex, *integer);
      } else if (const auto* real = std::get_if<double>(&value)) {
        OGR_F_SetFieldDouble(feature.get(), fieldIndex, *real);
      } else {
        OGR_F_SetFieldString(feature.get(), fieldIndex, std::get<std::string>(value).c_str());
      }
    }
    OGRGeometryH polygon = OGR_G_CreateGeometry(wkbPolygon);
    OGR_G_AddGeometryDirectly(polygon, makeRing(source.polygon.outer, geo));
    for (const auto& hole : source.polygon.holes) OGR_G_AddGeometryDirectly(polygon, makeRing(hole, geo));
    OGR_F_SetGeometryDirectly(feature.get(), polygon);
    if (OGR_L_CreateFeature(layer, feature.get()) != OGRERR_NONE) {
      fail("cannot write feature " + std::to_string(i));
    }
  }
  if (inTransaction && GDALDatasetCommitTransaction(ds) != OGRERR_NONE) fail("cannot commit the features");
  errors.reset();
  dataset.reset();  // closing flushes GeoJSON text / finalises the GeoPackage
  if (errors.failed()) {
    const std::string message = errors.describe("cannot finish the file");
    std::error_code ec;
    if (!detail::isVirtualPath(path)) std::filesystem::remove(path, ec);
    throw Error(ErrorCode::WriteFailed, message, path);
  }
}

}  // namespace

void writeFeatures(const std::string& path, const std::vector<core::Feature>& features, const GeoReference& geo,
                   const std::string& layerName) {
  writeAtomically(path, [&](const std::string& file) { writeFeaturesAt(file, features, geo, layerName); });
}

}  // namespace delineo::io
