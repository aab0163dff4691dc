// `delineo-cli run`'s steps and the export of the buildings: the outline of one pending building
// with its method, the scene analysis's proposals, the exports to GeoJSON / GeoPackage and
// CityJSON blocks (declared in pipeline.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "delineo/core/error.hpp"
#include "delineo/delineation/roof_interval.hpp"
#include "delineo/io/cityjson.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/roof_parts.hpp"

namespace delineo::project {

namespace fs = std::filesystem;
using core::Error;
using core::ErrorCode;

std::vector<core::Feature> buildingFeatures(const Project& project,
                                            const std::vector<BuildingStatus>& statuses) {
  std::vector<core::Feature> features;
  for (const auto& b : project.buildings) {
    if (std::find(statuses.begin(), statuses.end(), b.status) == statuses.end()) continue;
    core::Feature f;
    f.polygon = b.currentPolygon();
    f.attributes["id"] = static_cast<long long>(b.id);
    f.attributes["status"] = toString(b.status);
    if (b.hasOutline()) f.attributes["method"] = b.method.empty() ? std::string(kActivePolygon) : b.method;
    long long vertices = static_cast<long long>(f.polygon.outer.size());
    for (const auto& hole : f.polygon.holes) vertices += static_cast<long long>(hole.size());
    f.attributes["vertices"] = vertices;
    if (std::isfinite(b.roofHeight)) f.attributes["roof_height_m"] = b.roofHeight;
    if (std::isfinite(b.energy)) f.attributes["energy"] = b.energy;
    if (!b.sourceId.empty()) f.attributes["source_id"] = b.sourceId;
    features.push_back(std::move(f));
  }
  return features;
}

namespace {
// The left image's georeferencing; none when it is missing or unreadable (pixel coordinates
// then; the image problem is reported where it is read).
io::GeoReference leftGeoReference(const Project& project) {
  std::error_code ec;
  if (project.left.empty() || !fs::exists(project.left, ec)) return {};
  try {
    return io::readRasterInfo(project.left).geo;
  } catch (const Error&) {
    return {};
  }
}

std::string buildingName(const core::Feature& feature) {
  const auto id = feature.attributes.find("id");
  const auto* number = id != feature.attributes.end() ? std::get_if<long long>(&id->second) : nullptr;
  return number != nullptr ? "building " + std::to_string(*number) : std::string("a building");
}

// Each feature with a roof height gets its base, ground_height_m: the ground next to it on
// `heights` (the 3D view's estimate). Without heights, or without ground next to a building, the
// block stands on the ground level: `summary.notes` says so.
std::vector<core::Feature> withGroundHeights(const Project& project, const cv::Mat& heights,
                                             std::vector<core::Feature> features, ExportSummary& summary,
                                             core::Progress* progress) {
  if (heights.empty()) {
    summary.notes.push_back("no heights: every block stands on the height model's ground level (z = 0)");
    return features;
  }
  summary.onLocalGround = true;
  for (size_t i = 0; i < features.size(); ++i) {
    core::Feature& feature = features[i];
    if (core::isCanceled(progress)) return {};
    core::report(progress, static_cast<double>(i) / static_cast<double>(features.size()));
    if (feature.attributes.count("roof_height_m") == 0) continue;
    const std::optional<double> ground = groundHeightNextTo(project, heights, feature.polygon);
    if (ground) {
      feature.attributes["ground_height_m"] = *ground;
    } else {
      summary.notes.push_back(buildingName(feature) + ": no ground next to it: its block stands on the ground level");
    }
  }
  return features;
}

// Each feature with a roof height and its roof parts on `heights` (roofParts(), the project's
// "roof-levels" group): none when its roof has one level, without heights, or with roof levels off.
std::vector<io::CityJsonBuilding> withRoofParts(const Project& project, const cv::Mat& heights,
                                                const std::vector<core::Feature>& features,
                                                core::Progress* progress) {
  std::vector<io::CityJsonBuilding> buildings;
  for (size_t i = 0; i < features.size(); ++i) {
    const core::Feature& feature = features[i];
    if (core::isCanceled(progress)) return {};
    core::report(progress, static_cast<double>(i) / static_cast<double>(features.size()));
    io::CityJsonBuilding building{feature, {}};
    if (!heights.empty() && feature.attributes.count("roof_height_m") > 0) {
      const std::vector<RoofPart> parts = roofParts(project, heights, feature.polygon);
      if (parts.size() >= 2) {
        for (const auto& part : parts) building.parts.push_back({part.polygon, part.height});
      }
    }
    buildings.push_back(std::move(building));
  }
  return buildings;
}

// The CityJSON of `features`: blocks on the ground next to each, the terrain when there is a DTM.
ExportSummary writeCityModel(const Project& project, const std::string& path, const std::vector<core::Feature>& features,
                             const io::GeoReference& geo, const CityModelInputs& model, core::Progress* progress) {
  ExportSummary summary;
  io::CityJsonOptions options;
  options.geo = geo;
  options.localPixelSize = project.height.gsd;
  options.zOffset = project.height.groundElevation;
  if (!model.dtm.empty()) {
    model.terrain.validate();
    options.terrain = {model.dtm, model.terrain.resolvedStep(project.height.gsd)};
  }
  // The grounds take a tenth of the bar, the roof parts the rest; a cancel writes nothing.
  std::vector<core::Feature> grounded;
  {
    core::Progress::Range range(progress, 0.0, 0.1);
    grounded = withGroundHeights(project, model.heights, features, summary, &range);
  }
  std::vector<io::CityJsonBuilding> buildings;
  if (!core::isCanceled(progress)) {
    core::Progress::Range range(progress, 0.1, 0.95);
    buildings = withRoofParts(project, model.heights, grounded, &range);
  }
  if (core::isCanceled(progress)) {
    summary.status = core::RunStatus::Canceled;
    return summary;
  }
  const io::CityJsonSummary blocks = io::writeCityJson(path, buildings, options);
  core::report(progress, 1.0);
  summary.written = blocks.written;
  summary.parts = blocks.parts;
  summary.leftOut = blocks.leftOut;
  summary.terrainVertices = blocks.terrainVertices;
  summary.terrainTriangles = blocks.terrainTriangles;
  return summary;
}

// Writes `features` (the project's buildings) to `path` in the format its name says.
ExportSummary writeBuildingFeatures(const Project& project, const std::string& path,
                                    const std::vector<core::Feature>& features, const CityModelInputs& model = {},
                                    core::Progress* progress = nullptr) {
  const io::GeoReference geo = leftGeoReference(project);
  std::error_code mk;
  fs::create_directories(fs::absolute(path).parent_path(), mk);
  if (io::isCityJsonPath(path)) return writeCityModel(project, path, features, geo, model, progress);
  ExportSummary summary;
  io::writeFeatures(path, features, geo);
  summary.written = static_cast<int>(features.size());
  return summary;
}
}  // namespace

int TerrainParams::resolvedStep(double gsd) const {
  if (step > 0) return step;
  if (!(gsd > 0.0)) return 1;
  return static_cast<int>(std::clamp(std::round(1.0 / gsd), 1.0, 10000.0));
}

ExportSummary exportBuildings(const Project& project, const std::string& path,
                              const std::vector<BuildingStatus>& statuses, const CityModelInputs& model,
                              core::Progress* progress) {
  return writeBuildingFeatures(project, path, buildingFeatures(project, statuses), model, progress);
}

namespace {
// The roof interval proposed for a pending building that has none (suggestRoofInterval()); none
// without a disparity map or matches. Throws ProcessingFailed when the main level under the
// polygon is the ground next to it (a building of an imported map the images no longer show, a
// polygon on the ground): the active polygon would outline a patch of ground.
std::optional<DisparityInterval> roofIntervalAboveGround(const cv::Mat& disparity, const core::Polygon& polygon) {
  if (disparity.empty()) return std::nullopt;
  const delineation::RoofIntervalParams params;
  const delineation::RoofIntervalProposal proposal = delineation::proposeRoofInterval(disparity, polygon, params);
  if (!proposal.found) return std::nullopt;
  if (std::isfinite(proposal.groundLevel) && std::abs(proposal.peak - proposal.groundLevel) < params.minRoofHeight) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "nothing stands above the ground under its polygon (its disparities peak at %.1f px, the ground "
                  "next to it lies at %.1f px); give it a roof interval to outline it anyway",
                  proposal.peak, proposal.groundLevel);
    throw Error(ErrorCode::ProcessingFailed, text);
  }
  return DisparityInterval{proposal.low, proposal.high};
}

