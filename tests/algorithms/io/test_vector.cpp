#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include <gdal.h>
#include <gtest/gtest.h>
#include <cpl_conv.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "delineo/core/error.hpp"
#include "delineo/io/vector.hpp"
#include "epsg_wkt.hpp"
#include "temp_dir.hpp"

namespace delineo::io {
namespace {

using core::ErrorCode;
using testing::TempDir;
using testing::wktOfEpsg;

using testing::captureError;

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

std::vector<core::Feature> sampleFeatures() {
  core::Feature courtyard;
  courtyard.polygon.outer = {{10.5, 20.25}, {110.5, 20.25}, {110.5, 90.75}, {10.5, 90.75}};
  courtyard.polygon.holes = {{{40, 40}, {40, 60}, {70, 60}, {70, 40}}};
  courtyard.attributes = {{"id", 7LL}, {"height", 12.5}, {"label", std::string("hall")},
                          {"note", std::monostate{}}};
  core::Feature plain;
  plain.polygon.outer = {{200, 10}, {260, 10}, {230, 55}};
  plain.attributes = {{"id", 8LL}, {"height", 3.25}, {"label", std::string("kiosk")},
                      {"note", std::string("triangle")}};
  return {courtyard, plain};
}

void expectSameRing(const core::Ring& actual, const core::Ring& expected, double tolerance) {
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(actual[i].x, expected[i].x, tolerance) << i;
    EXPECT_NEAR(actual[i].y, expected[i].y, tolerance) << i;
  }
}

void expectSameFeatures(const std::vector<core::Feature>& actual, const std::vector<core::Feature>& expected,
                        double tolerance) {
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t f = 0; f < expected.size(); ++f) {
    SCOPED_TRACE("feature " + std::to_string(f));
    expectSameRing(actual[f].polygon.outer, expected[f].polygon.outer, tolerance);
    ASSERT_EQ(actual[f].polygon.holes.size(), expected[f].polygon.holes.size());
    for (size_t h = 0; h < expected[f].polygon.holes.size(); ++h) {
      expectSameRing(actual[f].polygon.holes[h], expected[f].polygon.holes[h], tolerance);
    }
    EXPECT_EQ(actual[f].attributes, expected[f].attributes);
  }
}

// North-up 0.5 m pixels from the top-left corner (x0, y0) in EPSG `epsg`.
GeoReference halfMetreGeo(double x0, double y0, int epsg) {
  GeoReference geo;
  geo.geoTransform = {x0, 0.5, 0.0, y0, 0.0, -0.5};
  geo.hasTransform = true;
  geo.crsWkt = wktOfEpsg(epsg);
  return geo;
}

GeoReference utmGeo() { return halfMetreGeo(741000.0, 3737000.0, 32616); }

class VectorRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(VectorRoundTrip, PixelCoordinatesHolesAndAttributes) {
  TempDir dir;
  const std::string path = dir.file("buildings" + GetParam());
  const auto features = sampleFeatures();
  writeFeatures(path, features);
  expectSameFeatures(readFeatures(path), features, 0.0);
  // Writing again overwrites rather than appending or failing.
  writeFeatures(path, {features[1]});
  EXPECT_EQ(readFeatures(path).size(), 1u);
}

