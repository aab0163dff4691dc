#pragma once
// The Delineo project: one stereo pair, its derived rasters, the algorithm parameters and the
// buildings an operator delineates, with their statuses and history. Qt-free so that the GUI
// and `delineo-cli run PROJECT` load, modify and save projects with the same code.
//
// On disk a project is a JSON file (format in docs/project-file.md). In memory every path is
// absolute; on disk paths are stored relative to the project file's folder when they lie under
// it (so a project folder can be moved or shared), absolute otherwise.
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"

namespace delineo::project {

// Current file format version; older versions are upgraded on load, newer ones refused.
inline constexpr int kFormatVersion = 1;

enum class BuildingStatus {
  Pending,    // picked, no outline computed yet
  Automatic,  // outline from the active polygon, not touched by the operator
  Corrected,  // outline edited by hand after (or instead of) the algorithm
  Accepted,   // validated by the operator: exported
  Rejected,   // discarded by the operator: kept for the record, never exported
};
std::string toString(BuildingStatus status);
// Throws core::Error(UnreadableFile) for an unknown name.
BuildingStatus statusFromString(const std::string& name);

// The methods an outline comes from (Building::method, Project::method): the statistical
// active polygon on the stereo pair (docs/delineation.md) or box-fitting on the DEM and the left
// image's edges (docs/boxfit.md).
inline constexpr const char* kActivePolygon = "active-polygon";
inline constexpr const char* kBoxFitting = "box-fitting";
bool isOutlineMethod(const std::string& name);

// One entry of a building's history: what happened, when (UTC, ISO 8601) and a short detail.
struct HistoryEntry {
  std::string action;  // "picked", "delineated", "edited", "accepted", "rejected", "reopened"
  std::string time;
  std::string detail;
  bool operator==(const HistoryEntry&) const = default;
};

// Inclusive integer roof disparity interval [low, high] in px.
struct DisparityInterval {
  int low = 0;
  int high = 0;
  bool operator==(const DisparityInterval&) const = default;
};

// The active polygon's energy terms, weighted and signed as they add up to F(C):
// roof, ground, occlusion, left edges, right edges, shape prior (docs/delineation.md).
using EnergyTerms = std::array<double, 6>;
inline constexpr std::array<const char*, 6> kEnergyTermNames = {"roof",      "ground",     "occlusion",
                                                                "leftEdges", "rightEdges", "shape"};

struct Building {
  int id = 0;
  core::Polygon initial;   // the operator's rough polygon or rectangle (left-image pixels)
  core::Polygon outline;   // current outline; empty outer ring while Pending
  BuildingStatus status = BuildingStatus::Pending;
  std::optional<DisparityInterval> roofInterval;  // chosen on the ROI histogram
  double roofHeight = std::nan("");  // m above ground, NaN when unknown
  double energy = std::nan("");      // active polygon energy F(C) of the outline, NaN when unknown
  std::optional<EnergyTerms> energyTerms;  // its terms, when known
  // The method that produced the outline (kActivePolygon, kBoxFitting); for a Pending building
  // the one `delineo-cli run` uses. Empty: not chosen (the project's method applies).
  std::string method;
  // The building's identifier in the layer it was imported from (importOutlines(): a cadastre's
  // or OpenStreetMap's id), written with its outline so the two can be joined; empty otherwise.
  std::string sourceId;
  std::vector<HistoryEntry> history;
  // Keys of the building's JSON object this version does not know, written back on save.
  nlohmann::json unknownKeys = nlohmann::json::object();

