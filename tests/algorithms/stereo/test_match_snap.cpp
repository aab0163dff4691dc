// Depth steps moved onto the left image's contour (internal snapStepsToContours).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core.hpp>

#include "match_snap.hpp"
#include "synthetic.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Ground grey 100, a roof [40, 70) grey 160 on every row, noise sigma 1.
cv::Mat roofImage(bool withContour) {
  cv::Mat left(20, 120, CV_32F, cv::Scalar(100));
  if (withContour) left(cv::Rect(40, 0, 30, 20)).setTo(160);
  cv::Mat noise(left.size(), CV_32F);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::NORMAL, 0, 1);
  return left + noise;
}

// Textured ground (grey 100 ± 12, lightly blurred) of rows × cols, flat (100) on its first
// `flatCols` columns: where the noise level is read. `rng` goes on to the views' noise.
cv::Mat texturedGround(int rows, int cols, int flatCols, cv::RNG& rng) {
  cv::Mat ground(rows, cols, CV_32F);
  rng.fill(ground, cv::RNG::NORMAL, 100, 12);
  cv::GaussianBlur(ground, ground, {0, 0}, 0.7);
  ground.colRange(0, flatCols).setTo(100);
  return ground;
}

// Every row: d on [x0, x1), NaN elsewhere unless already set.
void setRun(cv::Mat& disparity, int x0, int x1, float d) {
  disparity(cv::Rect(x0, 0, x1 - x0, disparity.rows)).setTo(d);
}

TEST(SnapSteps, ExtendsAShortNearSideToTheContour) {
  // Roof's +x edge at x = 70: the roof is matched up to 65, the ground from 75.
  cv::Mat disparity(20, 120, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 40, 66, 20.0f);
  setRun(disparity, 75, 120, 5.0f);
  const int changed =
      snapStepsToContours(roofImage(true), cv::Mat(), StepSnapSettings{}, 0.3f, disparity, score);
  EXPECT_EQ(changed, 4 * 20);
  for (int x = 66; x < 70; ++x) EXPECT_FLOAT_EQ(disparity.at<float>(10, x), 20.0f) << x;
  for (int x = 70; x < 75; ++x) EXPECT_TRUE(std::isnan(disparity.at<float>(10, x))) << x;
}

TEST(SnapSteps, CutsANearSideThatRunsOverTheContour) {
  // Roof's -x edge at x = 40 (near side on the right): ground matched up to 34, the roof's value
  // spread over 37..39 (fattening, within `reach`); its +x edge: roof value on 70..72, ground
  // from 73.
  cv::Mat disparity(20, 120, CV_32F, cv::Scalar(kNaN)), score(20, 120, CV_32F, cv::Scalar(0.9));
  setRun(disparity, 0, 35, 5.0f);
  setRun(disparity, 37, 73, 20.0f);
  setRun(disparity, 73, 120, 5.0f);
  snapStepsToContours(roofImage(true), cv::Mat(), StepSnapSettings{}, 0.3f, disparity, score);
  for (int x = 35; x < 40; ++x) EXPECT_TRUE(std::isnan(disparity.at<float>(10, x))) << x;
  for (int x = 40; x < 70; ++x) EXPECT_FLOAT_EQ(disparity.at<float>(10, x), 20.0f) << x;
  for (int x = 70; x < 73; ++x) {
    EXPECT_TRUE(std::isnan(disparity.at<float>(10, x))) << x;
    EXPECT_TRUE(std::isnan(score.at<float>(10, x))) << x;
  }
  EXPECT_FLOAT_EQ(disparity.at<float>(10, 73), 5.0f);  // the far side is left alone
  EXPECT_FLOAT_EQ(disparity.at<float>(10, 34), 5.0f);
}

TEST(SnapSteps, LeavesStepsWithoutAContourAndSmallDifferencesAlone) {
  cv::Mat disparity(20, 120, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 40, 66, 20.0f);
  setRun(disparity, 75, 120, 5.0f);
  const cv::Mat before = disparity.clone();
  // Noise only: no contour strong enough.
  EXPECT_EQ(
      snapStepsToContours(roofImage(false), cv::Mat(), StepSnapSettings{}, 0.3f, disparity, score),
      0);
  // A contour, but 1.5 px of disparity is a slope, not a step.
  setRun(disparity, 75, 120, 18.5f);
  EXPECT_EQ(
      snapStepsToContours(roofImage(true), cv::Mat(), StepSnapSettings{}, 0.3f, disparity, score),
      0);
  // A gap wider than maxGap.
  cv::Mat wide(20, 120, CV_32F, cv::Scalar(kNaN));
  setRun(wide, 40, 50, 20.0f);
  setRun(wide, 75, 120, 5.0f);
  EXPECT_EQ(snapStepsToContours(roofImage(true), cv::Mat(), StepSnapSettings{}, 0.3f, wide, score),
            0);
  EXPECT_EQ(cv::countNonZero(before(cv::Rect(0, 0, 75, 20)) == disparity(cv::Rect(0, 0, 75, 20))),
            cv::countNonZero(before(cv::Rect(0, 0, 75, 20)) == before(cv::Rect(0, 0, 75, 20))));
}

