// Project file model: round trips, relative paths, atomic save, corrupt files, autosave; export.
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "delineo/core/error.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/project.hpp"
#include "delineo/stereo/match.hpp"
#include "temp_dir.hpp"

namespace fs = std::filesystem;
using namespace delineo;
using project::Building;
using project::BuildingStatus;
using project::Project;

namespace {

using project::testing::TempDir;

void touch(const std::string& path) { std::ofstream(path) << "x"; }

struct DemoParams {
  double edgeWeight = 5.0;
  int window = 7;
  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"edge-weight", "Edge weight", "", "lambda", 0, 1000}, edgeWeight);
    v(core::ParamInfo{"window", "Window", "px", "side", 3, 31}, window);
  }
  void validate() const { core::checkDeclaredRanges(*this); }
};

Project sampleProject(const TempDir& dir) {
  Project p;
  p.name = "sample";
  p.left = dir.file("images/left.tif");
  p.right = dir.file("images/right.tif");
  p.disparity = dir.file("output/disparity.tif");
  p.exclude = dir.file("images/vegetation.tif");
  p.outputDir = "output";
  p.disparityRange = project::DisparityInterval{-4, 40};
  p.height = {2.0, 0.5, 0.25};
  project::setParameters(p, "delineation", DemoParams{7.5, 9});
  Building b;
  b.id = 3;
  b.initial.outer = {{10, 10}, {50, 10}, {50, 40}, {10, 40}};
  b.outline.outer = {{12.5, 11}, {48, 11}, {48, 39.25}, {12.5, 39.25}};
  b.outline.holes.push_back({{20, 20}, {30, 20}, {30, 30}, {20, 30}});
  b.status = BuildingStatus::Corrected;
  b.roofInterval = project::DisparityInterval{18, 24};
  b.roofHeight = 9.5;
  b.energy = -1234.5;
  b.energyTerms = project::EnergyTerms{-1000, 200, 15.5, -300, -200, 50};
  b.method = project::kBoxFitting;
  b.history = {{"picked", "2024-01-01T00:00:00Z", ""}, {"delineated", "2024-01-01T00:01:00Z", "12 vertices"}};
  p.buildings.push_back(b);
  Building pending;
  pending.id = 4;
  pending.initial.outer = {{60, 60}, {80, 60}, {80, 90}};
  p.buildings.push_back(pending);
  return p;
}

}  // namespace

TEST(ProjectFile, RoundTripKeepsEveryField) {
  TempDir dir;
  const Project p = sampleProject(dir);
  project::saveProject(p, dir.file("demo.delineo.json"));
  const Project loaded = project::loadProject(dir.file("demo.delineo.json"));
  EXPECT_TRUE(loaded == p);
  ASSERT_EQ(loaded.buildings.size(), 2u);
  EXPECT_EQ(loaded.buildings[0].outline.holes.size(), 1u);
  EXPECT_TRUE(std::isnan(loaded.buildings[1].roofHeight));
  EXPECT_FALSE(loaded.buildings[1].roofInterval.has_value());
  EXPECT_EQ(project::parameters<DemoParams>(loaded, "delineation").window, 9);
  EXPECT_EQ(project::parameters<DemoParams>(loaded, "missing-group").window, 7);
  EXPECT_EQ(loaded.buildings[0].method, project::kBoxFitting);
  EXPECT_TRUE(loaded.buildings[1].method.empty());
}

TEST(ProjectFile, FilesWithoutMethodsOutlineWithTheActivePolygon) {
  // A file as written before outlines had a method: no project-level nor building "method".
  TempDir dir;
  const std::string path = dir.file("old.delineo.json");
  std::ofstream(path) << R"({"format":"delineo-project","version":1,"images":{"left":"l.tif","right":"r.tif"},
    "buildings":[{"id":1,"status":"automatic","initial":[[[0,0],[9,0],[9,9]]],"outline":[[[1,1],[8,1],[8,8]]]},
                 {"id":2,"status":"pending","initial":[[[20,20],[29,20],[29,29]]]}]})";
  Project p = project::loadProject(path);
  EXPECT_EQ(p.method, project::kActivePolygon);
  ASSERT_EQ(p.buildings.size(), 2u);
  EXPECT_TRUE(p.buildings[0].method.empty());
  EXPECT_EQ(p.methodOf(p.buildings[1]), project::kActivePolygon);
  // The project's method applies to buildings naming none; a building's own method wins.
  p.method = project::kBoxFitting;
  EXPECT_EQ(p.methodOf(p.buildings[1]), project::kBoxFitting);
  p.buildings[1].method = project::kActivePolygon;
  EXPECT_EQ(p.methodOf(p.buildings[1]), project::kActivePolygon);
  // Saved, both are written and read back.
  project::saveProject(p, path);
  const Project again = project::loadProject(path);
  EXPECT_TRUE(again == p);
  std::ifstream in(path);
  const nlohmann::json written = nlohmann::json::parse(in);
  EXPECT_EQ(written["method"], "box-fitting");
  EXPECT_EQ(written["buildings"][1]["method"], "active-polygon");
  EXPECT_FALSE(written["buildings"][0].contains("method"));  // none chosen: nothing written
}

