#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <cpl_conv.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <ogr_srs_api.h>

#include "delineo/core/error.hpp"
#include "delineo/io/cityjson.hpp"
#include "temp_dir.hpp"

namespace delineo::io {
namespace {

using core::ErrorCode;
using testing::captureError;
using testing::TempDir;
using Vec3 = std::array<double, 3>;

constexpr double kPixelSize = 0.5;   // m per pixel of the local frame
constexpr double kSquareRoof = 6.5;  // m
constexpr double kLRoof = 12.25;     // m

core::Feature building(long long id, core::Polygon polygon, std::optional<double> roof) {
  core::Feature f;
  f.polygon = std::move(polygon);
  f.attributes["id"] = id;
  f.attributes["status"] = std::string("accepted");
  f.attributes["method"] = std::string("active-polygon");
  if (roof) f.attributes["roof_height_m"] = *roof;
  return f;
}

// A 20 x 20 px square; clockwise on screen (y down), so the writer has to orient it.
core::Polygon square() { return {{{10, 10}, {30, 10}, {30, 30}, {10, 30}}, {}}; }

// An L of two 60 px arms with a 10 x 10 px courtyard in the corner block; the outline is
// counter-clockwise on screen and so is the hole, which the writer has to turn.
core::Polygon lShapeWithCourtyard() {
  return {{{100, 10}, {100, 70}, {160, 70}, {160, 50}, {120, 50}, {120, 10}}, {{{105, 55}, {105, 65}, {115, 65}, {115, 55}}}};
}

CityJsonOptions localFrame() {
  CityJsonOptions options;
  options.localPixelSize = kPixelSize;
  return options;
}

std::vector<core::Feature> sampleBuildings() {
  return {building(1, square(), kSquareRoof), building(2, lShapeWithCourtyard(), kLRoof),
          building(3, square(), std::nullopt), building(4, square(), 0.0)};
}

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);  // throws on invalid JSON
}

// The file's vertices with the transform applied.
std::vector<Vec3> decodedVertices(const nlohmann::json& city) {
  std::vector<Vec3> out;
  const auto& scale = city["transform"]["scale"];
  const auto& translate = city["transform"]["translate"];
  for (const auto& v : city["vertices"]) {
    Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = translate[a].get<double>() + scale[a].get<double>() * v[a].get<double>();
    out.push_back(p);
  }
  return out;
}

