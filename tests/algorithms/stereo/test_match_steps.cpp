// The step cut (internal refineDepthSteps): on a depth step whose +x side is nearer, the strip
// before the near surface is seen by the reference view only; an outline that runs with the
// rows is cut along the columns.
#include <gtest/gtest.h>

#include <cmath>

#include "match_steps.hpp"
#include "synthetic.hpp"

namespace delineo::stereo::detail {
namespace {

cv::Mat mirrored(const cv::Mat& m) {
  cv::Mat out;
  cv::flip(m, out, 1);
  return out;
}

struct StripCounts {
  int nearLocated = 0, nearTotal = 0;    // near-surface pixels next to the strip within 1 px
  int farLocated = 0, farTotal = 0;      // far-surface pixels next to the strip within 1 px
  int stripMatched = 0, stripTotal = 0;  // strip pixels given any disparity
};

// The right map of a square without contour in front of a background, refined as the matcher
// does (mirrored: x'_other = x'_ref − d), from a validated map that lost every pixel within 9 px
// of the strip (the windows straddling it failed). Counted in right-image coordinates.
StripCounts refineRightMap(bool occlusionStrip) {
  const cv::Rect square(50, 30, 60, 40);
  const int background = 4, foreground = 14, margin = 9;
  const auto scene = testing::squareScene({170, 100}, square, background, foreground, 11, 30.0);
  // Right pixel xr sees the square when xr + foreground lies in it; the background point it sees
  // otherwise (xr + background) is hidden from the left view when it lies in the square.
  const int nearEnd = square.br().x - foreground;   // first right column past the square
  const int stripEnd = square.br().x - background;  // first right column past the strip
  cv::Mat validated(scene.right.size(), CV_32F, cv::Scalar(background));
  for (int y = square.y; y < square.br().y; ++y) {
    for (int x = 0; x < validated.cols; ++x) {
      if (x + foreground >= square.x && x < nearEnd) validated.at<float>(y, x) = float(foreground);
      if (x >= nearEnd - margin && x < stripEnd + margin) validated.at<float>(y, x) = NAN;
    }
  }
  LevelOutput raw;
  raw.disparity = mirrored(validated);
  raw.lineShift = cv::Mat::zeros(validated.size(), CV_32F);
  raw.score = cv::Mat::zeros(validated.size(), CV_32F);
  const cv::Mat valid = cv::Mat::ones(validated.size(), CV_8U);
  StepRefineSettings settings;
  settings.occlusionStrip = occlusionStrip;
  refineDepthSteps(mirrored(scene.right), mirrored(scene.left), valid, valid, mirrored(validated),
                   settings, raw);
  const cv::Mat refined = mirrored(raw.disparity);
  StripCounts c;
  for (int y = square.y + 2; y < square.br().y - 2; ++y) {
    for (int x = nearEnd - margin; x < stripEnd + margin; ++x) {
      const float d = refined.at<float>(y, x);
      if (x < nearEnd) {
        ++c.nearTotal;
        c.nearLocated += std::abs(d - foreground) <= 1.0F;
      } else if (x < stripEnd) {
        ++c.stripTotal;
        c.stripMatched += std::isfinite(d);
      } else {
        ++c.farTotal;
        c.farLocated += std::abs(d - background) <= 1.0F;
      }
    }
  }
  return c;
}

TEST(StepCut, LeavesTheStripSeenByOneViewOutOfBothSides) {
  const StripCounts with = refineRightMap(true), without = refineRightMap(false);
  // With the strip modelled, the boundary's cost compares the two sides on the pixels each
  // really shows, and neither side's window holds the strip.
  EXPECT_EQ(with.stripMatched, 0);
  EXPECT_GT(with.nearLocated, with.nearTotal * 9 / 10)
      << with.nearLocated << " of " << with.nearTotal;
  EXPECT_GT(with.farLocated, with.farTotal * 9 / 10) << with.farLocated << " of " << with.farTotal;
  // Without it the strip is given to one side and matched there: a match the other view cannot
  // confirm, which the left/right check may still let through next to the outline.
  EXPECT_GT(without.stripMatched, without.stripTotal / 2)
      << without.stripMatched << " of " << without.stripTotal;
}

// Left map of a contourless square whose bottom band (the `band` rows above its lower outline)
// carries the background's disparity, as windows straddling an outline that runs with the rows
// leave it: no row crosses that outline, so only the columns can see the step. Returns how many
// band pixels (away from the square's sides) end within 1 px of the square's disparity.
int bandPixelsOnTheSquare(bool columnSteps, int& total) {
  const cv::Rect square(60, 30, 70, 40);
  const int background = 4, foreground = 14, band = 5;
  const auto scene = testing::squareScene({190, 100}, square, background, foreground, 11, 30.0);
  cv::Mat validated = scene.truth.clone();
  const int bandTop = square.br().y - band;
  for (int y = bandTop; y < square.br().y; ++y) {
    for (int x = square.x; x < square.br().x; ++x) validated.at<float>(y, x) = float(background);
  }
  LevelOutput raw;
  raw.disparity = validated.clone();
  raw.lineShift = cv::Mat::zeros(validated.size(), CV_32F);
  raw.score = cv::Mat::zeros(validated.size(), CV_32F);
  const cv::Mat valid = cv::Mat::ones(validated.size(), CV_8U);
  StepRefineSettings settings;
  settings.columnSteps = columnSteps;
  refineDepthSteps(scene.left, scene.right, valid, valid, validated, settings, raw);
  int onSquare = 0;
  total = 0;
  // Half a window from the square's sides, where the rows' own segments decide.
  for (int y = bandTop; y < square.br().y; ++y) {
    for (int x = square.x + 8; x < square.br().x - 8; ++x) {
      ++total;
      onSquare += std::abs(raw.disparity.at<float>(y, x) - foreground) <= 1.0F;
    }
  }
  return onSquare;
}

TEST(StepCut, CutsAnOutlineThatRunsWithTheRowsAlongTheColumns) {
  int total = 0;
  const int with = bandPixelsOnTheSquare(true, total);
  EXPECT_GT(with, total * 9 / 10) << with << " of " << total;
  const int without = bandPixelsOnTheSquare(false, total);
  EXPECT_LT(without, total / 10) << without << " of " << total;
}

}  // namespace
}  // namespace delineo::stereo::detail
