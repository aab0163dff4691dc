#include "delineo/eval/footprint_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "delineo/eval/polygon_measures.hpp"

namespace delineo::eval {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

bool boxesOverlap(const cv::Rect2d& a, const cv::Rect2d& b) {
  return a.x <= b.x + b.width && b.x <= a.x + a.width && a.y <= b.y + b.height &&
         b.y <= a.y + a.height;
}

// Mean of the finite values; NaN when there is none.
double finiteMean(const std::vector<double>& values) {
  double sum = 0.0;
  int count = 0;
  for (double v : values) {
    if (std::isfinite(v)) {
      sum += v;
      ++count;
    }
  }
  return count > 0 ? sum / count : kNaN;
}

nlohmann::json scoresJson(const FootprintScores& s) {
  return {{"iou", number(s.iou)},
          {"p1", number(s.p1)},
          {"polis", number(s.polis)},
          {"hausdorff", number(s.hausdorff)},
          {"corner_rms", number(s.cornerRms)}};
}

}  // namespace

FootprintScores compareFootprints(const core::Polygon& predicted, const core::Polygon& truth,
                                  const FootprintMetricsParams& params) {
  params.validate();
  FootprintScores s;
  s.iou = intersectionOverUnion(predicted, truth);
  s.p1 = shapeErrorP1(predicted, truth);
  s.polis = polisDistance(predicted, truth);
  s.hausdorff = hausdorffDistance(predicted, truth, params.boundaryStep);
  const CornerMatching corners = matchCorners(polygonCorners(predicted, params.cornerMinTurn),
                                              polygonCorners(truth, params.cornerMinTurn),
                                              params.cornerRadius);
  s.cornerRms = corners.rms;
  s.cornersMatched = corners.matched;
  s.truthCorners = corners.truthCorners;
  s.predictedCorners = corners.predictedCorners;
  return s;
}

FootprintEvaluation evaluateFootprints(const std::vector<core::Polygon>& predicted,
                                       const std::vector<core::Polygon>& truth,
                                       const FootprintMetricsParams& params,
                                       core::Progress* progress) {
  params.validate();
  FootprintEvaluation result;
  result.truthCount = truth.size();
  result.predictedCount = predicted.size();

  std::vector<cv::Rect2d> predictedBoxes;
  predictedBoxes.reserve(predicted.size());
  for (const auto& p : predicted) predictedBoxes.push_back(core::boundingBox(p.outer));

  // Candidate pairs (IoU, truth, predicted); the scoring of matches is the second half of the
  // work.
  std::vector<std::tuple<double, size_t, size_t>> candidates;
  for (size_t t = 0; t < truth.size(); ++t) {
    if (core::isCanceled(progress)) {
      result.status = core::RunStatus::Canceled;
      return result;
    }
    const cv::Rect2d box = core::boundingBox(truth[t].outer);
    for (size_t p = 0; p < predicted.size(); ++p) {
      if (!boxesOverlap(box, predictedBoxes[p])) continue;
      const double iou = intersectionOverUnion(predicted[p], truth[t]);
      if (iou > params.matchIou) candidates.emplace_back(iou, t, p);
    }
    core::report(progress, 0.5 * static_cast<double>(t + 1) / static_cast<double>(truth.size()));
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) > std::get<0>(b);
    return std::make_pair(std::get<1>(a), std::get<2>(a)) <
           std::make_pair(std::get<1>(b), std::get<2>(b));
  });
  std::vector<bool> truthUsed(truth.size(), false), predictedUsed(predicted.size(), false);
  for (const auto& [iou, t, p] : candidates) {
    if (truthUsed[t] || predictedUsed[p]) continue;
    truthUsed[t] = predictedUsed[p] = true;
    result.matches.push_back({t, p, {}});
  }
  std::sort(result.matches.begin(), result.matches.end(),
            [](const BuildingMatch& a, const BuildingMatch& b) { return a.truthIndex < b.truthIndex; });

  for (size_t k = 0; k < result.matches.size(); ++k) {
    if (core::isCanceled(progress)) {
      result.status = core::RunStatus::Canceled;
      return result;
    }
    auto& m = result.matches[k];
    m.scores = compareFootprints(predicted[m.predictedIndex], truth[m.truthIndex], params);
    core::report(progress,
                 0.5 + 0.5 * static_cast<double>(k + 1) / static_cast<double>(result.matches.size()));
  }

  std::vector<double> iou, p1, polis, hausdorff, cornerRms;
  for (const auto& m : result.matches) {
    iou.push_back(m.scores.iou);
    p1.push_back(m.scores.p1);
    polis.push_back(m.scores.polis);
    hausdorff.push_back(m.scores.hausdorff);
    cornerRms.push_back(m.scores.cornerRms);
    result.mean.cornersMatched += m.scores.cornersMatched;
    result.mean.truthCorners += m.scores.truthCorners;
    result.mean.predictedCorners += m.scores.predictedCorners;
  }
  result.mean.iou = finiteMean(iou);
  result.mean.p1 = finiteMean(p1);
  result.mean.polis = finiteMean(polis);
  result.mean.hausdorff = finiteMean(hausdorff);
  result.mean.cornerRms = finiteMean(cornerRms);

  for (size_t t = 0; t < truth.size(); ++t) {
    if (!truthUsed[t]) result.missedTruths.push_back(t);
  }
  for (size_t p = 0; p < predicted.size(); ++p) {
    if (!predictedUsed[p]) result.falsePredictions.push_back(p);
  }
  core::report(progress, 1.0);
  return result;
}