// The active polygon on one pending building; nullopt when canceled.
std::optional<Building> delineatePending(const Project& project, Building b, const StereoPair& pair,
                                         core::Progress* progress, const std::string& origin) {
  if (!b.roofInterval) b.roofInterval = roofIntervalAboveGround(pair.disparity, b.initial);
  DelineationOutcome outcome = delineateBuilding(project, b, pair, progress);
  if (outcome.status == core::RunStatus::Canceled) return std::nullopt;
  b.outline = outcome.outline;
  b.energy = outcome.energy;
  b.energyTerms = outcome.terms;
  b.roofHeight = roofHeight(project, pair.disparity, b.outline);
  b.status = BuildingStatus::Automatic;
  b.method = kActivePolygon;
  std::string detail = origin + ", " + std::to_string(b.outline.outer.size()) + " vertices";
  if (!outcome.regularization.empty()) detail += ", " + outcome.regularization;
  if (!outcome.regularizationNote.empty()) detail += " (" + outcome.regularizationNote + ")";
  b.addHistory("delineated", detail);
  return b;
}
}  // namespace

std::optional<Building> outlinePendingBuilding(const Project& project, const Building& building,
                                               const StereoPair& pair, cv::Mat& heights,
                                               core::Progress* progress, const std::string& origin) {
  if (project.methodOf(building) != kBoxFitting) {
    core::setStage(progress, core::StageId::DelineatingBuilding, building.id);
    return delineatePending(project, building, pair, progress, origin);
  }
  core::setStage(progress, core::StageId::BoxFittingBuilding, building.id);
  if (heights.empty()) heights = projectHeights(project, pair.disparity);
  if (heights.empty()) {
    throw Error(ErrorCode::InvalidParameter,
                "box-fitting needs heights: the project names no DEM and has no height model");
  }
  const BoxFitOutcome outcome = fitBuildingBoxes(project, building, heights, pair.left, progress);
  if (outcome.status == core::RunStatus::Canceled) return std::nullopt;
  if (!outcome.hasOutline()) throw Error(ErrorCode::ProcessingFailed, "box-fitting: " + outcome.message);
  return withBoxFitOutline(project, building, outcome, pair.disparity, origin);
}

