#pragma once
// The project's processing steps, shared by the GUI (run in its job runner) and by
// `delineo-cli run PROJECT`: reading the pair, dense matching, the active polygon for one
// building, roof height, export of accepted buildings and the bundled sample project.
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"
#include "delineo/dem/heights.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/project/project.hpp"

namespace delineo::project {

// Checks every parameter group the steps read ("range", "matching", "delineation", "boxfit", "roof-levels",
// "enhance", and the scene analysis's): a bad value is found when the project is loaded, not after matching.
// Throws core::Error(InvalidParameter) naming the group and the parameter.
void validateParameters(const Project& project);

// The pair as float32 grey (NaN = no data). Throws FileNotFound / UnreadableFile naming the
// image, MismatchedInputs when the two images differ in size (an epipolar pair shares rows).
struct StereoPair {
  cv::Mat left, right;
  io::GeoReference geo;  // of the left image
  cv::Mat exclude;  // CV_8U, 255 on pixels that are not roof (project's images.exclude), or empty
  // CV_32F, the matcher's disparity map when there is one (NaN = unmatched), or empty: the active
  // polygon's costs and ground estimate read it. Not read by readStereoPair: set by whoever holds it.
  cv::Mat disparity;
};
StereoPair readStereoPair(const Project& project);

// The project's disparity raster (float32, NaN = no data), or an empty matrix when the project
// names none. Throws like io::readRaster, and MismatchedInputs when its size differs from `size`.
cv::Mat readDisparity(const Project& project, cv::Size size);

// The pair's disparity search range estimated from sparse feature matches
// (stereo::estimateDisparityRange with the project's "range" parameters). Throws
// ProcessingFailed when the images give too few matches (the range must then be given by hand).
struct RangeOutcome {
  DisparityInterval range;
  int matches = 0;  // feature matches the range was read from
  core::RunStatus status = core::RunStatus::Completed;
};
RangeOutcome estimateDisparityRange(const Project& project, const StereoPair& pair, core::Progress* progress);

// Dense matching with the project's "matching" parameters; dmin/dmax come from the project's
// disparity range (InvalidParameter when it has none). Canceled → empty disparity and status
// Canceled.
struct MatchingOutcome {
  cv::Mat disparity;
  core::RunStatus status = core::RunStatus::Completed;
};
MatchingOutcome computeDisparity(const Project& project, const cv::Mat& left, const cv::Mat& right,
                                 core::Progress* progress);

// Roof disparity interval suggested for an operator's rough polygon: the most populated
// histogram peak inside it, away from its border and above the ground level, as wide as the
// peak's spread (delineation::proposeRoofInterval, default parameters). nullopt when the polygon
// holds fewer than 10 finite disparities.
std::optional<DisparityInterval> suggestRoofInterval(const cv::Mat& disparity, const core::Polygon& polygon);

// Ground level (px) around a polygon: the main low disparity level of a 120 px band
// outside it (delineation::estimateGroundLevel). The histogram's ground line and the roof
// interval above use the same estimate. nullopt when no disparity is finite there.
std::optional<double> suggestGroundLevel(const cv::Mat& disparity, const core::Polygon& polygon);
// The ground level (px) of the whole map, by the same estimate (the height model's ground
// disparity, proposed to the operator). nullopt when nothing is finite.
std::optional<double> suggestSceneGroundLevel(const cv::Mat& disparity);

// The project's height model as the DEM library takes it (reference height 0 at the ground
// disparity). Throws InvalidParameter when the model is unknown.
dem::HeightModel demHeightModel(const HeightModel& model);

// Heights (m) from the disparity map through the project's height model (dem::heightsFromDisparity);
// an empty matrix when the map is empty or the model unknown.
cv::Mat heightsFromDisparity(const Project& project, const cv::Mat& disparity);

// The above-ground object under `click` (left-image pixels), for "Pick an above-ground object":
// delineation::aboveGroundObjectAt() with the project's "pick" parameters and the ground estimate
// of suggestGroundLevel(). It reads the disparity map when there is one and the height model is
// known, else the DEM brought to disparity by the height model (or read as disparity at 1 m per
// px without one). Outcome NoHeights when there is neither.
struct ObjectPick {
  enum class Outcome { Found, NoHeights, NoGround, NotAboveGround };
  Outcome outcome = Outcome::NoHeights;
  core::Polygon outline;  // Found: the initial polygon of a new building
  double groundLevel = std::nan("");   // px of disparity of the map read (suggestGroundLevel of the outline)
  double groundHeight = std::nan("");  // m, the same ground by the height model (NaN when unknown)
};
ObjectPick pickAboveGroundObject(const Project& project, const cv::Mat& disparity, const cv::Mat& dem,
                                 cv::Point2d click);

// Ground height (m) next to `polygon` on a DEM in metres (the 3D view's block base): the ground
// estimate of suggestGroundLevel() on the DEM brought to disparity by the height model, brought
// back to metres; with a DEM derived from the disparity, the histogram's ground line in metres.
// Without a height model the DEM is read as disparity at 1 m per px. nullopt when no height is
// near the polygon.
std::optional<double> groundHeightNextTo(const Project& project, const cv::Mat& dem, const core::Polygon& polygon);

// Median disparity inside `polygon` turned into metres by the project's height model; NaN when
// the model is unknown or no disparity is finite there.
double roofHeight(const Project& project, const cv::Mat& disparity, const core::Polygon& polygon);

// ---- the active polygon (src/active_polygon_steps.cpp) ----

// The active polygon for one building. `onContour` (may be empty) receives intermediate
// contours in left-image pixels from the worker thread.
struct DelineationOutcome {
  core::Polygon outline;  // regularized when its last stage passed the gate
  double energy = 0.0;
  EnergyTerms terms{};  // the energy's terms, summing to `energy`
  int iterations = 0;
  core::RunStatus status = core::RunStatus::Completed;
  core::Polygon rawOutline;       // the active polygon's outline before regularization
  std::string regularization;     // "regularized", "kept-raw" or "off"
  std::string regularizationNote; // why the raw outline was kept (empty otherwise)
};
using ContourListener = std::function<void(const core::Polygon&)>;
DelineationOutcome delineateBuilding(const Project& project, const Building& building,
                                     const StereoPair& pair, core::Progress* progress,
                                     const ContourListener& onContour = {});

// The active polygon's energy F(C) of `outline` (an operator's edit of the building's outline),
// with the building's roof interval and the project's parameters, as delineateBuilding() would
// score it. Throws InvalidParameter without a roof interval or for an outline that is not a
// valid polygon on the pixel grid.
struct EnergyOutcome {
  double energy = 0.0;
  EnergyTerms terms{};
  core::RunStatus status = core::RunStatus::Completed;
};
EnergyOutcome outlineEnergy(const Project& project, const Building& building, const StereoPair& pair,
                            const core::Polygon& outline, core::Progress* progress);

// The delineation's last stage (regularization, with the project's parameters) on `outline` (the
// building's current outline, an operator's edit): the regularized outline when it passes the
// gate, energy included (as delineateBuilding() would score it), else `outline` itself with the
// reason. The per-building "Regularize" action. Throws InvalidParameter without a roof interval
// or for an outline that is not a polygon; cancel returns `outline` with regularization "off".
struct RegularizationOutcome {
  core::Polygon outline;
  std::string regularization;      // "regularized", "kept-raw" or "off"
  std::string regularizationNote;  // why the outline was kept (empty otherwise)
  int verticesBefore = 0, verticesAfter = 0;
  double energyChange = 0.0;  // F(result) - F(outline) when the energy gate ran
};
RegularizationOutcome regularizeOutline(const Project& project, const Building& building,
                                        const StereoPair& pair, const core::Polygon& outline,
                                        core::Progress* progress);

// ---- methods on the DEM (src/dem_methods.cpp) ----

// Heights (m, CV_32F, NaN = none) on the left image's grid: the project's DEM raster when it
// names one, else `disparity` through the height model. Empty when neither is there (no DEM file,
// and no disparity or no height model). Throws like io::readRaster for a DEM file.
cv::Mat projectHeights(const Project& project, const cv::Mat& disparity);

// Box-fitting (boxfit::fitBoxes with the project's "boxfit" parameters) on one building, from
// its initial polygon. `heights` as projectHeights() gives them, `left` the left image (one
// channel). An empty outline means no building came out, `message` says why.
struct FittedBox {
  core::Ring corners;   // four corners, left-image pixels
  double energy = 0.0;  // px, mean cost of its sides
};
struct BoxFitOutcome {
  core::Polygon outline;
  std::vector<FittedBox> boxes;
  double energy = std::nan("");  // px, area-weighted mean energy of the boxes
  std::string message;
  core::RunStatus status = core::RunStatus::Completed;
  bool hasOutline() const { return outline.outer.size() >= 3; }
};
BoxFitOutcome fitBuildingBoxes(const Project& project, const Building& building, const cv::Mat& heights,
                               const cv::Mat& left, core::Progress* progress);

// The building with a box-fitting outline as its result: status Automatic, method kBoxFitting,
// F(C) unknown (scored later by outlineEnergy when wanted), roof height from `disparity`, and a
// "delineated" history entry naming the method, its boxes and their energy (`origin` first, e.g.
// "delineo-cli run").
Building withBoxFitOutline(const Project& project, const Building& building, const BoxFitOutcome& outcome,
                           const cv::Mat& disparity, const std::string& origin = {});

// DEM enhancement (dem::enhanceDem with the project's "enhance" parameters) of `heights` with the
// outlines of the buildings that have one, rejected ones left out. Without any outline `dem` is
// `heights` itself and `footprints` 0. Canceled: `heights` unchanged, status Canceled.
struct EnhancedDemOutcome {
  cv::Mat dem;
  int footprints = 0;
  core::RunStatus status = core::RunStatus::Completed;
};
EnhancedDemOutcome enhanceHeights(const Project& project, const cv::Mat& heights, core::Progress* progress);

// ---- scene analysis (src/scene_analysis.cpp) ----

// Parameter groups of the scene analysis in the project file.
inline constexpr const char* kSegmentGroup = "segment";    // segmentation::GroundParams
inline constexpr const char* kClassifyGroup = "classify";  // segmentation::ClassifyParams
inline constexpr const char* kObjectsGroup = "objects";    // segmentation::ObjectParams
inline constexpr const char* kDetectGroup = "detect";      // segmentation::DetectParams
// A proposal that covers, or is covered by, an existing building over more than this share of
// its pixels is that building: it is not added again.
inline constexpr double kProposalOverlap = 0.3;

// segmentation::analyseScene() with the project's groups and the height model's gsd: ground /
// above-ground, DTM, nDSM, building vs vegetation, objects and building proposals. `heights` as
// projectHeights() gives them, `image` the left image 8-bit grey or BGR (io::readImage8),
// `disparity` (may be empty) gives the objects their disparity intervals. Throws
// InvalidParameter without heights or gsd.
struct SceneAnalysisOutcome {
  core::RunStatus status = core::RunStatus::Completed;
  cv::Mat dtm;          // CV_32F m
  cv::Mat ndsm;         // CV_32F m, DEM - DTM, NaN where no height
  cv::Mat classes;      // CV_8U: 0 ground or no data, 1 building, 2 vegetation
  cv::Mat objectIndex;  // CV_32S, the object id of each pixel, 0 for none
  std::vector<core::Feature> objects;    // objects.geojson
  std::vector<core::Feature> proposals;  // one per proposed building (delineate --init)
  int regions = 0, rounds = 0;
  bool converged = false;
};
SceneAnalysisOutcome analyseScene(const Project& project, const cv::Mat& heights, const cv::Mat& image,
                                  const cv::Mat& disparity, core::Progress* progress);

// ---- buildings from elsewhere (src/pending_buildings.cpp) ----

// Adds each proposal that is not already a building (kProposalOverlap) as a Pending building:
// its polygon as the initial polygon, its roof interval (delineation::readFeatureIntervals), a
// "detected" history entry (`origin` first). Returns the new buildings' ids. A proposal whose
// roof interval is malformed is added without one; its history entry says why, and so does a
// line "building ID: ..." appended to `problems` when given.
std::vector<int> addProposedBuildings(Project& project, const std::vector<core::Feature>& proposals,
                                      const std::string& origin = {}, std::vector<std::string>* problems = nullptr);

// Outlines of another source (a cadastre, OpenStreetMap, another project's or tool's export)
// brought in as Pending buildings: File → Import outlines, `delineo-cli import`.
struct ImportOptions {
  std::string idField;  // attribute whose value becomes each building's sourceId; empty: none
  std::string source;   // the file's name, for the history entries (importOutlinesFile sets it)
  std::string origin;   // first word of the history entries ("delineo", "delineo-cli import")
};
struct ImportSummary {
  int read = 0;                    // polygons read (a multipolygon gives one per part)
  std::vector<int> added;          // ids of the new Pending buildings, in the file's order
  int alreadyThere = 0;            // covering, or covered by, a building of the project: not added
  int outsideImage = 0;            // less than kMinImportedArea on the left image: not added
  int clipped = 0;                 // of the added, cut at the image border
  std::vector<std::string> problems;  // "polygon 3: no osm_id", a malformed roof interval
};
// Least area (px²) of an imported polygon on the left image.
inline constexpr double kMinImportedArea = 16.0;
// Adds each of `features` (left-image pixels) that lies on the image (one across its border cut
// there, its largest part kept; less than kMinImportedArea left: outside) and is not already a
// building (kProposalOverlap, as for proposals) as a Pending building: its polygon as the initial
// polygon, its roof interval when it carries detect's roof_disparity_min/max, its `idField` value
// as sourceId, an "imported" history entry. Throws InvalidParameter when no feature has `idField`.
ImportSummary importOutlines(Project& project, const std::vector<core::Feature>& features, cv::Size imageSize,
                             const ImportOptions& options);
// importOutlines() of a vector file (GeoJSON, GeoPackage, Shapefile) read with the left image's
// georeferencing (io::readFeatures: map coordinates brought into the image's CRS, or pixels
// without one). Throws like io::readRasterInfo for the left image and io::readFeatures for the file.
ImportSummary importOutlinesFile(Project& project, const std::string& path, ImportOptions options);

// ---- elevation rasters (src/elevation_rasters.cpp) ----

// The elevation data of a project as files of one folder (File → Export elevation rasters, and
// `run --detect` for the scene analysis's), in this order.
enum class ElevationLayer { Disparity, Dem, EnhancedDem, Dtm, Ndsm, Labels, Objects };
inline constexpr ElevationLayer kSceneAnalysisLayers[] = {ElevationLayer::Dtm, ElevationLayer::Ndsm,
                                                          ElevationLayer::Labels, ElevationLayer::Objects};
struct ElevationLayers {
  cv::Mat disparity;    // CV_32F px, NaN = none                         → disparity.tif
  cv::Mat dem;          // CV_32F m (projectHeights())                    → dem.tif
  cv::Mat enhancedDem;  // CV_32F m (enhanceHeights())                    → enhanced_dem.tif
  cv::Mat dtm, ndsm;    // CV_32F m (SceneAnalysisOutcome)                → dtm.tif, ndsm.tif
  cv::Mat labels;       // CV_8U: 0 ground, 1 building, 2 vegetation      → labels.tif
  std::optional<std::vector<core::Feature>> objects;  // left-image px    → objects.geojson
  // The layers there are (a non-empty raster, objects set even when none), in the order above.
  std::vector<ElevationLayer> present() const;
  void leaveOut(ElevationLayer layer);
  // The scene analysis's layers: its DTM, nDSM, classes (labels.tif) and objects.
  void setSceneAnalysis(const SceneAnalysisOutcome& analysis);
};
// The scene analysis's layers alone.
ElevationLayers sceneAnalysisLayers(const SceneAnalysisOutcome& analysis);
// The file of each layer in `dir` ("disparity.tif", "dem.tif", "enhanced_dem.tif", "dtm.tif",
// "ndsm.tif", "labels.tif", "objects.geojson") with its format, for io::checkOutputs.
std::vector<io::OutputFile> elevationFiles(const std::string& dir, const std::vector<ElevationLayer>& layers);
// Leaves out of `layers` the disparity and the DEM when their file in `dir` is the project's own
// (its disparity or DEM raster is already that file: it is not replaced by itself). Returns the
// names of the files left out.
std::vector<std::string> leaveOutProjectSources(const Project& project, const std::string& dir,
                                                ElevationLayers& layers);

struct ElevationRastersWritten {
  std::vector<std::string> files;  // paths written, in the order of ElevationLayer
  int rasters = 0;                 // GeoTIFFs among them
  bool objects = false;            // objects.geojson among them
  core::RunStatus status = core::RunStatus::Completed;
};
// Writes the layers there are into the folder `dir`, the rasters as GeoTIFF (float32 with NaN as
// nodata; labels 8-bit) and the objects as GeoJSON, georeferenced by `geo` (the left image's)
// when valid. The outputs are checked first (io::checkOutputs against `inputs`). Each layer is
// written to a temporary file beside its target, and once all are complete they are moved over
// their targets: a failure or a cancel (polled between layers) leaves the folder as it was.
// Throws UnusableOutput, WriteFailed.
ElevationRastersWritten writeElevationRasters(const std::string& dir, const io::GeoReference& geo,
                                              const ElevationLayers& layers, core::Progress* progress = nullptr,
                                              const std::vector<std::string>& inputs = {});

// ---- run and export (src/run_and_export.cpp) ----

// One pending building outlined with its method (Project::methodOf), as `run` and the GUI's
// "Outline the pending buildings" do it: the active polygon on `pair` (whose disparity map gives
// the roof interval when the building has none), or box-fitting on `heights` (projectHeights(),
// read here when empty). Returns the building after: status Automatic, method, outline, energy,
// roof height and a "delineated" history entry starting with `origin`; nullopt when canceled.
// Throws core::Error when the method cannot outline it (InvalidParameter without heights for
// box-fitting, ProcessingFailed when box-fitting finds no building).
std::optional<Building> outlinePendingBuilding(const Project& project, const Building& building,
                                               const StereoPair& pair, cv::Mat& heights,
                                               core::Progress* progress, const std::string& origin);

// `delineo-cli run`: the disparity range estimated when the project has none, matching when
// the disparity is missing (written to
// `outputDir`/disparity.tif and recorded in the project), then the outline of every Pending
// building with its method (Project::methodOf: the active polygon, or box-fitting on
// projectHeights(); status becomes Automatic, method and history updated), then export of accepted +
// automatic + corrected outlines to `outputDir`/buildings.geojson, and when any of them has a
// roof height their LoD1 blocks to `outputDir`/buildings.city.json. `outputDir` is the resolved
// folder (outputDirectory()). The caller saves the project.
struct RunSummary {
  std::optional<RangeOutcome> rangeEstimated;  // set when the range was estimated
  bool matched = false;
  int delineated = 0;  // outlined by either method
  int boxFitted = 0;   // of which by box-fitting
  int skipped = 0;     // pending buildings whose method failed (reason in `messages`)
  int proposed = 0;    // buildings added from the scene analysis's proposals (RunOptions::detect)
  int objects = 0;     // above-ground objects the scene analysis found
  std::vector<std::string> messages;
  std::string exported;  // path of the written GeoJSON, empty when nothing was written
  std::string exportedBlocks;  // path of the written CityJSON, empty when nothing was written
  int terrainTriangles = 0;    // of the CityJSON's terrain (RunOptions::detect), 0 without
  bool blocksFailed = false;   // the CityJSON was not written: a building's outline is degenerate (in `messages`)
  core::RunStatus status = core::RunStatus::Completed;
};
// With `detect`, the scene analysis runs after matching on projectHeights() (analyseScene(),
// writing dtm.tif, ndsm.tif, labels.tif and objects.geojson into `outputDir` with
// writeElevationRasters()) and its proposals become pending buildings (addProposedBuildings())
// before the outlines are made; its DTM is the terrain of buildings.city.json. The blocks stand
// on the ground next to each building (exportBuildings() with projectHeights()).
struct RunOptions {
  bool detect = false;
};
RunSummary runPendingSteps(Project& project, const std::string& outputDir, core::Progress* progress,
                           const RunOptions& options = {});

// Features of the buildings with the given statuses (attributes: id, status, method, vertices,
// roof_height_m, energy), in left-image pixels.
std::vector<core::Feature> buildingFeatures(const Project& project,
                                            const std::vector<BuildingStatus>& statuses);
struct ExportSummary {
  int written = 0;                   // buildings written
  int parts = 0;                     // CityJSON: BuildingParts of the buildings with several roof levels
  std::vector<std::string> leftOut;  // CityJSON: "building 3: no roof height", one per building left out
  // CityJSON: what the operator should know about the bases ("no heights: ..."), one per line.
  std::vector<std::string> notes;
  bool onLocalGround = false;        // CityJSON: the blocks stand on the ground next to each building
  int terrainVertices = 0, terrainTriangles = 0;  // CityJSON: the terrain's, 0 without
  core::RunStatus status = core::RunStatus::Completed;  // Canceled: nothing was written
};

// The terrain grid of the CityJSON export.
struct TerrainParams {
  int step = 0;  // px between neighbouring vertices; 0: about 1 m, round(1 m / gsd)

  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"terrain-step", "Terrain step", "px",
                      "Pixels between neighbouring vertices of the terrain (0: about 1 m at the height model's gsd)",
                      0, 10000},
      step);
  }
  void validate() const { core::checkDeclaredRanges(*this); }
  // The step in px: `step`, or for 0 the one nearest to 1 m at `gsd` (m per px), at least 1.
  int resolvedStep(double gsd) const;
};