// A stereo pair: ground (grey 100, textured with sigma 10 right of the roof) at disparity 5, a
// uniform roof [40, 70) grey 160 at disparity 20, a bright line on the ground at x = 79 whose
// contrast beats the roof edge's, and noise sigma 1 in each view.
struct TexturedPair {
  cv::Mat left, right;
};

TexturedPair texturedPair() {
  cv::Mat ground(20, 160, CV_32F);
  cv::RNG rng(5);
  rng.fill(ground, cv::RNG::NORMAL, 100, 10);
  ground.colRange(0, 60).setTo(100);  // flat left of the roof: where the noise level is read
  ground.col(79 + 20).setTo(255);     // ground is indexed x + 20 in the left view
  TexturedPair p;
  p.left.create(20, 120, CV_32F);
  p.right.create(20, 120, CV_32F);
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 120; ++x) {
      p.left.at<float>(y, x) = x >= 40 && x < 70 ? 160.0f : ground.at<float>(y, x + 20);
      const bool roof = x + 20 >= 40 && x + 20 < 70;
      p.right.at<float>(y, x) = roof ? 160.0f : ground.at<float>(y, x + 5 + 20);
    }
  }
  testing::addSensorNoise(p.left, p.right, 1.0, rng);
  return p;
}

TEST(SnapSteps, ChecksEachChangedPixelAgainstTheRightView) {
  const TexturedPair pair = texturedPair();
  // +x edge at x = 70: roof matched up to 65, ground from 76; the strongest contrast in reach is
  // the ground's bright line (78|79 and 79|80), not the roof edge.
  cv::Mat disparity(20, 120, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 40, 66, 20.0f);
  setRun(disparity, 76, 120, 5.0f);
  cv::Mat unchecked = disparity.clone();
  snapStepsToContours(pair.left, cv::Mat(), StepSnapSettings{}, 0.3f, unchecked, score);
  EXPECT_FLOAT_EQ(unchecked.at<float>(10, 71), 20.0f);  // the roof carried onto the ground
  snapStepsToContours(pair.left, pair.right, StepSnapSettings{}, 0.3f, disparity, score);
  // Checked: the roof pixels are taken, the ground ones do not match at the roof's disparity.
  for (int x = 66; x < 70; ++x) EXPECT_FLOAT_EQ(disparity.at<float>(10, x), 20.0f) << x;
  for (int x = 70; x < 76; ++x) EXPECT_TRUE(std::isnan(disparity.at<float>(10, x))) << x;

  // Cut (the line out of reach): the roof's value spread over ground pixels 70..72 is cut, the
  // ground's disparity explaining them better.
  cv::Mat spread(20, 120, CV_32F, cv::Scalar(kNaN));
  setRun(spread, 40, 73, 20.0f);
  setRun(spread, 73, 120, 5.0f);
  snapStepsToContours(pair.left, pair.right, StepSnapSettings{}, 0.3f, spread, score);
  for (int x = 40; x < 70; ++x) EXPECT_FLOAT_EQ(spread.at<float>(10, x), 20.0f) << x;
  for (int x = 70; x < 73; ++x) EXPECT_TRUE(std::isnan(spread.at<float>(10, x))) << x;
}

// A roof of nearly the ground's grey (110 against textured ground 100 ± 12) at disparity 20
// over ground at 5, noise sigma 2; its value fattened 5 px onto the ground, as window matching
// leaves it next to textured ground. Texture contrasts on the ground beat the roof edge's in
// most rows: the cut must come from the two views, not from the strongest contrast.
TEST(SnapSteps, CutsAFattenedLowContrastRoofWhereTheViewsDisagree) {
  const int rows = 40;
  cv::RNG rng(11);
  const cv::Mat ground = texturedGround(rows, 200, 40, rng);
  cv::Mat left(rows, 140, CV_32F), right(rows, 140, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < 140; ++x) {
      left.at<float>(y, x) = x >= 40 && x < 70 ? 110.0f : ground.at<float>(y, x + 20);
      const bool roof = x + 20 >= 40 && x + 20 < 70;
      right.at<float>(y, x) = roof ? 110.0f : ground.at<float>(y, x + 5 + 20);
    }
  }
  testing::addSensorNoise(left, right, 2.0, rng);
  cv::Mat fattened(rows, 140, CV_32F, cv::Scalar(kNaN)), score;
  setRun(fattened, 40, 75, 20.0f);
  setRun(fattened, 75, 140, 5.0f);
  cv::Mat disparity = fattened.clone();
  snapStepsToContours(left, right, StepSnapSettings{}, 0.3f, disparity, score);
  int located = 0, onGround = 0;
  for (int y = 1; y + 1 < rows; ++y) {
    int end = 39;  // last pixel at the roof's disparity
    while (end + 1 < 140 && disparity.at<float>(y, end + 1) == 20.0f) ++end;
    located += std::abs(end - 69) <= 1 ? 1 : 0;
    for (int x = 71; x < 75; ++x) onGround += disparity.at<float>(y, x) == 20.0f ? 1 : 0;
  }
  EXPECT_GE(located, (rows - 2) * 9 / 10);
  EXPECT_LE(onGround, rows / 4);  // of 4 × 38 ground pixels given the roof's value
}

