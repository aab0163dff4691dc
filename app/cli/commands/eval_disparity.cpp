// delineo-cli eval-disparity: accuracy of a disparity map against a ground truth (density,
// bad-0.5/1/2/4, mean absolute error, RMS, optionally on roof pixels only). Definitions in
// docs/metrics.md.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/eval/disparity_metrics.hpp"
#include "delineo/io/raster.hpp"

namespace {
using namespace delineo;

// A scale of magnitude 1e-6..1e6: beyond, float32 disparities overflow or vanish.
bool usableScale(double v) { return std::isfinite(v) && std::abs(v) >= 1e-6 && std::abs(v) <= 1e6; }

// "0.5", "1/256" → the number; UsageError otherwise.
double parseScale(const std::string& key, const std::string& text) {
  try {
    const size_t slash = text.find('/');
    size_t used = 0;
    if (slash == std::string::npos) {
      const double v = std::stod(text, &used);
      if (used == text.size() && usableScale(v)) return v;
    } else {
      const std::string numText = text.substr(0, slash), denText = text.substr(slash + 1);
      size_t usedDen = 0;
      const double num = std::stod(numText, &used);
      const double den = std::stod(denText, &usedDen);
      const double v = num / den;
      if (used == numText.size() && usedDen == denText.size() && usableScale(v)) {
        return v;
      }
    }
  } catch (const std::exception&) {
  }
  throw cli::UsageError("--" + key + " expects a number or a fraction like 1/256 of magnitude 1e-6 to 1e6, got '" +
                        text + "'");
}

io::Raster readSingleBand(const std::string& path, io::PixelType type, const char* what) {
  io::ReadOptions options;
  options.type = type;
  io::Raster raster = io::readRaster(path, options);
  if (raster.data.channels() != 1) {
    throw core::Error(core::ErrorCode::UnsupportedInput,
                      std::string(what) + " must have one band, it has " +
                          std::to_string(raster.data.channels()),
                      path);
  }
  return raster;
}

std::string formatValue(double v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  return buffer;
}

void printTable(const eval::DisparityEvaluation& result) {
  const bool roof = result.roof.has_value();
  auto row = [&](const char* name, auto value, int decimals) {
    std::printf("%-18s %12s", name, formatValue(value(result.all), decimals).c_str());
    if (roof) std::printf(" %12s", formatValue(value(*result.roof), decimals).c_str());
    std::printf("\n");
  };
  std::printf("%-18s %12s%s\n", "metric", "all", roof ? "         roof" : "");
  using S = eval::DisparityScores;
  row("evaluated pixels", [](const S& s) { return static_cast<double>(s.evaluatedPixels); }, 0);
  row("predicted pixels", [](const S& s) { return static_cast<double>(s.predictedPixels); }, 0);
  row("density", [](const S& s) { return s.density; }, 4);
  row("bad-0.5", [](const S& s) { return s.bad05; }, 4);
  row("bad-1", [](const S& s) { return s.bad1; }, 4);
  row("bad-2", [](const S& s) { return s.bad2; }, 4);
  row("bad-4", [](const S& s) { return s.bad4; }, 4);
  row("bad-2 (all)", [](const S& s) { return s.bad2All; }, 4);
  row("mean abs err [px]", [](const S& s) { return s.meanAbsError; }, 3);
  row("rms [px]", [](const S& s) { return s.rms; }, 3);
}

int run(const std::vector<std::string>& args) {
  cli::Options opts("eval-disparity",
                    "Compares a disparity map with a ground truth: density, bad-0.5/1/2/4 "
                    "(fractions of predicted pixels with |error| above the threshold), mean "
                    "absolute error and RMS over valid truth pixels (docs/metrics.md).");
  opts.required("pred", "FILE", "predicted disparity (NaN or the file's nodata = no prediction)")
      .required("truth", "FILE",
                "ground-truth disparity: float, 8- or 16-bit (NaN, nodata or 0 = unknown)")
      .value("truth-scale", "S", "multiplies the raw truth values (e.g. 1/256 for 16-bit PNG)", "1")
      .value("pred-scale", "S",
             "multiplies the predicted values (e.g. -1 for the opposite sign convention)", "1")
      .value("truth-zero-unknown", "auto|true|false",
             "truth value 0 means unknown; auto = yes unless the truth file declares a nodata "
             "value",
             "auto")
      .value("mask", "FILE", "evaluate only where this image is non-zero (e.g. non-occluded)")
      .value("roof-mask", "FILE", "also report roof pixels only: where this image is non-zero")
      .value("roof-value", "N", "roof pixels are those equal to N in --roof-mask (e.g. 1 in labels)")
      .value("json", "FILE", "write the metrics as JSON");
  if (!opts.parse(args)) return cli::kExitOk;
  const double truthScale = parseScale("truth-scale", opts.get("truth-scale"));
  const double predScale = parseScale("pred-scale", opts.get("pred-scale"));
  const std::string zeroRule = opts.get("truth-zero-unknown");
  if (zeroRule != "auto" && zeroRule != "true" && zeroRule != "false") {
    throw cli::UsageError("--truth-zero-unknown expects auto, true or false, got '" + zeroRule + "'");
  }
  if (opts.has("roof-value") && !opts.has("roof-mask")) {
    throw cli::UsageError("--roof-value needs --roof-mask");
  }

  cli::checkOutputs(opts, {{"json", io::OutputFormat::Json}}, {"pred", "truth", "mask", "roof-mask"});
  auto& progress = cli::commandProgress();
  progress.setStage("reading");
  const io::Raster pred = readSingleBand(opts.get("pred"), io::PixelType::Float32, "prediction");
  const io::Raster truth = readSingleBand(opts.get("truth"), io::PixelType::Float32, "truth");
  io::requireSameSize(pred, truth);
  cv::Mat mask, roof;
  if (opts.has("mask")) {
    const io::Raster m = readSingleBand(opts.get("mask"), io::PixelType::Keep, "mask");
    io::requireSameSize(truth, m);
    mask = m.data;
  }
  if (opts.has("roof-mask")) {
    const io::Raster r = readSingleBand(opts.get("roof-mask"), io::PixelType::Keep, "roof mask");
    io::requireSameSize(truth, r);
    roof = opts.has("roof-value") ? cv::Mat(r.data == opts.getDouble("roof-value")) : r.data;
  }
  cli::throwIfCanceled(progress);

  eval::DisparityMetricsParams params;
  params.truthZeroIsUnknown = zeroRule == "auto" ? !truth.nodata.has_value() : zeroRule == "true";
  cv::Mat predicted, truthValues;
  pred.data.convertTo(predicted, CV_32F, predScale);
  truth.data.convertTo(truthValues, CV_32F, truthScale);
  progress.setStage("evaluating");
  const auto result = eval::evaluateDisparity(predicted, truthValues, mask, roof, params);
  progress.report(1.0);

  printTable(result);
  if (opts.has("json")) {
    io::writeTextFile(opts.get("json"), eval::disparityReport(result).dump(2) + "\n");
  }
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"eval-disparity", "disparity accuracy against ground truth (density, bad-x, MAE, RMS)", run});
}  // namespace
