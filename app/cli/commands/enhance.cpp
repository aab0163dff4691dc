// delineo-cli enhance: DEM enhancement from building footprints (docs/dem-enhancement.md):
// roofs median-filtered, vertical walls at the outlines, the ground beyond a band kept.
#include <cstdio>
#include <string>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/dem/enhance.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"

namespace {
using namespace delineo;

io::Raster readDem(const std::string& path) {
  io::ReadOptions options;
  options.type = io::PixelType::Float32;
  io::Raster dem = io::readRaster(path, options);
  if (dem.data.channels() != 1) {
    throw core::Error(core::ErrorCode::UnsupportedInput,
                      "the DEM must have one band of heights, it has " +
                          std::to_string(dem.data.channels()),
                      path);
  }
  return dem;
}

int run(const std::vector<std::string>& args) {
  cli::Options opts("enhance",
                    "Enhances a DEM (heights in metres in left-image geometry) with building "
                    "footprints: roofs median-filtered, vertical walls at the outlines, the "
                    "ground beyond a band along them kept.");
  opts.required("dem", "FILE", "DEM: one band of heights in metres (GeoTIFF float32, nodata = no "
                               "height), in the footprints' image geometry")
      .required("footprints", "FILE",
                "building footprints (.geojson, .gpkg, .shp): brought into the DEM's CRS when it "
                "is georeferenced, else in its pixels; holes are courtyards")
      .required("out", "FILE", "enhanced DEM (GeoTIFF float32, the input's georeferencing)")
      .flag("quiet", "no progress on stderr")
      .params(dem::EnhanceParams{});
  if (!opts.parse(args)) return cli::kExitOk;
  dem::EnhanceParams params;
  opts.apply(params);

  cli::checkOutputs(opts, {{"out", io::OutputFormat::GeoTiff}}, {"dem", "footprints"});
  auto& progress = cli::commandProgress();
  progress.setQuiet(opts.has("quiet"));
  progress.setStage("reading");
  const std::string demPath = opts.get("dem"), footprintsPath = opts.get("footprints");
  const io::Raster input = readDem(demPath);
  std::vector<core::Polygon> footprints;
  for (auto& f : io::readFeatures(footprintsPath, input.geo)) footprints.push_back(std::move(f.polygon));
  cli::throwIfCanceled(progress);

  progress.setStage("enhancing");
  core::Progress::Range enhancing(&progress, 0.0, 0.95);
  dem::EnhanceResult result;
  try {
    result = dem::enhanceDem(input.data, footprints, params, &enhancing);
  } catch (const core::Error& e) {
    // The algorithm knows no file names: the DEM's problems name the DEM, the others the
    // footprints.
    const bool aboutDem = e.code() == core::ErrorCode::UnsupportedInput;
    throw core::Error(e.code(), e.detail(), aboutDem ? demPath : footprintsPath);
  }
  if (result.status == core::RunStatus::Canceled) throw cli::Canceled();

  progress.setStage("writing");
  io::writeFloatGeoTiff(opts.get("out"), result.dem, input.geo);
  progress.report(1.0);
  progress.finish();

  int objects = 0, plain = 0, empty = 0, filled = 0;
  for (const auto& f : result.footprints) {
    if (f.window == 0) ++empty;
    else if (f.objectPixels >= params.minObjectPixels) ++objects;
    else ++plain;
    filled += f.filledPixels;
  }
  std::printf("enhanced %dx%d DEM with %zu footprints: gradient threshold %.3f m/px, %d roofs "
              "with an object (%d px window), %d plain (%d px), %d without heights; %d no-data "
              "pixels filled -> %s\n",
              input.data.cols, input.data.rows, footprints.size(), result.gradientThreshold,
              objects, params.smallWindow, plain, params.largeWindow, empty, filled,
              opts.get("out").c_str());
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"enhance", "DEM enhancement from footprints: vertical walls, filtered roofs", run});
}  // namespace
