#include "delineo/io/vector.hpp"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <set>
#include <sstream>

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

// OGR driver for a file extension we write, empty when the extension is not one of ours.
std::string driverForExtension(const std::string& path) {
  const std::string ext = detail::lowerExtension(path);
  if (ext == ".geojson" || ext == ".json") return "GeoJSON";
  if (ext == ".gpkg") return "GPKG";
  return {};
}

// OGR driver for a file extension we read: the written ones and Shapefiles (cadastres).
std::string readDriverForExtension(const std::string& path) {
  if (detail::lowerExtension(path) == ".shp") return "ESRI Shapefile";
  return driverForExtension(path);
}

struct TransformDeleter {
  void operator()(OGRCoordinateTransformationH transform) const { OCTDestroyCoordinateTransformation(transform); }
};
using TransformPtr = std::unique_ptr<std::remove_pointer_t<OGRCoordinateTransformationH>, TransformDeleter>;

// How a layer's vertices become left-image pixels: from the layer's CRS into the image's when
// they differ, then through the image's geotransform.
struct VertexMapping {
  const GeoReference& geo;
  TransformPtr toImageCrs;  // null when the vertices are already in the image's CRS (or either has none)
  std::string failure;      // "cannot be brought from CRS A to the image's CRS B", for errors
};

std::string crsName(OGRSpatialReferenceH srs) {
  const char* name = OSRGetName(srs);
  std::string text = name != nullptr ? name : "unnamed";
  const char* authority = OSRGetAuthorityName(srs, nullptr);
  const char* code = OSRGetAuthorityCode(srs, nullptr);
  if (authority != nullptr && code != nullptr) text += std::string(" (") + authority + ":" + code + ")";
  return text;
}

// A copy of `srs` with coordinates x = easting / longitude, y = northing / latitude, as the
// geotransform and the vector files have them.
detail::SpatialReferencePtr inGisOrder(OGRSpatialReferenceH srs) {
  detail::SpatialReferencePtr copy(OSRClone(srs));
  OSRSetAxisMappingStrategy(copy.get(), OAMS_TRADITIONAL_GIS_ORDER);
  return copy;
}

// A CRS that says no more than "none": a local (engineering) one, or GeoPackage's "undefined
// geographic" srs_id 0, which GDAL gives layers written without CRS ("undefined Cartesian", -1,
// is local). Vertices in such a layer are taken as they are, as in a layer without CRS.
bool isUndefinedCrs(OGRSpatialReferenceH srs) {
  if (OSRIsLocal(srs)) return true;
  const char* name = OSRGetName(srs);
  return name != nullptr && std::string(name) == "Undefined geographic SRS" &&
         OSRGetAuthorityName(srs, nullptr) == nullptr;
}

VertexMapping layerMapping(OGRLayerH layer, const GeoReference& geo, bool isGeoJson, const std::string& path) {
  VertexMapping mapping{geo, nullptr, {}};
  OGRSpatialReferenceH layerSrs = OGR_L_GetSpatialRef(layer);
  if (!geo.valid() || geo.crsWkt.empty() || layerSrs == nullptr || isUndefinedCrs(layerSrs)) return mapping;
  detail::SpatialReferencePtr imageSrs(OSRNewSpatialReference(nullptr));
  if (OSRSetFromUserInput(imageSrs.get(), geo.crsWkt.c_str()) != OGRERR_NONE) {
    throw Error(ErrorCode::InvalidParameter, "the image's CRS is not valid WKT", path);
  }
  OSRSetAxisMappingStrategy(imageSrs.get(), OAMS_TRADITIONAL_GIS_ORDER);
  const detail::SpatialReferencePtr source = inGisOrder(layerSrs);
  if (OSRIsSame(source.get(), imageSrs.get())) return mapping;

  mapping.failure = "cannot be brought from CRS " + crsName(source.get()) + " to the image's CRS " +
                    crsName(imageSrs.get());
  // GDAL reads a GeoJSON file without a "crs" member as WGS 84 (RFC 7946), pixel files included.
  if (isGeoJson && OSRIsGeographic(source.get())) {
    mapping.failure += " (a GeoJSON file without a \"crs\" member is in WGS 84 longitude/latitude)";
  }
  detail::ScopedGdalErrors errors;
  mapping.toImageCrs.reset(OCTNewCoordinateTransformation(source.get(), imageSrs.get()));
  if (!mapping.toImageCrs) {
    const char* name = OGR_L_GetName(layer);
    throw Error(ErrorCode::UnreadableFile, errors.describe(std::string("layer '") + name + "' " + mapping.failure),
                path);
  }
  return mapping;
}