TEST_P(VectorRoundTrip, GeoreferencedThroughGeoTransformAndCrs) {
  TempDir dir;
  const std::string path = dir.file("geo" + GetParam());
  const GeoReference geo = utmGeo();
  const auto features = sampleFeatures();
  writeFeatures(path, features, geo);

  expectSameFeatures(readFeatures(path, geo), features, 1e-6);

  // On disk: map coordinates, and the layer carries the CRS.
  const auto mapFeatures = readFeatures(path);
  const cv::Point2d expectedCorner = geo.pixelToMap(features[0].polygon.outer[0]);
  EXPECT_NEAR(mapFeatures[0].polygon.outer[0].x, expectedCorner.x, 1e-6);
  EXPECT_NEAR(mapFeatures[0].polygon.outer[0].y, expectedCorner.y, 1e-6);
  EXPECT_NEAR(expectedCorner.x, 741005.25, 1e-9);
  GDALDatasetH ds = GDALOpenEx(path.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
  ASSERT_NE(ds, nullptr);
  OGRSpatialReferenceH srs = OGR_L_GetSpatialRef(GDALDatasetGetLayer(ds, 0));
  ASSERT_NE(srs, nullptr);
  EXPECT_STREQ(OSRGetAuthorityCode(srs, nullptr), "32616");
  GDALClose(ds);
}

INSTANTIATE_TEST_SUITE_P(Formats, VectorRoundTrip, ::testing::Values(".geojson", ".json", ".gpkg"),
                         [](const auto& paramInfo) { return paramInfo.param.substr(1); });

// A 0.5 m image over Toulouse in UTM 31N.
GeoReference toulouseGeo() { return halfMetreGeo(374000.0, 4829000.0, 32631); }

// Map coordinates of `ring` (pixels of `geo`) brought into EPSG `epsg` (x = easting / longitude).
std::vector<cv::Point2d> ringInCrs(const core::Ring& ring, const GeoReference& geo, int epsg) {
  OGRSpatialReferenceH from = OSRNewSpatialReference(geo.crsWkt.c_str());
  OGRSpatialReferenceH to = OSRNewSpatialReference(nullptr);
  OSRImportFromEPSG(to, epsg);
  OSRSetAxisMappingStrategy(from, OAMS_TRADITIONAL_GIS_ORDER);
  OSRSetAxisMappingStrategy(to, OAMS_TRADITIONAL_GIS_ORDER);
  OGRCoordinateTransformationH transform = OCTNewCoordinateTransformation(from, to);
  std::vector<cv::Point2d> result;
  for (const auto& pixel : ring) {
    cv::Point2d point = geo.pixelToMap(pixel);
    EXPECT_TRUE(OCTTransform(transform, 1, &point.x, &point.y, nullptr));
    result.push_back(point);
  }
  OCTDestroyCoordinateTransformation(transform);
  OSRDestroySpatialReference(from);
  OSRDestroySpatialReference(to);
  return result;
}

OGRGeometryH ogrRing(const std::vector<cv::Point2d>& points) {
  OGRGeometryH ring = OGR_G_CreateGeometry(wkbLinearRing);
  for (const auto& p : points) OGR_G_AddPoint_2D(ring, p.x, p.y);
  OGR_G_AddPoint_2D(ring, points.front().x, points.front().y);
  return ring;
}

// Writes `polygon` (pixels of `geo`) with OGR into a layer in EPSG `epsg`; epsg 0 writes a layer
// without CRS holding the map coordinates of `geo`.
void writePolygonInCrs(const std::string& path, const char* driverName, const GeoReference& geo, int epsg,
                       const core::Polygon& polygon) {
  const int crs = epsg == 0 ? 32631 : epsg;
  OGRSpatialReferenceH srs = nullptr;
  if (epsg != 0) {
    srs = OSRNewSpatialReference(nullptr);
    OSRImportFromEPSG(srs, epsg);
    OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
  }
  GDALAllRegister();
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName(driverName), path.c_str(), 0, 0, 0, GDT_Unknown, nullptr);
  ASSERT_NE(ds, nullptr) << path;
  OGRLayerH layer = GDALDatasetCreateLayer(ds, "outlines", srs, wkbPolygon, nullptr);
  ASSERT_NE(layer, nullptr) << path;
  OGRFeatureH feature = OGR_F_Create(OGR_L_GetLayerDefn(layer));
  OGRGeometryH geometry = OGR_G_CreateGeometry(wkbPolygon);
  OGR_G_AddGeometryDirectly(geometry, ogrRing(ringInCrs(polygon.outer, geo, crs)));
  for (const auto& hole : polygon.holes) OGR_G_AddGeometryDirectly(geometry, ogrRing(ringInCrs(hole, geo, crs)));
  OGR_F_SetGeometryDirectly(feature, geometry);
  EXPECT_EQ(OGR_L_CreateFeature(layer, feature), OGRERR_NONE);
  OGR_F_Destroy(feature);
  GDALClose(ds);
  if (srs != nullptr) OSRDestroySpatialReference(srs);
}

struct CrsCase {
  const char* extension;
  const char* driver;
  int epsg;
};

class VectorInAnotherCrs : public ::testing::TestWithParam<CrsCase> {};

