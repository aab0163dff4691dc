#include "delineo/eval/disparity_metrics.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "delineo/core/error.hpp"

namespace delineo::eval {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

std::string sizeText(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

// Single-channel "non-zero = evaluate" mask as CV_8U, or an empty Mat when none was given.
cv::Mat binaryMask(const cv::Mat& mask, const cv::Size& size, const char* what) {
  if (mask.empty()) return {};
  if (mask.channels() != 1) {
    throw core::Error(core::ErrorCode::UnsupportedInput,
                      std::string(what) + " must have one channel, it has " +
                          std::to_string(mask.channels()));
  }
  if (mask.size() != size) {
    throw core::Error(core::ErrorCode::MismatchedInputs,
                      std::string(what) + " is " + sizeText(mask) + " but the disparity maps are " +
                          std::to_string(size.width) + "x" + std::to_string(size.height));
  }
  return mask != 0;
}

struct Accumulator {
  std::int64_t evaluated = 0, predicted = 0;
  std::int64_t over05 = 0, over1 = 0, over2 = 0, over4 = 0;
  double sumAbs = 0.0, sumSquares = 0.0;

  void add(float prediction, float truth) {
    ++evaluated;
    if (!std::isfinite(prediction)) return;
    ++predicted;
    const double error = std::abs(static_cast<double>(prediction) - static_cast<double>(truth));
    over05 += error > 0.5;
    over1 += error > 1.0;
    over2 += error > 2.0;
    over4 += error > 4.0;
    sumAbs += error;
    sumSquares += error * error;
  }

  DisparityScores scores() const {
    DisparityScores s;
    s.evaluatedPixels = evaluated;
    s.predictedPixels = predicted;
    const double e = static_cast<double>(evaluated);
    const double p = static_cast<double>(predicted);
    s.density = evaluated > 0 ? p / e : kNaN;
    s.bad2All = evaluated > 0 ? static_cast<double>(over2 + (evaluated - predicted)) / e : kNaN;
    s.bad05 = predicted > 0 ? static_cast<double>(over05) / p : kNaN;
    s.bad1 = predicted > 0 ? static_cast<double>(over1) / p : kNaN;
    s.bad2 = predicted > 0 ? static_cast<double>(over2) / p : kNaN;
    s.bad4 = predicted > 0 ? static_cast<double>(over4) / p : kNaN;
    s.meanAbsError = predicted > 0 ? sumAbs / p : kNaN;
    s.rms = predicted > 0 ? std::sqrt(sumSquares / p) : kNaN;
    return s;
  }
};

}  // namespace

DisparityEvaluation evaluateDisparity(const cv::Mat& predicted, const cv::Mat& truth,
                                      const cv::Mat& mask, const cv::Mat& roofMask,
                                      const DisparityMetricsParams& params) {
  params.validate();
  if (predicted.type() != CV_32FC1 || truth.type() != CV_32FC1) {
    throw core::Error(core::ErrorCode::UnsupportedInput,
                      "disparity maps must be single-channel float32");
  }
  if (predicted.size() != truth.size()) {
    throw core::Error(core::ErrorCode::MismatchedInputs,
                      "predicted disparity is " + sizeText(predicted) + " but the truth is " +
                          sizeText(truth));
  }
  const cv::Mat evaluate = binaryMask(mask, truth.size(), "mask");
  const cv::Mat roof = binaryMask(roofMask, truth.size(), "roof mask");

  Accumulator all, onRoofs;
  for (int y = 0; y < truth.rows; ++y) {
    const float* p = predicted.ptr<float>(y);
    const float* t = truth.ptr<float>(y);
    const uchar* m = evaluate.empty() ? nullptr : evaluate.ptr<uchar>(y);
    const uchar* r = roof.empty() ? nullptr : roof.ptr<uchar>(y);
    for (int x = 0; x < truth.cols; ++x) {
      if (!std::isfinite(t[x]) || (params.truthZeroIsUnknown && t[x] == 0.0f)) continue;
      if (m != nullptr && m[x] == 0) continue;
      all.add(p[x], t[x]);
      if (r != nullptr && r[x] != 0) onRoofs.add(p[x], t[x]);
    }
  }
  DisparityEvaluation result;
  result.all = all.scores();
  if (!roof.empty()) result.roof = onRoofs.scores();
  return result;
}

nlohmann::json disparityScoresJson(const DisparityScores& s) {
  return {{"density", number(s.density)},
          {"bad_0_5", number(s.bad05)},
          {"bad_1", number(s.bad1)},
          {"bad_2", number(s.bad2)},
          {"bad_4", number(s.bad4)},
          {"mean_abs_error", number(s.meanAbsError)},
          {"rms", number(s.rms)},
          {"bad_2_all", number(s.bad2All)},
          {"evaluated_pixels", s.evaluatedPixels},
          {"predicted_pixels", s.predictedPixels}};
}

nlohmann::json disparityReport(const DisparityEvaluation& evaluation) {
  nlohmann::json report = disparityScoresJson(evaluation.all);
  if (evaluation.roof) report["roof"] = disparityScoresJson(*evaluation.roof);
  return report;
}

}  // namespace delineo::eval
