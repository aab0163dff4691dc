// Ground / above-ground segmentation and DTM on synthetic DEMs.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/core/nan_mask.hpp"
#include "delineo/core/progress.hpp"
#include "delineo/segmentation/ground.hpp"
#include "delineo/sim/scene.hpp"

using namespace delineo;
using segmentation::GroundParams;
using segmentation::GroundResult;
using segmentation::segmentGround;

namespace {

constexpr double kGsd = 0.25;  // m/px
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Terrain 100 m + slope (fraction, rising along x) + Gaussian noise (m), deterministic.
cv::Mat terrain(cv::Size size, double slope, double noise = 0.0, int seed = 1) {
  cv::Mat dem(size, CV_32F);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      dem.at<float>(y, x) = static_cast<float>(100.0 + slope * kGsd * x + rng.gaussian(noise));
    }
  }
  return dem;
}

// Raises `box` by `height` metres over the terrain (a flat roof at the terrain's top there).
void addBox(cv::Mat& dem, const cv::Mat& ground, const cv::Rect& box, float height) {
  double top = -1e9;
  for (int y = box.y; y < box.br().y; ++y) {
    for (int x = box.x; x < box.br().x; ++x) top = std::max(top, static_cast<double>(ground.at<float>(y, x)));
  }
  dem(box).setTo(cv::Scalar(top + height));
}

// The wall left of `box` as the left view sees it: a ramp of `step` m per px from the ground up
// to the roof (walls are ramps of small steps in left-image geometry).
void addWallRamp(cv::Mat& dem, const cv::Mat& ground, const cv::Rect& box, float step) {
  for (int y = box.y; y < box.br().y; ++y) {
    const float roof = dem.at<float>(y, box.x);
    for (int i = 1; i <= box.x; ++i) {
      const int x = box.x - i;
      const float h = roof - step * static_cast<float>(i);
      if (h <= ground.at<float>(y, x)) break;
      dem.at<float>(y, x) = h;
    }
  }
}

// A tree crown: a dome of `height` m and `radius` px over the terrain.
void addCrown(cv::Mat& dem, const cv::Mat& ground, cv::Point centre, int radius, float height) {
  for (int y = centre.y - radius; y <= centre.y + radius; ++y) {
    for (int x = centre.x - radius; x <= centre.x + radius; ++x) {
      const double r2 = (cv::Point(x, y) - centre).ddot(cv::Point(x, y) - centre) / double(radius * radius);
      if (r2 < 1.0) dem.at<float>(y, x) = ground.at<float>(y, x) + height * static_cast<float>(std::sqrt(1.0 - r2));
    }
  }
}

int countAbove(const GroundResult& r, const cv::Rect& area) { return cv::countNonZero(r.aboveGround(area)); }

// RMS of DTM - ground over the pixels where `mask` is 0 (ground) and both are finite.
double dtmRms(const GroundResult& r, const cv::Mat& ground, const cv::Mat& objectMask) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < ground.rows; ++y) {
    for (int x = 0; x < ground.cols; ++x) {
      if (objectMask.at<unsigned char>(y, x)) continue;
      const double d = r.dtm.at<float>(y, x) - ground.at<float>(y, x);
      if (!std::isfinite(d)) return std::numeric_limits<double>::infinity();
      sum += d * d;
      ++n;
    }
  }
  return std::sqrt(sum / n);
}

bool allFinite(const cv::Mat& m) { return cv::checkRange(m, true, nullptr, -1e9, 1e9); }

}  // namespace

TEST(SegmentGround, FlatNoisyPlaneHasNoAboveGround) {
  const cv::Mat dem = terrain({200, 160}, 0.0, 0.05);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(r.status, core::RunStatus::Completed);
  EXPECT_EQ(cv::countNonZero(r.aboveGround), 0);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(dtmRms(r, terrain({200, 160}, 0.0), cv::Mat::zeros(dem.size(), CV_8U)), 0.1);
  ASSERT_EQ(r.ndsm.type(), CV_32F);
  EXPECT_TRUE(allFinite(r.ndsm));
}