TEST_P(VectorInAnotherCrs, ReadsToTheSamePixelsAsInTheImageCrs) {
  TempDir dir;
  const GeoReference geo = toulouseGeo();
  const core::Polygon courtyard = sampleFeatures()[0].polygon;
  const std::string path = dir.file("outlines" + std::string(GetParam().extension));
  writePolygonInCrs(path, GetParam().driver, geo, GetParam().epsg, courtyard);
  const auto raw = readFeatures(path);
  ASSERT_EQ(raw.size(), 1u);
  const double offset = cv::norm(raw[0].polygon.outer[0] - geo.pixelToMap(courtyard.outer[0]));
  if (GetParam().epsg != 32631) {
    EXPECT_GT(offset, 1.0) << "the file holds the image's map coordinates";
  }

  const auto features = readFeatures(path, geo);
  ASSERT_EQ(features.size(), 1u);
  expectSameRing(features[0].polygon.outer, courtyard.outer, 1e-3);
  ASSERT_EQ(features[0].polygon.holes.size(), 1u);
  expectSameRing(features[0].polygon.holes[0], courtyard.holes[0], 1e-3);
}

INSTANTIATE_TEST_SUITE_P(Crs, VectorInAnotherCrs,
                         ::testing::Values(CrsCase{".geojson", "GeoJSON", 4326}, CrsCase{".geojson", "GeoJSON", 2154},
                                           CrsCase{".gpkg", "GPKG", 4326}, CrsCase{".gpkg", "GPKG", 2154},
                                           CrsCase{".shp", "ESRI Shapefile", 2154},
                                           CrsCase{".shp", "ESRI Shapefile", 32631}),
                         [](const auto& paramInfo) {
                           return std::string(paramInfo.param.extension + 1) + "_" + std::to_string(paramInfo.param.epsg);
                         });

TEST(VectorCrs, AnRfc7946FileWithoutCrsMemberIsLongitudeLatitude) {
  TempDir dir;
  const GeoReference geo = toulouseGeo();
  const core::Ring square = {{100, 100}, {300, 100}, {300, 250}, {100, 250}};
  std::ostringstream text;
  text << std::setprecision(17)
       << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[)";
  const auto lonLat = ringInCrs(square, geo, 4326);
  for (size_t i = 0; i <= lonLat.size(); ++i) {
    const cv::Point2d& p = lonLat[i % lonLat.size()];
    text << (i ? "," : "") << "[" << p.x << "," << p.y << "]";
  }
  text << "]]}}]}";
  const std::string path = dir.file("rfc7946.geojson");
  writeText(path, text.str());
  EXPECT_NEAR(lonLat[0].x, 1.43, 0.05);  // Toulouse, longitude first
  EXPECT_NEAR(lonLat[0].y, 43.6, 0.05);
  const auto features = readFeatures(path, geo);
  ASSERT_EQ(features.size(), 1u);
  expectSameRing(features[0].polygon.outer, square, 1e-3);
}

TEST(VectorCrs, FilesWithoutCrsOrAnImageWithoutCrsReadAsBefore) {
  TempDir dir;
  GeoReference geo = toulouseGeo();
  const core::Polygon courtyard = sampleFeatures()[0].polygon;
  // Layers without CRS holding the image's map coordinates: only the geotransform applies.
  for (const auto& [name, driver] : {std::pair{"plain.shp", "ESRI Shapefile"}, std::pair{"plain.gpkg", "GPKG"}}) {
    writePolygonInCrs(dir.file(name), driver, geo, 0, courtyard);
    const auto features = readFeatures(dir.file(name), geo);
    ASSERT_EQ(features.size(), 1u) << name;
    expectSameRing(features[0].polygon.outer, courtyard.outer, 1e-6);
  }
  // GeoPackages written without a GeoReference: GDAL gives their layer GeoPackage's "undefined
  // geographic" CRS, which is no CRS either.
  const std::string pixels = dir.file("pixels.gpkg");
  writeFeatures(pixels, {sampleFeatures()[1]});
  const auto pixelFeatures = readFeatures(pixels, geo);
  ASSERT_EQ(pixelFeatures.size(), 1u);
  EXPECT_EQ(pixelFeatures[0].polygon.outer[0], geo.mapToPixel(sampleFeatures()[1].polygon.outer[0]));

  // A layer in WGS 84 over an image whose CRS is unknown: coordinates taken as they are.
  const std::string lonLat = dir.file("wgs84.gpkg");
  writePolygonInCrs(lonLat, "GPKG", geo, 4326, courtyard);
  const auto raw = readFeatures(lonLat);
  geo.crsWkt.clear();
  geo.geoTransform = {1.4, 1e-6, 0.0, 43.7, 0.0, -1e-6};
  const auto unknownCrs = readFeatures(lonLat, geo);
  ASSERT_EQ(raw.size(), 1u);
  ASSERT_EQ(unknownCrs.size(), 1u);
  for (size_t i = 0; i < raw[0].polygon.outer.size(); ++i) {
    const cv::Point2d expected = geo.mapToPixel(raw[0].polygon.outer[i]);
    EXPECT_EQ(unknownCrs[0].polygon.outer[i], expected) << i;
  }
}

