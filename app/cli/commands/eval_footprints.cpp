// delineo-cli eval-footprints: matches predicted building outlines to true ones by overlap and
// scores each pair (IoU, p1, PoLiS, Hausdorff, corner RMS). Definitions in docs/metrics.md.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <variant>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/eval/footprint_metrics.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"

namespace {
using namespace delineo;

// The feature's "id" attribute, else its index in the file.
std::vector<nlohmann::json> featureIds(const std::vector<core::Feature>& features) {
  std::vector<nlohmann::json> ids;
  ids.reserve(features.size());
  for (size_t i = 0; i < features.size(); ++i) {
    nlohmann::json id = i;
    if (auto it = features[i].attributes.find("id"); it != features[i].attributes.end()) {
      std::visit(
          [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (!std::is_same_v<T, std::monostate>) id = v;
          },
          it->second);
    }
    ids.push_back(std::move(id));
  }
  return ids;
}

std::vector<core::Polygon> polygonsOf(const std::vector<core::Feature>& features) {
  std::vector<core::Polygon> polygons;
  polygons.reserve(features.size());
  for (const auto& f : features) polygons.push_back(f.polygon);
  return polygons;
}

std::string formatValue(double v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  return buffer;
}

std::string idText(const nlohmann::json& id) {
  return id.is_string() ? id.get<std::string>() : id.dump();
}

void printScores(const std::string& truthId, const std::string& predId,
                 const eval::FootprintScores& s) {
  std::printf("%-12s %-12s %7s %8s %8s %9s %10s\n", truthId.c_str(), predId.c_str(),
              formatValue(s.iou, 4).c_str(), formatValue(s.p1, 2).c_str(),
              formatValue(s.polis, 3).c_str(), formatValue(s.hausdorff, 3).c_str(),
              formatValue(s.cornerRms, 3).c_str());
}

int run(const std::vector<std::string>& args) {
  cli::Options opts("eval-footprints",
                    "Matches predicted building outlines to true ones (greedy by IoU) and reports "
                    "IoU, shape error p1 [%], PoLiS, Hausdorff and corner RMS per building and on "
                    "average, with missed truths and false predictions (docs/metrics.md).");
  opts.required("pred", "FILE", "predicted outlines (GeoJSON, GeoPackage or Shapefile)")
      .required("truth", "FILE", "true outlines (GeoJSON, GeoPackage or Shapefile)")
      .value("raster", "FILE",
             "georeferenced image the outlines belong to: map coordinates are converted to its "
             "pixels, so distances are in pixels (without it, in the files' own units)")
      .value("json", "FILE", "write the report as JSON")
      .params(eval::FootprintMetricsParams{});
  if (!opts.parse(args)) return cli::kExitOk;
  eval::FootprintMetricsParams params;
  opts.apply(params);

  cli::checkOutputs(opts, {{"json", io::OutputFormat::Json}}, {"pred", "truth", "raster"});
  auto& progress = cli::commandProgress();
  progress.setStage("reading");
  io::GeoReference geo;
  if (opts.has("raster")) geo = io::readRaster(opts.get("raster")).geo;
  const auto predicted = io::readFeatures(opts.get("pred"), geo);
  const auto truth = io::readFeatures(opts.get("truth"), geo);
  cli::throwIfCanceled(progress);

  progress.setStage("matching");
  const auto result = eval::evaluateFootprints(polygonsOf(predicted), polygonsOf(truth), params,
                                               &progress);
  if (result.status == core::RunStatus::Canceled) throw cli::Canceled();

  const auto predIds = featureIds(predicted);
  const auto truthIds = featureIds(truth);
  std::printf("%-12s %-12s %7s %8s %8s %9s %10s\n", "truth", "pred", "iou", "p1[%]", "polis",
              "hausdorff", "corner_rms");
  for (const auto& m : result.matches) {
    printScores(idText(truthIds[m.truthIndex]), idText(predIds[m.predictedIndex]), m.scores);
  }
  printScores("mean", "", result.mean);
  std::printf("matched %zu of %zu true and %zu predicted outlines\n", result.matches.size(),
              result.truthCount, result.predictedCount);
  std::printf("missed truths:");
  for (size_t t : result.missedTruths) std::printf(" %s", idText(truthIds[t]).c_str());
  std::printf("\nfalse predictions:");
  for (size_t p : result.falsePredictions) std::printf(" %s", idText(predIds[p]).c_str());
  std::printf("\n");

  if (opts.has("json")) {
    io::writeTextFile(opts.get("json"), eval::footprintReport(result, predIds, truthIds).dump(2) + "\n");
  }
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"eval-footprints", "footprint accuracy against reference outlines (IoU, p1, PoLiS, ...)", run});
}  // namespace
