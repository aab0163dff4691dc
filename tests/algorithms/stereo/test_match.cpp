#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/stereo/match.hpp"
#include "synthetic.hpp"

namespace delineo::stereo {
namespace {

using testing::shiftedRight;
using testing::squareScene;
using testing::texture;

struct Stats {
  double density = 0, meanAbsError = 0, maxAbsError = 0;
};

Stats compare(const cv::Mat& disparity, double truth, int border) {
  Stats s;
  int valid = 0, total = 0;
  for (int y = border; y < disparity.rows - border; ++y) {
    for (int x = border; x < disparity.cols - border; ++x) {
      ++total;
      const float d = disparity.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      ++valid;
      const double e = std::abs(d - truth);
      s.meanAbsError += e;
      s.maxAbsError = std::max(s.maxAbsError, e);
    }
  }
  s.density = static_cast<double>(valid) / total;
  if (valid > 0) s.meanAbsError /= valid;
  return s;
}

TEST(Match, SubPixelShiftIsRecovered) {
  const cv::Mat left = texture({160, 120}, 21);
  const cv::Mat right = shiftedRight(left, 3.3);
  MatchParams p;
  p.dmin = -4;
  p.dmax = 12;
  const MatchResult r = matchStereo(left, right, p);
  ASSERT_EQ(r.status, core::RunStatus::Completed);
  ASSERT_EQ(r.disparity.type(), CV_32F);
  ASSERT_EQ(r.disparity.size(), left.size());
  const Stats s = compare(r.disparity, 3.3, 20);
  EXPECT_GT(s.density, 0.95);
  EXPECT_LT(s.meanAbsError, 0.1);
  EXPECT_LT(s.maxAbsError, 1.0);
  // Score is the NCC of the retained match: high on a clean shift.
  EXPECT_GT(r.score.at<float>(60, 80), 0.9F);
}

TEST(Match, NegativeDisparitiesAndMultiResolution) {
  const cv::Mat left = texture({256, 160}, 22);
  const cv::Mat right = shiftedRight(left, -17.6);
  MatchParams p;
  p.dmin = -40;
  p.dmax = 30;
  const MatchResult r = matchStereo(left, right, p);
  EXPECT_EQ(r.levelsUsed, autoLevels(-40, 30));
  EXPECT_EQ(r.levelsUsed, 3);
  const Stats s = compare(r.disparity, -17.6, 24);
  EXPECT_GT(s.density, 0.9);
  EXPECT_LT(s.meanAbsError, 0.15);
}

TEST(Match, AdaptiveShapesMatchTheImageBorder) {
  // Rows within the window radius of the top and bottom borders: a square window leaves the
  // image there, an adaptive shape stops at the border.
  const cv::Mat left = texture({160, 120}, 27);
  const cv::Mat right = shiftedRight(left, 3.3);
  MatchParams p;
  p.dmin = -4;
  p.dmax = 12;
  const int r = p.window / 2;
  auto borderStats = [&](const MatchResult& res) {
    int matched = 0, total = 0;
    double error = 0;
    for (int y = 0; y < left.rows; ++y) {
      if (y >= r && y < left.rows - r) continue;
      for (int x = 20; x < left.cols - 20; ++x) {
        ++total;
        const float d = res.disparity.at<float>(y, x);
        if (!std::isfinite(d)) continue;
        ++matched;
        error += std::abs(d - 3.3);
      }
    }
    return std::pair{static_cast<double>(matched) / total, matched ? error / matched : 0.0};
  };
  const auto [density, meanError] = borderStats(matchStereo(left, right, p));
  EXPECT_GT(density, 0.8);
  EXPECT_LT(meanError, 0.2);
  p.adaptive = false;
  EXPECT_EQ(borderStats(matchStereo(left, right, p)).first, 0.0);
}

TEST(Match, LineShiftAbsorbsAVerticalOffset) {
  // Residual rectification error: the right image is also one line lower.
  const cv::Mat left = texture({160, 120}, 28, 0.7);  // fine texture: one line matters
  const cv::Mat shifted = shiftedRight(left, 4.0);
  cv::Mat right;
  const cv::Mat down = (cv::Mat_<double>(2, 3) << 1, 0, 0, 0, 1, 1);
  cv::warpAffine(shifted, right, down, shifted.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  MatchParams p;
  p.dmin = -4;
  p.dmax = 12;
  const Stats withShift = compare(matchStereo(left, right, p).disparity, 4.0, 20);
  EXPECT_GT(withShift.density, 0.85);
  EXPECT_LT(withShift.meanAbsError, 0.08);
  // Without the line search the one-line misregistration biases the sub-pixel peaks
  // (measured: mean error 0.15 vs 0.05 px).
  p.lineShift = 0;
  const Stats without = compare(matchStereo(left, right, p).disparity, 4.0, 20);
  EXPECT_GT(without.meanAbsError, 2.0 * withShift.meanAbsError);
}

TEST(Match, AutoLevelsFollowsThePaper) {
  EXPECT_EQ(autoLevels(0, 10), 1);
  EXPECT_EQ(autoLevels(0, 20), 1);
  EXPECT_EQ(autoLevels(0, 40), 2);
  EXPECT_EQ(autoLevels(0, 60), 3);
  EXPECT_EQ(autoLevels(-20, 236), 5);
}

TEST(Match, ValidationRejectsTheOccludedStrip) {
  const auto scene = squareScene({160, 120}, cv::Rect(60, 30, 60, 60), 2, 14);
  MatchParams p;
  p.dmin = 0;
  p.dmax = 20;
  const MatchResult r = matchStereo(scene.left, scene.right, p);
  int occluded = 0, occludedRejected = 0, visible = 0, visibleGood = 0;
  for (int y = 10; y < scene.left.rows - 10; ++y) {
    for (int x = 25; x < scene.left.cols - 10; ++x) {
      const float d = r.disparity.at<float>(y, x);
      if (scene.occluded.at<uchar>(y, x)) {
        ++occluded;
        if (!std::isfinite(d)) ++occludedRejected;
      } else {
        ++visible;
        if (std::isfinite(d) && std::abs(d - scene.truth.at<float>(y, x)) < 1.0F) ++visibleGood;
      }
    }
  }
  ASSERT_GT(occluded, 500);
  EXPECT_GT(static_cast<double>(occludedRejected) / occluded, 0.9);
  EXPECT_GT(static_cast<double>(visibleGood) / visible, 0.85);
}

// Matches that keep the coarser level's check (coarse-check-score, on by default) lie on smooth
// surfaces: the occluded strip is still rejected, and the rest of the map is nearly the one that
// checking every match at full resolution gives.
TEST(Match, KeepingTheCoarserCheckOnSmoothSurfacesChangesLittle) {
  const auto scene = squareScene({160, 120}, cv::Rect(60, 30, 60, 60), 2, 14);
  MatchParams p;
  p.dmin = 0;
  p.dmax = 20;
  p.levels = 2;  // the check is kept from a coarser level (auto gives one level for 20 px)
  ASSERT_GT(p.coarseCheckScore, 0.0);
  const MatchResult kept = matchStereo(scene.left, scene.right, p);
  p.coarseCheckScore = 0;
  const MatchResult all = matchStereo(scene.left, scene.right, p);
  int occluded = 0, keptRejected = 0, matched = 0, same = 0;
  for (int y = 10; y < scene.left.rows - 10; ++y) {
    for (int x = 25; x < scene.left.cols - 10; ++x) {
      const float a = kept.disparity.at<float>(y, x), b = all.disparity.at<float>(y, x);
      if (scene.occluded.at<uchar>(y, x)) {
        ++occluded;
        keptRejected += !std::isfinite(a);
        continue;
      }
      if (!std::isfinite(a) && !std::isfinite(b)) continue;
      ++matched;
      same += std::abs(a - b) <= 0.05F;
    }
  }
  ASSERT_GT(occluded, 500);
  EXPECT_GT(static_cast<double>(keptRejected) / occluded, 0.9);
  // (Measured: 716 of 720 occluded pixels rejected, 11 030 of 11 285 matched pixels unchanged.)
  EXPECT_GT(static_cast<double>(same) / matched, 0.95) << same << " of " << matched;
  // Not the same map either: matches the full-resolution check would have rejected are kept.
  EXPECT_LT(same, matched);
}

// Matched pixels within `band` px of the square's vertical outline: how many, and how many
// are off by more than 1 px (a step drawn at the wrong place).
struct OutlineStats {
  int matched = 0, wrong = 0, total = 0;
};

OutlineStats outlineStats(const MatchResult& r, const testing::SquareScene& s, int band) {
  OutlineStats o;
  for (int y = s.square.y + 5; y < s.square.br().y - 5; ++y) {
    for (int x = s.square.x - band; x < s.square.br().x + band; ++x) {
      const bool nearOutline =
          std::abs(x - s.square.x) < band || std::abs(x - s.square.br().x) < band;
      if (!nearOutline || s.occluded.at<uchar>(y, x)) continue;
      ++o.total;
      const float d = r.disparity.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      ++o.matched;
      if (std::abs(d - s.truth.at<float>(y, x)) > 1.0F) ++o.wrong;
    }
  }
  return o;
}

TEST(Match, AdaptiveShapesKeepTheOutlineSharperThanSquareWindows) {
  const auto scene = squareScene({160, 120}, cv::Rect(60, 30, 60, 60), 2, 14);
  MatchParams p;
  p.dmin = 0;
  p.dmax = 20;
  const OutlineStats adaptive = outlineStats(matchStereo(scene.left, scene.right, p), scene, 7);
  p.adaptive = false;
  const OutlineStats square = outlineStats(matchStereo(scene.left, scene.right, p), scene, 7);
  // Square windows fatten the foreground by about half a window; adaptive shapes do not.
  EXPECT_GT(square.wrong, square.total / 5);
  EXPECT_LT(adaptive.wrong * 5, square.wrong) << adaptive.wrong << " vs " << square.wrong;
  EXPECT_GT(adaptive.matched, adaptive.total * 7 / 10);
}

// A textured block 12 px above its background with the SAME brightness and texture amplitude
// (no contour at its outline, as on half of the simulated roof outlines), plus noise.
testing::SquareScene contourlessBlock() {
  return testing::squareScene({160, 120}, {60, 30, 60, 60}, 2, 14, 11, /*squareLevel=*/30.0,
                              /*noiseSigma=*/2.0);
}

// Rows whose +x outline (the side whose ground both views see) is located within 1 px: the
// first pixel walking from the ground towards the block whose disparity is on the block's side
// of the mid-level is the true outline or its neighbour.
int locatedOutlineRows(const MatchResult& r, const testing::SquareScene& s) {
  int located = 0;
  const int xb = s.square.br().x - 1;  // last block pixel
  for (int y = s.square.y + 3; y < s.square.br().y - 3; ++y) {
    for (int x = xb + 8; x >= xb - 8; --x) {
      const float d = r.disparity.at<float>(y, x);
      if (!std::isfinite(d) || d < 8.0F) continue;
      if (std::abs(x - xb) <= 1) ++located;
      break;
    }
  }
  return located;
}

// A textureless roof (flat grey 200 with noise sigma 2) on textured ground; `rightShowsIt`
// false: a flat patch only the left image has.
using FlatRoofScene = testing::FlatRoofPair;

FlatRoofScene flatRoofScene(bool rightShowsIt) {
  return testing::flatRoofPair(rightShowsIt, 200.0f, 2.0, 21, 9);
}

// Share of the roof's interior (8 px from its outline) with a disparity, and of those within
// 1 px of `expected`.
std::pair<double, double> interiorMatches(const MatchResult& r, cv::Rect roof, float expected) {
  const cv::Rect inner(roof.x + 8, roof.y + 8, roof.width - 16, roof.height - 16);
  double matched = 0, right = 0;
  for (int y = inner.y; y < inner.br().y; ++y) {
    for (int x = inner.x; x < inner.br().x; ++x) {
      const float d = r.disparity.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      ++matched;
      if (std::abs(d - expected) <= 1.0f) ++right;
    }
  }
  return {matched / inner.area(), matched > 0 ? right / matched : 0.0};
}

MatchResult matchFlatRoof(const FlatRoofScene& scene, bool fill) {
  MatchParams p;
  p.dmin = 0;
  p.dmax = 32;
  p.fillRegions = fill;
  return matchStereo(scene.left, scene.right, p);
}

TEST(Match, FillsATexturelessRoofFromItsOutline) {
  const auto scene = flatRoofScene(true);
  const auto [plainShare, plainRight] =
      interiorMatches(matchFlatRoof(scene, false), scene.roof, 20);
  const MatchResult filled = matchFlatRoof(scene, true);
  const auto [share, right] = interiorMatches(filled, scene.roof, 20);
  // NCC of noise leaves the interior unmatched; the outline's matches and grey levels fix it.
  EXPECT_LT(plainShare, 0.3) << plainRight;
  EXPECT_GT(share, 0.95);
  EXPECT_GT(right, 0.99);
  // Filled pixels carry the minimum score, not a correlation they did not have.
  const cv::Point centre(scene.roof.x + 25, scene.roof.y + 20);
  EXPECT_FLOAT_EQ(filled.score.at<float>(centre), static_cast<float>(MatchParams{}.minScore));
}

TEST(Match, DoesNotFillAFlatPatchTheRightViewDoesNotShow) {
  const auto scene = flatRoofScene(false);
  const auto [share, right] = interiorMatches(matchFlatRoof(scene, true), scene.roof, 20);
  EXPECT_LT(share, 0.3) << right;
}

TEST(Match, StepCutLocatesAnOutlineWithoutContour) {
  const auto scene = contourlessBlock();
  MatchParams p;
  p.dmin = 0;
  p.dmax = 20;
  p.snapSteps = false;  // the step cut alone
  p.stepMinScore = 0;   // (the weak matches it rejects are closed by the snapping only)
  const MatchResult cut = matchStereo(scene.left, scene.right, p);
  p.stepCut = false;
  const MatchResult plain = matchStereo(scene.left, scene.right, p);
  const int rows = scene.square.height - 6;
  const int withCut = locatedOutlineRows(cut, scene);
  const int without = locatedOutlineRows(plain, scene);
  // Without a contour the window straddling the step misplaces most of the outline; cut at the
  // step located along the row, the block keeps its matches up to its true edge.
  EXPECT_LT(without, rows / 2) << without << " of " << rows;
  EXPECT_GT(withCut, rows * 6 / 10) << withCut << " of " << rows;
  EXPECT_GT(withCut, 2 * without) << withCut << " vs " << without;
  // And the occluded strip on the other side stays rejected.
  int occluded = 0, occludedRejected = 0;
  for (int y = 0; y < scene.left.rows; ++y) {
    for (int x = 0; x < scene.left.cols; ++x) {
      if (!scene.occluded.at<uchar>(y, x)) continue;
      ++occluded;
      if (!std::isfinite(cut.disparity.at<float>(y, x))) ++occludedRejected;
    }
  }
  EXPECT_GT(occludedRejected, occluded * 8 / 10) << occludedRejected << " of " << occluded;
}

TEST(Match, StepCutGivesTheSameMapOnAnyNumberOfThreads) {
  // The step cut runs on the matcher's own workers (threads = 1: the calling thread only);
  // rows are independent, so the map must not depend on how they are shared out.
  const auto scene = contourlessBlock();
  MatchParams p;
  p.dmin = 0;
  p.dmax = 20;
  p.threads = 1;
  const MatchResult one = matchStereo(scene.left, scene.right, p);
  p.threads = 3;
  const MatchResult three = matchStereo(scene.left, scene.right, p);
  ASSERT_EQ(one.disparity.size(), three.disparity.size());
  long differing = 0, matched = 0;
  for (int y = 0; y < one.disparity.rows; ++y) {
    for (int x = 0; x < one.disparity.cols; ++x) {
      const float a = one.disparity.at<float>(y, x), b = three.disparity.at<float>(y, x);
      if (std::isfinite(a)) ++matched;
      if (std::isfinite(a) != std::isfinite(b) || (std::isfinite(a) && a != b)) ++differing;
    }
  }
  EXPECT_GT(matched, one.disparity.total() / 2);
  EXPECT_EQ(differing, 0);
}

TEST(Match, MultiLevelMapIsBitIdenticalOnOneAndTwoThreads) {
  // Every step of the driver (preparation, Canny, validation, intervals, step cut) runs on the
  // level's threads; each task writes its own rows, so 1 and 2 threads give the same bits.
  const auto scene = contourlessBlock();
  cv::Mat left, right;
  // Several pyramid levels and many row bands: the block scene doubled, range over 20 px.
  cv::resize(scene.left, left, {}, 2.0, 2.0, cv::INTER_CUBIC);
  cv::resize(scene.right, right, {}, 2.0, 2.0, cv::INTER_CUBIC);
  MatchParams p;
  p.dmin = -8;
  p.dmax = 48;
  p.threads = 1;
  const MatchResult one = matchStereo(left, right, p);
  p.threads = 2;
  const MatchResult two = matchStereo(left, right, p);
  ASSERT_GT(one.levelsUsed, 1);
  ASSERT_EQ(one.disparity.size(), two.disparity.size());
  long matched = 0;
  for (int y = 0; y < one.disparity.rows; ++y) {
    for (int x = 0; x < one.disparity.cols; ++x) {
      if (std::isfinite(one.disparity.at<float>(y, x))) ++matched;
    }
  }
  EXPECT_GT(matched, static_cast<long>(one.disparity.total() / 2));
  const size_t bytes = one.disparity.total() * sizeof(float);
  EXPECT_EQ(std::memcmp(one.disparity.data, two.disparity.data, bytes), 0);
  EXPECT_EQ(std::memcmp(one.score.data, two.score.data, bytes), 0);
}

TEST(Match, SgbmFollowsTheSameConventions) {
  const cv::Mat left = texture({200, 120}, 23);
  const cv::Mat right = shiftedRight(left, -6.0);
  MatchParams p;
  p.method = "sgbm";
  p.dmin = -20;
  p.dmax = 10;
  const MatchResult r = matchStereo(left, right, p);
  ASSERT_EQ(r.disparity.type(), CV_32F);
  const Stats s = compare(r.disparity, -6.0, 30);
  EXPECT_GT(s.density, 0.8);
  EXPECT_LT(s.meanAbsError, 0.3);
  EXPECT_GT(r.score.at<float>(60, 100), 0.8F);
}

// The two maps agree on what is unmatched, for both backends (the NaN masks are taken over
// whole rows, wide enough for OpenCV's vectorised comparisons).
TEST(Match, ScoreIsNaNExactlyWhereDisparityIsNaN) {
  const cv::Mat left = texture({240, 140}, 31);
  cv::Mat right = shiftedRight(left, 4.0);
  texture({60, 50}, 32).copyTo(right(cv::Rect(90, 40, 60, 50)));  // seen by the right view only
  for (const char* method : {"adaptive", "sgbm"}) {
    MatchParams p;
    p.method = method;
    p.dmin = -8;
    p.dmax = 16;
    const MatchResult r = matchStereo(left, right, p);
    ASSERT_EQ(r.status, core::RunStatus::Completed);
    int unmatched = 0, disagree = 0;
    for (int y = 0; y < r.disparity.rows; ++y) {
      for (int x = 0; x < r.disparity.cols; ++x) {
        const bool noDisparity = std::isnan(r.disparity.at<float>(y, x));
        unmatched += noDisparity ? 1 : 0;
        disagree += noDisparity != std::isnan(r.score.at<float>(y, x)) ? 1 : 0;
      }
    }
    EXPECT_GT(unmatched, 500) << method;  // the foreign patch and the borders
    EXPECT_EQ(disagree, 0) << method;
  }
}

// A textured pair shifted by 5 px, matched on one thread: the progress reports come in the same
// order on every run, so a cancel can be aimed at one of them.
struct CancelCase {
  cv::Mat left, right;
  MatchParams params;
};
CancelCase cancelCase() {
  CancelCase c;
  c.left = texture({200, 160}, 24);
  c.right = shiftedRight(c.left, 5.0);
  c.params.dmin = 0;
  c.params.dmax = 40;
  c.params.threads = 1;
  return c;
}

TEST(Match, CancelMidRun) {
  const auto [left, right, p] = cancelCase();
  core::Progress progress;
  progress.cancelAfterReports(3);
  const MatchResult r = matchStereo(left, right, p, &progress);
  EXPECT_EQ(r.status, core::RunStatus::Canceled);
  EXPECT_TRUE(r.disparity.empty());
  // An uncanceled run reports monotone progress up to 1.
  core::Progress full;
  EXPECT_EQ(matchStereo(left, right, p, &full).status, core::RunStatus::Completed);
  EXPECT_GT(full.reportCount(), 3);
  EXPECT_DOUBLE_EQ(full.fraction(), 1.0);
}

TEST(Match, TheStepsAfterTheLevelsReportProgressAndHonourACancel) {
  const auto [left, right, p] = cancelCase();
  std::vector<double> fractions;
  core::Progress full([&](double fraction, const std::string&) { fractions.push_back(fraction); });
  ASSERT_EQ(matchStereo(left, right, p, &full).status, core::RunStatus::Completed);
  // The levels end at 80 %; the fill, speckles and snapping report the rest.
  int afterLevels = 0;
  for (const double f : fractions) afterLevels += f > 0.8 && f < 1.0 ? 1 : 0;
  EXPECT_GE(afterLevels, 3);
  EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
  // Canceled on the last report but one (after the snapping and the smoothing, before the roof
  // planes): no result.
  core::Progress late;
  late.cancelAfterReports(full.reportCount() - 1);
  const MatchResult r = matchStereo(left, right, p, &late);
  EXPECT_EQ(r.status, core::RunStatus::Canceled);
  EXPECT_TRUE(r.disparity.empty());
}

TEST(Match, BadInputsThrow) {
  const cv::Mat a = texture({60, 40}, 25);
  const cv::Mat b = texture({61, 40}, 26);
  MatchParams p;
  EXPECT_THROW(matchStereo(a, b, p), core::Error);
  p.dmin = 5;
  p.dmax = 4;
  EXPECT_THROW(matchStereo(a, a, p), core::Error);
  p = MatchParams{};
  p.window = 8;
  EXPECT_THROW(matchStereo(a, a, p), core::Error);
  p = MatchParams{};
  p.method = "census";
  EXPECT_THROW(matchStereo(a, a, p), core::Error);
  EXPECT_THROW(matchStereo(cv::Mat(), a, MatchParams{}), core::Error);
  cv::Mat bytes;
  a.convertTo(bytes, CV_8U);
  EXPECT_THROW(matchStereo(bytes, bytes, MatchParams{}), core::Error);
}

}  // namespace
}  // namespace delineo::stereo
