#include <cmath>
#include <fstream>
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
#include "temp_dir.hpp"

namespace delineo::io {
namespace {

using core::ErrorCode;
using testing::TempDir;

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

GeoReference utmGeo() {
  GeoReference geo;
  geo.geoTransform = {741000.0, 0.5, 0.0, 3737000.0, 0.0, -0.5};
  geo.hasTransform = true;
  OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
  OSRImportFromEPSG(srs, 32616);
  char* wkt = nullptr;
  OSRExportToWkt(srs, &wkt);
  geo.crsWkt = wkt;
  CPLFree(wkt);
  OSRDestroySpatialReference(srs);
  return geo;
}

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
  EXPECT_EQ(captureError([&] { writeFeatures(dir.file("out.shp"), features); }).code(), ErrorCode::WriteFailed);
}

}  // namespace
}  // namespace delineo::io
