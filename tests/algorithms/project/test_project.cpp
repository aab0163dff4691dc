// Project file model: round trips, relative paths, atomic save, corrupt files, autosave.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <unistd.h>

#include "delineo/core/error.hpp"
#include "delineo/project/project.hpp"

namespace fs = std::filesystem;
using namespace delineo;
using project::Building;
using project::BuildingStatus;
using project::Project;

namespace {

class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = fs::temp_directory_path() /
            ("delineo_project_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

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