std::string formatPoint(double x, double y) {
  std::ostringstream text;
  text << std::setprecision(12) << "(" << x << ", " << y << ")";
  return text.str();
}

// Ring vertices in the image's CRS (or as they are in the file when no change is needed).
std::vector<cv::Point2d> ringInImageCrs(OGRGeometryH ring, const VertexMapping& mapping, const std::string& where,
                                        const std::string& path) {
  const int count = std::max(OGR_G_GetPointCount(ring), 0);
  std::vector<double> xs(static_cast<size_t>(count)), ys(xs.size());
  for (int i = 0; i < count; ++i) {
    xs[i] = OGR_G_GetX(ring, i);
    ys[i] = OGR_G_GetY(ring, i);
  }
  if (mapping.toImageCrs && count > 0) {
    std::vector<double> xsIn = xs, ysIn = ys;
    std::vector<int> success(xs.size(), FALSE);
    OCTTransformEx(mapping.toImageCrs.get(), count, xs.data(), ys.data(), nullptr, success.data());
    for (int i = 0; i < count; ++i) {
      if (success[i] && std::isfinite(xs[i]) && std::isfinite(ys[i])) continue;
      throw Error(ErrorCode::UnreadableFile,
                  where + " has a vertex " + formatPoint(xsIn[i], ysIn[i]) + " that " + mapping.failure, path);
    }
  }
  std::vector<cv::Point2d> points;
  points.reserve(xs.size());
  for (size_t i = 0; i < xs.size(); ++i) points.emplace_back(xs[i], ys[i]);
  return points;
}

std::string describeFeature(long long index, GIntBig fid) {
  std::string text = "feature " + std::to_string(index);
  if (fid != OGRNullFID) text += " (id " + std::to_string(fid) + ")";
  return text;
}

bool samePoint(const cv::Point2d& a, const cv::Point2d& b) { return a.x == b.x && a.y == b.y; }