TEST(ProjectFile, PathsUnderTheProjectFolderAreStoredRelative) {
  TempDir dir;
  Project p = sampleProject(dir);
  p.dem = "/elsewhere/dem.tif";
  p.outputDir = dir.file("output");
  const nlohmann::json j = project::toJson(p, dir.path().string());
  EXPECT_EQ(j["images"]["left"], "images/left.tif");
  EXPECT_EQ(j["images"]["exclude"], "images/vegetation.tif");
  EXPECT_EQ(j["outputDir"], "output");
  EXPECT_EQ(j["images"]["dem"], "/elsewhere/dem.tif");
}

TEST(ProjectFile, MovedProjectFolderStillFindsItsImages) {
  TempDir dir;
  fs::create_directories(dir.path() / "a" / "images");
  Project p;
  p.left = dir.file("a/images/left.tif");
  p.right = dir.file("a/images/right.tif");
  touch(p.left);
  touch(p.right);
  project::saveProject(p, dir.file("a/p.json"));
  fs::rename(dir.path() / "a", dir.path() / "b");
  const Project moved = project::loadProject(dir.file("b/p.json"));
  EXPECT_EQ(moved.left, dir.file("b/images/left.tif"));
  EXPECT_TRUE(moved.missingFiles().empty());
}

TEST(ProjectFile, OutputFolderFollowsTheProjectFileWhenSavedElsewhere) {
  TempDir dir;
  Project p = sampleProject(dir);
  project::saveProject(p, dir.file("a/p.json"));
  EXPECT_EQ(project::outputDirectory(project::loadProject(dir.file("a/p.json")), dir.file("a/p.json")),
            dir.file("a/output"));
  // "Save as" into another folder: the outputs go beside the new file, not the old one.
  project::saveProject(project::loadProject(dir.file("a/p.json")), dir.file("b/p.json"));
  EXPECT_EQ(project::outputDirectory(project::loadProject(dir.file("b/p.json")), dir.file("b/p.json")),
            dir.file("b/output"));
  p.outputDir = "/data/results";
  EXPECT_EQ(project::outputDirectory(p, dir.file("a/p.json")), "/data/results");
}

TEST(ProjectFile, AnUnsavedProjectHasNoRelativeOutputFolder) {
  Project p;
  EXPECT_EQ(p.outputDir, "output");
  try {
    (void)project::outputDirectory(p, "");
    FAIL() << "an unsaved project must not resolve its output folder against the working folder";
  } catch (const core::Error& e) {
    EXPECT_EQ(e.code(), core::ErrorCode::InvalidParameter);
  }
}

TEST(ProjectFile, AProjectWithoutADisparityRangeKeepsItUnset) {
  TempDir dir;
  Project p = sampleProject(dir);
  p.disparityRange.reset();
  project::saveProject(p, dir.file("p.json"));
  EXPECT_TRUE(project::toJson(p, dir.path().string())["disparityRange"].is_null());
  EXPECT_FALSE(project::loadProject(dir.file("p.json")).disparityRange.has_value());
}

TEST(ProjectFile, ARangeAmongTheMatcherParametersBecomesTheProjectRange) {
  TempDir dir;
  Project p = sampleProject(dir);
  nlohmann::json j = project::toJson(p, dir.path().string());
  j["disparityRange"] = nullptr;
  j["parameters"]["matching"] = {{"dmin", -2}, {"dmax", 90}, {"window", 11}};
  const Project loaded = project::fromJson(j, dir.path().string());
  ASSERT_TRUE(loaded.disparityRange.has_value());
  EXPECT_EQ(*loaded.disparityRange, (project::DisparityInterval{-2, 90}));
  EXPECT_FALSE(loaded.parameters["matching"].contains("dmin"));
  EXPECT_EQ(loaded.parameters["matching"]["window"], 11);
}