TEST(SegmentGround, SlopedPlaneWithOneBoxFindsTheBoxAndFollowsTheSlope) {
  const cv::Mat ground = terrain({240, 200}, 0.10);
  cv::Mat dem = ground.clone();
  const cv::Rect box(100, 70, 48, 40);
  addBox(dem, ground, box, 8.0f);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(countAbove(r, box), box.area());
  EXPECT_EQ(cv::countNonZero(r.aboveGround) - countAbove(r, box), 0) << "ground pixels labelled above";
  cv::Mat objects = cv::Mat::zeros(dem.size(), CV_8U);
  objects(box).setTo(255);
  EXPECT_LT(dtmRms(r, ground, objects), 0.05);
  // Under the box the DTM is the slope, so the nDSM is the box's height over each pixel's ground.
  const double expected = dem.at<float>(box.y, box.x) - ground.at<float>(box.y + 20, box.x + 24);
  EXPECT_NEAR(r.ndsm.at<float>(box.y + 20, box.x + 24), expected, 0.1);
  EXPECT_TRUE(r.converged);
}

TEST(SegmentGround, BuildingLargerThanTheDtmWindowIsFound) {
  // 40 m x 30 m roof with 20 m DTM windows: in the first round the DTM runs over the roof; the
  // neighbours' term has to pull the roof out, then the next DTM passes under it.
  const cv::Mat ground = terrain({320, 260}, 0.10);
  cv::Mat dem = ground.clone();
  const cv::Rect box(80, 70, 160, 120);
  addBox(dem, ground, box, 6.0f);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(countAbove(r, box), box.area());
  EXPECT_EQ(cv::countNonZero(r.aboveGround), box.area());
  EXPECT_GE(r.iterations, 2);
}

TEST(SegmentGround, WallsSeenObliquelyDoNotJoinRoofsToTheGround) {
  // Ramps of 1 m per px from the ground to each roof (steps at the region threshold): grown
  // through, roof and ground would be one region.
  const cv::Mat ground = terrain({300, 220}, 0.10);
  cv::Mat dem = ground.clone();
  const cv::Rect a(60, 40, 60, 50), b(180, 120, 80, 60);
  addBox(dem, ground, a, 9.0f);
  addBox(dem, ground, b, 12.0f);
  addWallRamp(dem, ground, a, 0.95f);
  addWallRamp(dem, ground, b, 0.95f);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(countAbove(r, a), a.area());
  EXPECT_EQ(countAbove(r, b), b.area());
}

TEST(SegmentGround, SceneOfBuildingsAndTreesOnASlopeKeepsItsGround) {
  // Many neighbours of the one large ground region: its own height over the DTM must still
  // weigh against them (a region's data term counts once per link).
  const cv::Mat ground = terrain({400, 300}, 0.10, 0.02, 9);
  cv::Mat dem = ground.clone();
  cv::Mat truth(dem.size(), CV_8U, cv::Scalar(0));
  const cv::Rect boxes[] = {{40, 30, 70, 50}, {160, 40, 60, 90}, {280, 30, 80, 60}, {60, 170, 90, 70}, {250, 180, 100, 80}};
  float height = 6.0f;
  for (const cv::Rect& box : boxes) {
    addBox(dem, ground, box, height);
    addWallRamp(dem, ground, box, 0.95f);
    truth(box).setTo(255);
    height += 2.5f;
  }
  const cv::Point crowns[] = {{130, 150}, {200, 250}, {370, 150}, {20, 280}, {230, 160}};
  for (const cv::Point& c : crowns) {
    addCrown(dem, ground, c, 14, 7.0f);
    cv::circle(truth, c, 12, cv::Scalar(255), cv::FILLED);
  }
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  const int found = cv::countNonZero(r.aboveGround & truth), all = cv::countNonZero(truth);
  cv::Mat nearObjects;
  cv::dilate(truth, nearObjects, cv::Mat::ones(45, 45, CV_8U));  // walls: ramps up to 20 px long
  const int farFalse = cv::countNonZero(r.aboveGround & ~nearObjects);
  EXPECT_GT(found, 0.97 * all);
  EXPECT_EQ(farFalse, 0) << "above-ground far from every object";
  EXPECT_LT(dtmRms(r, ground, nearObjects), 0.1);
}

