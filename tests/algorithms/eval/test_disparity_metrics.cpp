#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "delineo/core/error.hpp"
#include "delineo/eval/disparity_metrics.hpp"

namespace eval = delineo::eval;
using delineo::core::Error;
using delineo::core::ErrorCode;

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// truth 0 and NaN are unknown: 7 evaluated pixels. Prediction errors on them:
// 0, 0.6, 1.5, (none), 0, 0, 5.
cv::Mat truthMap() { return (cv::Mat_<float>(3, 3) << 1, 2, 3, 4, 0, 6, kNaN, 8, 9); }
cv::Mat predictedMap() { return (cv::Mat_<float>(3, 3) << 1, 2.6f, 4.5f, kNaN, 5, 6, 1, 8, 14); }
}  // namespace

TEST(DisparityMetrics, HandMadeMapHasKnownRates) {
  const auto r = eval::evaluateDisparity(predictedMap(), truthMap());
  const auto& s = r.all;
  EXPECT_EQ(s.evaluatedPixels, 7);
  EXPECT_EQ(s.predictedPixels, 6);
  EXPECT_NEAR(s.density, 6.0 / 7.0, 1e-12);
  EXPECT_NEAR(s.bad05, 3.0 / 6.0, 1e-12);
  EXPECT_NEAR(s.bad1, 2.0 / 6.0, 1e-12);
  EXPECT_NEAR(s.bad2, 1.0 / 6.0, 1e-12);
  EXPECT_NEAR(s.bad4, 1.0 / 6.0, 1e-12);
  EXPECT_NEAR(s.meanAbsError, 7.1 / 6.0, 1e-6);
  EXPECT_NEAR(s.rms, std::sqrt((0.36 + 2.25 + 25.0) / 6.0), 1e-6);
  EXPECT_NEAR(s.bad2All, 2.0 / 7.0, 1e-12);  // one bad + one unpredicted
  EXPECT_FALSE(r.roof.has_value());
}

TEST(DisparityMetrics, MaskAndRoofMaskRestrictThePixels) {
  cv::Mat mask(3, 3, CV_8U, cv::Scalar(1));
  mask.at<uchar>(2, 2) = 0;  // drop the 5 px error
  cv::Mat roof(3, 3, CV_8U, cv::Scalar(0));
  roof.row(0).setTo(255);
  const auto r = eval::evaluateDisparity(predictedMap(), truthMap(), mask, roof);
  EXPECT_EQ(r.all.evaluatedPixels, 6);
  EXPECT_NEAR(r.all.bad2, 0.0, 1e-12);
  EXPECT_NEAR(r.all.bad2All, 1.0 / 6.0, 1e-12);
  ASSERT_TRUE(r.roof.has_value());
  EXPECT_EQ(r.roof->evaluatedPixels, 3);
  EXPECT_NEAR(r.roof->density, 1.0, 1e-12);
  EXPECT_NEAR(r.roof->bad1, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.roof->rms, std::sqrt((0.36 + 2.25) / 3.0), 1e-6);
}

TEST(DisparityMetrics, ZeroTruthCanBeAValue) {
  eval::DisparityMetricsParams params;
  params.truthZeroIsUnknown = false;
  const auto r = eval::evaluateDisparity(predictedMap(), truthMap(), {}, {}, params);
  EXPECT_EQ(r.all.evaluatedPixels, 8);
  EXPECT_NEAR(r.all.bad4, 2.0 / 7.0, 1e-12);  // the 5 px error at the former zero
}

TEST(DisparityMetrics, EmptyPredictionGivesNullRates) {
  const cv::Mat none(3, 3, CV_32F, cv::Scalar(kNaN));
  const auto r = eval::evaluateDisparity(none, truthMap());
  EXPECT_NEAR(r.all.density, 0.0, 1e-12);
  EXPECT_NEAR(r.all.bad2All, 1.0, 1e-12);
  EXPECT_TRUE(std::isnan(r.all.rms));
  const auto json = eval::disparityReport(r);
  EXPECT_TRUE(json["rms"].is_null());
  EXPECT_EQ(json["density"], 0.0);
}

TEST(DisparityMetrics, ReportHasTheDocumentedKeys) {
  cv::Mat roof(3, 3, CV_8U, cv::Scalar(1));
  const auto json = eval::disparityReport(eval::evaluateDisparity(predictedMap(), truthMap(), {}, roof));
  for (const char* key :
       {"density", "bad_0_5", "bad_1", "bad_2", "bad_4", "mean_abs_error", "rms", "bad_2_all"}) {
    EXPECT_TRUE(json.contains(key)) << key;
    EXPECT_TRUE(json["roof"].contains(key)) << key;
  }
  EXPECT_NEAR(json["bad_1"].get<double>(), 2.0 / 6.0, 1e-12);
}

TEST(DisparityMetrics, RejectsMismatchedOrWrongInputs) {
  try {
    eval::evaluateDisparity(cv::Mat(4, 3, CV_32F, cv::Scalar(1)), truthMap());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::MismatchedInputs);
  }
  try {
    eval::evaluateDisparity(predictedMap(), truthMap(), cv::Mat(2, 2, CV_8U, cv::Scalar(1)));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::MismatchedInputs);
    EXPECT_NE(std::string(e.what()).find("mask"), std::string::npos);
  }
  try {
    eval::evaluateDisparity(cv::Mat(3, 3, CV_8U, cv::Scalar(1)), truthMap());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::UnsupportedInput);
  }
}