// A roof edge slanted at half a pixel per row, of very low contrast (roof grey 104 over textured
// ground 100 ± 12, noise sigma 3), its value fattened 5 px onto the ground. Each row alone often
// cuts at a ground texture edge; the outline's continuity across rows puts the cut back on the
// line.
TEST(SnapSteps, ASlantedLowContrastEdgeIsCutAlongALine) {
  const int rows = 60, cols = 170;
  cv::RNG rng(5);
  const cv::Mat ground = texturedGround(rows, cols + 40, 30, rng);
  const auto edge = [](int y) { return 60 + y / 2; };  // last roof pixel + 1
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      left.at<float>(y, x) = x >= 30 && x < edge(y) ? 104.0f : ground.at<float>(y, x + 20);
      const bool roof = x + 20 >= 30 && x + 20 < edge(y);
      right.at<float>(y, x) = roof ? 104.0f : ground.at<float>(y, x + 5 + 20);
    }
  }
  testing::addSensorNoise(left, right, 3.0, rng);
  cv::Mat fattened(rows, cols, CV_32F, cv::Scalar(kNaN)), score;
  for (int y = 0; y < rows; ++y) {
    fattened.row(y).colRange(30, edge(y) + 5).setTo(20.0f);
    fattened.row(y).colRange(edge(y) + 5, cols).setTo(5.0f);
  }
  const auto locatedRows = [&](const StepSnapSettings& settings) {
    cv::Mat disparity = fattened.clone();
    snapStepsToContours(left, right, settings, 0.3f, disparity, score);
    int located = 0;
    for (int y = 1; y + 1 < rows; ++y) {
      int end = 29;  // last pixel at the roof's disparity
      while (end + 1 < cols && disparity.at<float>(y, end + 1) == 20.0f) ++end;
      located += std::abs(end - (edge(y) - 1)) <= 1 ? 1 : 0;
    }
    return located;
  };
  StepSnapSettings rowAlone;
  rowAlone.lineRows = 0;
  const int alone = locatedRows(rowAlone), alongLine = locatedRows(StepSnapSettings{});
  EXPECT_GE(alongLine, (rows - 2) * 9 / 10) << alone;
  EXPECT_GT(alongLine, alone + 5);
}

// A roof of the ground's own grey (100 in both views, noise sigma 1): nothing in the left view
// and nothing photometric tells where it ends. The right view sees the roof's east wall, a dark
// 2 px band just after the roof (at x − 20): that contour places the cut. The roof's value is
// fattened 4 px onto the ground.
TEST(SnapSteps, TheRightViewsContourPlacesTheCutWhereTheLeftViewShowsNone) {
  const int rows = 16, cols = 140;
  cv::Mat left(rows, cols, CV_32F, cv::Scalar(100)), right(rows, cols, CV_32F, cv::Scalar(100));
  right.colRange(50, 52).setTo(60);  // roof [40, 70) at disparity 20 ends at right x 49
  cv::RNG rng(9);
  testing::addSensorNoise(left, right, 1.0, rng);
  cv::Mat fattened(rows, cols, CV_32F, cv::Scalar(kNaN)), score;
  setRun(fattened, 40, 74, 20.0f);
  setRun(fattened, 74, cols, 5.0f);
  const auto locatedRows = [&](const StepSnapSettings& settings) {
    cv::Mat disparity = fattened.clone();
    snapStepsToContours(left, right, settings, 0.3f, disparity, score);
    int located = 0;
    for (int y = 0; y < rows; ++y) {
      int end = 39;
      while (end + 1 < cols && disparity.at<float>(y, end + 1) == 20.0f) ++end;
      located += std::abs(end - 69) <= 1 ? 1 : 0;
    }
    return located;
  };
  StepSnapSettings bothViews;
  bothViews.lineRows = 0;  // each row on its own evidence
  StepSnapSettings leftOnly = bothViews;
  leftOnly.rightContourWeight = 0;
  EXPECT_EQ(locatedRows(bothViews), rows);
  // Without it the noise decides (measured: 7 of 16 rows at contourWeight 1.5, 9 at 0.5).
  EXPECT_LT(locatedRows(leftOnly), rows * 3 / 4);
}