namespace {
// run --detect: the scene analysis on `heights`, its rasters and objects written into
// `outputDir`, its proposals added as pending buildings. False when canceled.
bool detectBuildings(Project& project, const cv::Mat& heights, const cv::Mat& disparity, const io::GeoReference& geo,
                     const std::string& outputDir, core::Progress* progress, RunSummary& summary, cv::Mat& dtm) {
  if (heights.empty()) {
    throw Error(ErrorCode::InvalidParameter,
                "detecting buildings needs heights: the project names no DEM and has no height model");
  }
  const cv::Mat image = io::readImage8(project.left);
  const SceneAnalysisOutcome analysis = analyseScene(project, heights, image, disparity, progress);
  if (analysis.status == core::RunStatus::Canceled) {
    summary.status = core::RunStatus::Canceled;
    return false;
  }
  writeElevationRasters(outputDir, geo, sceneAnalysisLayers(analysis));
  dtm = analysis.dtm;
  summary.objects = static_cast<int>(analysis.objects.size());
  summary.proposed =
      static_cast<int>(addProposedBuildings(project, analysis.proposals, "delineo-cli run", &summary.messages).size());
  return true;
}
}  // namespace

namespace {
// run's exports: the outlines to buildings.geojson, and the LoD1 blocks to buildings.city.json
// when any building has a roof height, on the ground next to each (`model.heights`) with the
// terrain of `model.dtm` when there is one. A degenerate outline stops the blocks only: the
// outlines and the project's work are kept, the problem is in the summary.
void exportRunOutputs(const Project& project, const std::string& outputDir, const CityModelInputs& model,
                      RunSummary& summary) {
  const std::vector<BuildingStatus> statuses{BuildingStatus::Automatic, BuildingStatus::Corrected,
                                             BuildingStatus::Accepted};
  const auto features = buildingFeatures(project, statuses);
  if (features.empty()) return;
  summary.exported = (fs::path(outputDir) / "buildings.geojson").string();
  writeBuildingFeatures(project, summary.exported, features);
  const bool anyHeight = std::any_of(features.begin(), features.end(),
                                     [](const core::Feature& f) { return f.attributes.count("roof_height_m") > 0; });
  if (!anyHeight) return;
  const std::string blocksPath = (fs::path(outputDir) / "buildings.city.json").string();
  try {
    const ExportSummary blocks = writeBuildingFeatures(project, blocksPath, features, model);
    summary.exportedBlocks = blocksPath;
    summary.terrainTriangles = blocks.terrainTriangles;
    for (const auto& line : blocks.leftOut) summary.messages.push_back("not in buildings.city.json: " + line);
    for (const auto& line : blocks.notes) summary.messages.push_back("buildings.city.json: " + line);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::InvalidParameter) throw;
    summary.blocksFailed = true;
    summary.messages.push_back("buildings.city.json not written: " + e.detail());
  }
}
}  // namespace

