// delineo-cli match: dense disparity of an epipolar pair (adaptive-window multi-resolution NCC of
// Cord et al., or OpenCV SGBM). Writes float32 GeoTIFF with NaN as nodata; x_right = x_left - d.
#include <cmath>
#include <cstdio>
#include <string>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/stereo/match.hpp"
#include "range_support.hpp"

namespace {
using namespace delineo;

int run(const std::vector<std::string>& args) {
  cli::Options opts("match",
                    "Dense disparity of an epipolar pair (left = reference, x_right = x_left - d).\n"
                    "Usage: delineo-cli match --left L --right R [--dmin A --dmax B] --out D.tif "
                    "[options]\nWithout --dmin/--dmax the range is estimated from feature "
                    "matches (docs/disparity-range.md).");
  opts.required("left", "FILE", "left (reference) image")
      .required("right", "FILE", "right image, same size, epipolar with the left")
      .required("out", "FILE", "output disparity GeoTIFF (float32, NaN = rejected)")
      .value("dmin", "PX", "smallest disparity searched, x_right = x_left - d; estimated from the pair when absent")
      .value("dmax", "PX", "largest disparity searched; estimated from the pair when absent")
      .value("score", "FILE", "optional output of the correlation score (NCC of the match)")
      .flag("quiet", "no progress on stderr");
  opts.params(stereo::MatchParams{});
  // --levels also accepts "auto", the same as 0 (depth from the range, as in the paper).
  std::vector<std::string> normalised = args;
  for (size_t i = 0; i < normalised.size(); ++i) {
    if (normalised[i] == "--levels=auto") normalised[i] = "--levels=0";
    if (normalised[i] == "--levels" && i + 1 < normalised.size() && normalised[i + 1] == "auto") {
      normalised[i + 1] = "0";
    }
  }
  if (!opts.parse(normalised)) return cli::kExitOk;
  stereo::MatchParams params;
  opts.apply(params);
  const bool rangeGiven = opts.has("dmin") && opts.has("dmax");
  // Without both ends the range is validated once estimated: a lone --dmin above the default
  // dmax is no error.
  params.dmin = opts.has("dmin") ? opts.getInt("dmin") : -100000;
  params.dmax = opts.has("dmax") ? opts.getInt("dmax") : 100000;
  params.validate();

  cli::checkOutputs(opts, {{"out", io::OutputFormat::GeoTiff}, {"score", io::OutputFormat::GeoTiff}}, {"left", "right"});
  auto& progress = cli::commandProgress();
  const bool quiet = opts.has("quiet");
  progress.setQuiet(quiet);
  io::GeoReference geo;
  progress.setStage("reading images");
  const cv::Mat left = io::readGreyFloat(opts.get("left"), &geo);
  const cv::Mat right = io::readGreyFloat(opts.get("right"));
  if (left.size() != right.size()) {
    throw core::Error(core::ErrorCode::MismatchedInputs,
                      "left " + opts.get("left") + " is " + std::to_string(left.cols) + "x" +
                          std::to_string(left.rows) + " but right is " +
                          std::to_string(right.cols) + "x" + std::to_string(right.rows),
                      opts.get("right"));
  }
  core::Progress::Range matchProgress(&progress, rangeGiven ? 0.0 : 0.05, 1.0);
  if (!rangeGiven) {
    // A flag given alone overrides its end of the estimate.
    core::Progress::Range rangeProgress(&progress, 0.0, 0.05);
    const stereo::RangeEstimate estimate = cli::estimateRangeForCommand(
        left, right, "give --dmin and --dmax", quiet, &rangeProgress);
    if (!opts.has("dmin")) params.dmin = estimate.dmin;
    if (!opts.has("dmax")) params.dmax = estimate.dmax;
    params.validate();
  }
  const stereo::MatchResult result = stereo::matchStereo(left, right, params, &matchProgress);
  cli::throwIfCanceled(progress);
  if (result.status == core::RunStatus::Canceled) throw cli::Canceled();
  progress.finish();

  io::writeFloatGeoTiff(opts.get("out"), result.disparity, geo);
  if (opts.has("score")) io::writeFloatGeoTiff(opts.get("score"), result.score, geo);
  if (quiet) return cli::kExitOk;
  const int valid = cv::countNonZero(result.disparity == result.disparity);
  std::fprintf(stderr,
               "match: %s, disparities %d..%d, %d level(s), %.1f %% of pixels matched, written "
               "to %s\n",
               params.method.c_str(), params.dmin, params.dmax, result.levelsUsed,
               100.0 * valid / static_cast<double>(result.disparity.total()),
               opts.get("out").c_str());
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"match", "dense disparity of an epipolar pair (adaptive NCC or SGBM)", run});
}  // namespace
