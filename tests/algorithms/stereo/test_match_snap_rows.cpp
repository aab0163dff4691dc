// Depth steps between rows moved onto the image contour (internal snapStepsAcrossRows).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <opencv2/core.hpp>

#include "match_snap_rows.hpp"
#include "synthetic.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kRoof = 20.0F, kGround = 4.0F;
constexpr double kNoise = 1.5;

struct Pair {
  cv::Mat left, right, truth;
};

// A roof at disparity 20 on textured ground (grey 80..110, seed 11) at disparity 4: `onRoof(x,
// y)` tells the roof's points (in the left view's geometry of the surface), `roofGrey(x, y)` their
// grey; the right pixel x shows the roof point x + 20 where there is one (the roof is nearer),
// the ground point x + 4 elsewhere. Sensor noise kNoise in each view.
template <class OnRoof, class RoofGrey>
Pair render(cv::Size size, OnRoof&& onRoof, RoofGrey&& roofGrey) {
  const cv::Mat ground = stereo::testing::texture({size.width + 64, size.height}, 11) * 0.12 + 80.0;
  Pair p;
  p.left.create(size, CV_32F);
  p.right.create(size, CV_32F);
  p.truth.create(size, CV_32F);
  const int dRoof = static_cast<int>(kRoof), dGround = static_cast<int>(kGround);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const bool l = onRoof(x, y);
      p.left.at<float>(y, x) = l ? roofGrey(x, y) : ground.at<float>(y, x + 32);
      p.truth.at<float>(y, x) = l ? kRoof : kGround;
      const bool r = onRoof(x + dRoof, y);
      p.right.at<float>(y, x) = r ? roofGrey(x + dRoof, y) : ground.at<float>(y, x + 32 + dGround);
    }
  }
  cv::RNG rng(5);
  stereo::testing::addSensorNoise(p.left, p.right, kNoise, rng);
  return p;
}

// A weakly textured roof (grey 60..80) below the ground, 160x80: a contrast across the outline
// of about 25 grey levels, as on seed 2 1000². The roof's top row is `top` at column 0, its
// outline `slant` px lower per column (0: along the rows); with `darkLine`, a dark line (−30
// grey) runs on the roof 4 rows below its outline.
Pair roofBelowGround(int top, double slant, bool darkLine = false) {
  const cv::Size size(160, 80);
  const cv::Mat roof = stereo::testing::texture({size.width + 64, size.height}, 12) * 0.08 + 60.0;
  // Row offset of (x, y) below the outline.
  const auto belowOutline = [&](int x, int y) { return y - (top + slant * x); };
  return render(
      size, [&](int x, int y) { return belowOutline(x, y) >= 0; },
      [&](int x, int y) {
        const double below = belowOutline(x, y);
        const bool onLine = darkLine && below >= 4 && below < 5;
        return roof.at<float>(y, x + 32) - (onLine ? 30.0F : 0.0F);
      });
}

// The map a window matcher leaves: the truth, with the ground's disparity carried `carried`
// rows into the roof below its outline (columns [x0, x1)) and one unmatched row after them.
cv::Mat carriedMap(const Pair& p, int top, int carried, int x0, int x1) {
  cv::Mat d = p.truth.clone();
  for (int x = x0; x < x1; ++x) {
    for (int y = top; y < top + carried; ++y) d.at<float>(y, x) = kGround + 0.5F;
    d.at<float>(top + carried, x) = kNaN;
  }
  return d;
}

int snap(const Pair& p, cv::Mat& disparity, const RowStepSnapSettings& settings = {}) {
  cv::Mat score(disparity.size(), CV_32F, cv::Scalar(0.9));
  return snapStepsAcrossRows(p.left, p.right, kNoise, settings, 0.3F, disparity, score);
}

int pixelsAt(const cv::Mat& disparity, const cv::Rect& area, float value) {
  int n = 0;
  for (int y = area.y; y < area.br().y; ++y) {
    for (int x = area.x; x < area.br().x; ++x) {
      n += std::abs(disparity.at<float>(y, x) - value) < 0.01F ? 1 : 0;
    }
  }
  return n;
}

