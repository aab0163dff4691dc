// delineo-cli export PROJECT --out FILE: a project's buildings written as the GUI's export writes
// them (project::exportBuildings): outlines to GeoJSON / GeoPackage, or CityJSON LoD1 blocks on
// the ground next to each building (a roof with several levels as one part per level, unless
// --roof-levels off), with --terrain the TIN of the scene analysis's DTM.
#include <cstdio>
#include <sstream>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/cityjson.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/project.hpp"
#include "delineo/project/roof_parts.hpp"
#include "delineo/segmentation/roof_levels.hpp"

namespace {
using namespace delineo;
using project::BuildingStatus;

// --status: comma-separated status names, "all" for every delineated building not rejected.
std::vector<BuildingStatus> statusesOf(const std::string& list) {
  std::vector<BuildingStatus> statuses;
  std::stringstream names(list);
  std::string name;
  while (std::getline(names, name, ',')) {
    if (name == "all") {
      statuses.insert(statuses.end(), {BuildingStatus::Automatic, BuildingStatus::Corrected, BuildingStatus::Accepted});
      continue;
    }
    try {
      statuses.push_back(project::statusFromString(name));
    } catch (const core::Error&) {
      throw cli::UsageError("--status: unknown status '" + name +
                            "' (accepted, automatic, corrected, rejected, pending or all)");
    }
  }
  if (statuses.empty()) throw cli::UsageError("--status: give at least one status");
  return statuses;
}

// The project's heights on the left image's grid and, with `terrain`, the scene analysis's DTM.
project::CityModelInputs cityModelOf(const project::Project& proj, bool terrain, const cli::Options& opts) {
  project::CityModelInputs model;
  opts.apply(model.terrain);
  auto& progress = cli::commandProgress();
  progress.setStage("reading");
  const cv::Mat image = io::readImage8(proj.left);
  const cv::Mat disparity = project::readDisparity(proj, image.size());
  model.heights = project::projectHeights(proj, disparity);
  if (!model.heights.empty() && model.heights.size() != image.size()) {
    throw core::Error(core::ErrorCode::MismatchedInputs, "the DEM does not have the size of the left image", proj.dem);
  }
  if (!terrain) return model;
  if (model.heights.empty()) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "--terrain needs heights: the project names no DEM, and no disparity with a height model");
  }
  const project::SceneAnalysisOutcome analysis = project::analyseScene(proj, model.heights, image, disparity, &progress);
  cli::throwIfCanceled(progress);
  model.dtm = analysis.dtm;
  return model;
}

void printSummary(const project::ExportSummary& summary, const std::string& out, bool cityJson) {
  for (const auto& line : summary.leftOut) std::fprintf(stderr, "export: left out: %s\n", line.c_str());
  for (const auto& line : summary.notes) std::fprintf(stderr, "export: %s\n", line.c_str());
  std::printf("export: %d building(s) written to %s", summary.written, out.c_str());
  if (cityJson) {
    std::printf("%s", summary.onLocalGround ? ", on the ground next to each" : ", on the ground level");
    if (summary.parts > 0) std::printf("; %d roof parts", summary.parts);
    if (summary.terrainTriangles > 0) {
      std::printf("; terrain: %d vertices, %d triangles", summary.terrainVertices, summary.terrainTriangles);
    }
  }
  std::printf("\n");
}

int run(const std::vector<std::string>& args) {
  cli::Options opts("export",
                    "Writes a project's buildings as the GUI's export does, by the extension of --out.\n"
                    "Usage: delineo-cli export PROJECT --out FILE [options]");
  opts.required("out", "FILE", "outlines (.geojson, .gpkg) or LoD1 blocks (.city.json, .cityjson)")
      .value("status", "LIST", "statuses to write, comma-separated: accepted, automatic, corrected, rejected, pending, or all (the delineated buildings not rejected)", "accepted")
      .flag("terrain", "add the terrain: the scene analysis's DTM of the project's heights, as a TIN (CityJSON only)")
      .params(project::TerrainParams{})
      .params(segmentation::RoofLevelParams{})
      .flag("quiet", "no progress on stderr");
  std::vector<std::string> rest;
  const std::string projectPath = cli::positionalArgument(
      args, {"--out", "--status", "--terrain-step", "--roof-levels", "--roof-level-step", "--roof-level-min-area",
             "--roof-level-clean-width"},
      rest);
  if (!opts.parse(rest)) return cli::kExitOk;
  if (projectPath.empty()) throw cli::UsageError("missing PROJECT (see --help)");
  const std::string out = opts.get("out");
  const bool cityJson = io::isCityJsonPath(out);
  if (opts.has("terrain") && !cityJson) throw cli::UsageError("--terrain needs a CityJSON --out (.city.json, .cityjson)");
  const std::vector<BuildingStatus> statuses = statusesOf(opts.get("status"));
  cli::commandProgress().setQuiet(opts.has("quiet"));

  project::Project proj = project::loadProject(projectPath);
  auto roofLevels = project::parameters<segmentation::RoofLevelParams>(proj, project::kRoofLevelsGroup);
  opts.apply(roofLevels);  // the flags given override the project's group
  project::setParameters(proj, project::kRoofLevelsGroup, roofLevels);
  for (const auto& missing : proj.missingFiles()) {
    throw core::Error(core::ErrorCode::FileNotFound, "referenced by the project " + projectPath, missing);
  }
  std::vector<std::string> inputs = project::inputFiles(proj);
  inputs.push_back(projectPath);
  io::checkOutputs({{out, cityJson ? io::OutputFormat::CityJson : io::OutputFormat::Vector}}, inputs);
  const project::CityModelInputs model = cityJson ? cityModelOf(proj, opts.has("terrain"), opts) : project::CityModelInputs{};
  const project::ExportSummary summary = project::exportBuildings(proj, out, statuses, model, &cli::commandProgress());
  cli::throwIfCanceled(cli::commandProgress());
  cli::commandProgress().finish();
  printSummary(summary, out, cityJson);
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"export", "write a project's buildings as outlines (GeoJSON, GeoPackage) or CityJSON blocks with terrain", run});
}  // namespace
