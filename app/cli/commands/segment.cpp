// delineo-cli segment: ground / above-ground segmentation of a DEM with its DTM, building vs
// vegetation and the above-ground objects (segmentation::analyseScene, docs/dem.md). Writes
// dtm.tif, ndsm.tif, labels.tif (0 ground, 1 building, 2 vegetation) and objects.geojson.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/sim/scene.hpp"
#include "scene_support.hpp"

namespace delineo::cli {

namespace fs = std::filesystem;

void addSceneInputs(Options& opts, bool needsDisparity) {
  opts.required("dem", "FILE", "DEM: one band of heights in metres on the left image's grid (GeoTIFF float32, NaN = none)")
      .required("image", "FILE", "the left image (grey or RGB), same size as the DEM")
      .value("gsd", "M", "ground sample distance of a pixel in metres")
      .value("scene", "FILE", "scene.json of a simulated scene: its ground sample distance");
  if (needsDisparity) {
    opts.required("disparity", "FILE", "disparity map of the pair (px): the roof and ground intervals");
  } else {
    opts.value("disparity", "FILE", "disparity map of the pair (px): gives the objects their roof and ground intervals");
  }
  opts.flag("quiet", "no progress on stderr")
      .params(segmentation::GroundParams{})
      .params(segmentation::ClassifyParams{})
      .params(segmentation::ObjectParams{});
}

namespace {
double groundSampleDistance(const Options& opts) {
  if (opts.has("gsd") == opts.has("scene")) throw UsageError("give either --gsd or --scene");
  if (opts.has("scene")) return sim::readSceneJson(opts.get("scene")).gsd;
  const double gsd = opts.getDouble("gsd");
  if (!(gsd > 0.0)) throw UsageError("--gsd must be a positive number of metres");
  return gsd;
}

void requireSize(const cv::Mat& raster, const io::Raster& dem, const std::string& path, const char* what) {
  if (raster.size() == dem.data.size()) return;
  throw core::Error(core::ErrorCode::MismatchedInputs,
                    std::string(what) + " is " + std::to_string(raster.cols) + "x" + std::to_string(raster.rows) +
                        " px but the DEM " + dem.path + " is " + std::to_string(dem.data.cols) + "x" +
                        std::to_string(dem.data.rows),
                    path);
}

io::Raster readOneBand(const std::string& path, const char* what) {
  io::ReadOptions options;
  options.type = io::PixelType::Float32;
  io::Raster raster = io::readRaster(path, options);
  if (raster.data.channels() != 1) {
    throw core::Error(core::ErrorCode::UnsupportedInput,
                      std::string(what) + " must have one band, it has " + std::to_string(raster.data.channels()),
                      path);
  }
  return raster;
}
}  // namespace

SceneInputs readSceneInputs(const Options& opts) {
  SceneInputs in;
  in.gsd = groundSampleDistance(opts);
  in.dem = readOneBand(opts.get("dem"), "the DEM");
  in.image = io::readImage8(opts.get("image"));
  requireSize(in.image, in.dem, opts.get("image"), "the image");
  if (opts.has("disparity")) {
    in.disparity = readOneBand(opts.get("disparity"), "the disparity map").data;
    requireSize(in.disparity, in.dem, opts.get("disparity"), "the disparity map");
  }
  return in;
}

SceneRun runSceneAnalysis(const Options& opts, const segmentation::SceneParams& params) {
  auto& progress = commandProgress();
  progress.setQuiet(opts.has("quiet"));
  progress.setStage("reading");
  SceneRun run{readSceneInputs(opts), {}};
  throwIfCanceled(progress);
  core::Progress::Range working(&progress, 0.0, 0.95);
  try {
    run.analysis = segmentation::analyseScene(run.inputs.dem.data, run.inputs.image, run.inputs.gsd, params,
                                              run.inputs.disparity, &working);
  } catch (const core::Error& e) {
    // The algorithms know no file names: input problems name the DEM.
    if (e.code() == core::ErrorCode::InvalidParameter) throw;
    throw core::Error(e.code(), e.detail(), run.inputs.dem.path);
  }
  if (run.analysis.status == core::RunStatus::Canceled) throw Canceled();
  progress.setStage("writing");
  return run;
}

}  // namespace delineo::cli

namespace {
using namespace delineo;
namespace fs = std::filesystem;

int run(const std::vector<std::string>& args) {
  cli::Options opts("segment",
                    "Ground and above-ground objects of a DEM: regions, ground labelling with its "
                    "terrain model (DTM) until stable, heights above it (nDSM), building vs "
                    "vegetation and the objects with their outlines.");
  cli::addSceneInputs(opts, false);
  opts.required("out", "DIR", "folder for dtm.tif, ndsm.tif, labels.tif and objects.geojson");
  if (!opts.parse(args)) return cli::kExitOk;
  segmentation::SceneParams params;
  opts.apply(params.ground);
  opts.apply(params.classify);
  opts.apply(params.objects);

  const fs::path dir(opts.get("out"));
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw core::Error(core::ErrorCode::UnusableOutput, "cannot create the folder: " + ec.message(), dir.string());
  const std::vector<io::OutputFile> outputs{{(dir / "dtm.tif").string(), io::OutputFormat::GeoTiff},
                                            {(dir / "ndsm.tif").string(), io::OutputFormat::GeoTiff},
                                            {(dir / "labels.tif").string(), io::OutputFormat::GeoTiff},
                                            {(dir / "objects.geojson").string(), io::OutputFormat::Vector}};
  io::checkOutputs(outputs, {opts.get("dem"), opts.get("image"), opts.has("disparity") ? opts.get("disparity") : ""});
  const auto [inputs, analysis] = cli::runSceneAnalysis(opts, params);
  const io::GeoReference& geo = inputs.dem.geo;
  io::writeFloatGeoTiff(outputs[0].path, analysis.ground.dtm, geo);
  io::writeFloatGeoTiff(outputs[1].path, analysis.ground.ndsm, geo);
  io::writeGeoTiff(outputs[2].path, analysis.classes(), geo);
  io::writeFeatures(outputs[3].path, segmentation::objectFeatures(analysis.detection.objects.objects), geo, "objects");
  cli::commandProgress().report(1.0);
  cli::commandProgress().finish();

  const cv::Mat& classes = analysis.classes();
  const double total = std::max(1, classes.rows * classes.cols);
  int buildings = 0, vegetation = 0;
  for (const auto& object : analysis.detection.objects.objects) {
    (object.cls == segmentation::kClassBuilding ? buildings : vegetation) += 1;
  }
  std::printf("segment %dx%d: %d regions, %d rounds (%s), above ground %.1f %% (building %.1f %%, vegetation "
              "%.1f %%), %d building and %d vegetation objects -> %s\n",
              classes.cols, classes.rows, analysis.ground.regionCount, analysis.ground.iterations,
              analysis.ground.converged ? "stable" : "unstable regions set to ground",
              100.0 * cv::countNonZero(analysis.ground.aboveGround) / total,
              100.0 * cv::countNonZero(classes == segmentation::kClassBuilding) / total,
              100.0 * cv::countNonZero(classes == segmentation::kClassVegetation) / total, buildings, vegetation,
              dir.string().c_str());
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"segment", "ground / above-ground, DTM, nDSM, building vs vegetation and objects of a DEM", run});
}  // namespace