// Newell's normal of a ring (not normalised): the right-hand rule's direction.
Vec3 newellNormal(const nlohmann::json& ring, const std::vector<Vec3>& vertices) {
  Vec3 n{0, 0, 0};
  for (size_t i = 0; i < ring.size(); ++i) {
    const Vec3& a = vertices.at(ring[i].get<size_t>());
    const Vec3& b = vertices.at(ring[(i + 1) % ring.size()].get<size_t>());
    n[0] += (a[1] - b[1]) * (a[2] + b[2]);
    n[1] += (a[2] - b[2]) * (a[0] + b[0]);
    n[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  return n;
}

// Even-odd test of (x, y) against rings given in the output frame.
bool insideRings(const std::vector<std::vector<cv::Point2d>>& rings, double x, double y) {
  bool inside = false;
  for (const auto& ring : rings) {
    for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
      const cv::Point2d& a = ring[i];
      const cv::Point2d& b = ring[j];
      if ((a.y > y) != (b.y > y) && x < (b.x - a.x) * (y - a.y) / (b.y - a.y) + a.x) inside = !inside;
    }
  }
  return inside;
}

// The block the test expects, independent of the file: footprint in the output frame, 0..roof.
struct ExpectedBlock {
  std::vector<std::vector<cv::Point2d>> rings;
  double roof = 0;
  bool contains(const Vec3& p) const { return p[2] > 0 && p[2] < roof && insideRings(rings, p[0], p[1]); }
};

ExpectedBlock expectedBlock(const core::Polygon& polygon, double roof, const std::function<cv::Point2d(cv::Point2d)>& toFrame) {
  ExpectedBlock block;
  block.roof = roof;
  auto ring = [&](const core::Ring& r) {
    std::vector<cv::Point2d> out;
    for (const auto& p : r) out.push_back(toFrame(p));
    return out;
  };
  block.rings.push_back(ring(polygon.outer));
  for (const auto& hole : polygon.holes) block.rings.push_back(ring(hole));
  return block;
}

// A point of the surface away from its edges: the middle of a wall; for the ground and the
// roof, a point inside the footprint (the middle of a sliver along the outline's first edge).
Vec3 pointOnSurface(const nlohmann::json& surface, const std::vector<Vec3>& vertices, const ExpectedBlock& block) {
  const auto& ring = surface[0];
  const Vec3& a = vertices.at(ring[0].get<size_t>());
  if (ring.size() == 4 && std::abs(vertices.at(ring[2].get<size_t>())[2] - a[2]) > 0) {
    const Vec3& c = vertices.at(ring[2].get<size_t>());
    return {(a[0] + c[0]) / 2, (a[1] + c[1]) / 2, (a[2] + c[2]) / 2};
  }
  const cv::Point2d p = block.rings[0][0], q = block.rings[0][1];
  const cv::Point2d mid = (p + q) * 0.5, normal(-(q.y - p.y), q.x - p.x);
  for (double side : {1e-3, -1e-3}) {
    const cv::Point2d probe = mid + normal * side;
    if (insideRings(block.rings, probe.x, probe.y)) return {probe.x, probe.y, a[2]};
  }
  ADD_FAILURE() << "no point inside the footprint next to its first edge";
  return a;
}

// Every surface's normal points out of the block: a step along it leaves the solid, a step
// against it enters it.
void expectOutwardSurfaces(const nlohmann::json& shell, const std::vector<Vec3>& vertices, const ExpectedBlock& block) {
  for (size_t s = 0; s < shell.size(); ++s) {
    const Vec3 n = newellNormal(shell[s][0], vertices);
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    ASSERT_GT(length, 0.0) << "surface " << s << " has no area";
    const Vec3 p = pointOnSurface(shell[s], vertices, block);
    const double step = 0.01;
    const Vec3 out{p[0] + step * n[0] / length, p[1] + step * n[1] / length, p[2] + step * n[2] / length};
    const Vec3 in{p[0] - step * n[0] / length, p[1] - step * n[1] / length, p[2] - step * n[2] / length};
    EXPECT_FALSE(block.contains(out)) << "surface " << s << " faces into the solid";
    EXPECT_TRUE(block.contains(in)) << "surface " << s << " faces away from a solid behind it";
  }
}

// The shell is closed and consistently oriented: every directed edge of a ring is walked once,
// and once in the opposite direction by the neighbouring surface.
void expectClosedShell(const nlohmann::json& shell) {
  std::map<std::pair<int, int>, int> edges;
  for (const auto& surface : shell) {
    for (const auto& ring : surface) {
      for (size_t i = 0; i < ring.size(); ++i) ++edges[{ring[i].get<int>(), ring[(i + 1) % ring.size()].get<int>()}];
    }
  }
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1) << "edge " << edge.first << "-" << edge.second << " walked " << count << " times";
    const auto reverse = edges.find({edge.second, edge.first});
    EXPECT_TRUE(reverse != edges.end() && reverse->second == 1)
        << "edge " << edge.first << "-" << edge.second << " has no opposite";
  }
}