// The matcher's tile size (large pairs, docs/stereo.md) is kept by the file like any parameter;
// a file without it matches in tiles of the default size.
TEST(ProjectFile, TheMatchersTileSizeRoundTrips) {
  TempDir dir;
  Project p = sampleProject(dir);
  stereo::MatchParams match;
  match.tile = 512;
  project::setParameters(p, "matching", match);
  project::saveProject(p, dir.file("tiles.delineo.json"));
  const Project loaded = project::loadProject(dir.file("tiles.delineo.json"));
  EXPECT_EQ(loaded.parameters["matching"]["tile"], 512);
  EXPECT_EQ(project::parameters<stereo::MatchParams>(loaded, "matching").tile, 512);
  nlohmann::json j = project::toJson(p, dir.path().string());
  j["parameters"]["matching"].erase("tile");
  const Project old = project::fromJson(j, dir.path().string());
  EXPECT_EQ(project::parameters<stereo::MatchParams>(old, "matching").tile,
            stereo::MatchParams{}.tile);
}

TEST(ProjectFile, MissingFilesNamesEachAbsentImage) {
  TempDir dir;
  Project p = sampleProject(dir);
  fs::create_directories(dir.path() / "images");
  touch(p.left);
  const auto missing = p.missingFiles();
  ASSERT_EQ(missing.size(), 3u);  // right, disparity and the exclusion mask
  EXPECT_EQ(missing[0], p.right);
  EXPECT_EQ(missing[1], p.disparity);
  EXPECT_EQ(missing[2], p.exclude);
}

TEST(ProjectFile, SaveIsAtomicAndLeavesNoTemporaryFile) {
  TempDir dir;
  const std::string path = dir.file("p.json");
  Project p = sampleProject(dir);
  project::saveProject(p, path);
  p.name = "second";
  project::saveProject(p, path);
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1);
  EXPECT_EQ(project::loadProject(path).name, "second");
}

TEST(ProjectFile, SaveIntoAFileInsteadOfAFolderIsRefused) {
  TempDir dir;
  touch(dir.file("not-a-folder"));
  try {
    project::saveProject(sampleProject(dir), dir.file("not-a-folder/p.json"));
    FAIL() << "expected UnusableOutput";
  } catch (const core::Error& e) {
    EXPECT_EQ(e.code(), core::ErrorCode::UnusableOutput);
  }
}

TEST(ProjectFile, CorruptFilesAreRejectedWithTheFieldNamed) {
  TempDir dir;
  const std::string path = dir.file("bad.json");
  auto expectUnreadable = [&](const std::string& text, const std::string& mention) {
    std::ofstream(path) << text;
    try {
      project::loadProject(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const core::Error& e) {
      EXPECT_EQ(e.code(), core::ErrorCode::UnreadableFile) << text;
      EXPECT_EQ(e.path(), path);
      EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
    }
  };
  expectUnreadable("{ not json", "invalid JSON");
  expectUnreadable(R"({"format":"other","version":1})", "format");
  expectUnreadable(R"({"format":"delineo-project","version":99,"images":{"left":"l","right":"r"}})", "newer");
  expectUnreadable(R"({"format":"delineo-project","version":1,"images":{"left":"l"}})", "images");
  expectUnreadable(R"({"format":"delineo-project","version":1,"images":{"left":"l","right":"r"},
    "buildings":[{"id":1,"status":"done","initial":[[[0,0],[1,0],[1,1]]]}]})", "status");
  expectUnreadable(R"({"format":"delineo-project","version":1,"images":{"left":"l","right":"r"},
    "buildings":[{"id":1,"initial":[[[0,0],[1,0]]]}]})", "buildings[0].initial");
  expectUnreadable(R"({"format":"delineo-project","version":1,"images":{"left":"l","right":"r"},
    "buildings":[{"id":1,"initial":[[[0,0],[1,0],[1,1]]]},{"id":1,"initial":[[[0,0],[1,0],[1,1]]]}]})", "duplicate");
  expectUnreadable(R"({"format":"delineo-project","version":1,"images":{"left":"l","right":"r"},
    "buildings":[{"id":1,"initial":[[[0,0],[1,0],[1,1]]],"roofInterval":[5,2]}]})", "roofInterval");
  expectUnreadable(R"({"format":"delineo-project","version":1,"images":{"left":"l","right":"r"},
    "method":"snakes"})", "method");
  expectUnreadable(R"({"format":"delineo-project","version":1,"images":{"left":"l","right":"r"},
    "buildings":[{"id":1,"initial":[[[0,0],[1,0],[1,1]]],"method":"boxes"}]})", "buildings[0].method");
}

TEST(ProjectFile, MissingProjectIsFileNotFound) {
  try {
    project::loadProject("/nonexistent/delineo/p.json");
    FAIL();
  } catch (const core::Error& e) {
    EXPECT_EQ(e.code(), core::ErrorCode::FileNotFound);
  }
}