TEST(SegmentGround, AdjacentBuildingsOfDifferentHeightsAreBothAboveGround) {
  const cv::Mat ground = terrain({260, 200}, 0.05);
  cv::Mat dem = ground.clone();
  const cv::Rect low(60, 60, 60, 70), high(120, 60, 50, 70);  // touching along x = 120
  addBox(dem, ground, low, 4.0f);
  addBox(dem, ground, high, 15.0f);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(countAbove(r, low), low.area());
  EXPECT_EQ(countAbove(r, high), high.area());
  EXPECT_EQ(cv::countNonZero(r.aboveGround), low.area() + high.area());
}

TEST(SegmentGround, RoofSuperstructureOnlyTouchingTheRoofIsAboveGround) {
  const cv::Mat ground = terrain({200, 200}, 0.0);
  cv::Mat dem = ground.clone();
  const cv::Rect roof(50, 50, 100, 100), chimney(90, 90, 12, 12);
  addBox(dem, ground, roof, 7.0f);
  addBox(dem, ground, chimney, 10.0f);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(countAbove(r, roof), roof.area());
}

TEST(SegmentGround, LowObjectUnderTheCriticalHeightStaysGround) {
  const cv::Mat ground = terrain({200, 200}, 0.0);
  cv::Mat dem = ground.clone();
  const cv::Rect wall(60, 60, 40, 40);
  addBox(dem, ground, wall, 1.5f);  // a step over δ_g but under δ_0
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(cv::countNonZero(r.aboveGround), 0);
}

TEST(SegmentGround, NoDataAlongWallsIsKeptUnlabelledAndTheDtmCoversIt) {
  const cv::Mat ground = terrain({240, 200}, 0.10);
  cv::Mat dem = ground.clone();
  const cv::Rect box(80, 60, 60, 60);
  addBox(dem, ground, box, 10.0f);
  // Occlusions along the rows: 10 px of no data right of the box, 4 px left of it.
  const cv::Rect rightGap(box.br().x, box.y, 10, box.height), leftGap(box.x - 4, box.y, 4, box.height);
  dem(rightGap).setTo(kNaN);
  dem(leftGap).setTo(kNaN);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(countAbove(r, box), box.area());
  EXPECT_EQ(cv::countNonZero(r.aboveGround), box.area());
  EXPECT_EQ(cv::countNonZero(r.regions(rightGap) >= 0), 0) << "kept gap pixels have no region";
  EXPECT_GT(r.keptGapPixels, 0);
  EXPECT_TRUE(allFinite(r.dtm));
  EXPECT_NEAR(r.dtm.at<float>(rightGap.y + 30, rightGap.x + 5), ground.at<float>(rightGap.y + 30, rightGap.x + 5), 0.1);
  EXPECT_TRUE(std::isnan(r.ndsm.at<float>(rightGap.y + 30, rightGap.x + 5)));
}

