// delineo-cli boxfit: building outlines by box-fitting (docs/boxfit.md): the building segment
// from a DEM, boxes grown from its skeleton onto the left image's Canny edges, merged and
// straightened. One call runs a batch: every polygon of --init is one building; with neither
// --init nor --roi every building segment of the image is fitted.
#include <cstdio>
#include <string>

#include "cli_support.hpp"
#include "delineo/boxfit/box_fitting.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"

namespace {
using namespace delineo;

// Heights (m) on the image's grid: --dem as it is, or --disparity through the height model.
cv::Mat readHeights(const cli::Options& opts, cv::Size imageSize, bool quiet) {
  if (opts.has("dem") == opts.has("disparity")) throw cli::UsageError("give exactly one of --dem and --disparity");
  const std::string path = opts.has("dem") ? opts.get("dem") : opts.get("disparity");
  io::ReadOptions options;
  options.type = io::PixelType::Float32;
  const cv::Mat raster = io::readRaster(path, options).data;
  if (raster.channels() != 1) {
    throw core::Error(core::ErrorCode::UnsupportedInput,
                      "a DEM or disparity map has one band, this one has " + std::to_string(raster.channels()), path);
  }
  if (raster.size() != imageSize) {
    throw core::Error(core::ErrorCode::MismatchedInputs,
                      "the raster is " + std::to_string(raster.cols) + "x" + std::to_string(raster.rows) +
                          " px but the image " + std::to_string(imageSize.width) + "x" +
                          std::to_string(imageSize.height) + ": it must be on the left image's grid",
                      path);
  }
  if (opts.has("dem")) return raster;
  const double metresPerPixel = opts.getDouble("metres-per-pixel");
  if (!(metresPerPixel > 0)) throw cli::UsageError("--metres-per-pixel must be positive");
  if (!opts.has("metres-per-pixel") && !quiet) {
    std::fprintf(stderr, "boxfit: no --metres-per-pixel: heights in px of disparity (min-height etc. in px)\n");
  }
  return boxfit::heightsFromDisparity(raster, opts.getDouble("ground-disparity"), metresPerPixel);
}

std::vector<core::Feature> initialPolygons(const cli::Options& opts, const io::GeoReference& geo) {
  if (opts.has("init") && opts.has("roi")) throw cli::UsageError("give at most one of --init and --roi");
  if (opts.has("init")) return io::readFeatures(opts.get("init"), geo);
  if (!opts.has("roi")) return {};
  return {cli::roiFeature(opts)};
}

core::Feature outlineFeature(const boxfit::BoxFitBuilding& b, long long id) {
  core::Feature f;
  f.polygon = b.outline;
  f.attributes["id"] = id;
  f.attributes["method"] = std::string("box-fitting");
  f.attributes["status"] = std::string("completed");
  f.attributes["boxes"] = static_cast<long long>(b.boxes.size());
  f.attributes["area"] = core::area(b.outline);
  f.attributes["vertices"] = static_cast<long long>(b.diagnostics.vertices);
  f.attributes["energy"] = b.energy;
  f.attributes["roof_height_m"] = b.diagnostics.roofHeight;
  return f;
}

// The boxes of building `id`, each clipped to the image of `size` (attributes: the whole box).
void appendBoxes(const boxfit::BoxFitBuilding& b, long long id, cv::Size size, std::vector<core::Feature>& out) {
  long long k = 0;
  for (const auto& box : b.boxes) {
    core::Feature f;
    f.polygon.outer = box.cornersWithin(size);
    if (f.polygon.outer.empty()) continue;
    f.attributes["building_id"] = id;
    f.attributes["box"] = ++k;
    f.attributes["angle_deg"] = box.angleDeg;
    f.attributes["length"] = box.length;
    f.attributes["width"] = box.width;
    f.attributes["energy"] = box.energy;
    out.push_back(std::move(f));
  }
}

// The command's flags: the image, the heights (a DEM, or a disparity map and its scale), the
// initial polygons (or rectangle), the outputs, and every box-fitting parameter.
cli::Options boxfitOptions() {
  cli::Options opts("boxfit",
                    "Delineates buildings by box-fitting: the building segment from a DEM on the left "
                    "image's grid, chains of boxes fitted to the image's edges, merged into one outline.\n"
                    "Usage: delineo-cli boxfit --dem D --image L [--init F | --roi X,Y,W,H] --out F.geojson "
                    "[--boxes B.geojson]\nWithout --init and --roi every building segment of the image "
                    "is fitted.");
  opts.required("image", "FILE", "left (reference) image")
      .value("dem", "FILE", "heights in metres on the left image's grid (NaN or nodata = none)")
      .value("disparity", "FILE", "disparity map of the left image (as `match` writes it), instead of --dem")
      .value("metres-per-pixel", "M", "with --disparity: metres of height per px of disparity", "1")
      .value("ground-disparity", "PX", "with --disparity: disparity of zero height", "0")
      .value("init", "FILE", "initial polygons (.geojson, .gpkg, .shp; map coordinates over a georeferenced image, else pixels); may hold many")
      .value("roi", "X,Y,W,H", "initial rectangle in left-image pixels (instead of --init)")
      .required("out", "FILE", "output outlines (GeoJSON/GeoPackage) with their attributes")
      .value("boxes", "FILE", "also write the fitted boxes (one polygon each, with building_id)")
      .flag("quiet", "no progress on stderr")
      .params(boxfit::BoxFitParams{});
  return opts;
}

// What every building is fitted on.
struct Fitting {
  const cv::Mat& heights;
  const cv::Mat& image;
  const boxfit::BoxFitParams& params;
};

// The outlines and boxes to write, and how the run went.
struct Results {
  std::vector<core::Feature> outlines, boxes;
  int failed = 0;
  bool canceled = false;
};

// Whole image: every segment; nothing found is a processing failure.
void fitWholeImage(const Fitting& fitting, const std::string& imagePath, core::Progress* progress,
                   Results& results) {
  const auto r = boxfit::fitBoxes(fitting.heights, fitting.image, {}, fitting.params, progress);
  results.canceled = r.status == core::RunStatus::Canceled;
  if (r.buildings.empty() && !results.canceled) {
    throw core::Error(core::ErrorCode::ProcessingFailed, r.message, imagePath);
  }
  long long id = 0;
  for (const auto& b : r.buildings) {
    results.outlines.push_back(outlineFeature(b, ++id));
    appendBoxes(b, id, fitting.image.size(), results.boxes);
  }
}

// One building of --init or --roi: its outline and boxes or, in a batch (`single` false), its
// init marked failed with the error.
void fitBuilding(const Fitting& fitting, const core::Feature& init, long long id, bool single,
                 const std::string& initFile, core::Progress* progress, Results& results) {
  boxfit::BoxFitRequest request;
  request.init = init.polygon;
  request.init.holes.clear();
  std::string error;
  try {
    const auto r =
        boxfit::fitBoxes(fitting.heights, fitting.image, request, fitting.params, progress);
    results.canceled = r.status == core::RunStatus::Canceled;
    if (!r.buildings.empty()) {
      results.outlines.push_back(outlineFeature(r.buildings.front(), id));
      appendBoxes(r.buildings.front(), id, fitting.image.size(), results.boxes);
      return;
    }
    error = results.canceled ? "canceled" : r.message;
  } catch (const core::Error& e) {
    if (single) throw;  // a single building reports its error
    error = e.detail();
  }
  if (results.canceled) return;
  if (single) throw core::Error(core::ErrorCode::ProcessingFailed, error, initFile);
  // One building without an outline does not stop the batch: its init is written, marked.
  ++results.failed;
  core::Feature f;
  f.polygon = request.init;
  f.attributes["id"] = id;
  f.attributes["method"] = std::string("box-fitting");
  f.attributes["status"] = std::string("failed");
  f.attributes["error"] = error;
  results.outlines.push_back(std::move(f));
  std::fprintf(stderr, "building %lld: %s\n", id, error.c_str());
}

int run(const std::vector<std::string>& args) {
  cli::Options opts = boxfitOptions();
  if (!opts.parse(args)) return cli::kExitOk;
  boxfit::BoxFitParams params;
  opts.apply(params);
  cli::checkOutputs(opts, {{"out", io::OutputFormat::Vector}, {"boxes", io::OutputFormat::Vector}},
                    {"image", "dem", "disparity", "init"});
  auto& progress = cli::commandProgress();
  const bool quiet = opts.has("quiet");
  progress.setQuiet(quiet);
  progress.setStage("reading");
  io::GeoReference geo;
  const cv::Mat image = io::readGreyFloat(opts.get("image"), &geo);
  const cv::Mat heights = readHeights(opts, image.size(), quiet);
  const std::vector<core::Feature> inits = initialPolygons(opts, geo);
  const std::string initFile = opts.has("init") ? opts.get("init") : "";
  // Every id read before any work: a malformed one is an input error, not a failure found late.
  std::vector<long long> ids;
  for (size_t i = 0; i < inits.size(); ++i) ids.push_back(cli::featureId(inits[i], i, initFile));

  const Fitting fitting{heights, image, params};
  Results results;
  if (inits.empty()) fitWholeImage(fitting, opts.get("image"), &progress, results);
  const size_t count = inits.size();
  for (size_t i = 0; i < count && !results.canceled; ++i) {
    progress.setStage("building " + std::to_string(i + 1) + "/" + std::to_string(count));
    core::Progress::Range range(&progress, double(i) / count, double(i + 1) / count);
    fitBuilding(fitting, inits[i], ids[i], count == 1, initFile, &range, results);
  }
  io::writeFeatures(opts.get("out"), results.outlines, geo, "buildings");
  if (opts.has("boxes")) io::writeFeatures(opts.get("boxes"), results.boxes, geo, "boxes");
  progress.report(1.0);
  progress.finish();
  if (results.canceled) throw cli::Canceled();
  if (!quiet) {
    std::fprintf(stderr, "boxfit: %zu outline(s), %zu box(es), %d failed, written to %s\n",
                 results.outlines.size() - results.failed, results.boxes.size(), results.failed,
                 opts.get("out").c_str());
  }
  return results.failed > 0 ? cli::kExitProcessing : cli::kExitOk;
}

const bool registered =
    cli::registerCommand({"boxfit", "building outlines by box-fitting on a DEM and the left image's edges", run});
}  // namespace
