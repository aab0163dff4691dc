// Large pairs matched in overlapping tiles (match_tiles.hpp): the grid, the stitched maps against
// the whole pair's, the progress and cancel across tiles, the thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/error.hpp"
#include "delineo/core/progress.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/match.hpp"
#include "match_tiles.hpp"
#include "simulated_views.hpp"

namespace delineo::stereo {
namespace {

// How many tiles' kept parts hold each pixel.
cv::Mat keptCount(cv::Size size, const std::vector<detail::MatchTile>& tiles) {
  cv::Mat count(size, CV_32S, cv::Scalar(0));
  for (const detail::MatchTile& t : tiles) count(t.kept) += 1;
  return count;
}

void expectGridCoversEveryPixelOnce(cv::Size size, int tile) {
  const int dmin = -5, dmax = 40, context = 16, alignment = 8;
  const auto tiles = detail::matchTileGrid(size, tile, context, dmin, dmax, alignment);
  ASSERT_FALSE(tiles.empty());
  const cv::Mat count = keptCount(size, tiles);
  double lo = 0, hi = 0;
  cv::minMaxLoc(count, &lo, &hi);
  EXPECT_EQ(lo, 1) << size << " tile " << tile;
  EXPECT_EQ(hi, 1) << size << " tile " << tile;
  const cv::Rect image(cv::Point(0, 0), size);
  for (const detail::MatchTile& t : tiles) {
    EXPECT_LE(t.kept.width, tile);
    EXPECT_LE(t.kept.height, tile);
    EXPECT_GT(t.kept.area(), 0);
    EXPECT_EQ((t.crop & t.kept), t.kept) << "the crop holds its kept part";
    EXPECT_EQ((t.crop & image), t.crop) << "the crop lies in the image";
    EXPECT_EQ(t.crop.x % alignment, 0);
    EXPECT_EQ(t.crop.y % alignment, 0);
    // The range's columns (and the right view's own check, up to the range's width) and the
    // context reached on both sides, where the image has them.
    EXPECT_LE(t.crop.x, std::max(0, t.kept.x - (dmax - dmin) - context));
    EXPECT_GE(t.crop.br().x, std::min(size.width, t.kept.br().x + (dmax - dmin) + context));
    EXPECT_LE(t.crop.y, std::max(0, t.kept.y - context));
    EXPECT_GE(t.crop.br().y, std::min(size.height, t.kept.br().y + context));
  }
}

TEST(MatchTileGrid, CoversEveryPixelExactlyOnce) {
  expectGridCoversEveryPixelOnce({1000, 777}, 128);  // odd sizes
  expectGridCoversEveryPixelOnce({129, 300}, 128);   // one column more than a tile
  expectGridCoversEveryPixelOnce({300, 257}, 128);   // one row more than two tiles
  expectGridCoversEveryPixelOnce({90, 70}, 128);     // smaller than a tile: one
  expectGridCoversEveryPixelOnce({1, 1}, 64);
}

TEST(MatchTileGrid, TilesOnlyImagesLargerThanATile) {
  EXPECT_FALSE(detail::matchesInTiles({2048, 2048}, 2048));
  EXPECT_TRUE(detail::matchesInTiles({2049, 100}, 2048));
  EXPECT_TRUE(detail::matchesInTiles({100, 2049}, 2048));
  EXPECT_FALSE(detail::matchesInTiles({100000, 100000}, 0));
  EXPECT_EQ(detail::matchTileGrid({129, 300}, 128, 0, 0, 0, 1).size(), 6U);  // 2 x 3
}

TEST(MatchTileGrid, ASmallTileIsRejected) {
  MatchParams p;
  p.tile = 63;
  EXPECT_THROW(p.validate(), core::Error);
  p.tile = 0;
  EXPECT_NO_THROW(p.validate());
  p.tile = 64;
  EXPECT_NO_THROW(p.validate());
}

using testing::SceneViews;
using testing::sceneViews;

double matchedShare(const cv::Mat& d) {
  long n = 0;
  for (int y = 0; y < d.rows; ++y) {
    for (int x = 0; x < d.cols; ++x) n += std::isfinite(d.at<float>(y, x)) ? 1 : 0;
  }
  return static_cast<double>(n) / static_cast<double>(d.total());
}

// Of the pixels either map matched, the share both matched within 1 px.
double agreementWithin1px(const cv::Mat& a, const cv::Mat& b) {
  long either = 0, close = 0;
  for (int y = 0; y < a.rows; ++y) {
    for (int x = 0; x < a.cols; ++x) {
      const float u = a.at<float>(y, x), v = b.at<float>(y, x);
      if (!std::isfinite(u) && !std::isfinite(v)) continue;
      ++either;
      close += std::abs(u - v) <= 1.0F ? 1 : 0;  // (NaN: not close)
    }
  }
  return static_cast<double>(close) / static_cast<double>(std::max(1L, either));
}

bool sameBits(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  for (int y = 0; y < a.rows; ++y) {
    if (std::memcmp(a.ptr(y), b.ptr(y), a.elemSize() * static_cast<size_t>(a.cols)) != 0) {
      return false;
    }
  }
  return true;
}

// A 400² city block in 128 px tiles (4 x 4) against the whole: the kept parts read enough
// context that the stitched map matches the whole one's within 1 px on nearly every pixel either
// matches, with the same density within a point.
TEST(MatchTiles, ASimulatedSceneMatchedInSmallTilesAgreesWithTheWholeMatch) {
  SceneViews v = sceneViews(400, 7);
  v.params.tile = 0;
  const MatchResult whole = matchStereo(v.left, v.right, v.params);
  v.params.tile = 128;
  const MatchResult tiled = matchStereo(v.left, v.right, v.params);
  ASSERT_EQ(tiled.status, core::RunStatus::Completed);
  ASSERT_EQ(tiled.disparity.size(), whole.disparity.size());
  ASSERT_EQ(tiled.score.size(), whole.score.size());
  EXPECT_EQ(tiled.levelsUsed, whole.levelsUsed);
  ASSERT_GT(matchedShare(whole.disparity), 0.8);
  EXPECT_NEAR(matchedShare(tiled.disparity), matchedShare(whole.disparity), 0.01);
  EXPECT_GE(agreementWithin1px(tiled.disparity, whole.disparity), 0.995);  // measured: 99.97 %
  // The score map is stitched alike: NaN exactly where the disparity is.
  for (int y = 0; y < tiled.score.rows; ++y) {
    for (int x = 0; x < tiled.score.cols; ++x) {
      ASSERT_EQ(std::isnan(tiled.score.at<float>(y, x)), std::isnan(tiled.disparity.at<float>(y, x)))
          << x << "," << y;
    }
  }
}

TEST(MatchTiles, APairNoLargerThanATileIsMatchedWhole) {
  SceneViews v = sceneViews(200, 3);
  v.params.tile = 0;
  const MatchResult whole = matchStereo(v.left, v.right, v.params);
  v.params.tile = 200;
  const MatchResult one = matchStereo(v.left, v.right, v.params);
  EXPECT_TRUE(sameBits(whole.disparity, one.disparity));
  EXPECT_TRUE(sameBits(whole.score, one.score));
}

TEST(MatchTiles, TiledMapsAreTheSameBitsOnOneAndTwoThreads) {
  SceneViews v = sceneViews(300, 15);
  v.params.tile = 128;
  v.params.threads = 1;
  const MatchResult one = matchStereo(v.left, v.right, v.params);
  v.params.threads = 2;
  const MatchResult two = matchStereo(v.left, v.right, v.params);
  ASSERT_GT(matchedShare(one.disparity), 0.5);
  EXPECT_TRUE(sameBits(one.disparity, two.disparity));
  EXPECT_TRUE(sameBits(one.score, two.score));
}

// Records every fraction reported and cancels itself once the bar passes `cancelFrom`.
class RecordingProgress : public core::Progress {
 public:
  explicit RecordingProgress(double cancelFrom = 2.0) : cancelFrom_(cancelFrom) {}
  void report(double fraction) override {
    Progress::report(fraction);
    fractions.push_back(this->fraction());
    if (this->fraction() >= cancelFrom_) cancel();
  }
  std::vector<double> fractions;