TEST(SegmentGround, UnmatchedPatchInsideARoofJoinsIt) {
  // A roof of two levels (10 m and 13 m) with a hole of no data across its step: the hole's
  // border spreads over 3 m, so the gap is kept, and all of its border is above-ground.
  const cv::Mat ground = terrain({240, 200}, 0.0);
  cv::Mat dem = ground.clone();
  const cv::Rect box(60, 50, 120, 100), upper(120, 50, 60, 100), hole(105, 80, 30, 30);
  addBox(dem, ground, box, 10.0f);
  addBox(dem, ground, upper, 13.0f);
  dem(hole).setTo(kNaN);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_GT(r.keptGapPixels, 0);
  EXPECT_EQ(countAbove(r, box), box.area());
  EXPECT_EQ(cv::countNonZero(r.regions(hole) < 0), 0) << "the patch takes its border's region";
  GroundParams unlabelled;
  unlabelled.gapAboveShare = 1.0;
  const GroundResult kept = segmentGround(dem, kGsd, unlabelled);
  EXPECT_EQ(countAbove(kept, box), box.area() - hole.area());
}

TEST(SegmentGround, GapSpanningARoofAndTheGroundIsSplitAtTheNearestHeight) {
  // One unmatched strip crosses the roof's right half and runs 20 px onto the ground beside it:
  // most of its border is roof, so it is labelled, but its ground part stays ground.
  const cv::Mat ground = terrain({240, 200}, 0.0);
  cv::Mat dem = ground.clone();
  const cv::Rect box(40, 40, 120, 120), hole(100, 85, 80, 30);
  addBox(dem, ground, box, 10.0f);
  dem(hole).setTo(kNaN);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(countAbove(r, box), box.area()) << "the roof's unmatched part joins it";
  const cv::Rect street(box.br().x + 6, hole.y, hole.br().x - box.br().x - 6, hole.height);
  EXPECT_EQ(cv::countNonZero(r.aboveGround(street)), 0) << "the part beyond the roof's edge is ground's";
}

TEST(SegmentGround, OcclusionLeftOfARoofStaysUnlabelledInAJoinedGap) {
  // The strip left of a roof that the right view cannot see (x_right = x_left - d) is joined,
  // through a slab of unmatched roof, to a gap mostly bordered by the roof. By nearest height its
  // right half would be roof; along the rows it runs from the ground to a surface 10 m higher:
  // hidden ground, left unlabelled.
  const cv::Mat ground = terrain({240, 200}, 0.0);
  cv::Mat dem = ground.clone();
  const cv::Rect box(80, 50, 120, 100), strip(60, 50, 20, 100), slab(80, 60, 60, 20);
  addBox(dem, ground, box, 10.0f);
  dem(strip).setTo(kNaN);
  dem(slab).setTo(kNaN);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  const cv::Rect stripBelowSlab(strip.x, slab.br().y, strip.width, strip.br().y - slab.br().y);
  EXPECT_EQ(cv::countNonZero(r.aboveGround(stripBelowSlab)), 0) << "the occlusion is not the roof's";
  EXPECT_EQ(cv::countNonZero(r.aboveGround(box)), box.area() - slab.area())
      << "rows from the ground into the roof's gap stay unlabelled as a whole";
}

TEST(SegmentGround, TwoBuildingsAcrossAnUnmatchedStreetStayApart) {
  // Roofs at 10 m and 13 m face each other across a 20 px street without heights: the gap's
  // border is mostly roof, so it is labelled from its nearest heights, but a seam stays
  // unlabelled where the two roofs' parts meet, and the mask keeps two objects.
  const cv::Mat ground = terrain({240, 200}, 0.0);
  cv::Mat dem = ground.clone();
  const cv::Rect left(40, 50, 60, 100), right(120, 50, 60, 100), street(100, 50, 20, 100);
  addBox(dem, ground, left, 10.0f);
  addBox(dem, ground, right, 13.0f);
  dem(street).setTo(kNaN);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(countAbove(r, left) + countAbove(r, right), left.area() + right.area());
  EXPECT_GT(countAbove(r, street), street.area() / 2) << "the street's gap is labelled";
  cv::Mat components;
  EXPECT_EQ(cv::connectedComponents(r.aboveGround, components, 8), 3) << "background and two objects";
}

