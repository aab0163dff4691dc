#include <gtest/gtest.h>

#include <cmath>

#include "delineo/core/error.hpp"
#include "delineo/eval/label_metrics.hpp"

namespace eval = delineo::eval;

namespace {
// (truth, predicted) pairs: (0,0) (0,1) (1,1) (1,1) (1,0) / (2,2) (2,0) (0,0) (1,1) and one
// truth 255 (unknown, not evaluated).
cv::Mat truthLabels() { return (cv::Mat_<uchar>(2, 5) << 0, 0, 1, 1, 1, 2, 2, 0, 1, 255); }
cv::Mat predictedLabels() { return (cv::Mat_<uchar>(2, 5) << 0, 1, 1, 1, 0, 2, 0, 0, 1, 2); }
}  // namespace

TEST(LabelMetrics, KnownConfusion) {
  const auto r = eval::evaluateLabels(predictedLabels(), truthLabels());
  EXPECT_EQ(r.evaluatedPixels, 9);
  ASSERT_EQ(r.classes.size(), 3u);
  EXPECT_NEAR(r.classes[0].precision, 2.0 / 4.0, 1e-12);
  EXPECT_NEAR(r.classes[0].recall, 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.classes[0].iou, 2.0 / 5.0, 1e-12);
  EXPECT_NEAR(r.classes[1].precision, 3.0 / 4.0, 1e-12);
  EXPECT_NEAR(r.classes[1].recall, 3.0 / 4.0, 1e-12);
  EXPECT_NEAR(r.classes[1].iou, 3.0 / 5.0, 1e-12);
  EXPECT_NEAR(r.classes[2].precision, 1.0, 1e-12);
  EXPECT_NEAR(r.classes[2].recall, 1.0 / 2.0, 1e-12);
  EXPECT_NEAR(r.classes[2].iou, 1.0 / 2.0, 1e-12);
  EXPECT_NEAR(r.accuracy, 6.0 / 9.0, 1e-12);
  EXPECT_EQ(r.confusion[1][0], 1);
  EXPECT_EQ(r.confusion[0][1], 1);
}

TEST(LabelMetrics, OutOfRangePredictionIsAMissNotAFalsePositive) {
  cv::Mat predicted = predictedLabels();
  predicted.at<uchar>(0, 0) = 7;  // was a correct ground pixel
  cv::Mat mask(2, 5, CV_8U, cv::Scalar(1));
  mask.at<uchar>(1, 1) = 0;  // drop the (2,0) pixel
  const auto r = eval::evaluateLabels(predicted, truthLabels(), mask);
  EXPECT_EQ(r.evaluatedPixels, 8);
  EXPECT_NEAR(r.classes[0].recall, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.classes[0].precision, 1.0 / 2.0, 1e-12);  // predicted ground: (0,0) and (1,0)
  EXPECT_EQ(r.confusion[0][3], 1);
  EXPECT_NEAR(r.classes[2].recall, 1.0, 1e-12);
  const auto json = eval::labelReport(r);
  EXPECT_EQ(json["classes"][1]["name"], "building");
}

TEST(LabelMetrics, AbsentClassHasNullScores) {
  const cv::Mat zeros(2, 2, CV_8U, cv::Scalar(0));
  const auto r = eval::evaluateLabels(zeros, zeros);
  EXPECT_NEAR(r.classes[0].iou, 1.0, 1e-12);
  EXPECT_TRUE(std::isnan(r.classes[1].precision));
  EXPECT_TRUE(eval::labelReport(r)["classes"][1]["recall"].is_null());
  EXPECT_THROW(eval::evaluateLabels(zeros, cv::Mat(3, 2, CV_8U, cv::Scalar(0))),
               delineo::core::Error);
}