TEST(VectorCrs, PixelCoordinatesThatAreNoLongitudeLatitudeAreRefusedNamingTheFeature) {
  TempDir dir;
  // Our own files without a GeoReference: pixel coordinates, no "crs" member, so WGS 84 to GDAL.
  const std::string path = dir.file("pixels.geojson");
  const auto features = sampleFeatures();
  writeFeatures(path, features);
  expectSameFeatures(readFeatures(path), features, 0.0);  // without an image CRS, as they are

  const core::Error error = captureError([&] { readFeatures(path, toulouseGeo()); });
  EXPECT_EQ(error.code(), ErrorCode::UnreadableFile) << error.what();
  EXPECT_EQ(error.path(), path);
  EXPECT_NE(error.detail().find("feature 0"), std::string::npos) << error.what();
  EXPECT_NE(error.detail().find("cannot be brought from CRS WGS 84"), std::string::npos) << error.what();
  EXPECT_NE(error.detail().find("UTM zone 31N"), std::string::npos) << error.what();
}

TEST(VectorIo, MultiPolygonGivesOneFeaturePerPart) {
  TempDir dir;
  const std::string path = dir.file("multi.geojson");
  writeText(path, R"({"type":"FeatureCollection","features":[
    {"type":"Feature","properties":{"name":"pair"},"geometry":{"type":"MultiPolygon","coordinates":[
      [[[0,0],[10,0],[10,10],[0,10],[0,0]]],
      [[[20,0],[30,0],[30,10],[20,10],[20,0]],[[22,2],[22,4],[24,4],[24,2],[22,2]]]]}}]})");
  const auto features = readFeatures(path);
  ASSERT_EQ(features.size(), 2u);
  EXPECT_EQ(features[0].polygon.outer.size(), 4u);  // closing vertex dropped
  EXPECT_TRUE(features[0].polygon.holes.empty());
  ASSERT_EQ(features[1].polygon.holes.size(), 1u);
  EXPECT_DOUBLE_EQ(core::area(features[1].polygon), 96.0);
  for (const auto& feature : features) {
    EXPECT_EQ(std::get<std::string>(feature.attributes.at("name")), "pair");
  }
}

TEST(VectorIoErrors, MissingFile) {
  TempDir dir;
  const std::string path = dir.file("absent.geojson");
  const core::Error error = captureError([&] { readFeatures(path); });
  EXPECT_EQ(error.code(), ErrorCode::FileNotFound);
  EXPECT_EQ(error.path(), path);
}

TEST(VectorIoErrors, InvalidGeoJsonAndNotAVectorFile) {
  TempDir dir;
  writeText(dir.file("broken.geojson"), R"({"type":"FeatureCollection","features":[{"type":)");
  writeText(dir.file("text.json"), "hello, this is not json");
  writeText(dir.file("fake.gpkg"), "not a sqlite database either");
  for (const char* name : {"broken.geojson", "text.json", "fake.gpkg"}) {
    const core::Error error = captureError([&] { readFeatures(dir.file(name)); });
    EXPECT_EQ(error.code(), ErrorCode::UnreadableFile) << name << ": " << error.what();
    EXPECT_NE(std::string(error.what()).find(dir.file(name)), std::string::npos);
  }
}

