#include "delineo/eval/label_metrics.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "delineo/core/error.hpp"

namespace delineo::eval {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

double ratio(std::int64_t numerator, std::int64_t denominator) {
  return denominator > 0 ? static_cast<double>(numerator) / static_cast<double>(denominator) : kNaN;
}

}  // namespace

LabelEvaluation evaluateLabels(const cv::Mat& predicted, const cv::Mat& truth, const cv::Mat& mask,
                               const LabelMetricsParams& params) {
  params.validate();
  if (predicted.type() != CV_8UC1 || truth.type() != CV_8UC1) {
    throw core::Error(core::ErrorCode::UnsupportedInput, "label maps must be single-channel 8-bit");
  }
  if (predicted.size() != truth.size() || (!mask.empty() && mask.size() != truth.size())) {
    throw core::Error(core::ErrorCode::MismatchedInputs,
                      "label maps and mask must have the same size");
  }
  if (!mask.empty() && mask.channels() != 1) {
    throw core::Error(core::ErrorCode::UnsupportedInput, "the mask must have one channel");
  }
  const cv::Mat evaluate = mask.empty() ? cv::Mat() : cv::Mat(mask != 0);
  const int n = params.classCount;

  LabelEvaluation result;
  result.confusion.assign(static_cast<size_t>(n), std::vector<std::int64_t>(static_cast<size_t>(n) + 1, 0));
  for (int y = 0; y < truth.rows; ++y) {
    const uchar* p = predicted.ptr<uchar>(y);
    const uchar* t = truth.ptr<uchar>(y);
    const uchar* m = evaluate.empty() ? nullptr : evaluate.ptr<uchar>(y);
    for (int x = 0; x < truth.cols; ++x) {
      if (t[x] >= n || (m != nullptr && m[x] == 0)) continue;
      const int column = p[x] < n ? p[x] : n;
      ++result.confusion[t[x]][static_cast<size_t>(column)];
      ++result.evaluatedPixels;
    }
  }
  std::int64_t correct = 0;
  for (int c = 0; c < n; ++c) {
    ClassScores s;
    s.truePositives = result.confusion[c][c];
    for (int k = 0; k <= n; ++k) s.truthPixels += result.confusion[c][k];
    for (int k = 0; k < n; ++k) s.predictedPixels += result.confusion[k][c];
    s.precision = ratio(s.truePositives, s.predictedPixels);
    s.recall = ratio(s.truePositives, s.truthPixels);
    s.iou = ratio(s.truePositives, s.truthPixels + s.predictedPixels - s.truePositives);
    correct += s.truePositives;
    result.classes.push_back(s);
  }
  result.accuracy = ratio(correct, result.evaluatedPixels);
  return result;
}

nlohmann::json labelReport(const LabelEvaluation& evaluation) {
  static const char* const kNames[] = {"ground", "building", "vegetation"};
  nlohmann::json classes = nlohmann::json::array();
  for (size_t c = 0; c < evaluation.classes.size(); ++c) {
    const auto& s = evaluation.classes[c];
    classes.push_back({{"label", c},
                       {"name", c < 3 ? kNames[c] : "class " + std::to_string(c)},
                       {"precision", number(s.precision)},
                       {"recall", number(s.recall)},
                       {"iou", number(s.iou)},
                       {"true_positives", s.truePositives},
                       {"truth_pixels", s.truthPixels},
                       {"predicted_pixels", s.predictedPixels}});
  }
  return {{"classes", classes},
          {"accuracy", number(evaluation.accuracy)},
          {"evaluated_pixels", evaluation.evaluatedPixels},
          {"confusion", evaluation.confusion}};
}

}  // namespace delineo::eval