// Ring vertices in pixel coordinates, without the closing repeat and consecutive duplicates.
core::Ring readRing(OGRGeometryH ring, const VertexMapping& mapping, const std::string& where,
                    const std::string& path) {
  core::Ring result;
  const std::vector<cv::Point2d> points = ringInImageCrs(ring, mapping, where, path);
  result.reserve(points.size());
  for (cv::Point2d point : points) {
    if (mapping.geo.valid()) point = mapping.geo.mapToPixel(point);
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

core::Polygon readPolygon(OGRGeometryH polygon, const VertexMapping& mapping, const std::string& where,
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
  result.outer = readRing(OGR_G_GetGeometryRef(polygon, 0), mapping, where, path);
  requireFiniteRing(result.outer, where, path);
  if (isDegenerate(result.outer)) {
    throw Error(ErrorCode::UnreadableFile,
                where + " has a degenerate polygon (fewer than 3 distinct vertices or zero area)", path);
  }
  for (int i = 1; i < rings; ++i) {
    core::Ring hole = readRing(OGR_G_GetGeometryRef(polygon, i), mapping, where, path);
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

// Opens a vector file read-only. Restricting the driver to the one the extension names gives a
// precise error ("invalid GeoJSON") instead of a generic one; other extensions may use any OGR driver.
DatasetPtr openVectorFile(const std::string& path, const detail::ScopedGdalErrors& errors) {
  if (!detail::isVirtualPath(path)) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(ErrorCode::FileNotFound, "no such file", path);
    if (std::filesystem::is_directory(path, ec)) {
      throw Error(ErrorCode::UnreadableFile, "is a directory, not a vector file", path);
    }
  }
  const std::string driverName = readDriverForExtension(path);
  CPLStringList allowedDrivers;
  if (!driverName.empty()) allowedDrivers.AddString(driverName.c_str());
  DatasetPtr dataset(GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR,
                                driverName.empty() ? nullptr : allowedDrivers.List(), nullptr, nullptr));
  if (!dataset) {
    const std::string what = driverName.empty() ? "not a readable vector file" : "not a valid " + driverName + " file";
    throw Error(ErrorCode::UnreadableFile, errors.describe(what), path);
  }
  return dataset;
}

// Appends the polygons of one feature (one per part of a MultiPolygon).
void appendFeature(OGRFeatureH feature, const VertexMapping& mapping, const std::string& where,
                   const std::string& path, std::vector<core::Feature>& features) {
  OGRGeometryH geometry = OGR_F_GetGeometryRef(feature);
  if (geometry == nullptr) throw Error(ErrorCode::UnreadableFile, where + " has no geometry", path);
  const auto attributes = readAttributes(feature);
  const OGRwkbGeometryType type = wkbFlatten(OGR_G_GetGeometryType(geometry));
  if (type == wkbPolygon) {
    features.push_back({readPolygon(geometry, mapping, where, path), attributes});
  } else if (type == wkbMultiPolygon) {
    const int parts = OGR_G_GetGeometryCount(geometry);
    if (parts == 0) throw Error(ErrorCode::UnreadableFile, where + " has an empty multipolygon", path);
    for (int p = 0; p < parts; ++p) {
      const std::string part = where + " part " + std::to_string(p);
      features.push_back({readPolygon(OGR_G_GetGeometryRef(geometry, p), mapping, part, path), attributes});
    }
  } else {
    throw Error(ErrorCode::UnsupportedInput,
                where + " has a " + OGRGeometryTypeToName(type) + " geometry; only polygons are supported", path);
  }
}

}  // namespace

std::vector<core::Feature> readFeatures(const std::string& path, const GeoReference& geo) {
  detail::ensureGdalRegistered();
  detail::ScopedGdalErrors errors;
  const DatasetPtr dataset = openVectorFile(path, errors);
  GDALDatasetH ds = dataset.get();
  const bool isGeoJson = std::string(GDALGetDriverShortName(GDALGetDatasetDriver(ds))) == "GeoJSON";

  std::vector<core::Feature> features;
  long long index = 0;
  const int layers = GDALDatasetGetLayerCount(ds);
  for (int l = 0; l < layers; ++l) {
    OGRLayerH layer = GDALDatasetGetLayer(ds, l);
    const VertexMapping mapping = layerMapping(layer, geo, isGeoJson, path);
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
      appendFeature(feature.get(), mapping, where, path, features);
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

// The feature of `definition`'s layer holding `source`'s attributes (those the layer has a field
// for) and its polygon, in map coordinates through `geo` when it is valid.
FeaturePtr ogrFeature(OGRFeatureDefnH definition, const core::Feature& source, const GeoReference& geo) {
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
  return feature;
}

// Writes the file at `path` itself; writeFeatures() points it at a temporary file.
void writeFeaturesAt(const std::string& path, const std::vector<core::Feature>& features,
                     const GeoReference& geo, const std::string& layerName) {
  detail::ensureGdalRegistered();
  const std::string driverName = driverForExtension(path);
  if (driverName.empty()) {
    // Shapefiles are read only: the DBF's 10-character field names would cut the attribute names.
    const std::string what = readDriverForExtension(path).empty()
                                 ? "unknown vector format"
                                 : "Shapefiles are read, not written (field names of at most 10 characters)";
    throw Error(ErrorCode::WriteFailed, what + ": use .geojson, .json or .gpkg", path);
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

  for (const auto& [name, kind] : fieldSchema(features)) {
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
    const FeaturePtr feature = ogrFeature(definition, features[i], geo);
    if (OGR_L_CreateFeature(layer, feature.get()) != OGRERR_NONE) fail("cannot write feature " + std::to_string(i));
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
