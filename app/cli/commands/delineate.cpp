// delineo-cli delineate: building outlines by the statistical active polygon
// (docs/delineation.md). One call runs a batch: every polygon of --init is one building, and its
// roof_disparity_min/max and ground_disparity properties override the flags for it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/delineation/feature_request.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "range_support.hpp"

namespace {
using namespace delineo;
using delineation::DisparityInterval;
using delineation::kMaxFeatureDisparity;

DisparityInterval intervalFlag(const cli::Options& opts, const std::string& key) {
  const auto [a, b] = opts.getPair(key);
  if (a != std::floor(a) || b != std::floor(b)) {
    throw cli::UsageError("--" + key + " expects integer disparities A:B");
  }
  if (std::abs(a) > kMaxFeatureDisparity || std::abs(b) > kMaxFeatureDisparity || a > b) {
    throw cli::UsageError("--" + key + " expects A:B with A <= B, both within +-" +
                          std::to_string(static_cast<int>(kMaxFeatureDisparity)) + " px");
  }
  return {static_cast<int>(a), static_cast<int>(b)};
}

// The estimated search range widened to hold the building's intervals: the operator's (or the
// feature's) intervals are known, the estimate is a statistic of the whole pair.
DisparityInterval hull(DisparityInterval range, const DisparityInterval& roof,
                       const std::optional<DisparityInterval>& ground) {
  range = {std::min(range.min, roof.min), std::max(range.max, roof.max)};
  if (ground) range = {std::min(range.min, ground->min), std::max(range.max, ground->max)};
  return range;
}

std::string text(const DisparityInterval& d) {
  return "[" + std::to_string(d.min) + ", " + std::to_string(d.max) + "]";
}

std::string statusName(core::RunStatus s) {
  return s == core::RunStatus::Completed ? "completed" : "canceled";
}

// One building of the batch: its id and what the active polygon is asked.
struct BuildingJob {
  long long id = 0;
  delineation::DelineationRequest request;
  std::string missing;  // why the building cannot run (reported as failed), empty when it can
};

struct Flags {
  std::optional<DisparityInterval> roof, ground, search;
};

// Every building's request, checked whole before any work: a bad property of one feature is an
// input error (exit 3) naming its id, not a failure found after matching.
std::vector<BuildingJob> buildingJobs(const std::vector<core::Feature>& inits, const Flags& flags,
                                      const delineation::DelineationParams& params,
                                      const std::string& file) {
  std::vector<BuildingJob> jobs;
  for (size_t i = 0; i < inits.size(); ++i) {
    const core::Feature& init = inits[i];
    BuildingJob job;
    job.id = cli::featureId(init, i, file);
    const std::string name = "building id " + std::to_string(job.id);
    const auto intervals =
        cli::readFeatureProperties([&] { return delineation::readFeatureIntervals(init); }, name, file);
    auto& req = job.request;
    req.init.outer = init.polygon.outer;
    if (intervals.roof) {
      req.roof = *intervals.roof;
    } else if (flags.roof) {
      req.roof = *flags.roof;
    } else {
      // Not malformed, only not ready: the batch goes on and reports this building as failed.
      job.missing = "no roof disparity interval: give --roof-disparity or the feature's "
                    "roof_disparity_min/max";
    }
    if (intervals.groundDisparity) {
      const int c = *intervals.groundDisparity;
      req.ground = DisparityInterval{c - params.groundTolerance, c + params.groundTolerance};
    } else {
      req.ground = flags.ground;
    }
    if (job.missing.empty() && req.ground && req.ground->max >= req.roof.min) {
      throw core::Error(core::ErrorCode::InvalidParameter,
                        name + ": the ground disparity " + text(*req.ground) +
                            " is not below the roof interval " + text(req.roof) +
                            " (a roof's disparities are larger than its ground's)",
                        file);
    }
    jobs.push_back(std::move(job));
  }
  return jobs;
}

std::vector<core::Feature> initialPolygons(const cli::Options& opts, const io::GeoReference& geo) {
  if (opts.has("init")) return io::readFeatures(opts.get("init"), geo);
  return {cli::roiFeature(opts)};
}

// The delineated building as an output feature with its energies and what the stage did.
void describeResult(const delineation::DelineationResult& r, core::Feature& result) {
  result.polygon = r.polygon;
  result.attributes["status"] = statusName(r.status);
  result.attributes["energy"] = r.terms.total();
  static const char* names[6] = {"e_roof", "e_ground", "e_occlusion", "e_edges_left",
                                 "e_edges_right", "e_shape"};
  for (int k = 0; k < 6; ++k) result.attributes[names[k]] = r.terms.term[k];
  result.attributes["iterations"] = static_cast<long long>(r.iterations);
  result.attributes["vertices"] = static_cast<long long>(r.vertexCount);
  result.attributes["regularization"] = delineation::toString(r.regularization.status);
  if (!r.regularization.reason.empty()) result.attributes["regularization_note"] = r.regularization.reason;
  long long rawVertices = static_cast<long long>(r.rawPolygon.outer.size());
  for (const auto& hole : r.rawPolygon.holes) rawVertices += static_cast<long long>(hole.size());
  result.attributes["raw_vertices"] = rawVertices;
  result.attributes["roof_disparity_min"] = static_cast<long long>(r.roof.min);
  result.attributes["roof_disparity_max"] = static_cast<long long>(r.roof.max);
  result.attributes["ground_disparity_min"] = static_cast<long long>(r.ground.min);
  result.attributes["ground_disparity_max"] = static_cast<long long>(r.ground.max);
  result.attributes["no_match_cost"] = r.noMatchCost;
}

// The command's flags: the pair, the initial polygons (or rectangle), the intervals, the optional
// mask and map, the output, and every parameter of the active polygon.
cli::Options delineateOptions() {
  cli::Options opts("delineate",
                    "Delineates buildings on an epipolar pair with the statistical active polygon: "
                    "one output polygon per initial polygon (or per --roi rectangle).");
  opts.required("left", "FILE", "left (reference) epipolar image")
      .required("right", "FILE", "right epipolar image")
      .value("init", "FILE",
             "initial polygons (.geojson, .gpkg, .shp; map coordinates over a georeferenced image, else pixels); may hold many")
      .value("roi", "X,Y,W,H", "initial rectangle in left-image pixels (instead of --init)")
      .value("roof-disparity", "A:B",
             "roof disparity interval (a feature's roof_disparity_min/max override it)")
      .value("ground-disparity", "A:B",
             "ground disparity interval (a feature's ground_disparity overrides it); estimated "
             "around each init when absent")
      .value("disparity-range", "A:B",
             "full disparity search range; estimated from the pair when absent (widened to "
             "hold the roof and ground intervals)")
      .value("exclude", "FILE",
             "mask of the left image's size, non-zero where a pixel is known not to be roof "
             "(vegetation, a neighbour's roof); kept outside every outline")
      .value("disparity", "FILE",
             "the matcher's disparity map (float, the left image's size, NaN = none): where it has a "
             "value it says roof or not (map-cost), and it gives the ground when none is given")
      .required("out", "FILE", "output polygons (GeoJSON/GeoPackage) with energies and status")
      .flag("quiet", "no progress and no range estimate on stderr")
      .params(delineation::DelineationParams{});
  return opts;
}

// The intervals given by --roof-disparity, --ground-disparity and --disparity-range.
Flags intervalFlags(const cli::Options& opts) {
  Flags flags;
  if (opts.has("roof-disparity")) flags.roof = intervalFlag(opts, "roof-disparity");
  if (opts.has("ground-disparity")) flags.ground = intervalFlag(opts, "ground-disparity");
  if (opts.has("disparity-range")) flags.search = intervalFlag(opts, "disparity-range");
  return flags;
}

// The --disparity map (empty without it), of the left image's size.
cv::Mat readDisparityMap(const cli::Options& opts, cv::Size leftSize) {
  cv::Mat disparity;
  if (opts.has("disparity")) {
    io::ReadOptions options;
    options.type = io::PixelType::Float32;
    options.toGrey = true;
    disparity = io::readRaster(opts.get("disparity"), options).data;
    if (disparity.size() != leftSize) {
      throw core::Error(core::ErrorCode::MismatchedInputs,
                        "the disparity map does not have the size of the left image", opts.get("disparity"));
    }
  }
  return disparity;
}

// The pair's search range from feature matches (the first 5 % of `progress`); none, with a
// warning, when the pair gives no estimate.
std::optional<DisparityInterval> estimatedRange(const cv::Mat& left, const cv::Mat& right, bool quiet,
                                                core::Progress* progress) {
  core::Progress::Range rangeProgress(progress, 0.0, 0.05);
  try {
    const auto e = cli::estimateRangeForCommand(left, right, "give --disparity-range", quiet,
                                                &rangeProgress);
    return DisparityInterval{e.dmin, e.dmax};
  } catch (const core::Error& e) {
    // Each building then searches around its own intervals, as without an estimate.
    std::fprintf(stderr, "warning: %s; searching around each building's intervals only\n",
                 e.what());
    return std::nullopt;
  }
}

// What every building of the batch is delineated with besides its own request.
struct Batch {
  const cv::Mat& left;
  const cv::Mat& right;
  const cv::Mat& exclude;
  const cv::Mat& disparity;
  std::optional<DisparityInterval> search;     // --disparity-range
  std::optional<DisparityInterval> estimated;  // the pair's estimate, without it
  const delineation::DelineationParams& params;
};

// One building as an output feature: its outline with what the stage did, or, in a batch of
// more than one (`single` false), its error (counted in `failed`).
core::Feature delineateBuilding(const BuildingJob& job, const Batch& batch, bool single,
                                const core::Progress& progress, core::Progress::Range& range, int& failed) {
  core::Feature result;
  result.polygon = job.request.init;
  result.attributes["id"] = job.id;
  try {
    if (!job.missing.empty()) throw core::Error(core::ErrorCode::InvalidParameter, job.missing);
    delineation::DelineationRequest req = job.request;
    req.searchRange = batch.search;
    if (batch.estimated) req.searchRange = hull(*batch.estimated, req.roof, req.ground);
    req.excludeMask = batch.exclude;
    req.disparity = batch.disparity;
    const auto r = delineation::delineate(batch.left, batch.right, req, batch.params, {}, &range);
    // A canceled batch writes nothing: the previous output, if any, stays as it was.
    if (r.status == core::RunStatus::Canceled || progress.canceled()) throw cli::Canceled();
    describeResult(r, result);
  } catch (const core::Error& e) {
    // One bad building does not stop the batch; a single-building run reports the error.
    if (single) throw;
    ++failed;
    result.attributes["status"] = std::string("failed");
    result.attributes["error"] = e.detail();
    std::fprintf(stderr, "building id %lld: %s\n", job.id, e.what());
  }
  return result;
}

int run(const std::vector<std::string>& args) {
  cli::Options opts = delineateOptions();
  if (!opts.parse(args)) return cli::kExitOk;
  if (opts.has("init") == opts.has("roi")) {
    throw cli::UsageError("give exactly one of --init and --roi");
  }
  delineation::DelineationParams params;
  opts.apply(params);
  const Flags flags = intervalFlags(opts);
  cli::checkOutputs(opts, {{"out", io::OutputFormat::Vector}}, {"left", "right", "init", "exclude", "disparity"});

  auto& progress = cli::commandProgress();
  const bool quiet = opts.has("quiet");
  progress.setQuiet(quiet);
  progress.setStage("reading");
  io::GeoReference geo;
  const cv::Mat left = io::readGreyFloat(opts.get("left"), &geo);
  const cv::Mat right = io::readGreyFloat(opts.get("right"));
  if (left.size() != right.size()) {
    throw core::Error(core::ErrorCode::MismatchedInputs,
                      "left and right images differ in size", opts.get("right"));
  }
  const std::vector<BuildingJob> jobs =
      buildingJobs(initialPolygons(opts, geo), flags, params, opts.has("init") ? opts.get("init") : "");
  cv::Mat exclude;
  if (opts.has("exclude")) exclude = io::readMask(opts.get("exclude"), left.size());
  const cv::Mat disparity = readDisparityMap(opts, left.size());

  core::Progress::Range buildingsProgress(&progress, flags.search ? 0.0 : 0.05, 1.0);
  std::optional<DisparityInterval> estimated;
  if (!flags.search) estimated = estimatedRange(left, right, quiet, &progress);
  const Batch batch{left, right, exclude, disparity, flags.search, estimated, params};

  std::vector<core::Feature> out;
  int failed = 0;
  const size_t count = jobs.size();
  for (size_t i = 0; i < count; ++i) {
    progress.setStage("building " + std::to_string(i + 1) + "/" + std::to_string(count));
    core::Progress::Range range(&buildingsProgress, double(i) / count, double(i + 1) / count);
    out.push_back(delineateBuilding(jobs[i], batch, count == 1, progress, range, failed));
  }
  io::writeFeatures(opts.get("out"), out, geo, "buildings");
  progress.report(1.0);
  progress.finish();
  return failed > 0 ? cli::kExitProcessing : cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"delineate", "building outlines by the statistical active polygon (batch over --init)", run});
}  // namespace