nlohmann::json footprintReport(const FootprintEvaluation& evaluation,
                               const std::vector<nlohmann::json>& predictedIds,
                               const std::vector<nlohmann::json>& truthIds) {
  auto truthId = [&](size_t i) { return i < truthIds.size() ? truthIds[i] : nlohmann::json(i); };
  auto predictedId = [&](size_t i) {
    return i < predictedIds.size() ? predictedIds[i] : nlohmann::json(i);
  };
  nlohmann::json report;
  report["mean"] = scoresJson(evaluation.mean);
  report["buildings"] = nlohmann::json::array();
  for (const auto& m : evaluation.matches) {
    nlohmann::json b = scoresJson(m.scores);
    b["truth_id"] = truthId(m.truthIndex);
    b["pred_id"] = predictedId(m.predictedIndex);
    b["corners_matched"] = m.scores.cornersMatched;
    b["truth_corners"] = m.scores.truthCorners;
    b["pred_corners"] = m.scores.predictedCorners;
    report["buildings"].push_back(std::move(b));
  }
  report["missed"] = nlohmann::json::array();
  for (size_t t : evaluation.missedTruths) report["missed"].push_back(truthId(t));
  report["false"] = nlohmann::json::array();
  for (size_t p : evaluation.falsePredictions) report["false"].push_back(predictedId(p));

  const double matched = static_cast<double>(evaluation.matches.size());
  const double precision =
      evaluation.predictedCount > 0 ? matched / static_cast<double>(evaluation.predictedCount) : kNaN;
  const double recall =
      evaluation.truthCount > 0 ? matched / static_cast<double>(evaluation.truthCount) : kNaN;
  const double f1 = (std::isfinite(precision) && std::isfinite(recall) && precision + recall > 0)
                        ? 2 * precision * recall / (precision + recall)
                        : kNaN;
  report["counts"] = {{"truths", evaluation.truthCount},
                      {"predictions", evaluation.predictedCount},
                      {"matched", evaluation.matches.size()},
                      {"precision", number(precision)},
                      {"recall", number(recall)},
                      {"f1", number(f1)},
                      {"corners_matched", evaluation.mean.cornersMatched},
                      {"truth_corners", evaluation.mean.truthCorners}};
  return report;
}

}  // namespace delineo::eval