// A roof (grey 120, disparity 20, [40, 70)) whose +x side is a flat shadow (grey 40) that
// nothing matches; the right view sees a bright facade (200) beyond the roof instead of the
// shadow. Both views blurred: the last roof pixel mixes with the shadow in the left view and
// with the facade in the right one, so it does not match at the roof's disparity.
TEST(SnapSteps, ExtendsARoofRunEndingInUnmatchedShadowToTheContour) {
  const int rows = 12, cols = 130;
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      left.at<float>(y, x) = x < 40 ? 90.0f : x < 70 ? 120.0f : 40.0f;
      right.at<float>(y, x) = x < 20 ? 90.0f : x < 50 ? 120.0f : x < 65 ? 200.0f : 40.0f;
    }
  }
  cv::GaussianBlur(left, left, {0, 0}, 0.8);
  cv::GaussianBlur(right, right, {0, 0}, 0.8);
  cv::RNG rng(3);
  testing::addSensorNoise(left, right, 1.0, rng);
  cv::Mat disparity(rows, cols, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 40, 68, 20.0f);  // matched up to 67: 2 px short of the outline
  snapStepsToContours(left, right, StepSnapSettings{}, 0.3f, disparity, score);
  for (int y = 1; y + 1 < rows; ++y) {
    EXPECT_FLOAT_EQ(disparity.at<float>(y, 69), 20.0f) << y;
    for (int x = 70; x < cols; ++x)
      EXPECT_TRUE(std::isnan(disparity.at<float>(y, x))) << y << "," << x;
  }
  // Without the right view the run is left as it is (nothing to check an extension against).
  cv::Mat unchecked(rows, cols, CV_32F, cv::Scalar(kNaN));
  setRun(unchecked, 40, 68, 20.0f);
  snapStepsToContours(left, cv::Mat(), StepSnapSettings{}, 0.3f, unchecked, score);
  EXPECT_TRUE(std::isnan(unchecked.at<float>(5, 68)));
}

// A roof (grey 140, disparity 20, [40, 70)) whose +x side is a textured shadow on the ground
// (0.6 × its grey, disparity 5, [70, 90)); at the roof's disparity the right view shows the
// roof's east wall there, plain (grey 100). The roof's value was carried `carried` px onto the
// shadow, followed by an unmatched gap and the ground's run from x 100. Noise sigma 1.5. Wide,
// so that the views' grey-level map (from their column moments) comes from the ground. Returns
// the rows (of 28) whose roof ends within 1 px of its outline after the snapping.
int roofRowsLocatedAfterACarriedRun(int carried, const StepSnapSettings& settings) {
  const int rows = 30;
  cv::RNG rng(17);
  const cv::Mat ground = texturedGround(rows, 400, 60, rng);
  auto groundAt = [&](int y, int x) {  // left-image column x of the ground, shadowed on [70, 90)
    // (The right view's last 5 columns read past the ground's 400: its last column repeats.)
    const float g = ground.at<float>(y, std::min(x + 40, ground.cols - 1));
    return x >= 70 && x < 90 ? 0.6f * g : g;
  };
  cv::Mat left(rows, 360, CV_32F), right(rows, 360, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < 360; ++x) {
      left.at<float>(y, x) = x >= 40 && x < 70 ? 140.0f : groundAt(y, x);
      const bool roof = x + 20 >= 40 && x + 20 < 70;
      const bool wall = x + 20 >= 70 && x + 5 < 70;  // between the roof edge and the ground
      right.at<float>(y, x) = roof ? 140.0f : wall ? 100.0f : groundAt(y, x + 5);
    }
  }
  testing::addSensorNoise(left, right, 1.5, rng);
  cv::Mat disparity(rows, 360, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 40, 70 + carried, 20.0f);
  setRun(disparity, 100, 360, 5.0f);
  snapStepsToContours(left, right, settings, 0.3f, disparity, score);
  int located = 0;
  for (int y = 1; y + 1 < rows; ++y) {
    int end = 39;  // last pixel at the roof's disparity
    while (end + 1 < 360 && disparity.at<float>(y, end + 1) == 20.0f) ++end;
    located += std::abs(end - 69) <= 1 ? 1 : 0;
  }
  return located;
}

TEST(SnapSteps, ARoofRunCarriedOverAShadowStopsAtTheContour) {
  StepSnapSettings off;
  off.carriedRuns = 0;
  EXPECT_EQ(roofRowsLocatedAfterACarriedRun(12, off), 0);
  EXPECT_GE(roofRowsLocatedAfterACarriedRun(12, StepSnapSettings{}), 28 * 9 / 10);
}

// Carried only 2 px: the contour is split however few run pixels lie past it (requiring 3 on
// each side, as carriedRuns 3 does, left these runs alone).
TEST(SnapSteps, ARoofRunCarriedAFewPixelsOverAShadowStopsAtTheContourToo) {
  StepSnapSettings threeEachSide;
  threeEachSide.carriedRuns = 3;
  EXPECT_EQ(roofRowsLocatedAfterACarriedRun(2, threeEachSide), 0);
  EXPECT_GE(roofRowsLocatedAfterACarriedRun(2, StepSnapSettings{}), 28 * 9 / 10);
}

// Rows (all but the first and the last) whose run of `value` from x 40 ends within 1 px of
// `outline`.
int rowsWhoseRoofRunEndsAt(const cv::Mat& disparity, float value, int outline) {
  int located = 0;
  for (int y = 1; y + 1 < disparity.rows; ++y) {
    int end = 39;  // last pixel of the roof's run
    while (end + 1 < disparity.cols && disparity.at<float>(y, end + 1) == value) ++end;
    located += std::abs(end - outline) <= 1 ? 1 : 0;
  }
  return located;
}

