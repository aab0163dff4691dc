// The CityJSON export of a project: blocks on the ground next to each building (the 3D view's
// estimate), the terrain from a DTM, the ground level's elevation; heightModel.groundElevation
// in the project file.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "delineo/core/error.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/project.hpp"
#include "temp_dir.hpp"

namespace fs = std::filesystem;
using namespace delineo;
using project::Building;
using project::BuildingStatus;
using project::Project;

namespace {

using project::testing::TempDir;

constexpr double kSlope = 0.02;      // m of ground per px of column
constexpr double kBuildingTall = 9;  // m above the ground at its centre

double groundAt(double col) { return kSlope * col; }

// Building `id`: a 40 x 40 px square whose left edge is at `col`, rows 80..120.
Building squareBuilding(int id, double col) {
  Building b;
  b.id = id;
  b.status = BuildingStatus::Accepted;
  b.initial.outer = {{col, 80}, {col + 40, 80}, {col + 40, 120}, {col, 120}};
  b.outline = b.initial;
  b.roofHeight = groundAt(col + 20) + kBuildingTall;
  return b;
}

// A project on a slope rising 12 m from west to east: one building at the foot, one near the top.
// No images: the local frame (x = column x 0.25 m).
Project slopeProject() {
  Project p;
  p.name = "slope";
  p.left = "/nonexistent/left.tif";
  p.right = "/nonexistent/right.tif";
  p.height = {2.0, 0.5, 0.25};
  p.buildings = {squareBuilding(1, 100), squareBuilding(2, 460)};
  return p;
}

// The DEM (m): the slope, each building's square raised by kBuildingTall.
cv::Mat slopeDem(const Project& p) {
  cv::Mat dem(200, 600, CV_32F);
  for (int row = 0; row < dem.rows; ++row) {
    for (int col = 0; col < dem.cols; ++col) dem.at<float>(row, col) = static_cast<float>(groundAt(col + 0.5));
  }
  for (const Building& b : p.buildings) {
    const cv::Rect box(static_cast<int>(b.outline.outer[0].x), 80, 40, 40);
    dem(box) += kBuildingTall;
  }
  return dem;
}

cv::Mat slopeDtm() {
  cv::Mat dtm(200, 600, CV_32F);
  for (int row = 0; row < dtm.rows; ++row) {
    for (int col = 0; col < dtm.cols; ++col) dtm.at<float>(row, col) = static_cast<float>(groundAt(col + 0.5));
  }
  return dtm;
}

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The z of the vertices a Building's solid uses (transform applied), at 1 mm.
std::set<double> solidHeights(const nlohmann::json& city, const std::string& key) {
  const double scale = city["transform"]["scale"][2], translate = city["transform"]["translate"][2];
  std::set<double> heights;
  for (const auto& surface : city["CityObjects"][key]["geometry"][0]["boundaries"][0]) {
    for (const auto& ring : surface) {
      for (const auto& index : ring) {
        const double z = translate + scale * city["vertices"][index.get<size_t>()][2].get<double>();
        heights.insert(std::round(z * 1000) / 1000);
      }
    }
  }
  return heights;
}

TEST(CityModelExport, EachBlockStandsOnTheGroundNextToItAsThe3DViewDrawsIt) {
  TempDir dir;
  const Project p = slopeProject();
  const cv::Mat dem = slopeDem(p);
  project::CityModelInputs model;
  model.heights = dem;
  const project::ExportSummary summary = project::exportBuildings(p, dir.file("slope.city.json"), {BuildingStatus::Accepted}, model);
  EXPECT_EQ(summary.written, 2);
  EXPECT_TRUE(summary.onLocalGround);
  EXPECT_TRUE(summary.notes.empty());
  const nlohmann::json city = readJson(dir.file("slope.city.json"));
  std::vector<double> bases;
  for (const Building& b : p.buildings) {
    const std::string key = "building-" + std::to_string(b.id);
    SCOPED_TRACE(key);
    const double base = project::groundHeightNextTo(p, dem, b.outline).value();  // the 3D view's base
    const auto& attributes = city["CityObjects"][key]["attributes"];
    EXPECT_NEAR(attributes["ground_height_m"].get<double>(), base, 1e-9);
    EXPECT_NEAR(attributes["roof_height_m"].get<double>(), b.roofHeight, 1e-9);
    EXPECT_NEAR(attributes["measuredHeight"].get<double>(), b.roofHeight - base, 1e-9);
    EXPECT_EQ(solidHeights(city, key), (std::set<double>{std::round(base * 1000) / 1000, std::round(b.roofHeight * 1000) / 1000}));
    // The ground next to it: within the slope's rise across the 120 px band around the building.
    EXPECT_NEAR(base, groundAt(b.outline.outer[0].x + 20), kSlope * 60) << "the base does not follow the slope";
    bases.push_back(base);
  }
  EXPECT_NEAR(bases[1] - bases[0], kSlope * 360, kSlope * 60);
}

TEST(CityModelExport, WithoutHeightsTheBlocksStandOnTheGroundLevelAndTheSummarySaysSo) {
  TempDir dir;
  const Project p = slopeProject();
  const project::ExportSummary summary = project::exportBuildings(p, dir.file("flat.city.json"));
  EXPECT_EQ(summary.written, 2);
  EXPECT_FALSE(summary.onLocalGround);
  ASSERT_EQ(summary.notes.size(), 1u);
  EXPECT_NE(summary.notes[0].find("no heights"), std::string::npos);
  const nlohmann::json city = readJson(dir.file("flat.city.json"));
  EXPECT_EQ(*solidHeights(city, "building-1").begin(), 0.0);
  EXPECT_FALSE(city["CityObjects"]["building-1"]["attributes"].contains("ground_height_m"));
  EXPECT_NE(city["metadata"]["title"].get<std::string>().find("no ground heights"), std::string::npos);
}

TEST(CityModelExport, ARoofNotAboveItsGroundIsLeftOutWithTheReason) {
  TempDir dir;
  Project p = slopeProject();
  p.buildings[1].roofHeight = 2.0;  // below the slope's ground there (about 9.6 m)
  project::CityModelInputs model;
  model.heights = slopeDem(p);
  const project::ExportSummary summary = project::exportBuildings(p, dir.file("sunk.city.json"), {BuildingStatus::Accepted}, model);
  EXPECT_EQ(summary.written, 1);
  ASSERT_EQ(summary.leftOut.size(), 1u);
  EXPECT_EQ(summary.leftOut[0].rfind("building 2: roof height 2 m is not above its ground height ", 0), 0u) << summary.leftOut[0];
}

TEST(CityModelExport, TheTerrainAndTheGroundElevationComeFromTheProject) {
  TempDir dir;
  Project p = slopeProject();
  p.height.groundElevation = 146.5;
  project::CityModelInputs model;
  model.heights = slopeDem(p);
  model.dtm = slopeDtm();
  const project::ExportSummary summary = project::exportBuildings(p, dir.file("terrain.city.json"), {BuildingStatus::Accepted}, model);
  // gsd 0.25 m: a vertex every 4 px, 150 x 50 grid points, 149 x 49 cells of two triangles.
  EXPECT_EQ(project::TerrainParams{}.resolvedStep(p.height.gsd), 4);
  EXPECT_EQ(summary.terrainVertices, 150 * 50);
  EXPECT_EQ(summary.terrainTriangles, 2 * 149 * 49);
  const nlohmann::json city = readJson(dir.file("terrain.city.json"));
  ASSERT_TRUE(city["CityObjects"].contains("terrain"));
  const double scale = city["transform"]["scale"][2], translate = city["transform"]["translate"][2];
  double lowest = INFINITY;
  for (const auto& v : city["vertices"]) lowest = std::min(lowest, translate + scale * v[2].get<double>());
  EXPECT_NEAR(lowest, 146.5 + groundAt(0.5), 1e-3);  // the terrain's west edge, raised
  const auto& attributes = city["CityObjects"]["building-1"]["attributes"];
  const double base = project::groundHeightNextTo(p, model.heights, p.buildings[0].outline).value();
  EXPECT_NEAR(attributes["ground_height_m"].get<double>(), base, 1e-9);  // relative, not raised
  // Its walls reach down to the terrain's lowest point along the outline: the west wall's foot.
  const double foot = groundAt(p.buildings[0].outline.outer[0].x);  // the TIN at the wall
  ASSERT_LT(foot, base);
  EXPECT_NEAR(*solidHeights(city, "building-1").begin(), foot + 146.5, 1e-3);

  model.terrain.step = 25;
  EXPECT_EQ(project::exportBuildings(p, dir.file("coarse.city.json"), {BuildingStatus::Accepted}, model).terrainVertices, 24 * 8);
}

// A progress that records what it is told and cancels once it has reached `cancelAt`.
class RecordingProgress : public core::Progress {
 public:
  explicit RecordingProgress(double cancelAt) : cancelAt_(cancelAt) {}
  void report(double fraction) override {
    core::Progress::report(fraction);
    fractions.push_back(fraction);
    if (fraction >= cancelAt_) cancel();
  }
  std::vector<double> fractions;

