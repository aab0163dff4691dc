#include <gtest/gtest.h>

#include <cmath>

#include "delineo/core/error.hpp"
#include "delineo/eval/footprint_metrics.hpp"

using delineo::core::Polygon;
namespace eval = delineo::eval;

namespace {
Polygon square(double x0, double y0, double side) {
  return {{{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}}, {}};
}
}  // namespace

TEST(FootprintMetrics, PairScoresOfAShiftedSquare) {
  const auto s = eval::compareFootprints(square(3, 0, 10), square(0, 0, 10));
  EXPECT_NEAR(s.iou, 70.0 / 130.0, 1e-12);
  EXPECT_NEAR(s.p1, 60.0, 1e-9);  // symmetric difference 60 over truth area 100
  EXPECT_NEAR(s.polis, 1.5, 1e-12);
  EXPECT_NEAR(s.hausdorff, 3.0, 1e-9);
  EXPECT_EQ(s.cornersMatched, 4);  // all within the 3 px default radius
  EXPECT_NEAR(s.cornerRms, 3.0, 1e-12);
}

TEST(FootprintMetrics, GreedyMatchingReportsMissedAndFalse) {
  const std::vector<Polygon> truth{square(0, 0, 10), square(100, 0, 10), square(200, 0, 10)};
  const std::vector<Polygon> predicted{
      square(101, 0, 10),   // matches truth 1
      square(0, 0, 10),     // matches truth 0 exactly
      square(500, 500, 10), // nothing
      square(9, 9, 3),      // touches truth 0 with IoU 1/108: below the threshold
      square(2, 0, 10),     // overlaps truth 0 (IoU 2/3) but truth 0 prefers the exact one
  };
  const auto result = eval::evaluateFootprints(predicted, truth);
  ASSERT_EQ(result.status, delineo::core::RunStatus::Completed);
  ASSERT_EQ(result.matches.size(), 2u);
  EXPECT_EQ(result.matches[0].truthIndex, 0u);
  EXPECT_EQ(result.matches[0].predictedIndex, 1u);
  EXPECT_NEAR(result.matches[0].scores.iou, 1.0, 1e-12);
  EXPECT_EQ(result.matches[1].truthIndex, 1u);
  EXPECT_EQ(result.matches[1].predictedIndex, 0u);
  EXPECT_NEAR(result.matches[1].scores.iou, 90.0 / 110.0, 1e-12);
  EXPECT_EQ(result.missedTruths, std::vector<size_t>{2});
  EXPECT_EQ(result.falsePredictions, (std::vector<size_t>{2, 3, 4}));
  EXPECT_NEAR(result.mean.iou, 0.5 * (1.0 + 90.0 / 110.0), 1e-12);
  EXPECT_NEAR(result.mean.hausdorff, 0.5, 1e-9);

  const auto json = eval::footprintReport(result, {"a", "b", "c", "d", "e"}, {10, 11, 12});
  EXPECT_EQ(json["missed"], nlohmann::json::array({12}));
  EXPECT_EQ(json["false"], nlohmann::json::array({"c", "d", "e"}));
  EXPECT_EQ(json["buildings"][0]["truth_id"], 10);
  EXPECT_EQ(json["buildings"][0]["pred_id"], "b");
  for (const char* key : {"iou", "p1", "polis", "hausdorff", "corner_rms"}) {
    EXPECT_TRUE(json["mean"].contains(key)) << key;
    EXPECT_TRUE(json["buildings"][1].contains(key)) << key;
  }
  EXPECT_NEAR(json["counts"]["recall"].get<double>(), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(json["counts"]["precision"].get<double>(), 2.0 / 5.0, 1e-12);
}

TEST(FootprintMetrics, GreedyTakesTheBestPairFirst) {
  // Truth 0 overlaps both predictions; prediction 1 fits truth 0 best, so truth 1 gets
  // prediction 0 even though prediction 0 overlaps truth 0 more than truth 1 does.
  const std::vector<Polygon> truth{square(0, 0, 10), square(6, 0, 10)};
  const std::vector<Polygon> predicted{square(4, 0, 10), square(0.5, 0, 10)};
  const auto result = eval::evaluateFootprints(predicted, truth);
  ASSERT_EQ(result.matches.size(), 2u);
  EXPECT_EQ(result.matches[0].predictedIndex, 1u);
  EXPECT_EQ(result.matches[1].predictedIndex, 0u);
}

TEST(FootprintMetrics, NoMatchGivesNaNMeans) {
  const auto result = eval::evaluateFootprints({square(50, 50, 5)}, {square(0, 0, 5)});
  EXPECT_TRUE(result.matches.empty());
  EXPECT_TRUE(std::isnan(result.mean.iou));
  const auto json = eval::footprintReport(result, {}, {});
  EXPECT_TRUE(json["mean"]["iou"].is_null());
  EXPECT_EQ(json["missed"], nlohmann::json::array({0}));
  EXPECT_EQ(json["false"], nlohmann::json::array({0}));
}

TEST(FootprintMetrics, CancelIsAnOutcome) {
  std::vector<Polygon> truth, predicted;
  for (int k = 0; k < 10; ++k) {
    truth.push_back(square(20.0 * k, 0, 10));
    predicted.push_back(square(20.0 * k + 1, 0, 10));
  }
  delineo::core::Progress progress;
  progress.cancelAfterReports(2);
  const auto result = eval::evaluateFootprints(predicted, truth, {}, &progress);
  EXPECT_EQ(result.status, delineo::core::RunStatus::Canceled);
}

TEST(FootprintMetrics, ParametersAreValidated) {
  eval::FootprintMetricsParams params;
  params.boundaryStep = 0.0;
  EXPECT_THROW(params.validate(), delineo::core::Error);
  params = {};
  params.matchIou = 1.5;
  EXPECT_THROW(eval::evaluateFootprints({}, {}, params), delineo::core::Error);
}
