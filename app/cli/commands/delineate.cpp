// delineo-cli delineate: building outlines by the statistical active polygon
// (docs/delineation.md). One call runs a batch: every polygon of --init is one building, and its
// roof_disparity_min/max and ground_disparity properties override the flags for it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <variant>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "range_support.hpp"

namespace {
using namespace delineo;
using delineation::DisparityInterval;

DisparityInterval intervalFlag(const cli::Options& opts, const std::string& key) {
  const auto [a, b] = opts.getPair(key);
  if (a != std::floor(a) || b != std::floor(b)) {
    throw cli::UsageError("--" + key + " expects integer disparities A:B");
  }
  return {static_cast<int>(a), static_cast<int>(b)};
}

std::optional<double> numberAttribute(const core::Feature& f, const std::string& key) {
  const auto it = f.attributes.find(key);
  if (it == f.attributes.end()) return std::nullopt;
  if (const auto* i = std::get_if<long long>(&it->second)) return static_cast<double>(*i);
  if (const auto* d = std::get_if<double>(&it->second)) return *d;
  if (const auto* s = std::get_if<std::string>(&it->second)) {
    try {
      return std::stod(*s);
    } catch (const std::exception&) {
    }
  }
  return std::nullopt;
}

// The estimated search range widened to hold the building's intervals: the operator's (or the
// feature's) intervals are known, the estimate is a statistic of the whole pair.
DisparityInterval hull(DisparityInterval range, const DisparityInterval& roof,
                       const std::optional<DisparityInterval>& ground) {
  range = {std::min(range.min, roof.min), std::max(range.max, roof.max)};
  if (ground) range = {std::min(range.min, ground->min), std::max(range.max, ground->max)};
  return range;
}

std::string statusName(core::RunStatus s) {
  return s == core::RunStatus::Completed ? "completed" : "canceled";
}

int run(const std::vector<std::string>& args) {
  cli::Options opts("delineate",
                    "Delineates buildings on an epipolar pair with the statistical active polygon: "
                    "one output polygon per initial polygon (or per --roi rectangle).");
  opts.required("left", "FILE", "left (reference) epipolar image")
      .required("right", "FILE", "right epipolar image")
      .value("init", "FILE",
             "initial polygons (GeoJSON/GeoPackage, left-image pixels); may hold many")
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
      .required("out", "FILE", "output polygons (GeoJSON/GeoPackage) with energies and status")
      .flag("quiet", "no progress and no range estimate on stderr")
      .params(delineation::DelineationParams{});
  if (!opts.parse(args)) return cli::kExitOk;
  if (opts.has("init") == opts.has("roi")) {
    throw cli::UsageError("give exactly one of --init and --roi");
  }
  delineation::DelineationParams params;
  opts.apply(params);

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

  std::vector<core::Feature> inits;
  if (opts.has("init")) {
    inits = io::readFeatures(opts.get("init"), geo);
  } else {
    const auto v = opts.getList("roi");
    if (v.size() != 4 || v[2] <= 0 || v[3] <= 0) {
      throw cli::UsageError("--roi expects X,Y,W,H with positive W and H");
    }
    core::Feature f;
    f.polygon.outer = {{v[0], v[1]}, {v[0] + v[2], v[1]}, {v[0] + v[2], v[1] + v[3]}, {v[0], v[1] + v[3]}};
    inits.push_back(f);
  }
  cv::Mat exclude;
  if (opts.has("exclude")) exclude = io::readMask(opts.get("exclude"), left.size());
  std::optional<DisparityInterval> roofFlag, groundFlag, searchFlag;
  if (opts.has("roof-disparity")) roofFlag = intervalFlag(opts, "roof-disparity");
  if (opts.has("ground-disparity")) groundFlag = intervalFlag(opts, "ground-disparity");
  if (opts.has("disparity-range")) searchFlag = intervalFlag(opts, "disparity-range");
  core::Progress::Range buildingsProgress(&progress, searchFlag ? 0.0 : 0.05, 1.0);
  std::optional<DisparityInterval> estimated;
  if (!searchFlag) {
    core::Progress::Range rangeProgress(&progress, 0.0, 0.05);
    try {
      const auto e = cli::estimateRangeForCommand(left, right, "give --disparity-range", quiet,
                                                  &rangeProgress);
      estimated = DisparityInterval{e.dmin, e.dmax};
    } catch (const core::Error& e) {
      // Each building then searches around its own intervals, as without an estimate.
      std::fprintf(stderr, "warning: %s; searching around each building's intervals only\n",
                   e.what());
    }
  }

  std::vector<core::Feature> out;
  int failed = 0;
  bool canceled = false;
  const size_t count = inits.size();
  for (size_t i = 0; i < count; ++i) {
    const core::Feature& init = inits[i];
    core::Feature result;
    result.polygon = init.polygon;
    const auto id = numberAttribute(init, "id");
    result.attributes["id"] = static_cast<long long>(id ? *id : static_cast<double>(i + 1));
    progress.setStage("building " + std::to_string(i + 1) + "/" + std::to_string(count));
    core::Progress::Range range(&buildingsProgress, double(i) / count, double(i + 1) / count);
    try {
      delineation::DelineationRequest req;
      req.init = init.polygon;
      req.init.holes.clear();
      const auto rmin = numberAttribute(init, "roof_disparity_min");
      const auto rmax = numberAttribute(init, "roof_disparity_max");
      if (rmin && rmax) {
        req.roof = {static_cast<int>(std::floor(*rmin)), static_cast<int>(std::ceil(*rmax))};
      } else if (roofFlag) {
        req.roof = *roofFlag;
      } else {
        throw core::Error(core::ErrorCode::InvalidParameter,
                          "no roof disparity interval: give --roof-disparity or the feature's "
                          "roof_disparity_min/max");
      }
      const auto g = numberAttribute(init, "ground_disparity");
      if (g) {
        const int c = static_cast<int>(std::lround(*g));
        req.ground = DisparityInterval{c - params.groundTolerance, c + params.groundTolerance};
      } else {
        req.ground = groundFlag;
      }
      req.searchRange = searchFlag;
      if (estimated) req.searchRange = hull(*estimated, req.roof, req.ground);
      req.excludeMask = exclude;
      const auto r = delineation::delineate(left, right, req, params, {}, &range);
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
      if (r.status == core::RunStatus::Canceled) canceled = true;
    } catch (const core::Error& e) {
      // One bad building does not stop the batch; a single-building run reports the error.
      if (count == 1) throw;
      ++failed;
      result.attributes["status"] = std::string("failed");
      result.attributes["error"] = e.detail();
      std::fprintf(stderr, "building %zu: %s\n", i + 1, e.what());
    }
    out.push_back(std::move(result));
    if (canceled) break;
  }
  io::writeFeatures(opts.get("out"), out, geo, "buildings");
  progress.report(1.0);
  progress.finish();
  if (canceled) throw cli::Canceled();
  return failed > 0 ? cli::kExitProcessing : cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"delineate", "building outlines by the statistical active polygon (batch over --init)", run});
}  // namespace