namespace {
// The heights the blocks stand on: `heights` when read already, else projectHeights(). A DEM
// that cannot be read now leaves the blocks on the ground level, said in the summary: the run's
// work is kept.
cv::Mat heightsForBases(const Project& project, const cv::Mat& heights, const cv::Mat& disparity, RunSummary& summary) {
  if (!heights.empty()) return heights;
  try {
    return projectHeights(project, disparity);
  } catch (const Error& e) {
    summary.messages.push_back(std::string("buildings.city.json: heights not read: ") + e.what());
    return {};
  }
}
}  // namespace

namespace {
// The files `run` may write, checked before any work: never over an input of the project.
std::vector<io::OutputFile> runOutputs(const Project& project, const std::string& outputDir, const RunOptions& options) {
  const fs::path out(outputDir);
  std::vector<io::OutputFile> outputs{{(out / "buildings.geojson").string(), io::OutputFormat::Vector},
                                      {(out / "buildings.city.json").string(), io::OutputFormat::CityJson}};
  if (project.disparity.empty()) outputs.push_back({(out / "disparity.tif").string(), io::OutputFormat::GeoTiff});
  if (options.detect) {
    const std::vector<ElevationLayer> scene(std::begin(kSceneAnalysisLayers), std::end(kSceneAnalysisLayers));
    for (const io::OutputFile& file : elevationFiles(outputDir, scene)) outputs.push_back(file);
  }
  return outputs;
}

// The pair's disparity into `pair.disparity`: the project's map, or the range estimated when the
// project has none and the map matched over `share` of the progress (written to
// `outputDir`/disparity.tif and recorded in the project). False when canceled.
bool ensureDisparity(Project& project, StereoPair& pair, const std::string& outputDir, core::Progress* progress,
                     double share, RunSummary& summary) {
  if (!project.disparity.empty()) {
    pair.disparity = readDisparity(project, pair.left.size());
    return true;
  }
  if (!project.disparityRange) {
    core::Progress::Range range(progress, 0.0, 0.1 * share);
    const RangeOutcome estimated = estimateDisparityRange(project, pair, &range);
    if (estimated.status == core::RunStatus::Canceled) return false;
    project.disparityRange = estimated.range;
    summary.rangeEstimated = estimated;
  }
  core::Progress::Range range(progress, 0.1 * share, share);
  range.setStage(core::StageId::DenseMatching);
  MatchingOutcome matched = computeDisparity(project, pair.left, pair.right, &range);
  if (matched.status == core::RunStatus::Canceled) return false;
  const std::string written = (fs::path(outputDir) / "disparity.tif").string();
  fs::create_directories(outputDir);
  io::writeFloatGeoTiff(written, matched.disparity, pair.geo);
  project.disparity = written;
  pair.disparity = matched.disparity;
  summary.matched = true;
  return true;
}

// Every pending building outlined with its method over [begin, 1] of the progress; a building its
// method cannot outline is skipped with the reason. False when canceled.
bool outlineEveryPending(Project& project, const StereoPair& pair, cv::Mat& heights, core::Progress* progress,
                         double begin, RunSummary& summary) {
  const std::vector<int> pending = project.pendingBuildings();
  const double n = static_cast<double>(pending.size());
  for (size_t i = 0; i < pending.size(); ++i) {
    core::Progress::Range range(progress, begin + (1.0 - begin) * static_cast<double>(i) / n,
                                begin + (1.0 - begin) * static_cast<double>(i + 1) / n);
    Building& b = *project.find(pending[i]);
    try {
      const std::optional<Building> outlined = outlinePendingBuilding(project, b, pair, heights, &range, "delineo-cli run");
      if (!outlined) return false;
      if (outlined->method == kBoxFitting) ++summary.boxFitted;
      b = *outlined;
      ++summary.delineated;
    } catch (const Error& e) {
      if (core::isInputError(e.code()) && e.code() != ErrorCode::InvalidParameter) throw;
      ++summary.skipped;
      summary.messages.push_back("building " + std::to_string(b.id) + ": " + e.what());
    }
  }
  return true;
}
}  // namespace