  bool hasOutline() const { return outline.outer.size() >= 3; }
  // The outline when there is one, else the initial polygon.
  const core::Polygon& currentPolygon() const { return hasOutline() ? outline : initial; }
  void addHistory(const std::string& action, const std::string& detail = {});
};

// Relation between disparity and height for a DEM in left-image geometry:
// height = (disparity - groundDisparity) * metresPerPixel. Zero metresPerPixel = unknown.
struct HeightModel {
  double groundDisparity = 0.0;  // px, disparity of the ground plane
  double metresPerPixel = 0.0;   // m per px of disparity above the ground
  double gsd = 1.0;              // m, ground sample distance of one image pixel (hillshade, 3D)
  double groundElevation = 0.0;  // m, elevation of the ground level (height 0) above the vertical datum
  bool known() const { return metresPerPixel != 0.0; }
  double heightAt(double disparity) const { return (disparity - groundDisparity) * metresPerPixel; }
  bool operator==(const HeightModel&) const = default;
};

struct Project {
  std::string name;
  // Inputs and derived rasters, absolute paths in memory; empty when absent.
  std::string left;
  std::string right;
  std::string disparity;   // float32 disparity in left geometry (computed when missing)
  std::string dem;         // float32 heights in left geometry, optional
  std::string labels;      // ground truth / classification labels, optional
  std::string exclude;     // mask of pixels that are not roof (vegetation...), optional
  // Where computed rasters and exports go: relative to the project file's folder (the default,
  // "output", so outputs follow the project when it is saved elsewhere) or absolute. Resolve it
  // with outputDirectory().
  std::string outputDir = "output";
  // The pair's full disparity search range (px); unset until estimated from the images or given.
  std::optional<DisparityInterval> disparityRange;
  HeightModel height;
  // The method `delineo-cli run` outlines Pending buildings with when they name none.
  std::string method = kActivePolygon;
  // Algorithm parameters by group ("matching", "delineation", ...): each value is the JSON of a
  // parameter struct (core::toJson). Kept as JSON so the project does not depend on every
  // algorithm library; typed access through parameters()/setParameters().
  nlohmann::json parameters = nlohmann::json::object();
  std::vector<Building> buildings;
  // Keys of the project file this version does not know (a newer version's, a user's own),
  // written back on save as they were read ("images" holds those of the images object).
  nlohmann::json unknownKeys = nlohmann::json::object();

  Building* find(int id);
  const Building* find(int id) const;
  int nextBuildingId() const;
  // Buildings that still need an outline (Pending with a roof interval or not).
  std::vector<int> pendingBuildings() const;
  // The method a building is (or is to be) outlined with: its own, else the project's.
  const std::string& methodOf(const Building& building) const;
  // Paths of the inputs that are named but do not exist on disk (left, right, ...).
  std::vector<std::string> missingFiles() const;
  bool operator==(const Project&) const;
};

// Typed parameter access: default-constructed struct overlaid with the stored keys. Keys the
// struct does not know (a newer version's parameter, a removed one) are ignored here and kept
// in the file; a known key with a bad value throws core::Error(InvalidParameter).
template <class Params>
Params parameters(const Project& project, const std::string& group) {
  Params params;
  auto it = project.parameters.find(group);
  if (it == project.parameters.end() || !it->is_object()) return params;
  nlohmann::json known = nlohmann::json::object();
  params.visit([&](const core::ParamInfo& info, auto&) {
    const std::string key(info.key);
    if (auto value = it->find(key); value != it->end()) known[key] = *value;
  });
  core::fromJson(params, known);
  return params;
}
// Stores `params` in `group`, keeping the group's keys the struct does not know.
template <class Params>
void setParameters(Project& project, const std::string& group, const Params& params) {
  nlohmann::json& stored = project.parameters[group];
  if (!stored.is_object()) stored = nlohmann::json::object();
  const nlohmann::json values = core::toJson(params);
  for (auto it = values.begin(); it != values.end(); ++it) stored[it.key()] = it.value();
}

// JSON conversion. `baseDir` is the folder paths are made relative to (toJson) or resolved
// against (fromJson). fromJson throws core::Error(UnreadableFile) naming the faulty field.
nlohmann::json toJson(const Project& project, const std::string& baseDir);
Project fromJson(const nlohmann::json& json, const std::string& baseDir);

// Reads a project file. Throws FileNotFound, UnreadableFile (not JSON, wrong fields, newer
// format). Missing images are not an error here: see Project::missingFiles().
Project loadProject(const std::string& path);
// Writes atomically: a temporary file in the same folder, then rename, so a crash never leaves
// a half-written project. Throws WriteFailed.
void saveProject(const Project& project, const std::string& path);

// The files the project reads (its images, disparity, DEM, labels and mask; empty names
// included): no output of the project may replace one of them (io::checkOutputs).
std::vector<std::string> inputFiles(const Project& project);

// Autosave companion of a project file: "<dir>/.<file name>.autosave".
std::string autosavePath(const std::string& projectPath);
// True when an autosave exists and is newer than the project file (e.g. after a crash).
bool hasNewerAutosave(const std::string& projectPath);

// The absolute output folder of a project saved at `projectPath`. Throws InvalidParameter when
// the folder is relative and the project has no file yet (nothing is written for an unsaved
// project: its outputs would otherwise land in the current folder or beside the images).
std::string outputDirectory(const Project& project, const std::string& projectPath);

// "2024-05-01T12:34:56Z".
std::string currentUtcTime();

}  // namespace delineo::project
