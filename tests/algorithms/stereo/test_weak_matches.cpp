// Weak matches beside depth steps and beside plain regions left unmatched rejected (internal
// rejectWeakMatchesBesideSteps, rejectWeakMatchesBesideUnmatchedPlain).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include <opencv2/core.hpp>

#include "delineo/stereo/match.hpp"
#include "weak_matches.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kFillScore = 0.3F;

// Two float maps equal bit for bit, NaNs included.
void expectSameBits(const cv::Mat& a, const cv::Mat& b) {
  ASSERT_EQ(a.size(), b.size());
  for (int y = 0; y < a.rows; ++y) {
    EXPECT_EQ(std::memcmp(a.ptr(y), b.ptr(y), a.cols * sizeof(float)), 0) << "row " << y;
  }
}

// A roof (disparity 30, x >= 20) beside the ground (10), every match scoring 0.9.
struct StepScene {
  cv::Mat disparity{24, 40, CV_32F, cv::Scalar(10.0)};
  cv::Mat score{24, 40, CV_32F, cv::Scalar(0.9)};
  StepScene() { disparity(cv::Rect(20, 0, 20, 24)).setTo(30.0F); }
};

TEST(RejectWeakMatchesBesideSteps, RejectsWeakFarSideMatchesWithinTheRadiusOfAStepOnly) {
  StepScene s;
  s.disparity.at<float>(10, 21) = 10.5F;  // the ground's value carried onto the roof, weak
  s.score.at<float>(10, 21) = 0.6F;
  s.score.at<float>(12, 17) = 0.7F;   // weak, 3 px from the step: rejected
  s.score.at<float>(14, 16) = 0.7F;   // weak, 4 px from the step: kept
  s.score.at<float>(16, 22) = 0.85F;  // beside the step, strong enough: kept
  s.score.at<float>(8, 20) = 0.5F;    // weak, but on the near side (the roof): kept
  s.score.at<float>(18, 3) = 0.4F;    // weak, far from any step: kept
  WeakMatchSettings settings;
  EXPECT_EQ(rejectWeakMatchesBesideSteps(settings, kFillScore, s.disparity, s.score), 2);
  EXPECT_TRUE(std::isnan(s.disparity.at<float>(10, 21)));
  EXPECT_TRUE(std::isnan(s.score.at<float>(10, 21)));
  EXPECT_TRUE(std::isnan(s.disparity.at<float>(12, 17)));
  EXPECT_EQ(s.disparity.at<float>(14, 16), 10.0F);
  EXPECT_EQ(s.disparity.at<float>(16, 22), 30.0F);
  EXPECT_EQ(s.disparity.at<float>(8, 20), 30.0F);
  EXPECT_EQ(s.disparity.at<float>(18, 3), 10.0F);
}

TEST(RejectWeakMatchesBesideSteps, KeepsFilledPixelsAndIsOffAtZero) {
  StepScene s;
  s.score.at<float>(5, 19) = kFillScore;  // set by the fill: not a match
  s.score.at<float>(6, 18) = 0.5F;
  WeakMatchSettings settings;
  settings.minScore = 0;
  EXPECT_EQ(rejectWeakMatchesBesideSteps(settings, kFillScore, s.disparity, s.score), 0);
  settings.minScore = 0.8;
  EXPECT_EQ(rejectWeakMatchesBesideSteps(settings, kFillScore, s.disparity, s.score), 1);
  EXPECT_EQ(s.disparity.at<float>(5, 19), 10.0F);
  EXPECT_TRUE(std::isnan(s.disparity.at<float>(6, 18)));
}

TEST(RejectWeakMatchesBesideSteps, SlopesAndGapsAreNotSteps) {
  // A facet sloping by 0.4 px per px: 2.4 px over the 7 px neighbourhood, under the 3 px step.
  cv::Mat disparity(20, 40, CV_32F), score(20, 40, CV_32F, cv::Scalar(0.5));
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) disparity.at<float>(y, x) = 5.0F + 0.4F * x;
  }
  // An unmatched gap inside it is no step either.
  disparity(cv::Rect(15, 5, 4, 6)).setTo(kNaN);
  score(cv::Rect(15, 5, 4, 6)).setTo(kNaN);
  WeakMatchSettings settings;
  settings.threads = 2;
  EXPECT_EQ(rejectWeakMatchesBesideSteps(settings, kFillScore, disparity, score), 0);
}

