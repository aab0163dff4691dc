#include <algorithm>
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
  double base = 0;
  double roof = 0;
  bool contains(const Vec3& p) const { return p[2] > base && p[2] < roof && insideRings(rings, p[0], p[1]); }
};

ExpectedBlock expectedBlock(const core::Polygon& polygon, double roof, const std::function<cv::Point2d(cv::Point2d)>& toFrame,
                            double base = 0.0) {
  ExpectedBlock block;
  block.base = base;
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

// ---- blocks on their own ground, the ground level's elevation, the terrain ----

core::Feature onGround(core::Feature feature, double ground) {
  feature.attributes["ground_height_m"] = ground;
  return feature;
}

// The z of every vertex a Building's solid uses, at 1 mm.
std::set<double> solidHeights(const nlohmann::json& object, const std::vector<Vec3>& vertices) {
  std::set<double> heights;
  for (const auto& surface : object["geometry"][0]["boundaries"][0]) {
    for (const auto& ring : surface) {
      for (const auto& index : ring) heights.insert(std::round(vertices.at(index.get<size_t>())[2] * 1000) / 1000);
    }
  }
  return heights;
}

TEST(CityJson, ABlockStandsOnItsGroundHeightAndMeasuresFromIt) {
  TempDir dir;
  const std::string path = dir.file("ground.city.json");
  const std::vector<core::Feature> buildings{onGround(building(1, square(), 10.0), 3.0),
                                             onGround(building(2, lShapeWithCourtyard(), 14.0), -1.5)};
  EXPECT_EQ(writeCityJson(path, buildings, localFrame()).written, 2);
  const nlohmann::json city = readJson(path);
  const std::vector<Vec3> vertices = decodedVertices(city);
  const auto toFrame = [](cv::Point2d p) { return cv::Point2d(p.x * kPixelSize, -p.y * kPixelSize); };
  struct Case {
    const char* key;
    core::Polygon polygon;
    double ground, roof;
  };
  for (const Case& c : {Case{"building-1", square(), 3.0, 10.0}, Case{"building-2", lShapeWithCourtyard(), -1.5, 14.0}}) {
    SCOPED_TRACE(c.key);
    const auto& object = city["CityObjects"].at(c.key);
    EXPECT_EQ(solidHeights(object, vertices), (std::set<double>{c.ground, c.roof}));
    EXPECT_DOUBLE_EQ(object["attributes"]["measuredHeight"].get<double>(), c.roof - c.ground);
    EXPECT_DOUBLE_EQ(object["attributes"]["roof_height_m"].get<double>(), c.roof);
    EXPECT_DOUBLE_EQ(object["attributes"]["ground_height_m"].get<double>(), c.ground);
    expectClosedShell(object["geometry"][0]["boundaries"][0]);
    expectOutwardSurfaces(object["geometry"][0]["boundaries"][0], vertices, expectedBlock(c.polygon, c.roof, toFrame, c.ground));
  }
  EXPECT_NE(city["metadata"]["title"].get<std::string>().find("from the ground next to it"), std::string::npos);
}

// A 40 x 20 px building split into a 20 x 20 px part at 10 m and one at 14 m, on ground at 2 m.
CityJsonBuilding twoLevelBuilding() {
  const core::Polygon outline{{{10, 10}, {50, 10}, {50, 30}, {10, 30}}, {}};
  CityJsonBuilding b{onGround(building(5, outline, 14.0), 2.0), {}};
  b.parts.push_back({{{{10, 10}, {30, 10}, {30, 30}, {10, 30}}, {}}, 10.0});
  b.parts.push_back({{{{30, 10}, {50, 10}, {50, 30}, {30, 30}}, {}}, 14.0});
  return b;
}

TEST(CityJson, ABuildingWithRoofPartsIsAParentOfBuildingPartSolids) {
  TempDir dir;
  const std::string path = dir.file("parts.city.json");
  const CityJsonBuilding split = twoLevelBuilding();
  const CityJsonSummary summary = writeCityJson(path, std::vector<CityJsonBuilding>{split, {building(6, square(), 7.0), {}}}, localFrame());
  EXPECT_EQ(summary.written, 2);
  EXPECT_EQ(summary.parts, 2);
  const nlohmann::json city = readJson(path);
  const std::vector<Vec3> vertices = decodedVertices(city);
  const auto toFrame = [](cv::Point2d p) { return cv::Point2d(p.x * kPixelSize, -p.y * kPixelSize); };
  const auto& parent = city["CityObjects"].at("building-5");
  EXPECT_EQ(parent["type"], "Building");
  EXPECT_FALSE(parent.contains("geometry")) << "the parts carry the geometry";
  EXPECT_DOUBLE_EQ(parent["attributes"]["roof_height_m"].get<double>(), 14.0);
  EXPECT_DOUBLE_EQ(parent["attributes"]["ground_height_m"].get<double>(), 2.0);
  EXPECT_EQ(parent["attributes"]["status"], "accepted");
  ASSERT_EQ(parent["children"], nlohmann::json::array({"building-5-part-1", "building-5-part-2"}));
  for (size_t i = 0; i < split.parts.size(); ++i) {
    const std::string key = parent["children"][i];
    SCOPED_TRACE(key);
    const auto& child = city["CityObjects"].at(key);
    EXPECT_EQ(child["type"], "BuildingPart");
    EXPECT_EQ(child["parents"], nlohmann::json::array({"building-5"}));
    EXPECT_DOUBLE_EQ(child["attributes"]["roof_height_m"].get<double>(), split.parts[i].height);
    EXPECT_DOUBLE_EQ(child["attributes"]["measuredHeight"].get<double>(), split.parts[i].height - 2.0);
    ASSERT_EQ(child["geometry"].size(), 1u);
    EXPECT_EQ(child["geometry"][0]["type"], "Solid");
    EXPECT_EQ(child["geometry"][0]["lod"], "1");
    EXPECT_EQ(solidHeights(child, vertices), (std::set<double>{2.0, split.parts[i].height}));
    expectClosedShell(child["geometry"][0]["boundaries"][0]);
    expectOutwardSurfaces(child["geometry"][0]["boundaries"][0], vertices,
                          expectedBlock(split.parts[i].polygon, split.parts[i].height, toFrame, 2.0));
  }
  // Every BuildingPart names a parent that lists it; a building without parts is one block.
  for (const auto& [key, object] : city["CityObjects"].items()) {
    if (object["type"] != "BuildingPart") continue;
    const auto& children = city["CityObjects"].at(object["parents"][0].get<std::string>())["children"];
    EXPECT_NE(std::find(children.begin(), children.end(), key), children.end()) << key;
  }
  EXPECT_EQ(city["CityObjects"]["building-6"]["geometry"].size(), 1u);
  EXPECT_FALSE(city["CityObjects"]["building-6"].contains("children"));
}

TEST(CityJson, APartNotAboveTheBaseIsLeftOutAndOnePartLeftIsOneBlock) {
  TempDir dir;
  const std::string path = dir.file("low-part.city.json");
  CityJsonBuilding split = twoLevelBuilding();
  split.parts[0].height = 1.0;  // below the building's ground at 2 m
  const CityJsonSummary summary = writeCityJson(path, std::vector<CityJsonBuilding>{split}, localFrame());
  EXPECT_EQ(summary.parts, 0);
  EXPECT_TRUE(summary.leftOut.empty());
  const nlohmann::json city = readJson(path);
  EXPECT_EQ(city["CityObjects"]["building-5"]["geometry"].size(), 1u);
  split.parts.push_back({{{{10, 30}, {50, 30}, {50, 40}, {10, 40}}, {}}, 5.0});
  const CityJsonSummary three = writeCityJson(path, std::vector<CityJsonBuilding>{split}, localFrame());
  EXPECT_EQ(three.parts, 2);
  ASSERT_EQ(three.leftOut.size(), 1u);
  EXPECT_NE(three.leftOut[0].find("building 5 part 1"), std::string::npos) << three.leftOut[0];
}

TEST(CityJson, ARoofNotAboveItsGroundIsLeftOutWithTheReason) {
  TempDir dir;
  const std::string path = dir.file("sunk.city.json");
  const CityJsonSummary summary = writeCityJson(
      path, {onGround(building(1, square(), 10.0), 3.0), onGround(building(5, square(), 4.0), 6.0)}, localFrame());
  EXPECT_EQ(summary.written, 1);
  EXPECT_EQ(summary.leftOut, std::vector<std::string>{"building 5: roof height 4 m is not above its ground height 6 m"});
  EXPECT_FALSE(readJson(path)["CityObjects"].contains("building-5"));
}

TEST(CityJson, TheGroundLevelsElevationRaisesEveryZButNotTheAttributes) {
  TempDir dir;
  const std::string path = dir.file("elevated.city.json");
  CityJsonOptions options = localFrame();
  options.zOffset = 146.25;
  options.terrain.heights = cv::Mat(5, 5, CV_32F, cv::Scalar(2.0f));
  options.terrain.step = 2;
  writeCityJson(path, {onGround(building(1, square(), 10.0), 3.0)}, options);
  const nlohmann::json city = readJson(path);
  const std::vector<Vec3> vertices = decodedVertices(city);
  std::set<double> heights;
  for (const Vec3& v : vertices) heights.insert(std::round(v[2] * 1000) / 1000);
  // The terrain (2 m, under the block's 3 m ground: its walls reach down to it) and the roof.
  EXPECT_EQ(heights, (std::set<double>{148.25, 156.25}));
  const auto& attributes = city["CityObjects"]["building-1"]["attributes"];
  EXPECT_DOUBLE_EQ(attributes["measuredHeight"].get<double>(), 7.0);
  EXPECT_DOUBLE_EQ(attributes["roof_height_m"].get<double>(), 10.0);
  EXPECT_NE(city["metadata"]["title"].get<std::string>().find("+ 146.25 m, the ground level's elevation"), std::string::npos);
  EXPECT_NEAR(city["metadata"]["geographicalExtent"][2].get<double>(), 148.25, 1e-9);

  options.zOffset = std::nan("");
  EXPECT_EQ(captureError([&] { writeCityJson(path, std::vector<core::Feature>{}, options); }).code(), ErrorCode::InvalidParameter);
}

// A sloped DTM, z = 0.1 col + 0.2 row + 5 m on a 9 x 7 px grid, with no height at pixel (4, 2).
cv::Mat slopedDtm() {
  cv::Mat dtm(7, 9, CV_32F);
  for (int row = 0; row < dtm.rows; ++row) {
    for (int col = 0; col < dtm.cols; ++col) dtm.at<float>(row, col) = static_cast<float>(0.1 * col + 0.2 * row + 5.0);
  }
  dtm.at<float>(2, 4) = NAN;  // a grid point at step 2: its four cells are left out
  dtm.at<float>(1, 1) = NAN;  // between grid points: changes nothing
  return dtm;
}

// The terrain's checks: triangles only, each facing up, every index a vertex, each vertex on the DTM.
void expectUpwardTerrain(const nlohmann::json& city, const std::function<cv::Point2d(Vec3)>& toPixel) {
  const nlohmann::json& terrain = city["CityObjects"].at("terrain");
  EXPECT_EQ(terrain["type"], "TINRelief");
  ASSERT_EQ(terrain["geometry"].size(), 1u);
  const auto& surface = terrain["geometry"][0];
  EXPECT_EQ(surface["type"], "CompositeSurface");
  EXPECT_EQ(surface["lod"], "1");
  const std::vector<Vec3> vertices = decodedVertices(city);
  // 4 x 3 cells of 2 px, less the 4 around the point without height: 8 cells of 2 triangles.
  ASSERT_EQ(surface["boundaries"].size(), 16u);
  std::set<size_t> used;
  for (const auto& triangle : surface["boundaries"]) {
    ASSERT_EQ(triangle.size(), 1u);  // no inner ring
    ASSERT_EQ(triangle[0].size(), 3u);
    for (const auto& index : triangle[0]) {
      ASSERT_LT(index.get<size_t>(), vertices.size());
      used.insert(index.get<size_t>());
    }
    EXPECT_GT(newellNormal(triangle[0], vertices)[2], 0.0) << triangle.dump() << " faces down";
  }
  // 5 x 4 grid points, less the one without height and the one whose cells all touch it.
  EXPECT_EQ(used.size(), 18u);
  for (size_t index : used) {
    const cv::Point2d pixel = toPixel(vertices[index]);
    EXPECT_NEAR(vertices[index][2], 0.1 * (pixel.x - 0.5) + 0.2 * (pixel.y - 0.5) + 5.0, 1e-3) << "vertex " << index;
  }
}

TEST(CityJson, TheTerrainIsAnUpwardTinOfTheDtmsGridWithoutItsHoles) {
  TempDir dir;
  const std::string path = dir.file("terrain.city.json");
  CityJsonOptions options = localFrame();
  options.terrain.heights = slopedDtm();
  options.terrain.step = 2;
  const CityJsonSummary summary = writeCityJson(path, std::vector<core::Feature>{}, options);
  EXPECT_EQ(summary.terrainTriangles, 16);
  EXPECT_EQ(summary.terrainVertices, 18);
  const nlohmann::json city = readJson(path);
  EXPECT_EQ(city["vertices"].size(), 18u);
  expectUpwardTerrain(city, [](Vec3 v) { return cv::Point2d(v[0] / kPixelSize, -v[1] / kPixelSize); });
  EXPECT_NE(city["metadata"]["title"].get<std::string>().find("one vertex every 2 px"), std::string::npos);
}

TEST(CityJson, TheTerrainFacesUpUnderAMirroringGeotransformAndSharesVerticesWithTheBlocks) {
  TempDir dir;
  const std::string path = dir.file("mirrored-terrain.city.json");
  CityJsonOptions options;
  options.geo.hasTransform = true;
  options.geo.geoTransform = {1000.0, 2.0, 0.0, 2000.0, 0.0, 2.0};  // y grows with the rows
  options.terrain.heights = slopedDtm();
  options.terrain.step = 2;
  // A block whose corner (0.5, 0.5) px is the terrain's first vertex, at the same height.
  const core::Polygon square{{{0.5, 0.5}, {2.5, 0.5}, {2.5, 2.5}, {0.5, 2.5}}, {}};
  const CityJsonSummary summary = writeCityJson(path, {onGround(building(1, square, 9.0), 5.0)}, options);
  const nlohmann::json city = readJson(path);
  expectUpwardTerrain(city, [](Vec3 v) { return cv::Point2d((v[0] - 1000.0) / 2.0, (v[1] - 2000.0) / 2.0); });
  std::set<std::vector<long long>> distinct;
  for (const auto& v : city["vertices"]) distinct.insert(v.get<std::vector<long long>>());
  EXPECT_EQ(distinct.size(), city["vertices"].size()) << "a vertex is written twice";
  EXPECT_EQ(city["vertices"].size(), static_cast<size_t>(summary.terrainVertices) + 8 - 1);  // one corner shared
}

TEST(CityJson, ABlockReachesDownToTheTerrainWhereItIsLowerThanItsGround) {
  TempDir dir;
  const std::string path = dir.file("reach.city.json");
  CityJsonOptions options = localFrame();
  options.terrain.heights = slopedDtm();
  options.terrain.step = 2;
  // Two squares on the slope; along the first one's outline the terrain rises from 5.8 m at its
  // corner (0.5, 4.5) px to 6.4 m: below its 7 m ground. The second stands below the terrain.
  const core::Polygon onSlope{{{0.5, 4.5}, {2.5, 4.5}, {2.5, 6.5}, {0.5, 6.5}}, {}};
  const core::Polygon sunk{{{4.5, 4.5}, {6.5, 4.5}, {6.5, 6.5}, {4.5, 6.5}}, {}};
  EXPECT_EQ(writeCityJson(path, {onGround(building(1, onSlope, 12.0), 7.0), onGround(building(2, sunk, 12.0), 5.0)}, options).written, 2);
  const nlohmann::json city = readJson(path);
  const std::vector<Vec3> vertices = decodedVertices(city);
  const auto& reaching = city["CityObjects"]["building-1"];
  EXPECT_EQ(solidHeights(reaching, vertices), (std::set<double>{5.8, 12.0}));
  EXPECT_DOUBLE_EQ(reaching["attributes"]["ground_height_m"].get<double>(), 7.0);
  EXPECT_DOUBLE_EQ(reaching["attributes"]["measuredHeight"].get<double>(), 5.0);  // from its ground, not the foot
  expectClosedShell(reaching["geometry"][0]["boundaries"][0]);
  EXPECT_EQ(solidHeights(city["CityObjects"]["building-2"], vertices), (std::set<double>{5.0, 12.0}));
  EXPECT_NE(city["metadata"]["title"].get<std::string>().find("walls reach down to the terrain"), std::string::npos);
}

TEST(CityJson, ATerrainWithoutAnyHeightWritesNoReliefAndABadStepIsRefused) {
  TempDir dir;
  const std::string path = dir.file("flat.city.json");
  CityJsonOptions options = localFrame();
  options.terrain.heights = cv::Mat(6, 6, CV_32F, cv::Scalar(NAN));
  options.terrain.step = 1;
  const CityJsonSummary summary = writeCityJson(path, {building(1, square(), 5.0)}, options);
  EXPECT_EQ(summary.terrainTriangles, 0);
  EXPECT_FALSE(readJson(path)["CityObjects"].contains("terrain"));
  options.terrain.step = 0;
  const core::Error error = captureError([&] { writeCityJson(path, std::vector<core::Feature>{}, options); });
  EXPECT_EQ(error.code(), ErrorCode::InvalidParameter);
  EXPECT_NE(std::string(error.what()).find("terrain step"), std::string::npos) << error.what();
}

}  // namespace
}  // namespace delineo::io
