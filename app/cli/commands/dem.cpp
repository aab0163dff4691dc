// delineo-cli dem: heights from disparity by the linear model, elevation gaps merged or kept,
// optionally every gap filled (docs/dem.md).
#include <cstdio>
#include <string>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/dem/heights.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/sim/scene.hpp"

namespace {
using namespace delineo;

io::Raster readDisparity(const std::string& path) {
  io::ReadOptions options;
  options.type = io::PixelType::Float32;
  io::Raster disparity = io::readRaster(path, options);
  if (disparity.data.channels() != 1) {
    throw core::Error(core::ErrorCode::UnsupportedInput,
                      "the disparity map must have one band, it has " +
                          std::to_string(disparity.data.channels()),
                      path);
  }
  return disparity;
}

// The height model from scene.json (its metres per disparity and ground disparity, height 0 at
// the ground) or from the flags.
dem::HeightModel heightModel(const cli::Options& opts) {
  const bool scene = opts.has("scene"), flags = opts.has("metres-per-pixel");
  if (scene == flags) {
    throw cli::UsageError("give either --scene or --metres-per-pixel (with --reference-height and "
                          "--ground-disparity when needed)");
  }
  dem::HeightModel model;
  if (scene) {
    if (opts.has("reference-height") || opts.has("ground-disparity")) {
      throw cli::UsageError("--reference-height and --ground-disparity go with --metres-per-pixel, "
                            "not with --scene");
    }
    const sim::SceneInfo info = sim::readSceneJson(opts.get("scene"));
    model.metresPerPixel = info.metresPerDisparity;
    model.groundDisparity = info.groundDisparity;
    try {
      model.validate();
    } catch (const core::Error& e) {
      throw core::Error(core::ErrorCode::UnreadableFile, e.detail(), opts.get("scene"));
    }
    return model;
  }
  opts.apply(model);
  return model;
}

int run(const std::vector<std::string>& args) {
  cli::Options opts("dem",
                    "Heights in metres from a disparity map: height = reference height + "
                    "(disparity - ground disparity) x metres per pixel, in the map's geometry; "
                    "no-data gaps with an even border merged, gaps at height steps kept (or all "
                    "filled with --fill).");
  opts.required("disparity", "FILE", "disparity map (GeoTIFF float32, nodata = no value)")
      .value("scene", "FILE", "scene.json of a simulated scene: its metres per disparity and ground disparity")
      .required("out", "FILE", "DEM (GeoTIFF float32 heights in metres, NaN = no data, the map's georeferencing)")
      .flag("fill", "also interpolate the gaps kept at height steps, from their lower side (display, export)")
      .flag("quiet", "no progress on stderr")
      .params(dem::HeightModel{})
      .params(dem::GapParams{});
  if (!opts.parse(args)) return cli::kExitOk;
  dem::GapParams gaps;
  opts.apply(gaps);
  const dem::HeightModel model = heightModel(opts);

  cli::checkOutputs(opts, {{"out", io::OutputFormat::GeoTiff}}, {"disparity", "scene"});
  auto& progress = cli::commandProgress();
  progress.setQuiet(opts.has("quiet"));
  progress.setStage("reading");
  const std::string disparityPath = opts.get("disparity");
  const io::Raster input = readDisparity(disparityPath);
  cli::throwIfCanceled(progress);

  progress.setStage("heights and gaps");
  core::Progress::Range working(&progress, 0.0, 0.95);
  dem::GapResult result;
  try {
    result = dem::demFromDisparity(input.data, model, gaps, opts.has("fill"), &working);
  } catch (const core::Error& e) {
    // The algorithm knows no file names: input problems name the disparity map.
    if (e.code() == core::ErrorCode::InvalidParameter) throw;
    throw core::Error(e.code(), e.detail(), disparityPath);
  }
  if (result.status == core::RunStatus::Canceled) throw cli::Canceled();

  progress.setStage("writing");
  io::writeFloatGeoTiff(opts.get("out"), result.dem, input.geo);
  progress.report(1.0);
  progress.finish();

  int merged = 0, kept = 0;
  for (const auto& gap : result.gaps) (gap.merged ? merged : kept) += 1;
  std::printf("DEM %dx%d from %s (%.4g m per px of disparity, height %.4g m at %.4g px): %zu gaps, "
              "%d merged (%d px), %d kept (%d px)%s -> %s\n",
              input.data.cols, input.data.rows, disparityPath.c_str(), model.metresPerPixel,
              model.referenceHeight, model.groundDisparity, result.gaps.size(), merged,
              result.mergedPixels, kept, result.keptPixels,
              opts.has("fill") ? (", " + std::to_string(result.filledPixels) + " px filled").c_str() : "",
              opts.get("out").c_str());
  return cli::kExitOk;
}

const bool registered =
    cli::registerCommand({"dem", "DEM from disparity: heights by the linear model, gaps merged or kept", run});
}  // namespace