TEST(SegmentGround, BoxSeparatedFromTheGroundOnlyByGapsIsFound) {
  // A box ringed by no data: only the links across the gaps make it the ground's neighbour.
  const cv::Mat ground = terrain({200, 200}, 0.0);
  cv::Mat dem = ground.clone();
  const cv::Rect ring(40, 40, 120, 120), box(50, 50, 100, 100);  // bigger than the DTM window
  dem(ring).setTo(kNaN);
  addBox(dem, ground, box, 9.0f);
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(countAbove(r, box), box.area());
  EXPECT_EQ(cv::countNonZero(r.aboveGround), box.area());
  EXPECT_EQ(r.gapLinks, 1);
}

TEST(SegmentGround, DemWithManyGapsGivesAFullDtm) {
  cv::Mat dem = terrain({300, 240}, 0.10, 0.1, 3);
  const cv::Mat ground = dem.clone();
  addBox(dem, ground, cv::Rect(50, 40, 60, 50), 9.0f);
  addBox(dem, ground, cv::Rect(180, 120, 70, 80), 12.0f);
  cv::RNG rng(5);
  for (int i = 0; i < 6000; ++i) dem.at<float>(rng.uniform(0, dem.rows), rng.uniform(0, dem.cols)) = kNaN;
  for (int i = 0; i < 40; ++i) {
    const cv::Rect hole(rng.uniform(0, 280), rng.uniform(0, 220), rng.uniform(2, 20), rng.uniform(2, 20));
    dem(hole & cv::Rect(0, 0, dem.cols, dem.rows)).setTo(kNaN);
  }
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_TRUE(allFinite(r.dtm));
  EXPECT_GT(countAbove(r, cv::Rect(60, 50, 40, 30)), 1000);
  EXPECT_GT(countAbove(r, cv::Rect(190, 130, 50, 60)), 2500);
}

TEST(SegmentGround, AllNoDataGivesAnEmptyResult) {
  const cv::Mat dem(50, 60, CV_32F, cv::Scalar(kNaN));
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(r.status, core::RunStatus::Completed);
  EXPECT_EQ(r.regionCount, 0);
  EXPECT_EQ(cv::countNonZero(r.aboveGround), 0);
  EXPECT_EQ(cv::countNonZero(r.regions >= 0), 0);
  EXPECT_EQ(cv::countNonZero(core::numberMask(r.dtm)), 0) << "no ground: the DTM is NaN";
}

TEST(SegmentGround, SingleValidPixelIsGroundAndGivesALevelDtm) {
  cv::Mat dem(40, 30, CV_32F, cv::Scalar(kNaN));
  dem.at<float>(10, 12) = 42.0f;
  const GroundResult r = segmentGround(dem, kGsd, GroundParams{});
  EXPECT_EQ(r.regionCount, 1);
  EXPECT_EQ(r.regions.at<int>(10, 12), 0);
  EXPECT_EQ(cv::countNonZero(r.aboveGround), 0);
  EXPECT_FLOAT_EQ(r.dtm.at<float>(0, 0), 42.0f);
  EXPECT_FLOAT_EQ(r.dtm.at<float>(39, 29), 42.0f);
}