TEST(RejectWeakMatchesBesideSteps, TheSameOnAnyNumberOfThreads) {
  cv::Mat disparity(97, 61, CV_32F), score(97, 61, CV_32F);
  cv::RNG rng(7);
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      disparity.at<float>(y, x) = (x / 9 + y / 11) % 2 ? 25.0F : 8.0F;
      score.at<float>(y, x) = static_cast<float>(rng.uniform(0.3, 1.0));
    }
  }
  cv::Mat d1 = disparity.clone(), s1 = score.clone(), d2 = disparity.clone(), s2 = score.clone();
  WeakMatchSettings settings;
  const int one = rejectWeakMatchesBesideSteps(settings, kFillScore, d1, s1);
  settings.threads = 3;
  EXPECT_EQ(rejectWeakMatchesBesideSteps(settings, kFillScore, d2, s2), one);
  EXPECT_GT(one, 0);
  expectSameBits(d1, d2);
}

TEST(RejectWeakMatchesBesideSteps, OnlyCandidatesAreRejectedWhenAMaskIsGiven) {
  // The wider pass over plain pixels: radius 7, only the pixels of the mask.
  StepScene s;
  s.score.at<float>(10, 14) = 0.5F;  // weak, 6 px from the step, plain: rejected
  s.score.at<float>(12, 14) = 0.5F;  // weak, 6 px from the step, textured: kept
  s.score.at<float>(14, 11) = 0.5F;  // weak, plain, 9 px from the step: kept
  cv::Mat plain = cv::Mat::zeros(s.disparity.size(), CV_8U);
  plain.at<uchar>(10, 14) = 255;
  plain.at<uchar>(14, 11) = 255;
  WeakMatchSettings settings;
  settings.minScore = 0.6;
  settings.radius = 7;
  EXPECT_EQ(rejectWeakMatchesBesideSteps(settings, kFillScore, s.disparity, s.score, plain), 1);
  EXPECT_TRUE(std::isnan(s.disparity.at<float>(10, 14)));
  EXPECT_EQ(s.disparity.at<float>(12, 14), 10.0F);
  EXPECT_EQ(s.disparity.at<float>(14, 11), 10.0F);
  // Without the mask the textured one goes too.
  EXPECT_EQ(rejectWeakMatchesBesideSteps(settings, kFillScore, s.disparity, s.score), 1);
  EXPECT_TRUE(std::isnan(s.disparity.at<float>(12, 14)));
}

TEST(RejectWeakMatchesBesideSteps, ThePlainPassIsAParameterBetweenZeroAndOne) {
  MatchParams p;
  EXPECT_DOUBLE_EQ(p.plainStepMinScore, 0.6);
  p.plainStepMinScore = 1.2;
  EXPECT_THROW(p.validate(), std::exception);
  p.plainStepMinScore = 0;
  EXPECT_NO_THROW(p.validate());
}

TEST(RejectWeakMatchesBesideSteps, ItsParameterIsAScoreBetweenZeroAndOne) {
  MatchParams p;
  EXPECT_DOUBLE_EQ(p.stepMinScore, 0.8);
  p.stepMinScore = 1.5;
  EXPECT_THROW(p.validate(), std::exception);
  p.stepMinScore = -0.1;
  EXPECT_THROW(p.validate(), std::exception);
  p.stepMinScore = 0;
  EXPECT_NO_THROW(p.validate());
}

// A plain scene (every pixel plain) of ground at 10 scoring 0.9, with a plain roof left unmatched
// in (20..49, 10..29): 600 px.
struct UnmatchedRoofScene {
  cv::Mat disparity{40, 70, CV_32F, cv::Scalar(10.0)};
  cv::Mat score{40, 70, CV_32F, cv::Scalar(0.9)};
  cv::Mat plain{40, 70, CV_8U, cv::Scalar(255)};
  UnmatchedRoofScene() {
    disparity(cv::Rect(20, 10, 30, 20)).setTo(kNaN);
    score(cv::Rect(20, 10, 30, 20)).setTo(kNaN);
  }
};