// A roof (grey 140, disparity 20, [40, 70)) beside a courtyard ([70, 85), textured ground of
// grey ~70 at disparity 5) that the right view does not see: the next building's roof (textured,
// disparity 20, from x 85) hides it there. At the roof's disparity the courtyard falls, in the
// right view, on the first roof's east wall (plain, grey 40), which only that view shows, so no
// disparity explains the courtyard. The roof's value was carried 10 px onto it, up to a 5 px gap
// before the next roof. With `hidden` false the courtyard is a dark band of the roof itself
// (grey ~70, disparity 20, seen by both views): the run is right there. Returns the rows (of 28)
// whose roof run ends within 1 px of x 69.
// With `ownRunGap` > 0 the carried value is a run of its own, 18 px, starting that many pixels
// past the roof's run (ended at the outline); returns then the rows (of 28) whose courtyard
// ([70, 80)) keeps none of it. `skewedImages`: see below.
int roofRowsEndingAtTheCourtyard(bool hidden, const StepSnapSettings& settings, int ownRunGap = 0,
                                 bool skewedImages = false) {
  const int rows = 30, cols = 300;
  cv::RNG rng(23);
  const cv::Mat texture = texturedGround(rows, cols, 0, rng);
  const auto courtyard = [&](int y, int x) { return 0.7f * texture.at<float>(y, x); };
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      float& l = left.at<float>(y, x);
      l = x < 40   ? texture.at<float>(y, x)
          : x < 70 ? 140.0f
          : x < 85 ? courtyard(y, x)
                   : texture.at<float>(y, x) + 40.0f;
      // Right column x: the first roof up to 50, the wall or the band up to 65, the next roof
      // after; the ground (disparity 5) before the first roof.
      const int onRoof = x + 20;
      float& r = right.at<float>(y, x);
      r = onRoof < 40   ? texture.at<float>(y, std::min(x + 5, cols - 1))
          : onRoof < 70 ? 140.0f
          : onRoof < 85 ? (hidden ? 40.0f : courtyard(y, onRoof))
                        : texture.at<float>(y, std::min(onRoof, cols - 1)) + 40.0f;
    }
  }
  testing::addSensorNoise(left, right, 1.5, rng);
  cv::Mat disparity(rows, cols, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 0, 15, 5.0f);
  if (ownRunGap > 0) {
    setRun(disparity, 40, 70, 20.0f);
    setRun(disparity, 70 + ownRunGap, 80, 18.0f);
  } else {
    setRun(disparity, 40, 80, 20.0f);
  }
  setRun(disparity, 85, cols, 20.0f);
  if (skewedImages) {
    // The right view exposed with gain 0.8 and offset 30, and its last 20 columns a bright band
    // (grey 230) of a surface only it shows (no left pixel pairs with them at these
    // disparities): the images' moments then give gain 0.785 and offset 24.1 for the map
    // whose gain is 1.25 and offset -37.5; the matched pairs give 1.247 and -37.2.
    right = 0.8 * right + 30.0;
    right.colRange(cols - 20, cols).setTo(230.0);
  }
  snapStepsToContours(left, right, settings, 0.3f, disparity, score);
  if (ownRunGap == 0) return rowsWhoseRoofRunEndsAt(disparity, 20.0f, 69);
  int clear = 0;
  for (int y = 1; y + 1 < rows; ++y) {
    bool carried = false;
    for (int x = 70; x < 80; ++x) carried = carried || std::isfinite(disparity.at<float>(y, x));
    clear += carried ? 0 : 1;
  }
  return clear;
}

TEST(SnapSteps, ARoofRunCarriedOverGroundTheRightViewDoesNotSeeStopsAtTheContour) {
  StepSnapSettings noOffset;
  noOffset.carriedOffset = 0;
  EXPECT_EQ(roofRowsEndingAtTheCourtyard(true, noOffset), 0);
  EXPECT_GE(roofRowsEndingAtTheCourtyard(true, StepSnapSettings{}), 28 * 9 / 10);
  // A dark band of the roof itself, which both views show alike, keeps the roof's value.
  EXPECT_EQ(roofRowsEndingAtTheCourtyard(false, StepSnapSettings{}), 0);
}

TEST(SnapSteps, ItsChecksReadTheRightViewThroughTheMatchedPairsGreyMap) {
  // The courtyard scene above with the right view exposed differently and skewed images'
  // moments. (Measured: 28 of 28 rows, 0 through the images' map.)
  EXPECT_GE(roofRowsEndingAtTheCourtyard(true, StepSnapSettings{}, 0, true), 28 * 9 / 10);
}