// The checks every written file passes, whatever the frame.
void expectBlocks(const nlohmann::json& city, const std::function<cv::Point2d(cv::Point2d)>& toFrame) {
  ASSERT_EQ(city["type"], "CityJSON");
  EXPECT_EQ(city["version"], "1.1");
  ASSERT_EQ(city["CityObjects"].size(), 2u);
  const std::vector<Vec3> vertices = decodedVertices(city);
  // 4 + 6 outline vertices and 4 hole vertices, each at the ground and at the roof, once each.
  EXPECT_EQ(vertices.size(), 2u * (4 + 6 + 4));
  std::set<std::vector<long long>> distinct;
  for (const auto& v : city["vertices"]) distinct.insert(v.get<std::vector<long long>>());
  EXPECT_EQ(distinct.size(), city["vertices"].size()) << "a vertex is written twice";
  for (const auto& v : city["vertices"]) {
    for (const auto& c : v) EXPECT_TRUE(c.is_number_integer());
  }
  struct Case {
    const char* key;
    core::Polygon polygon;
    double roof;
    size_t surfaces;
  };
  for (const Case& c : {Case{"building-1", square(), kSquareRoof, 2 + 4}, Case{"building-2", lShapeWithCourtyard(), kLRoof, 2 + 6 + 4}}) {
    SCOPED_TRACE(c.key);
    const auto& object = city["CityObjects"].at(c.key);
    EXPECT_EQ(object["type"], "Building");
    ASSERT_EQ(object["geometry"].size(), 1u);
    const auto& solid = object["geometry"][0];
    EXPECT_EQ(solid["type"], "Solid");
    EXPECT_EQ(solid["lod"], "1");
    ASSERT_EQ(solid["boundaries"].size(), 1u);  // one shell
    const auto& shell = solid["boundaries"][0];
    ASSERT_EQ(shell.size(), c.surfaces);
    EXPECT_EQ(shell[1].size(), 1 + c.polygon.holes.size()) << "the roof keeps the courtyard";
    EXPECT_EQ(solid["semantics"]["values"][0].size(), c.surfaces);
    std::set<double> heights;
    for (const auto& surface : shell) {
      for (const auto& ring : surface) {
        for (const auto& index : ring) heights.insert(std::round(vertices.at(index.get<size_t>())[2] * 1000) / 1000);
      }
    }
    EXPECT_EQ(heights, (std::set<double>{0.0, c.roof}));
    EXPECT_DOUBLE_EQ(object["attributes"]["roof_height_m"].get<double>(), c.roof);
    EXPECT_EQ(object["attributes"]["status"], "accepted");
    EXPECT_EQ(object["attributes"]["method"], "active-polygon");
    expectClosedShell(shell);
    expectOutwardSurfaces(shell, vertices, expectedBlock(c.polygon, c.roof, toFrame));
  }
}