TEST(RejectWeakMatchesBesideUnmatchedPlain, RejectsWeakPlainMatchesWithinTheRadiusOfALargeRegion) {
  UnmatchedRoofScene s;
  s.score.at<float>(12, 50) = 0.4F;        // weak, plain, 1 px beside the region: rejected
  s.score.at<float>(20, 54) = 0.4F;        // 5 px beside it: rejected
  s.score.at<float>(20, 55) = 0.4F;        // 6 px: kept
  s.score.at<float>(5, 30) = 0.6F;         // 5 px above it, but not weak: kept
  s.score.at<float>(31, 30) = kFillScore;  // filled, not matched: kept
  s.score.at<float>(32, 25) = 0.4F;        // weak beside it, but textured: kept
  s.plain.at<uchar>(32, 25) = 0;
  UnmatchedPlainSettings settings;
  EXPECT_EQ(
      rejectWeakMatchesBesideUnmatchedPlain(settings, kFillScore, s.plain, s.disparity, s.score),
      2);
  EXPECT_TRUE(std::isnan(s.disparity.at<float>(12, 50)));
  EXPECT_TRUE(std::isnan(s.score.at<float>(20, 54)));
  EXPECT_EQ(s.disparity.at<float>(20, 55), 10.0F);
  EXPECT_EQ(s.disparity.at<float>(5, 30), 10.0F);
  EXPECT_EQ(s.disparity.at<float>(31, 30), 10.0F);
  EXPECT_EQ(s.disparity.at<float>(32, 25), 10.0F);
}

TEST(RejectWeakMatchesBesideUnmatchedPlain, SmallOrTexturedUnmatchedRegionsAndZeroLeaveAll) {
  UnmatchedRoofScene s;
  s.score.at<float>(12, 50) = 0.4F;
  UnmatchedPlainSettings settings;
  settings.minArea = 601;  // the region has 600 px
  EXPECT_EQ(
      rejectWeakMatchesBesideUnmatchedPlain(settings, kFillScore, s.plain, s.disparity, s.score),
      0);
  settings.minArea = 500;
  cv::Mat textured = s.plain.clone();
  textured(cv::Rect(20, 10, 30, 20)).setTo(0);  // unmatched but not plain: not such a region
  EXPECT_EQ(
      rejectWeakMatchesBesideUnmatchedPlain(settings, kFillScore, textured, s.disparity, s.score),
      0);
  settings.minScore = 0;
  EXPECT_EQ(
      rejectWeakMatchesBesideUnmatchedPlain(settings, kFillScore, s.plain, s.disparity, s.score),
      0);
  EXPECT_EQ(s.disparity.at<float>(12, 50), 10.0F);
}

TEST(RejectWeakMatchesBesideUnmatchedPlain, TheSameOnAnyNumberOfThreads) {
  cv::Mat disparity(97, 61, CV_32F), score(97, 61, CV_32F), plain(97, 61, CV_8U);
  cv::RNG rng(11);
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      const bool hole = (x / 25 + y / 30) % 2 == 1;
      disparity.at<float>(y, x) = hole ? kNaN : 12.0F;
      score.at<float>(y, x) = static_cast<float>(rng.uniform(0.3, 1.0));
      plain.at<uchar>(y, x) = rng.uniform(0, 4) > 0 ? 255 : 0;
    }
  }
  cv::Mat d1 = disparity.clone(), s1 = score.clone(), d2 = disparity.clone(), s2 = score.clone();
  UnmatchedPlainSettings settings;
  settings.minArea = 100;
  const int one = rejectWeakMatchesBesideUnmatchedPlain(settings, kFillScore, plain, d1, s1);
  settings.threads = 3;
  EXPECT_EQ(rejectWeakMatchesBesideUnmatchedPlain(settings, kFillScore, plain, d2, s2), one);
  EXPECT_GT(one, 0);
  expectSameBits(d1, d2);
}

TEST(RejectWeakMatchesBesideUnmatchedPlain, ItsParameterIsAScoreBetweenZeroAndOne) {
  MatchParams p;
  EXPECT_DOUBLE_EQ(p.unmatchedPlainMinScore, 0.5);
  p.unmatchedPlainMinScore = 1.1;
  EXPECT_THROW(p.validate(), std::exception);
  p.unmatchedPlainMinScore = -0.2;
  EXPECT_THROW(p.validate(), std::exception);
  p.unmatchedPlainMinScore = 0;
  EXPECT_NO_THROW(p.validate());
}

}  // namespace
}  // namespace delineo::stereo::detail
