// delineo-cli match: dense disparity of an epipolar pair (adaptive-window multi-resolution NCC of
// Cord et al., or OpenCV SGBM). Writes float32 GeoTIFF with NaN as nodata; x_right = x_left - d.
#include <cmath>
#include <cstdio>
#include <string>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/stereo/match.hpp"

namespace {
using namespace delineo;

int run(const std::vector<std::string>& args) {
  cli::Options opts("match",
                    "Dense disparity of an epipolar pair (left = reference, x_right = x_left - d).\n"
                    "Usage: delineo-cli match --left L --right R --dmin A --dmax B --out D.tif "
                    "[options]");
  opts.required("left", "FILE", "left (reference) image")
      .required("right", "FILE", "right image, same size, epipolar with the left")
      .required("out", "FILE", "output disparity GeoTIFF (float32, NaN = rejected)")
      .value("dmin", "PX", "smallest disparity searched (x_right = x_left - d)")
      .value("dmax", "PX", "largest disparity searched")
      .value("score", "FILE", "optional output of the correlation score (NCC of the match)", "")
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
  if (!opts.has("dmin") || !opts.has("dmax")) {
    throw cli::UsageError("--dmin and --dmax are required (the disparity search range)");
  }
  stereo::MatchParams params;
  opts.apply(params);
  params.dmin = opts.getInt("dmin");
  params.dmax = opts.getInt("dmax");
  params.validate();

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
  const stereo::MatchResult result = stereo::matchStereo(left, right, params, &progress);
  cli::throwIfCanceled(progress);
  if (result.status == core::RunStatus::Canceled) throw cli::Canceled();
  progress.finish();

  io::writeFloatGeoTiff(opts.get("out"), result.disparity, geo);
  if (!opts.get("score").empty()) io::writeFloatGeoTiff(opts.get("score"), result.score, geo);
  if (quiet) return cli::kExitOk;
  const int valid = cv::countNonZero(result.disparity == result.disparity);
  std::fprintf(stderr, "match: %s, %d level(s), %.1f %% of pixels matched, written to %s\n",
               params.method.c_str(), result.levelsUsed,
               100.0 * valid / static_cast<double>(result.disparity.total()),
               opts.get("out").c_str());
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"match", "dense disparity of an epipolar pair (adaptive NCC or SGBM)", run});
}  // namespace