TEST(SnapStepsAcrossRows, GivesTheRoofBackTheRowsTheGroundCarriedIntoIt) {
  const int top = 30;
  const Pair p = roofBelowGround(top, 0);
  cv::Mat disparity = carriedMap(p, top, 4, 40, 120);
  const int moved = snap(p, disparity);
  // Of the 4 carried rows of 80 columns, the pixels moved take the roof's disparity, and no
  // other pixel moves (the unmatched row stays so). A column's move stops at the first pixel its
  // strip does not clearly put on the roof (measured: 278 of 320 moved, all of them in 66
  // columns; 1–3 rows next to the gap in the others).
  const cv::Rect carried(40, top, 80, 4);
  EXPECT_EQ(moved, pixelsAt(disparity, carried, kRoof));
  EXPECT_GE(moved, carried.area() * 3 / 4);
  // The row next to the gap moves in every column.
  EXPECT_EQ(pixelsAt(disparity, cv::Rect(40, top + 3, 80, 1), kRoof), 80);
  // The ground above keeps its own.
  EXPECT_EQ(pixelsAt(disparity, cv::Rect(40, top - 6, 80, 6), kGround), 80 * 6);
}

TEST(SnapStepsAcrossRows, ReadsTheRightViewThroughTheMatchedPairsGreyMap) {
  // The scene above with the right view exposed with gain 0.8 and offset 30, and its last 30
  // columns a bright band (grey 230) that only it shows (the left pixels that would pair with
  // it unmatched): the images' moments then give gain 0.283 and offset 48.4 for the exposures'
  // 1.25 and -37.5, the matched pairs 1.251 and -37.6. (Measured: 278 moved, as above; none
  // through the images' map.)
  const int top = 30;
  Pair p = roofBelowGround(top, 0);
  const int band = p.right.cols - 30;
  p.right = 0.8 * p.right + 30.0;
  p.right.colRange(band, p.right.cols).setTo(230.0);
  cv::Mat disparity = carriedMap(p, top, 4, 40, 120);
  disparity.colRange(band + static_cast<int>(kGround), disparity.cols).setTo(kNaN);
  const int moved = snap(p, disparity);
  const cv::Rect carried(40, top, 80, 4);
  EXPECT_EQ(moved, pixelsAt(disparity, carried, kRoof));
  EXPECT_GE(moved, carried.area() * 3 / 4);
}

TEST(SnapStepsAcrossRows, ARunCarriedPastTheReachMovesInTwoPasses) {
  // 7 carried rows: the outline lies 7 rows before the run's last, past the contour search's
  // 6, and a dark line on the roof 4 rows below the outline is the strongest contrast within
  // reach. The first pass moves the run's rows past the line; the second sees the outline from
  // the new step and moves the rest.
  const int top = 30;
  const Pair p = roofBelowGround(top, 0, true);
  const cv::Rect carried(40, top, 80, 7);
  RowStepSnapSettings onePass;
  onePass.maxPasses = 1;
  cv::Mat once = carriedMap(p, top, 7, 40, 120);
  snap(p, once, onePass);
  cv::Mat repeated = carriedMap(p, top, 7, 40, 120);
  snap(p, repeated);
  // (Measured: 204 and 418 of 560; as in the test above, a column's move stops at the first
  // pixel its strip does not clearly put on the roof.)
  EXPECT_LT(pixelsAt(once, carried, kRoof), carried.area() / 2);
  EXPECT_GE(pixelsAt(repeated, carried, kRoof), carried.area() * 2 / 3);
}