 private:
  double cancelAt_;
};

TEST(CityModelExport, ItsProgressGoesThroughTheBuildingsAndACancelWritesNothing) {
  TempDir dir;
  const Project p = slopeProject();
  project::CityModelInputs model;
  model.heights = slopeDem(p);
  RecordingProgress whole(2.0);  // never cancels
  const auto done = project::exportBuildings(p, dir.file("whole.city.json"), {BuildingStatus::Accepted}, model, &whole);
  EXPECT_EQ(done.status, core::RunStatus::Completed);
  EXPECT_EQ(done.written, 2);
  ASSERT_GE(whole.fractions.size(), 4u);  // each building's ground and roof parts, then the end
  EXPECT_TRUE(std::is_sorted(whole.fractions.begin(), whole.fractions.end()));
  EXPECT_EQ(whole.fractions.back(), 1.0);

  RecordingProgress canceling(0.3);  // canceled during the roof parts
  const auto canceled = project::exportBuildings(p, dir.file("canceled.city.json"), {BuildingStatus::Accepted}, model, &canceling);
  EXPECT_EQ(canceled.status, core::RunStatus::Canceled);
  EXPECT_FALSE(fs::exists(dir.file("canceled.city.json")));
}

TEST(CityModelExport, TheGroundElevationRoundTripsAndIsBounded) {
  TempDir dir;
  Project p = slopeProject();
  p.height.groundElevation = -12.75;
  project::saveProject(p, dir.file("p.delineo.json"));
  EXPECT_EQ(project::loadProject(dir.file("p.delineo.json")).height.groundElevation, -12.75);
  nlohmann::json file = readJson(dir.file("p.delineo.json"));
  EXPECT_EQ(file["heightModel"]["groundElevation"], -12.75);
  for (const nlohmann::json& bad : {nlohmann::json(2e4), nlohmann::json("100")}) {
    file["heightModel"]["groundElevation"] = bad;
    std::ofstream(dir.file("bad.delineo.json")) << file.dump();
    try {
      project::loadProject(dir.file("bad.delineo.json"));
      ADD_FAILURE() << bad << " was accepted";
    } catch (const core::Error& e) {
      EXPECT_EQ(e.code(), core::ErrorCode::UnreadableFile);
      EXPECT_NE(std::string(e.what()).find("heightModel.groundElevation"), std::string::npos) << e.what();
    }
  }
  file.erase("heightModel");
  std::ofstream(dir.file("old.delineo.json")) << file.dump();
  EXPECT_EQ(project::loadProject(dir.file("old.delineo.json")).height.groundElevation, 0.0);
}

}  // namespace
