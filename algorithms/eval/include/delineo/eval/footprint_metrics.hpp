#pragma once
// Building footprint evaluation: per-pair scores (IoU, p1, PoLiS, Hausdorff, corner RMS) and
// matching of a predicted set against a truth set by overlap. Definitions: docs/metrics.md.
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::eval {

struct FootprintMetricsParams {
  double matchIou = 0.1;        // unitless; a pair is a match candidate when IoU > this
  double cornerRadius = 3.0;    // px; corners farther apart than this are never paired
  double cornerMinTurn = 20.0;  // degrees; a vertex is a corner when the outline turns this much
  double boundaryStep = 0.1;    // px; edge sampling step of the Hausdorff distance

  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"match-iou", "Match IoU", "",
                      "A predicted and a true outline can be matched when their IoU exceeds this",
                      0.0, 0.99},
      matchIou);
    v(core::ParamInfo{"corner-radius", "Corner radius", "px",
                      "Largest distance between a true and a predicted corner that are paired",
                      0.0, 1e6},
      cornerRadius);
    v(core::ParamInfo{"corner-min-turn", "Corner turn", "deg",
                      "Smallest turn of the outline at a vertex for it to count as a corner", 0.0,
                      179.0},
      cornerMinTurn);
    v(core::ParamInfo{"boundary-step", "Boundary step", "px",
                      "Edge sampling step of the Hausdorff distance (error at most half of it)",
                      1e-4, 100.0},
      boundaryStep);
  }
  void validate() const { core::checkDeclaredRanges(*this); }
};

struct FootprintScores {
  double iou = 0.0;         // [0, 1]
  double p1 = 0.0;          // percent, symmetric difference / truth area
  double polis = 0.0;       // px
  double hausdorff = 0.0;   // px
  double cornerRms = 0.0;   // px, NaN when no corner pair was found
  int cornersMatched = 0;
  int truthCorners = 0;
  int predictedCorners = 0;
};

// Scores of one predicted outline against one true outline.
FootprintScores compareFootprints(const core::Polygon& predicted, const core::Polygon& truth,
                                  const FootprintMetricsParams& params = {});

struct BuildingMatch {
  size_t truthIndex = 0;
  size_t predictedIndex = 0;
  FootprintScores scores;
};

struct FootprintEvaluation {
  core::RunStatus status = core::RunStatus::Completed;
  std::vector<BuildingMatch> matches;      // ordered by truth index
  FootprintScores mean;                    // NaN-free means over matches (NaN when no match)
  std::vector<size_t> missedTruths;        // truth indices without a match, ascending
  std::vector<size_t> falsePredictions;    // predicted indices without a match, ascending
  size_t truthCount = 0;
  size_t predictedCount = 0;
};

// Greedy one-to-one matching: all pairs with IoU > params.matchIou, taken by decreasing IoU
// (ties by truth then predicted index), each outline used at most once; matched pairs are then
// scored with compareFootprints. Polls `progress` once per true outline.
FootprintEvaluation evaluateFootprints(const std::vector<core::Polygon>& predicted,
                                       const std::vector<core::Polygon>& truth,
                                       const FootprintMetricsParams& params = {},
                                       core::Progress* progress = nullptr);

// The JSON report of eval-footprints:
// {"mean":{iou,p1,polis,hausdorff,corner_rms}, "buildings":[{truth_id,pred_id,iou,...}],
//  "missed":[truth ids], "false":[pred ids], "counts":{...}}. NaN is written as null.
// The id vectors give each outline's id (same order as the evaluated vectors).
nlohmann::json footprintReport(const FootprintEvaluation& evaluation,
                               const std::vector<nlohmann::json>& predictedIds,
                               const std::vector<nlohmann::json>& truthIds);

}  // namespace delineo::eval