TEST(SegmentGround, BadInputsAreClearErrors) {
  const cv::Mat dem = terrain({20, 20}, 0.0);
  auto code = [](auto&& call) {
    try {
      call();
    } catch (const core::Error& e) {
      EXPECT_FALSE(std::string(e.what()).empty());
      return e.code();
    }
    return core::ErrorCode::ProcessingFailed;  // no error: a failure of the test
  };
  EXPECT_EQ(code([&] { segmentGround(cv::Mat(), kGsd, {}); }), core::ErrorCode::UnsupportedInput);
  EXPECT_EQ(code([&] { segmentGround(cv::Mat(5, 5, CV_8U, cv::Scalar(1)), kGsd, {}); }),
            core::ErrorCode::UnsupportedInput);
  EXPECT_EQ(code([&] { segmentGround(cv::Mat(5, 5, CV_32FC2, cv::Scalar(1, 1)), kGsd, {}); }),
            core::ErrorCode::UnsupportedInput);
  cv::Mat infinite = dem.clone();
  infinite.at<float>(3, 3) = std::numeric_limits<float>::infinity();
  EXPECT_EQ(code([&] { segmentGround(infinite, kGsd, {}); }), core::ErrorCode::UnsupportedInput);
  EXPECT_EQ(code([&] { segmentGround(dem, 0.0, {}); }), core::ErrorCode::InvalidParameter);
  EXPECT_EQ(code([&] { segmentGround(dem, -1.0, {}); }), core::ErrorCode::InvalidParameter);
  EXPECT_EQ(code([&] { segmentGround(dem, std::nan(""), {}); }), core::ErrorCode::InvalidParameter);
  GroundParams p;
  p.criticalHeight = 1.5;  // < 2 δ_g
  EXPECT_EQ(code([&] { segmentGround(dem, kGsd, p); }), core::ErrorCode::InvalidParameter);
  p = {};
  p.dataWeight = 1.5;
  EXPECT_EQ(code([&] { segmentGround(dem, kGsd, p); }), core::ErrorCode::InvalidParameter);
  p = {};
  p.maxIterations = 0;
  EXPECT_EQ(code([&] { segmentGround(dem, kGsd, p); }), core::ErrorCode::InvalidParameter);
  p = {};
  p.gaps.minBorderPixels = 0;
  EXPECT_EQ(code([&] { segmentGround(dem, kGsd, p); }), core::ErrorCode::InvalidParameter);
}

TEST(SegmentGround, CancelReturnsCanceled) {
  const cv::Mat dem = terrain({100, 100}, 0.1);
  core::Progress progress;
  progress.cancel();
  EXPECT_EQ(segmentGround(dem, kGsd, GroundParams{}, &progress).status, core::RunStatus::Canceled);
  core::Progress late;
  late.cancelAfterReports(3);
  EXPECT_EQ(segmentGround(dem, kGsd, GroundParams{}, &late).status, core::RunStatus::Canceled);
}

TEST(SegmentGround, ParamsRoundTripThroughJson) {
  GroundParams p;
  p.dtmWindow = 35.0;
  p.gaps.maxBorderSpread = 0.5;
  GroundParams q;
  core::fromJson(q, core::toJson(p));
  EXPECT_EQ(q.dtmWindow, 35.0);
  EXPECT_EQ(q.gaps.maxBorderSpread, 0.5);
}

TEST(SegmentGround, SimulatedSlopedSceneFromItsTrueDem) {
  // The simulator's small scene (10 % slope, two buildings, two trees; walls seen obliquely):
  // with the plain sum of data potentials the one large ground region, linked to every object,
  // followed its neighbours and the whole scene came out above-ground.
  sim::SceneParams sp;
  sp.width = 240;
  sp.height = 200;
  sp.buildings = 2;
  sp.trees = 2;
  sp.slope = 10.0;
  const sim::Scene scene = sim::simulateScene(sp);
  const GroundResult r = segmentGround(scene.dem, scene.gsd, GroundParams{});
  int truth = 0, hit = 0, predicted = 0, wrong = 0;
  for (int y = 0; y < scene.dem.rows; ++y) {
    for (int x = 0; x < scene.dem.cols; ++x) {
      const int label = scene.labels.at<unsigned char>(y, x);
      if (label == sim::kLabelFacade) continue;  // walls: neither ground nor roof
      const bool above = r.aboveGround.at<unsigned char>(y, x) != 0;
      truth += label != sim::kLabelGround;
      hit += above && label != sim::kLabelGround;
      predicted += above;
      wrong += above && label == sim::kLabelGround;
    }
  }
  EXPECT_GT(hit, 0.95 * truth);
  EXPECT_LT(wrong, 0.05 * predicted);
}