TEST(SnapSteps, ARoofValueCarriedOntoHiddenGroundAsARunOfItsOwnIsSplitOff) {
  StepSnapSettings noOwnRuns;
  noOwnRuns.carriedOwnRuns = 0;
  for (const int gap : {1, 2}) {
    EXPECT_EQ(roofRowsEndingAtTheCourtyard(true, noOwnRuns, gap), 0);
    EXPECT_GE(roofRowsEndingAtTheCourtyard(true, StepSnapSettings{}, gap), 28 * 9 / 10);
    // A dark band of the roof, which both views show alike: its run is kept.
    EXPECT_EQ(roofRowsEndingAtTheCourtyard(false, StepSnapSettings{}, gap), 0);
  }
}

// A roof (disparity 20, [40, 70): grey 140, 130 on its last 3 columns, a step of 10 grey levels
// inside it) beside a textured shadow on the ground ([70, 90), 0.6 × the ground's grey,
// disparity 5) that is not matched: the roof's run ends at x 64 and is followed by 25
// unmatched pixels before the ground's run. At the roof's disparity the shadow falls, in the
// right view, on the roof's east wall, grey `wall`. Returns the rows (of 28) whose roof run
// ends within 1 px of x 69.
int roofRowsReachingTheOutlineFromAnOpenEnd(float wall, const StepSnapSettings& settings) {
  const int rows = 30, cols = 400;
  cv::RNG rng(29);
  const cv::Mat ground = texturedGround(rows, cols, 0, rng);
  const auto groundAt = [&](int y, int x) {  // left-image column x of the ground
    const float g = ground.at<float>(y, std::min(x, cols - 1));
    return x >= 70 && x < 90 ? 0.6f * g : g;
  };
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      left.at<float>(y, x) = x < 40 || x >= 70 ? groundAt(y, x) : x < 67 ? 140.0f : 130.0f;
    }
    for (int x = 0; x < cols; ++x) {
      const int onRoof = x + 20;
      right.at<float>(y, x) = onRoof >= 40 && onRoof < 70  ? left.at<float>(y, onRoof)
                              : onRoof >= 70 && x + 5 < 70 ? wall
                                                           : groundAt(y, x + 5);
    }
  }
  testing::addSensorNoise(left, right, 1.5, rng);
  cv::Mat disparity(rows, cols, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 40, 65, 20.0f);
  setRun(disparity, 90, cols, 5.0f);
  snapStepsToContours(left, right, settings, 0.3f, disparity, score);
  return rowsWhoseRoofRunEndsAt(disparity, 20.0f, 69);
}

TEST(SnapSteps, AnOpenEndReachesTheContourBeyondWhichTheRightViewShowsAnotherBrightness) {
  // A wall of grey 100 where the shadow (~60) would be: the outline, not the roof's inner
  // step (within `reach` of the run's end), ends the roof.
  // The growth over pixels only the run's disparity explains (next test) reaches it too: off.
  StepSnapSettings offset;
  offset.openGrowth = 0;
  StepSnapSettings nearest = offset;
  nearest.openReach = 0;
  EXPECT_EQ(roofRowsReachingTheOutlineFromAnOpenEnd(100.0f, nearest), 0);
  EXPECT_GE(roofRowsReachingTheOutlineFromAnOpenEnd(100.0f, offset), 28 * 9 / 10);
  // A wall as dark as the shadow: the brightness says little, the run mostly stops at the inner
  // step (in a few rows the shadow's own texture is offset from the plain wall by the bound).
  EXPECT_LE(roofRowsReachingTheOutlineFromAnOpenEnd(60.0f, offset), 28 / 3);
  // The roof's last pixels match at its disparity and not at the shadow's (they would fall on
  // the wall): the growth takes the run to the outline whatever the wall's brightness.
  EXPECT_GE(roofRowsReachingTheOutlineFromAnOpenEnd(60.0f, StepSnapSettings{}), 28 * 8 / 10);
}

// A roof (disparity 40, [40, 70)) whose run is matched on its textured part [40, 52) only, a
// tenth of a pixel off (40.1): a dark seam [52, 54) and then a plain strip (grey 140, with a thin
// dark line of grey 80 at x 60, which errs by ~5 sigmas at the run's disparity through the
// interpolation) up to the outline. Beside it plain dark ground
// ([70, 100), grey 60, disparity 5) is unmatched before the textured ground's run: the roof's
// run is an open end 48 px from the next run. At the roof's disparity the strip matches; at the
// ground's it falls, in the right view, on the roof's east wall (grey 90). Returns the rows (of
// 28) whose roof run ends within 1 px of x 69.
int roofRowsGrowingOverAPlainStripToTheOutline(const StepSnapSettings& settings) {
  const int rows = 30, cols = 300;
  cv::RNG rng(31);
  const cv::Mat ground = texturedGround(rows, cols, 0, rng);
  const auto groundAt = [&](int y, int x) {  // left-image column x of the ground
    return x >= 70 && x < 100 ? 60.0f : ground.at<float>(y, std::min(x, cols - 1));
  };
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      left.at<float>(y, x) = x < 40 || x >= 70 ? groundAt(y, x)
                             : x < 52          ? groundAt(y, x) + 40.0f
                             : x < 54          ? 80.0f
                             : x == 60         ? 80.0f
                                               : 140.0f;
    }
    for (int x = 0; x < cols; ++x) {
      const int onRoof = x + 40;
      right.at<float>(y, x) = onRoof >= 40 && onRoof < 70  ? left.at<float>(y, onRoof)
                              : onRoof >= 70 && x + 5 < 70 ? 90.0f
                                                           : groundAt(y, x + 5);
    }
  }
  testing::addSensorNoise(left, right, 1.5, rng);
  cv::Mat disparity(rows, cols, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 40, 52, 40.1f);
  setRun(disparity, 100, cols, 5.0f);
  snapStepsToContours(left, right, settings, 0.3f, disparity, score);
  return rowsWhoseRoofRunEndsAt(disparity, 40.1f, 69);
}