 private:
  double cancelFrom_;
};

// One bar through the tiles (by area, never backwards, to 1); a cancel inside a later tile
// ends the match there: status Canceled, no maps, the bar short of the end.
TEST(MatchTiles, TheBarGoesThroughTheTilesAndACancelInALaterTileEndsTheMatch) {
  SceneViews v = sceneViews(256, 7);
  v.params.tile = 128;  // 2 x 2 tiles
  RecordingProgress full;
  ASSERT_EQ(matchStereo(v.left, v.right, v.params, &full).status, core::RunStatus::Completed);
  ASSERT_GT(full.fractions.size(), 8U);
  for (size_t i = 1; i < full.fractions.size(); ++i) {
    EXPECT_GE(full.fractions[i], full.fractions[i - 1]);
  }
  EXPECT_EQ(full.fractions.back(), 1.0);
  // Each tile's reports fill its quarter: some fall strictly inside each quarter.
  for (const double quarter : {0.0, 0.25, 0.5, 0.75}) {
    EXPECT_TRUE(std::any_of(full.fractions.begin(), full.fractions.end(), [&](double f) {
      return f > quarter + 0.01 && f < quarter + 0.24;
    })) << "quarter from " << quarter;
  }
  RecordingProgress canceling(0.8);  // inside the fourth tile
  const MatchResult r = matchStereo(v.left, v.right, v.params, &canceling);
  EXPECT_EQ(r.status, core::RunStatus::Canceled);
  EXPECT_TRUE(r.disparity.empty() && r.score.empty());
  EXPECT_LT(canceling.fraction(), 1.0);
}

}  // namespace
}  // namespace delineo::stereo