TEST(VectorIoErrors, DegenerateAndEmptyPolygonsNameTheFeature) {
  TempDir dir;
  const std::string collinear = dir.file("collinear.geojson");
  writeText(collinear, R"({"type":"FeatureCollection","features":[
    {"type":"Feature","id":3,"properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[4,0],[4,4],[0,0]]]}},
    {"type":"Feature","id":42,"properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[1,1],[2,2],[0,0]]]}}]})");
  const core::Error flat = captureError([&] { readFeatures(collinear); });
  EXPECT_EQ(flat.code(), ErrorCode::UnreadableFile);
  EXPECT_NE(flat.detail().find("feature 1"), std::string::npos) << flat.what();
  EXPECT_NE(flat.detail().find("42"), std::string::npos) << flat.what();

  const std::string twoPoints = dir.file("two_points.geojson");
  writeText(twoPoints, R"({"type":"FeatureCollection","features":[
    {"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[5,5],[5,5],[0,0]]]}}]})");
  const core::Error tooFew = captureError([&] { readFeatures(twoPoints); });
  EXPECT_EQ(tooFew.code(), ErrorCode::UnreadableFile);
  EXPECT_NE(tooFew.detail().find("feature 0"), std::string::npos) << tooFew.what();

  const std::string empty = dir.file("empty.geojson");
  writeText(empty, R"({"type":"FeatureCollection","features":[
    {"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[]}}]})");
  const core::Error none = captureError([&] { readFeatures(empty); });
  EXPECT_EQ(none.code(), ErrorCode::UnreadableFile) << none.what();
  EXPECT_NE(none.detail().find("feature 0"), std::string::npos) << none.what();
}

TEST(VectorIoErrors, ANonFiniteVertexIsRefusedNamingTheFeature) {
  TempDir dir;
  const std::string path = dir.file("nan.geojson");
  writeText(path, R"({"type":"FeatureCollection","features":[
    {"type":"Feature","id":5,"properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[NaN,0],[4,4],[0,4],[0,0]]]}}]})");
  const core::Error error = captureError([&] { readFeatures(path); });
  EXPECT_TRUE(error.code() == ErrorCode::UnreadableFile) << error.what();
  EXPECT_NE(std::string(error.what()).find("feature 0"), std::string::npos) << error.what();
}

TEST(VectorIoErrors, APolygonWithTooManyVerticesIsRefusedAtOnce) {
  TempDir dir;
  const std::string path = dir.file("huge.geojson");
  std::ostringstream text;
  text << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},)"
       << R"("geometry":{"type":"Polygon","coordinates":[[)";
  const int n = 60000;
  for (int i = 0; i <= n; ++i) {
    const double a = 2 * 3.14159265358979 * (i % n) / n;
    text << (i ? "," : "") << "[" << 1000 + 900 * std::cos(a) << "," << 1000 + 900 * std::sin(a) << "]";
  }
  text << "]]}}]}";
  writeText(path, text.str());
  const core::Error error = captureError([&] { readFeatures(path); });
  EXPECT_EQ(error.code(), ErrorCode::UnsupportedInput) << error.what();
  EXPECT_NE(error.detail().find("at most 50000"), std::string::npos) << error.what();
}

TEST(VectorIoErrors, NonPolygonGeometry) {
  TempDir dir;
  const std::string path = dir.file("lines.geojson");
  writeText(path, R"({"type":"FeatureCollection","features":[
    {"type":"Feature","properties":{},"geometry":{"type":"LineString","coordinates":[[0,0],[5,5]]}}]})");
  const core::Error error = captureError([&] { readFeatures(path); });
  EXPECT_EQ(error.code(), ErrorCode::UnsupportedInput);
  EXPECT_NE(error.detail().find("Line String"), std::string::npos) << error.what();
}

TEST(VectorIoErrors, WriteFailures) {
  TempDir dir;
  const auto features = sampleFeatures();
  for (const char* name : {"no/such/dir/out.geojson", "no/such/dir/out.gpkg"}) {
    const core::Error error = captureError([&] { writeFeatures(dir.file(name), features); });
    EXPECT_EQ(error.code(), ErrorCode::WriteFailed) << error.what();
    EXPECT_EQ(error.path(), dir.file(name));
  }
  const core::Error shapefile = captureError([&] { writeFeatures(dir.file("out.shp"), features); });
  EXPECT_EQ(shapefile.code(), ErrorCode::WriteFailed);
  EXPECT_NE(shapefile.detail().find("use .geojson, .json or .gpkg"), std::string::npos) << shapefile.what();
}

}  // namespace
}  // namespace delineo::io
