#pragma once
// Per-class accuracy of a label map (0 ground, 1 building, 2 vegetation). Definitions:
// docs/metrics.md.
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"

namespace delineo::eval {

struct LabelMetricsParams {
  int classCount = 3;  // labels 0 .. classCount-1; larger truth values are "unknown"

  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"class-count", "Classes", "",
                      "Number of classes (0 ground, 1 building, 2 vegetation); larger truth "
                      "labels are not evaluated",
                      1, 255},
      classCount);
  }
  void validate() const { core::checkDeclaredRanges(*this); }
};

struct ClassScores {
  double precision = 0.0;  // TP / (TP + FP), NaN when the class was never predicted
  double recall = 0.0;     // TP / (TP + FN), NaN when the class is absent from the truth
  double iou = 0.0;        // TP / (TP + FP + FN), NaN when both are empty
  std::int64_t truePositives = 0;
  std::int64_t truthPixels = 0;      // TP + FN
  std::int64_t predictedPixels = 0;  // TP + FP
};

struct LabelEvaluation {
  std::vector<ClassScores> classes;                 // index = label
  std::vector<std::vector<std::int64_t>> confusion;  // [truth][predicted], predicted in 0..n
                                                    // where column n counts out-of-range labels
  double accuracy = 0.0;                            // Σ TP / evaluated, NaN when none
  std::int64_t evaluatedPixels = 0;
};

// `predicted`, `truth`: CV_8UC1 of the same size; `mask` optional (non-zero = evaluate).
// Pixels whose truth label is >= classCount are not evaluated. A predicted label >= classCount
// is wrong for the true class (a false negative) and a false positive of no class.
LabelEvaluation evaluateLabels(const cv::Mat& predicted, const cv::Mat& truth,
                               const cv::Mat& mask = {}, const LabelMetricsParams& params = {});

nlohmann::json labelReport(const LabelEvaluation& evaluation);

}  // namespace delineo::eval