RunSummary runPendingSteps(Project& project, const std::string& outputDir, core::Progress* progress,
                           const RunOptions& options) {
  RunSummary summary;
  std::error_code mk;
  fs::create_directories(outputDir, mk);
  io::checkOutputs(runOutputs(project, outputDir, options), inputFiles(project));
  StereoPair pair = readStereoPair(project);
  const bool work = !project.pendingBuildings().empty() || options.detect;
  double done = project.disparity.empty() ? (work ? 0.5 : 1.0) : 0.0;  // share of the progress matching takes
  auto canceled = [&summary] {
    summary.status = core::RunStatus::Canceled;
    return summary;
  };
  if (!ensureDisparity(project, pair, outputDir, progress, done, summary)) return canceled();
  cv::Mat heights;  // for box-fitting, the scene analysis and the blocks' bases, read when asked for
  cv::Mat dtm;      // the scene analysis's, the CityJSON's terrain
  if (options.detect) {
    core::Progress::Range range(progress, done, done + 0.3 * (1.0 - done));
    heights = projectHeights(project, pair.disparity);
    if (!detectBuildings(project, heights, pair.disparity, pair.geo, outputDir, &range, summary, dtm)) return summary;
    done += 0.3 * (1.0 - done);
  }
  if (!outlineEveryPending(project, pair, heights, progress, done, summary)) return canceled();
  exportRunOutputs(project, outputDir, {heightsForBases(project, heights, pair.disparity, summary), dtm, {}}, summary);
  core::report(progress, 1.0);
  return summary;
}

}  // namespace delineo::project