TEST(SnapSteps, AnOpenEndGrowsOverPixelsOnlyItsDisparityExplainsToTheContour) {
  StepSnapSettings noGrowth;
  noGrowth.openGrowth = 0;
  EXPECT_EQ(roofRowsGrowingOverAPlainStripToTheOutline(noGrowth), 0);
  EXPECT_GE(roofRowsGrowingOverAPlainStripToTheOutline(StepSnapSettings{}), 28 * 9 / 10);
}

// A roof (grey 112, disparity 20, [40, 70)) on textured ground (100 ± 12, disparity 5): a
// weak contour. In rows 10–14 the ground's value was carried 4 px onto the roof (ground run from
// x 66); elsewhere the step is at the outline. A row may not take far pixels on its own evidence
// (that fattened objects in the real pairs), but the line through its neighbours' cuts takes
// it over them, to the outline.
TEST(SnapSteps, ARowWhoseEdgeTookTheGroundsValueFollowsTheLineOfItsNeighbours) {
  const int rows = 30, cols = 170;
  cv::RNG rng(23);
  const cv::Mat ground = texturedGround(rows, cols + 40, 30, rng);
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      left.at<float>(y, x) = x >= 40 && x < 70 ? 112.0f : ground.at<float>(y, x + 20);
      const bool roof = x + 20 >= 40 && x + 20 < 70;
      right.at<float>(y, x) = roof ? 112.0f : ground.at<float>(y, x + 5 + 20);
    }
  }
  testing::addSensorNoise(left, right, 2.0, rng);
  cv::Mat matched(rows, cols, CV_32F, cv::Scalar(kNaN)), score;
  setRun(matched, 40, 70, 20.0f);
  setRun(matched, 70, cols, 5.0f);
  matched(cv::Rect(66, 10, 4, 5)).setTo(5.0f);
  const auto carriedRowsLocated = [&](const StepSnapSettings& settings) {
    cv::Mat disparity = matched.clone();
    snapStepsToContours(left, right, settings, 0.3f, disparity, score);
    int located = 0;
    for (int y = 10; y < 15; ++y) {
      int end = 39;  // last pixel at the roof's disparity
      while (end + 1 < cols && disparity.at<float>(y, end + 1) == 20.0f) ++end;
      located += std::abs(end - 69) <= 1 ? 1 : 0;
    }
    return located;
  };
  StepSnapSettings ownRangeOnly;
  ownRangeOnly.cutAhead = 0;
  EXPECT_EQ(carriedRowsLocated(ownRangeOnly), 0);
  EXPECT_EQ(carriedRowsLocated(StepSnapSettings{}), 5);
}

// A roof (disparity 20, [40, 70)) textured up to a dark seam at x 61-62, plain grey 100 after
// it, beside textured ground (disparity 5, grey ~100) matched from x 72. The right view shows the
// roof's east wall at its columns [50, 65): bright (160) on its first 6, the roof's grey after.
// So at the ground's disparity the plain strip [63, 70) falls on the wall's roof-grey part and
// is explained as well as at the roof's: only the ground past the outline, which at the roof's
// disparity falls on the bright part, tells where the roof ends. Returns the rows (of 28) whose
// roof run ends within 1 px of x 69.
int plainRoofStripRowsReachingTheOutline(const StepSnapSettings& settings) {
  const int rows = 30, cols = 200;
  cv::RNG rng(31);
  const cv::Mat texture = texturedGround(rows, cols, 0, rng);
  const auto leftAt = [&](int y, int x) {
    if (x < 40 || x >= 70) return texture.at<float>(y, x);
    if (x == 61 || x == 62) return 60.0f;
    return x < 61 ? texture.at<float>(y, (x + 100) % cols) + 20.0f : 100.0f;
  };
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      left.at<float>(y, x) = leftAt(y, x);
      const int onRoof = x + 20;
      right.at<float>(y, x) = onRoof >= 40 && onRoof < 70 ? leftAt(y, onRoof)
                              : x >= 50 && x < 65         ? (x < 56 ? 160.0f : 100.0f)
                                                  : texture.at<float>(y, std::min(x + 5, cols - 1));
    }
  }
  testing::addSensorNoise(left, right, 1.5, rng);
  cv::Mat disparity(rows, cols, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 40, 61, 20.0f);
  setRun(disparity, 72, cols, 5.0f);
  snapStepsToContours(left, right, settings, 0.3f, disparity, score);
  return rowsWhoseRoofRunEndsAt(disparity, 20.0f, 69);
}