TEST(SnapStepsAcrossRows, LeavesCorrectRowsAlone) {
  const int top = 30;
  const Pair p = roofBelowGround(top, 0);
  // The step where the outline is (the roof's first row unmatched): nothing to move; without
  // the gap's filling nothing changes (see the next test for the filling).
  RowStepSnapSettings noGapFill;
  noGapFill.gapErrorSigmas = 0;
  cv::Mat exact = carriedMap(p, top, 0, 40, 120);
  EXPECT_EQ(snap(p, exact, noGapFill), 0);
  // The roof's disparity carried 3 rows up into the ground: the ground's texture tells them
  // apart, and they move back to it.
  cv::Mat up = p.truth.clone();
  for (int x = 40; x < 120; ++x) {
    for (int y = top - 3; y < top; ++y) up.at<float>(y, x) = kRoof;
    up.at<float>(top - 4, x) = kNaN;
  }
  snap(p, up);
  EXPECT_EQ(pixelsAt(up, cv::Rect(40, top - 3, 80, 3), kGround), 80 * 3);
}

TEST(SnapStepsAcrossRows, FillsAGapUpToTheOutlineFromBothSides) {
  // Unmatched rows around the outline (the ground's last 2 rows and the roof's first 2, as the
  // windows straddling it leave them), straight and slanted (half a row per column): each side's
  // rows up to the outline take its disparity, none the other side's.
  for (const double slant : {0.0, 0.5}) {
    const int top = 30;
    const Pair p = roofBelowGround(top, slant);
    cv::Mat disparity = p.truth.clone();
    const int x0 = 20, x1 = 60;
    for (int x = x0; x < x1; ++x) {
      const int first = top + static_cast<int>(std::ceil(slant * x));  // the roof's first row
      for (int y = first - 2; y < first + 2; ++y) disparity.at<float>(y, x) = kNaN;
    }
    cv::Mat unfilled = disparity.clone();
    RowStepSnapSettings noGapFill;
    noGapFill.gapErrorSigmas = 0;
    EXPECT_EQ(snap(p, unfilled, noGapFill), 0);
    snap(p, disparity);
    int right = 0, wrong = 0, open = 0;
    for (int x = x0; x < x1; ++x) {
      const int first = top + static_cast<int>(std::ceil(slant * x));
      for (int y = first - 2; y < first + 2; ++y) {
        const float d = disparity.at<float>(y, x);
        if (!std::isfinite(d)) {
          ++open;
        } else {
          (d == p.truth.at<float>(y, x) ? right : wrong) += 1;
        }
      }
    }
    // (Measured: 160 and 138 of 160; the slanted outline's mixed pixels stay open.)
    EXPECT_EQ(wrong, 0) << "slant " << slant;
    EXPECT_GE(right, (x1 - x0) * 4 * 8 / 10) << "slant " << slant;
  }
}

TEST(SnapStepsAcrossRows, ChecksAPixelOnItsOwnSurfacesPartOfTheStrip) {
  // A narrow roof wing (6 px wide, disparity 20) below textured ground (4), its grey close to the
  // ground's (a weak outline) and a dark line on it 3 rows below its top: in each of its columns
  // the line is the strongest contrast, past the wing's first matched pixel (its first 2 rows
  // unmatched), as if that pixel were carried. On its row the strip holds 6 wing pixels and 9
  // of the ground beside it, which the ground's disparity explains: over the whole strip the
  // ground's disparity wins (measured: all 6 moved). Over the strip without the pixels that had
  // the ground's disparity, the wing's own wins: none moves.
  const cv::Size size(160, 60);
  const cv::Rect wing(80, 20, 6, 40);
  const cv::Mat roof = stereo::testing::texture({size.width + 64, size.height}, 12) * 0.08 + 85.0;
  const Pair p = render(
      size,
      [&](int x, int y) {
        return wing.contains({x, y});
      },
      [&](int x, int y) { return roof.at<float>(y, x + 32) - (y == wing.y + 3 ? 40.0F : 0.0F); });
  cv::Mat disparity = p.truth.clone();
  disparity(cv::Rect(wing.x, wing.y, wing.width, 2)).setTo(kNaN);
  EXPECT_EQ(snap(p, disparity), 0);
  EXPECT_EQ(pixelsAt(disparity, cv::Rect(wing.x, wing.y + 2, wing.width, 1), kRoof), wing.width);
}

}  // namespace
}  // namespace delineo::stereo::detail