// What the CityJSON export stands the blocks on, and its terrain.
struct CityModelInputs {
  // CV_32F m on the left image's grid (projectHeights()): each block's base is the ground next to
  // it, groundHeightNextTo() as the 3D view draws it. Empty: every block stands on the ground level.
  cv::Mat heights;
  cv::Mat dtm;  // CV_32F m on the left image's grid (analyseScene()'s DTM): the terrain; empty: none
  TerrainParams terrain;
};

// Writes the buildings with the given statuses, georeferenced like the left image when it has a
// geotransform: their outlines as GeoJSON or GeoPackage by extension, or for "*.city.json" /
// "*.cityjson" CityJSON LoD1 blocks from the ground next to each building (ground_height_m, on
// `model.heights`) to its roof height, with the DTM's TIN as terrain when `model.dtm` is given,
// every z raised by the height model's groundElevation (io/cityjson.hpp; local metres of the
// height model's gsd without georeferencing). A building without a roof height, or whose roof is
// not above its base, is left out; without heights (or without ground next to a building) a block
// stands on the ground level, said in `notes`. With heights, a building whose roof has several
// levels is written as its parts (roofParts(), the project's "roof-levels" group; CityJSON
// BuildingParts), each from the building's base to its own height. Throws WriteFailed, and InvalidParameter naming a
// building whose outline is degenerate or for a bad terrain step.
// `progress` goes through the buildings' grounds and roof parts (CityJSON); a cancel there returns
// status Canceled and writes nothing.
ExportSummary exportBuildings(const Project& project, const std::string& path,
                              const std::vector<BuildingStatus>& statuses = {BuildingStatus::Accepted},
                              const CityModelInputs& model = {}, core::Progress* progress = nullptr);

// ---- the bundled sample (src/pipeline.cpp) ----

// The bundled sample: a deterministic simulated scene written into `directory` (left, right,
// ground-truth DEM and labels) and a project file "sample.delineo.json" referencing them, with
// no disparity yet so the first step of the workflow is there to run. Reuses an existing
// sample. Returns the project path. Throws ProcessingFailed when the simulation is canceled.
std::string ensureSampleProject(const std::string& directory, core::Progress* progress = nullptr);

}  // namespace delineo::project