TEST(SnapSteps, APlainRoofStripTheGroundsValueExplainsReachesWhereTheRoofsValueFailsHard) {
  StepSnapSettings noHardEnd;
  noHardEnd.hardEndPenalty = 0;
  EXPECT_EQ(plainRoofStripRowsReachingTheOutline(noHardEnd), 0);
  EXPECT_GE(plainRoofStripRowsReachingTheOutline(StepSnapSettings{}), 28 * 9 / 10);
}

// A roof facet sloping towards its +x edge (disparity 30 at x 40 down to 18.4 at x 69, 0.4 px per
// px; textured as strongly as the ground, of its mean grey) beside textured ground (disparity 5).
// The roof is matched along its slope up to x 63, the ground from x 72. At the run's last disparity
// the facet's last pixels are 1-2.4 px off and fail as the ground's does; along the run's slope
// they match. Returns the rows (of 28) whose roof run ends within 1 px of x 69.
int slopedFacetRowsReachingTheOutline(const StepSnapSettings& settings) {
  const int rows = 30, cols = 200;
  cv::RNG rng(17);
  const cv::Mat texture = testing::texture(cv::Size(cols, rows), 17, 1.0) * 0.5 + 40;
  const auto roofDisparity = [](double x) { return 30.0 - 0.4 * (x - 40.0); };
  // The facet's texture at left x (linear between pixels; roof pixels are read 100 px on).
  const auto facet = [&](int y, double x) {
    const int x0 = static_cast<int>(std::floor(x));
    const double t = x - x0;
    return static_cast<float>((1 - t) * texture.at<float>(y, x0 + 100) +
                              t * texture.at<float>(y, x0 + 101));
  };
  cv::Mat left(rows, cols, CV_32F), right(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      left.at<float>(y, x) = x >= 40 && x < 70 ? facet(y, x) : texture.at<float>(y, x);
      // The facet point the right view sees at x: x = xl − roofDisparity(xl).
      const double xl = (x + 30.0 + 0.4 * 40.0) / 1.4;
      right.at<float>(y, x) =
          xl >= 40 && xl < 70 ? facet(y, xl) : texture.at<float>(y, std::min(x + 5, cols - 1));
    }
  }
  testing::addSensorNoise(left, right, 1.5, rng);
  cv::Mat disparity(rows, cols, CV_32F, cv::Scalar(kNaN)), score;
  for (int x = 40; x < 64; ++x) setRun(disparity, x, x + 1, static_cast<float>(roofDisparity(x)));
  setRun(disparity, 72, cols, 5.0f);
  snapStepsToContours(left, right, settings, 0.3f, disparity, score);
  int located = 0;
  for (int y = 1; y + 1 < rows; ++y) {
    int end = 39;  // last pixel on the roof's side of the mid-level
    while (end + 1 < cols && disparity.at<float>(y, end + 1) > 12.0f) ++end;
    located += std::abs(end - 69) <= 1 ? 1 : 0;
  }
  return located;
}

TEST(SnapSteps, ASlopedFacetIsCutAlongItsSlope) {
  // Each row on its own evidence (the line through the rows' cuts would hide the difference).
  StepSnapSettings rowAlone;
  rowAlone.lineRows = 0;
  StepSnapSettings level = rowAlone;
  level.nearSlopePixels = 0;
  const int alongSlope = slopedFacetRowsReachingTheOutline(rowAlone);
  EXPECT_GE(alongSlope, 28 * 3 / 4);
  EXPECT_LE(slopedFacetRowsReachingTheOutline(level), alongSlope - 6);
}

// The roof of texturedPair() matched on [40, 58) and on pixel 61 alone (a hole in between), the
// ground from x 76: the cut of the step after pixel 61 reaches back over the hole to the roof's
// run, and the roof's run from x 40 ends at the outline (x 69). Returns the rows (of 18) where it
// does.
int roofRowsClosedOverAHoleToTheOutline(const StepSnapSettings& settings) {
  const TexturedPair pair = texturedPair();
  cv::Mat disparity(20, 120, CV_32F, cv::Scalar(kNaN)), score;
  setRun(disparity, 40, 58, 20.0f);
  setRun(disparity, 61, 62, 20.0f);
  setRun(disparity, 76, 120, 5.0f);
  snapStepsToContours(pair.left, pair.right, settings, 0.3f, disparity, score);
  return rowsWhoseRoofRunEndsAt(disparity, 20.0f, 69);
}

TEST(SnapSteps, TheCutReachesBackOverAHoleInsideTheNearSide) {
  StepSnapSettings noHoles;
  noHoles.nearHoleGap = 0;
  EXPECT_EQ(roofRowsClosedOverAHoleToTheOutline(noHoles), 0);
  EXPECT_EQ(roofRowsClosedOverAHoleToTheOutline(StepSnapSettings{}), 18);
}

}  // namespace
}  // namespace delineo::stereo::detail
