#pragma once
// Disparity map accuracy against a ground truth (stereo benchmark style). Definitions:
// docs/metrics.md.
#include <cstdint>
#include <optional>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"

namespace delineo::eval {

struct DisparityMetricsParams {
  bool truthZeroIsUnknown = true;  // a truth value of exactly 0 means "no ground truth"

  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"truth-zero-unknown", "Zero truth is unknown", "",
                      "Treat ground-truth disparities equal to 0 as unknown (Middlebury, Dublin)"},
      truthZeroIsUnknown);
  }
  void validate() const { core::checkDeclaredRanges(*this); }
};

// Rates in [0, 1], errors in px. NaN where undefined (no evaluated or no predicted pixel).
struct DisparityScores {
  double density = 0.0;       // predicted / evaluated
  double bad05 = 0.0;         // among predicted pixels, fraction with |error| > 0.5 px
  double bad1 = 0.0;          // ... > 1 px
  double bad2 = 0.0;          // ... > 2 px
  double bad4 = 0.0;          // ... > 4 px
  double meanAbsError = 0.0;  // mean |error| over predicted pixels
  double rms = 0.0;           // sqrt(mean error²) over predicted pixels
  double bad2All = 0.0;       // (predicted with |error| > 2 px + unpredicted) / evaluated
  std::int64_t evaluatedPixels = 0;  // valid truth inside the mask
  std::int64_t predictedPixels = 0;  // evaluated pixels with a finite prediction
};

struct DisparityEvaluation {
  DisparityScores all;
  std::optional<DisparityScores> roof;  // set when a roof mask was given
};

// `predicted` and `truth`: CV_32FC1 of the same size. A non-finite prediction means "no
// prediction"; a non-finite truth (or 0 when params.truthZeroIsUnknown) means "unknown".
// `mask` and `roofMask`: optional single-channel images of the same size, non-zero = evaluate;
// the roof scores use the pixels inside both. Throws MismatchedInputs on a size mismatch and
// UnsupportedInput on a wrong type.
DisparityEvaluation evaluateDisparity(const cv::Mat& predicted, const cv::Mat& truth,
                                      const cv::Mat& mask = {}, const cv::Mat& roofMask = {},
                                      const DisparityMetricsParams& params = {});

// {"density","bad_0_5","bad_1","bad_2","bad_4","mean_abs_error","rms","bad_2_all",
//  "evaluated_pixels","predicted_pixels"} with NaN written as null.
nlohmann::json disparityScoresJson(const DisparityScores& scores);
// The scores of all pixels plus "roof" (same keys) when present.
nlohmann::json disparityReport(const DisparityEvaluation& evaluation);

}  // namespace delineo::eval