TEST(CityJson, SquareAndCourtyardLBecomeOutwardSolidsInTheLocalFrame) {
  TempDir dir;
  const std::string path = dir.file("buildings.city.json");
  const CityJsonSummary summary = writeCityJson(path, sampleBuildings(), localFrame());
  EXPECT_EQ(summary.written, 2);
  ASSERT_EQ(summary.leftOut.size(), 2u);
  EXPECT_EQ(summary.leftOut[0], "building 3: no roof height");
  EXPECT_NE(summary.leftOut[1].find("building 4: "), std::string::npos);
  EXPECT_NE(summary.leftOut[1].find("not above the ground"), std::string::npos);

  const nlohmann::json city = readJson(path);
  expectBlocks(city, [](cv::Point2d p) { return cv::Point2d(p.x * kPixelSize, -p.y * kPixelSize); });
  EXPECT_FALSE(city["metadata"].contains("referenceSystem"));
  EXPECT_NE(city["metadata"]["title"].get<std::string>().find("not georeferenced"), std::string::npos);
  EXPECT_EQ(city["CityObjects"]["building-1"]["attributes"]["id"], 1);
  const std::vector<double> extent = city["metadata"]["geographicalExtent"];
  const std::vector<double> expected{5.0, -35.0, 0.0, 80.0, -5.0, kLRoof};
  ASSERT_EQ(extent.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(extent[i], expected[i], 1e-9) << i;
}

std::string lambert93Wkt() {
  OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
  OSRImportFromEPSG(srs, 2154);
  char* wkt = nullptr;
  OSRExportToWkt(srs, &wkt);
  std::string text = wkt != nullptr ? wkt : "";
  CPLFree(wkt);
  OSRDestroySpatialReference(srs);
  return text;
}

TEST(CityJson, GeoreferencedBlocksAreInMapCoordinatesWithTheirEpsgCode) {
  TempDir dir;
  const std::string path = dir.file("buildings.cityjson");
  CityJsonOptions options;
  options.geo.hasTransform = true;
  options.geo.geoTransform = {574000.0, 0.5, 0.0, 6280000.0, 0.0, -0.5};
  options.geo.crsWkt = lambert93Wkt();
  EXPECT_EQ(writeCityJson(path, sampleBuildings(), options).written, 2);
  const nlohmann::json city = readJson(path);
  expectBlocks(city, [&](cv::Point2d p) { return options.geo.pixelToMap(p); });
  EXPECT_EQ(city["metadata"]["referenceSystem"], "https://www.opengis.net/def/crs/EPSG/0/2154");
  const std::vector<double> extent = city["metadata"]["geographicalExtent"];
  EXPECT_NEAR(extent[0], 574005.0, 1e-6);
  EXPECT_NEAR(extent[4], 6279995.0, 1e-6);
}

TEST(CityJson, AMirroringGeotransformStillGivesOutwardSurfaces) {
  TempDir dir;
  const std::string path = dir.file("mirrored.city.json");
  CityJsonOptions options;
  options.geo.hasTransform = true;
  options.geo.geoTransform = {1000.0, 2.0, 0.0, 2000.0, 0.0, 2.0};  // y grows with the rows
  writeCityJson(path, sampleBuildings(), options);
  expectBlocks(readJson(path), [&](cv::Point2d p) { return options.geo.pixelToMap(p); });
}

TEST(CityJson, ADegenerateRingIsAnErrorNamingTheBuildingAndWritesNothing) {
  TempDir dir;
  const std::string path = dir.file("bad.city.json");
  auto buildings = sampleBuildings();
  buildings.push_back(building(9, {{{0, 0}, {10, 10}, {20, 20}}, {}}, 5.0));  // collinear
  const core::Error error = captureError([&] { writeCityJson(path, buildings, localFrame()); });
  EXPECT_EQ(error.code(), ErrorCode::InvalidParameter);
  EXPECT_NE(std::string(error.what()).find("building 9"), std::string::npos) << error.what();
  EXPECT_EQ(error.path(), path);
  EXPECT_FALSE(std::filesystem::exists(path));

  auto withBadHole = sampleBuildings();
  withBadHole[1].polygon.holes.push_back({{140, 60}, {140.0001, 60}, {140, 60.0001}});  // below 1 mm
  const core::Error holeError = captureError([&] { writeCityJson(path, withBadHole, localFrame()); });
  EXPECT_NE(std::string(holeError.what()).find("building 2's hole 2"), std::string::npos) << holeError.what();
}

TEST(CityJson, ABuildingWithoutAnyHeightWritesAnEmptyValidModel) {
  TempDir dir;
  const std::string path = dir.file("none.city.json");
  const CityJsonSummary summary = writeCityJson(path, {building(5, square(), std::nullopt)}, localFrame());
  EXPECT_EQ(summary.written, 0);
  EXPECT_EQ(summary.leftOut, std::vector<std::string>{"building 5: no roof height"});
  const nlohmann::json city = readJson(path);
  EXPECT_EQ(city["type"], "CityJSON");
  EXPECT_TRUE(city["CityObjects"].empty());
  EXPECT_TRUE(city["vertices"].empty());
}

TEST(CityJson, FileNamesOfCityJson) {
  EXPECT_TRUE(isCityJsonPath("out/buildings.city.json"));
  EXPECT_TRUE(isCityJsonPath("B.CityJSON"));
  EXPECT_FALSE(isCityJsonPath("buildings.json"));
  EXPECT_FALSE(isCityJsonPath("buildings.geojson"));
  EXPECT_FALSE(isCityJsonPath(".cityjson"));
}

}  // namespace
}  // namespace delineo::io
