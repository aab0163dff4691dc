// delineo-cli range: the disparity search range of an epipolar pair, estimated from sparse
// feature matches (docs/disparity-range.md). Prints "--dmin A --dmax B" on stdout, so that a
// batch can pass it on to `match`; the details go to stderr and, with --json, to a file.
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "range_support.hpp"

namespace delineo::cli {

stereo::RangeEstimate estimateRangeForCommand(const cv::Mat& left, const cv::Mat& right,
                                              const std::string& byHand, bool quiet,
                                              core::Progress* progress) {
  if (progress != nullptr) progress->setStage("estimating the disparity range");
  stereo::RangeEstimate estimate;
  try {
    estimate = stereo::estimateDisparityRange(left, right, {}, progress);
  } catch (const core::Error& e) {
    throw core::Error(e.code(), e.detail() + "; " + byHand, e.path());
  }
  if (estimate.status == core::RunStatus::Canceled) throw Canceled();
  if (!quiet) {
    std::fprintf(stderr, "disparity range estimated from %d matches: [%d, %d] px\n",
                 estimate.matches, estimate.dmin, estimate.dmax);
  }
  return estimate;
}

}  // namespace delineo::cli

namespace {
using namespace delineo;

nlohmann::json report(const stereo::RangeEstimate& r, const stereo::RangeEstimateParams& params) {
  return {{"dmin", r.dmin},
          {"dmax", r.dmax},
          {"matches", r.matches},
          {"low_percentile_disparity", r.low},
          {"high_percentile_disparity", r.high},
          {"median_disparity", r.median},
          {"keypoints_left", r.keypointsLeft},
          {"keypoints_right", r.keypointsRight},
          {"detection_scale", r.scale},
          {"convention", "x_right = x_left - d"},
          {"params", core::toJson(params)}};
}

int run(const std::vector<std::string>& args) {
  cli::Options opts("range",
                    "Estimates the disparity search range of an epipolar pair from sparse "
                    "feature matches. Prints '--dmin A --dmax B' on stdout.");
  opts.required("left", "FILE", "left (reference) image")
      .required("right", "FILE", "right image, same size, epipolar with the left")
      .value("json", "FILE", "also write the estimate and what it was taken from as JSON")
      .flag("quiet", "nothing on stderr but errors");
  opts.params(stereo::RangeEstimateParams{});
  if (!opts.parse(args)) return cli::kExitOk;
  stereo::RangeEstimateParams params;
  opts.apply(params);

  cli::checkOutputs(opts, {{"json", io::OutputFormat::Json}}, {"left", "right"});
  auto& progress = cli::commandProgress();
  const bool quiet = opts.has("quiet");
  progress.setQuiet(quiet);
  progress.setStage("reading images");
  const cv::Mat left = io::readGreyFloat(opts.get("left"));
  const cv::Mat right = io::readGreyFloat(opts.get("right"));
  if (left.size() != right.size()) {
    throw core::Error(core::ErrorCode::MismatchedInputs,
                      "left " + opts.get("left") + " is " + std::to_string(left.cols) + "x" +
                          std::to_string(left.rows) + " but right is " +
                          std::to_string(right.cols) + "x" + std::to_string(right.rows),
                      opts.get("right"));
  }
  progress.setStage("estimating the disparity range");
  const stereo::RangeEstimate r = stereo::estimateDisparityRange(left, right, params, &progress);
  if (r.status == core::RunStatus::Canceled) throw cli::Canceled();
  progress.finish();

  if (opts.has("json")) {
    io::writeTextFile(opts.get("json"), report(r, params).dump(2) + "\n");
  }
  std::printf("--dmin %d --dmax %d\n", r.dmin, r.dmax);
  if (!quiet) {
    std::fprintf(stderr,
                 "disparity range estimated from %d matches: [%d, %d] px (match disparities "
                 "%.1f..%.1f px at the %g/%g percentiles, median %.1f px)\n",
                 r.matches, r.dmin, r.dmax, r.low, r.high, params.lowPercentile,
                 params.highPercentile, r.median);
  }
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"range", "disparity search range of a pair, estimated from feature matches", run});
}  // namespace