TEST(ProjectFile, WrongParameterTypeIsRejectedByTypedAccess) {
  TempDir dir;
  Project p = sampleProject(dir);
  p.parameters["delineation"]["window"] = "seven";
  EXPECT_THROW(project::parameters<DemoParams>(p, "delineation"), core::Error);
  p.parameters["delineation"]["window"] = 99;  // outside [3, 31]
  EXPECT_THROW(project::parameters<DemoParams>(p, "delineation"), core::Error);
}

TEST(ProjectModel, IdsStatusesAndPending) {
  TempDir dir;
  Project p = sampleProject(dir);
  EXPECT_EQ(p.nextBuildingId(), 5);
  EXPECT_EQ(p.pendingBuildings(), std::vector<int>{4});
  ASSERT_NE(p.find(3), nullptr);
  EXPECT_EQ(p.find(99), nullptr);
  EXPECT_EQ(&p.find(4)->currentPolygon(), &p.find(4)->initial);
  EXPECT_EQ(&p.find(3)->currentPolygon(), &p.find(3)->outline);
  for (auto s : {BuildingStatus::Pending, BuildingStatus::Automatic, BuildingStatus::Corrected,
                 BuildingStatus::Accepted, BuildingStatus::Rejected}) {
    EXPECT_EQ(project::statusFromString(project::toString(s)), s);
  }
  p.find(4)->addHistory("edited", "moved a vertex");
  ASSERT_EQ(p.find(4)->history.size(), 1u);
  EXPECT_EQ(p.find(4)->history[0].time.size(), 20u);  // 2024-01-01T00:00:00Z
  EXPECT_DOUBLE_EQ(p.height.heightAt(22.0), 10.0);
}

TEST(ProjectAutosave, NewerAutosaveIsDetected) {
  TempDir dir;
  const std::string path = dir.file("p.json");
  project::saveProject(sampleProject(dir), path);
  EXPECT_FALSE(project::hasNewerAutosave(path));
  const std::string autosave = project::autosavePath(path);
  EXPECT_EQ(fs::path(autosave).filename(), ".p.json.autosave");
  project::saveProject(sampleProject(dir), autosave);
  fs::last_write_time(autosave, fs::last_write_time(path) + std::chrono::seconds(5));
  EXPECT_TRUE(project::hasNewerAutosave(path));
  fs::last_write_time(autosave, fs::last_write_time(path) - std::chrono::seconds(5));
  EXPECT_FALSE(project::hasNewerAutosave(path));
}

TEST(ProjectExport, ACityJsonNameWritesLod1BlocksInTheHeightModelsMetres) {
  TempDir dir;
  Project p = sampleProject(dir);  // building 3 corrected with a 9.5 m roof, 4 pending; no images
  p.buildings[0].status = BuildingStatus::Accepted;
  Building noHeight = p.buildings[0];
  noHeight.id = 5;
  noHeight.roofHeight = std::nan("");
  p.buildings.push_back(noHeight);

  const project::ExportSummary outlines = project::exportBuildings(p, dir.file("out/accepted.geojson"));
  EXPECT_EQ(outlines.written, 2);
  EXPECT_TRUE(outlines.leftOut.empty());
  EXPECT_EQ(io::readFeatures(dir.file("out/accepted.geojson")).size(), 2u);

  const project::ExportSummary blocks = project::exportBuildings(p, dir.file("out/accepted.city.json"));
  EXPECT_EQ(blocks.written, 1);
  EXPECT_EQ(blocks.leftOut, std::vector<std::string>{"building 5: no roof height"});
  EXPECT_EQ(blocks.notes.size(), 1u) << "no heights given: the blocks stand on z = 0, said in the notes";
  std::ifstream in(dir.file("out/accepted.city.json"));
  const nlohmann::json city = nlohmann::json::parse(in);
  EXPECT_EQ(city["type"], "CityJSON");
  ASSERT_EQ(city["CityObjects"].size(), 1u);
  EXPECT_EQ(city["CityObjects"]["building-3"]["attributes"]["roof_height_m"], 9.5);
  // Not georeferenced: x = column x gsd (0.25 m), so the outline's 12.5 .. 48 px span 8.875 m.
  const auto& extent = city["metadata"]["geographicalExtent"];
  EXPECT_NEAR(extent[3].get<double>() - extent[0].get<double>(), (48 - 12.5) * 0.25, 1e-9);
  EXPECT_NEAR(extent[5].get<double>(), 9.5, 1e-9);
}
