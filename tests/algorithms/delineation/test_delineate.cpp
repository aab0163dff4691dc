#include <limits>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/stereo/cost_service.hpp"

using namespace delineo;
using namespace delineo::delineation;

namespace {

cv::Mat texture(cv::Size size, double mean, double contrast, int seed) {
  cv::Mat t(size, CV_32F);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(t, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(t, t, {0, 0}, 1.2);
  cv::Scalar m, s;
  cv::meanStdDev(t, m, s);
  return (t - m[0]) * (contrast / s[0]) + mean;
}

// A flat roof [x0, x1) x [y0, y1) at disparity dr on flat ground at dg, left view vertical
// (no walls seen), right view with x_right = x_left - d: it sees the east wall and loses the
// ground strip [x0 - (dr - dg), x0) behind the roof.
struct Pair {
  cv::Mat left, right;
  core::Polygon truth;
};

// `lineRow` >= 0 paints a bright 2-row line across the ground, over the whole width (a road
// marking, a shadow or a wall edge passing by the building). A non-empty `notch` (touching the
// roof's top-right corner) is cut out of the roof: an L-shaped building.
Pair raisedRoof(cv::Size size, cv::Rect roof, int dr, int dg, int lineRow = -1, cv::Rect notch = {}) {
  cv::Mat ground = texture(size + cv::Size(64, 0), 100, 25, 1);
  if (lineRow >= 0) ground(cv::Rect(0, lineRow, ground.cols, 2)).setTo(230.0f);
  const cv::Mat top = texture(size + cv::Size(64, 0), 160, 25, 2);
  const cv::Mat wall = texture(size + cv::Size(64, 0), 60, 10, 3);
  auto onRoof = [&](int x, int y) { return roof.contains({x, y}) && !notch.contains({x, y}); };
  Pair p;
  p.left.create(size, CV_32F);
  p.right.create(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    // East edge of the roof on this row (the notch only shortens rows from the east).
    const int east = notch.contains({notch.x, y}) ? notch.x : roof.br().x;
    for (int x = 0; x < size.width; ++x) {
      p.left.at<float>(y, x) = onRoof(x, y) ? top.at<float>(y, x) : ground.at<float>(y, x);
      const int xr = x;  // right pixel
      const int xRoof = xr + dr, xGround = xr + dg;
      float v;
      if (onRoof(xRoof, y)) v = top.at<float>(y, xRoof);
      else if (y >= roof.y && y < roof.br().y && xGround < east && xRoof >= east)
        v = wall.at<float>(y, xGround);  // east wall between the roof edge and the ground
      else v = ground.at<float>(y, std::clamp(xGround, 0, size.width + 63));
      p.right.at<float>(y, x) = 0.95f * v + 4.0f;
    }
  }
  const double x0 = roof.x, y0 = roof.y, x1 = roof.br().x, y1 = roof.br().y;
  if (notch.empty()) {
    p.truth.outer = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  } else {
    const double nx = notch.x, ny = notch.br().y;
    p.truth.outer = {{x0, y0}, {nx, y0}, {nx, ny}, {x1, ny}, {x1, y1}, {x0, y1}};
  }
  return p;
}

double iou(const core::Polygon& a, const core::Polygon& b, cv::Size size) {
  const cv::Mat ma = core::rasterize(a, size), mb = core::rasterize(b, size);
  return double(cv::countNonZero(ma & mb)) / cv::countNonZero(ma | mb);
}

core::Polygon grownBox(cv::Rect r, int g) {
  return core::Polygon{{{double(r.x - g), double(r.y - g)}, {double(r.br().x + g), double(r.y - g)},
                        {double(r.br().x + g), double(r.br().y + g)}, {double(r.x - g), double(r.br().y + g)}},
                       {}};
}

// The request for a raisedRoof(…, 14, 4) pair: the roof's box grown by 8 px, the roof interval
// around 14 px and the ground around 4 px.
DelineationRequest raisedRoofRequest(const cv::Rect& roof) {
  DelineationRequest req;
  req.init = grownBox(roof, 8);
  req.roof = {13, 15};
  req.ground = DisparityInterval{3, 5};
  return req;
}

}  // namespace

TEST(Delineate, ConvergesOnASyntheticPairWithGivenGround) {
  const cv::Rect roof(50, 40, 60, 50);
  const Pair pair = raisedRoof({170, 140}, roof, 14, 4);
  DelineationRequest req = raisedRoofRequest(roof);
  int reports = 0;
  const auto r = delineate(pair.left, pair.right, req, DelineationParams{},
                           [&](const IterationReport&) { ++reports; });
  EXPECT_EQ(r.status, core::RunStatus::Completed);
  EXPECT_GT(iou(r.polygon, pair.truth, pair.left.size()), 0.9);
  EXPECT_GT(reports, 0);
  EXPECT_GE(r.vertexCount, 4);
}

// Largest distance of a polygon vertex outside the rectangle.
double farthestOutside(const core::Polygon& p, cv::Rect r) {
  double far = 0;
  for (const auto& v : p.outer) {
    const double dx = std::max({r.x - v.x, 0.0, v.x - r.br().x});
    const double dy = std::max({r.y - v.y, 0.0, v.y - r.br().y});
    far = std::max(far, std::hypot(dx, dy));
  }
  return far;
}

TEST(Delineate, DoesNotFollowAStrongLineLeavingTheRoof) {
  // The edge terms reward contour length along any gradient: with the paper's plain terms a
  // thin finger along the line (both sides on the line; a horizontal line is ambiguous in
  // disparity, so its area costs nothing) runs to the ROI border.
  const cv::Rect roof(50, 40, 60, 50);
  // The line crosses the ROI 10 px above the roof (2 px beyond the init's top edge).
  const Pair pair = raisedRoof({200, 140}, roof, 14, 4, roof.y - 10);
  DelineationRequest req = raisedRoofRequest(roof);
  const auto r = delineate(pair.left, pair.right, req, DelineationParams{});
  EXPECT_GT(iou(r.polygon, pair.truth, pair.left.size()), 0.9);
  EXPECT_LT(farthestOutside(r.polygon, roof), 4.0);
  // The same without the leash (max-excursion): the gate, shape limits and shortcuts suffice.
  DelineationParams unleashed;
  unleashed.maxExcursion = unleashed.roiMargin;
  const auto free = delineate(pair.left, pair.right, req, unleashed);
  EXPECT_LT(farthestOutside(free.polygon, roof), 4.0);
  // The paper's plain terms and moves (per-pixel costs, constant band cost; no gate, shape limits,
  // shortcuts, leash or region stage): the defect is there.
  DelineationParams plain = unleashed;
  plain.edgeContrast = 0;
  plain.minAngle = 0;
  plain.minGap = 0;
  plain.shortcutVertices = 0;
  plain.regionInit = false;
  plain.costAggregation = 1;
  plain.costCap = 0;
  plain.costBrightness = 0;
  const auto spiky = delineate(pair.left, pair.right, req, plain);
  EXPECT_GT(farthestOutside(spiky.polygon, roof), 10.0);
}

TEST(Delineate, CarvesTheNotchOfAnLShapedRoofFromABox) {
  // From the bounding box the notch covers 54 % of the box. On this high-contrast pair local
  // moves carve most of it too (IoU 0.952 without the region stage, 0.956 with it); on the
  // simulator's scenes the region stage matters more (docs/delineation.md).
  const cv::Rect roof(50, 40, 90, 80);
  const cv::Rect notch(75, 40, 65, 60);  // leaves a 25 px wide arm and a 20 px wide base
  const Pair pair = raisedRoof({210, 170}, roof, 14, 4, -1, notch);
  DelineationRequest req = raisedRoofRequest(roof);
  const auto r = delineate(pair.left, pair.right, req, DelineationParams{});
  EXPECT_GT(iou(r.polygon, pair.truth, pair.left.size()), 0.93);
}

TEST(Delineate, EstimatesTheGroundFromTheRing) {
  const cv::Rect roof(40, 30, 70, 60);
  const Pair pair = raisedRoof({160, 130}, roof, 18, 6);
  DelineationRequest req;
  req.init = grownBox(roof, 8);
  req.roof = {17, 19};
  const auto r = delineate(pair.left, pair.right, req, DelineationParams{});
  EXPECT_NEAR(0.5 * (r.ground.min + r.ground.max), 6.0, 1.0);
  EXPECT_GT(iou(r.polygon, pair.truth, pair.left.size()), 0.9);
}

TEST(Delineate, OcclusionBandLiesOnTheMinusXSideForRaisedRoofs) {
  const cv::Rect roof(50, 40, 60, 50);
  const Pair pair = raisedRoof({170, 140}, roof, 14, 4);
  DelineationRequest req = raisedRoofRequest(roof);
  const DelineationParams params;
  const cv::Rect roi = regionOfInterest(pair.left, pair.right, req, params);
  const auto costs = stereo::CorrelationCostService::compute(pair.left, pair.right, roi, 3, 15);
  const PreparedEnergy prepared = prepareEnergy(*costs, pair.left, pair.right, req, params);
  EXPECT_EQ(prepared.images.occlusionSide, -1);
  EXPECT_NEAR(prepared.roofDisparity, 14.0, 0.5);
  // The data agree: at the true outline, the band on the -x side explains the unmatched
  // strip better than the same band on the +x side.
  IntPolygon truth{{{roof.x - roi.x, roof.y - roi.y}, {roof.br().x - roi.x, roof.y - roi.y},
                    {roof.br().x - roi.x, roof.br().y - roi.y}, {roof.x - roi.x, roof.br().y - roi.y}},
                   {}};
  EnergyImages flipped = prepared.images;
  flipped.occlusionSide = +1;
  const EnergyWeights w{params.edgeWeight, params.rigidity};
  EXPECT_LT(referenceEnergy(prepared.images, w, truth).total(), referenceEnergy(flipped, w, truth).total());
}

TEST(Delineate, CancelReturnsThePolygonSoFar) {
  const cv::Rect roof(50, 40, 60, 50);
  const Pair pair = raisedRoof({170, 140}, roof, 14, 4);
  DelineationRequest req = raisedRoofRequest(roof);
  core::Progress counting;
  delineate(pair.left, pair.right, req, DelineationParams{}, {}, &counting);
  ASSERT_GT(counting.reportCount(), 4);
  core::Progress progress;
  progress.cancelAfterReports(counting.reportCount() / 2);
  const auto r = delineate(pair.left, pair.right, req, DelineationParams{}, {}, &progress);
  EXPECT_EQ(r.status, core::RunStatus::Canceled);
  EXPECT_GE(r.polygon.outer.size(), 3u);
  EXPECT_TRUE(core::isSimple(r.polygon.outer));
}

TEST(Delineate, KeepsExcludedPixelsOutEvenWhenTheyMatchTheRoofInterval) {
  // A 10 px strip south of the roof at the roof's disparity (a tree crown at roof height): the
  // correlation costs cannot tell it from the roof, an exclusion mask can.
  const cv::Rect roof(50, 40, 60, 50), strip(50, 90, 60, 10);
  const Pair pair = raisedRoof({170, 150}, roof | strip, 14, 4);
  const core::Polygon truth{{{50, 40}, {110, 40}, {110, 90}, {50, 90}}, {}};
  DelineationRequest req;
  req.init = grownBox(roof | strip, 6);
  req.roof = {13, 15};
  req.ground = DisparityInterval{3, 5};
  const double without = iou(delineate(pair.left, pair.right, req, DelineationParams{}).polygon,
                             truth, pair.left.size());
  req.excludeMask = cv::Mat::zeros(pair.left.size(), CV_8U);
  req.excludeMask(strip).setTo(255);
  const double with = iou(delineate(pair.left, pair.right, req, DelineationParams{}).polygon, truth,
                          pair.left.size());
  EXPECT_LT(without, 0.88);  // the strip is taken as roof
  EXPECT_GT(with, 0.95);
}

// Flat textured layers, each at its own disparity, the nearer (larger d) hiding the farther in
// both views; ground everywhere else. Left view vertical, x_right = x_left - d.
struct Layer {
  cv::Rect area;
  int disparity;
  cv::Mat texture;  // image size + 64 columns
};
// The pair of a layered scene, and its true disparity map as a perfect matcher would give it
// (the nearest layer, the largest disparity, in front).
struct LayeredScene {
  Pair pair;
  cv::Mat disparity;
};
LayeredScene layeredScene(cv::Size size, int groundDisparity, std::vector<Layer> layers) {
  const cv::Mat ground = texture(size + cv::Size(64, 0), 100, 25, 1);
  std::sort(layers.begin(), layers.end(),
            [](const Layer& a, const Layer& b) { return a.disparity > b.disparity; });
  auto sample = [&](int x, int y, int shift) {
    for (const Layer& l : layers) {
      if (l.area.contains({x + shift * l.disparity, y}))
        return l.texture.at<float>(y, x + shift * l.disparity);
    }
    return ground.at<float>(y, std::clamp(x + shift * groundDisparity, 0, ground.cols - 1));
  };
  Pair p;
  p.left.create(size, CV_32F);
  p.right.create(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      p.left.at<float>(y, x) = sample(x, y, 0);
      p.right.at<float>(y, x) = 0.95f * sample(x, y, 1) + 4.0f;
    }
  }
  cv::Mat map(size, CV_32F, cv::Scalar(static_cast<float>(groundDisparity)));
  for (auto l = layers.rbegin(); l != layers.rend(); ++l) {
    map(l->area & cv::Rect({}, size)).setTo(static_cast<float>(l->disparity));
  }
  return {p, map};
}

TEST(Delineate, KeepsWhatMatchesBetweenTheGroundAndTheRoofOut) {
  // A crown lower than the roof along its south side, as bright as the roof and textured like
  // it: the edge between them is weak, the crown's edge on the ground strong. Its pixels match
  // neither interval (the cost cap makes them neutral) but match a disparity between the two.
  const cv::Rect roof(50, 40, 60, 50), crown(50, 90, 60, 12);
  const cv::Size size(170, 150);
  const Pair pair = layeredScene(size, 4,
                                {{roof, 14, texture(size + cv::Size(64, 0), 160, 25, 2)},
                                 {crown, 9, texture(size + cv::Size(64, 0), 160, 25, 5)}})
                        .pair;
  const core::Polygon truth{{{50, 40}, {110, 40}, {110, 90}, {50, 90}}, {}};
  DelineationRequest req;
  req.init = grownBox(roof | crown, 6);
  req.roof = {13, 15};
  req.ground = DisparityInterval{3, 5};
  DelineationParams off;
  off.intermediateMargin = 0;
  const DelineationParams on;
  const double without = iou(delineate(pair.left, pair.right, req, off).polygon, truth, size);
  const double with = iou(delineate(pair.left, pair.right, req, on).polygon, truth, size);
  EXPECT_LT(without, 0.9) << "without the cue the crown is taken as roof";
  EXPECT_GT(with, 0.95) << "without " << without;

  // The excluded pixels: most of the crown, none of the roof away from its outline.
  const cv::Rect roi = regionOfInterest(pair.left, pair.right, req, on);
  stereo::CostParams costParams;
  costParams.window = on.costWindow;
  costParams.brightnessScale = on.costBrightness;
  const auto costs =
      stereo::CorrelationCostService::compute(pair.left, pair.right, roi, 3, 15, costParams);
  ASSERT_TRUE(costs);
  const PreparedEnergy prepared = prepareEnergy(*costs, pair.left, pair.right, req, on);
  const cv::Point o = roi.tl();
  const cv::Rect crownInside(crown.x + 3 - o.x, crown.y + 3 - o.y, crown.width - 6,
                             crown.height - 6);
  const cv::Rect roofInside(roof.x + 3 - o.x, roof.y + 3 - o.y, roof.width - 6, roof.height - 6);
  EXPECT_GT(cv::countNonZero(prepared.excluded(crownInside)), 0.7 * crownInside.area());
  EXPECT_EQ(cv::countNonZero(prepared.excluded(roofInside)), 0);
  const PreparedEnergy plain = prepareEnergy(*costs, pair.left, pair.right, req, off);
  EXPECT_EQ(cv::countNonZero(plain.excluded), 0);
}

// A smooth texture: NCC of a window degrades slowly with a wrong shift.
cv::Mat smoothTexture(cv::Size size, double mean, double contrast, int seed) {
  cv::Mat t = texture(size, 0, 1, seed);
  cv::GaussianBlur(t, t, {0, 0}, 3.0);
  cv::Scalar m, s;
  cv::meanStdDev(t, m, s);
  return (t - m[0]) * (contrast / s[0]) + mean;
}

TEST(Delineate, LeavesANeighbourAtAnotherHeightOutside) {
  // A taller block along the roof's south side, as bright as the roof, with a smooth texture:
  // at the roof's disparities it matches better than at the ground's (5 px off against 15), so
  // c_roof < c_ground there, and the operator's rectangle takes in part of it. The matcher's
  // map (here the true disparities) puts it at its own height: outside the roof interval.
  const cv::Rect roof(50, 40, 60, 50), neighbour(40, 90, 80, 30);
  const cv::Size size(180, 160);
  const std::vector<Layer> layers{{roof, 14, texture(size + cv::Size(64, 0), 160, 25, 2)},
                                  {neighbour, 19, smoothTexture(size + cv::Size(64, 0), 160, 25, 5)}};
  const auto [pair, disparity] = layeredScene(size, 4, layers);
  const core::Polygon truth{{{50, 40}, {110, 40}, {110, 90}, {50, 90}}, {}};
  DelineationRequest req;
  req.init = grownBox(cv::Rect(roof.x, roof.y, roof.width, roof.height + 20), 8);
  req.roof = {13, 15};
  req.ground = DisparityInterval{3, 5};
  req.searchRange = DisparityInterval{0, 28};
  req.disparity = disparity;
  DelineationParams off;
  off.mapCost = 0;
  const DelineationParams on;
  const double without = iou(delineate(pair.left, pair.right, req, off).polygon, truth, size);
  const double with = iou(delineate(pair.left, pair.right, req, on).polygon, truth, size);
  RecordProperty("iou_without", std::to_string(without));
  RecordProperty("iou_with", std::to_string(with));
  EXPECT_LT(without, 0.85) << "without the map's costs the neighbour is taken as roof";
  EXPECT_GT(with, 0.93) << "without " << without;
  // Without a map there is nothing to read: the outline is the correlation costs' one.
  DelineationRequest noMap = req;
  noMap.disparity.release();
  EXPECT_NEAR(iou(delineate(pair.left, pair.right, noMap, on).polygon, truth, size), without, 1e-9);
}

TEST(Delineate, TakesTheGroundFromTheMatchersMapWhenATallerNeighbourRingsTheInit) {
  // A taller block frames the roof just outside the operator's rectangle (a courtyard building):
  // the ring around the rectangle lies on it. The matcher's map shows the ground beyond it, as
  // the GUI's pick and histogram read it (estimateGroundLevel).
  const cv::Rect roof(70, 60, 60, 50);
  const cv::Size size(220, 190);
  const cv::Mat frameTexture = texture(size + cv::Size(64, 0), 130, 25, 7);
  const std::vector<cv::Rect> frame{{40, 30, 120, 22}, {40, 118, 120, 22}, {40, 52, 22, 66}, {138, 52, 22, 66}};
  std::vector<Layer> layers{{roof, 14, texture(size + cv::Size(64, 0), 160, 25, 2)}};
  for (const cv::Rect& r : frame) layers.push_back({r, 22, frameTexture});
  const auto [pair, disparity] = layeredScene(size, 4, layers);
  const core::Polygon truth{{{70, 60}, {130, 60}, {130, 110}, {70, 110}}, {}};
  DelineationRequest req;
  req.init = grownBox(roof, 8);
  req.roof = {13, 15};
  req.searchRange = DisparityInterval{0, 28};
  req.disparity = disparity;
  const auto withMap = delineate(pair.left, pair.right, req, DelineationParams{});
  EXPECT_NEAR(0.5 * (withMap.ground.min + withMap.ground.max), 4.0, 1.0);
  EXPECT_GT(iou(withMap.polygon, truth, size), 0.9);
  // Without the map the ring's median is the frame's disparity, above the roof.
  DelineationRequest noMap = req;
  noMap.disparity.release();
  const auto ring = delineate(pair.left, pair.right, noMap, DelineationParams{});
  EXPECT_GT(ring.ground.min, req.roof.max);
}

TEST(Delineate, ASuperstructureAboveTheRoofIsNoCourtyard) {
  // A plant room 4 px above a flat roof: the map puts it off the roof interval, as it does a
  // courtyard floor, but above the roof. The footprint keeps it.
  const cv::Rect roof(50, 40, 80, 60), plant(80, 60, 22, 22);
  const cv::Size size(190, 150);
  const std::vector<Layer> layers{{roof, 14, texture(size + cv::Size(64, 0), 160, 25, 2)},
                                  {plant, 18, texture(size + cv::Size(64, 0), 120, 25, 3)}};
  const auto [pair, disparity] = layeredScene(size, 4, layers);
  const core::Polygon truth{{{50, 40}, {130, 40}, {130, 100}, {50, 100}}, {}};
  DelineationRequest req = raisedRoofRequest(roof);
  req.searchRange = DisparityInterval{0, 28};
  req.disparity = disparity;
  const auto r = delineate(pair.left, pair.right, req, DelineationParams{});
  EXPECT_TRUE(r.polygon.holes.empty()) << r.polygon.holes.size() << " holes";
  EXPECT_GT(iou(r.polygon, truth, size), 0.93);
}

TEST(Delineate, RejectsBadInputs) {
  const cv::Rect roof(50, 40, 60, 50);
  const Pair pair = raisedRoof({170, 140}, roof, 14, 4);
  DelineationRequest ok;
  ok.init = grownBox(roof, 8);
  ok.roof = {13, 15};
  const DelineationParams params;
  auto expectCode = [&](const DelineationRequest& req, core::ErrorCode code, const cv::Mat& right) {
    try {
      regionOfInterest(pair.left, right, req, params);
      ADD_FAILURE() << "no error";
    } catch (const core::Error& e) {
      EXPECT_EQ(e.code(), code) << e.what();
    }
  };
  DelineationRequest outside = ok;
  outside.init = grownBox(cv::Rect(150, 100, 60, 60), 0);
  expectCode(outside, core::ErrorCode::InvalidParameter, pair.right);
  DelineationRequest empty = ok;
  empty.roof = {15, 13};
  expectCode(empty, core::ErrorCode::InvalidParameter, pair.right);
  DelineationRequest beyond = ok;
  beyond.searchRange = DisparityInterval{0, 12};
  expectCode(beyond, core::ErrorCode::InvalidParameter, pair.right);
  DelineationRequest degenerate = ok;
  degenerate.init.outer = {{10, 10}, {20, 20}, {30, 30}};
  expectCode(degenerate, core::ErrorCode::InvalidParameter, pair.right);
  expectCode(ok, core::ErrorCode::MismatchedInputs, pair.right(cv::Rect(0, 0, 100, 100)));
  DelineationRequest smallMask = ok;
  smallMask.excludeMask = cv::Mat::zeros(100, 100, CV_8U);
  expectCode(smallMask, core::ErrorCode::MismatchedInputs, pair.right);
  DelineationRequest smallMap = ok;
  smallMap.disparity = cv::Mat::zeros(100, 100, CV_32F);
  expectCode(smallMap, core::ErrorCode::MismatchedInputs, pair.right);
  DelineationRequest intMap = ok;
  intMap.disparity = cv::Mat::zeros(pair.left.size(), CV_16S);
  expectCode(intMap, core::ErrorCode::MismatchedInputs, pair.right);
  // A roof is nearer than its ground: a ground interval at or above the roof's is refused.
  DelineationRequest groundAbove = ok;
  groundAbove.ground = DisparityInterval{20, 24};
  expectCode(groundAbove, core::ErrorCode::InvalidParameter, pair.right);
  DelineationRequest groundOverlap = ok;
  groundOverlap.ground = DisparityInterval{10, 13};
  expectCode(groundOverlap, core::ErrorCode::InvalidParameter, pair.right);
  // Nothing to delineate: no data under the polygon, or all of it excluded.
  const cv::Mat noData(pair.left.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  try {
    regionOfInterest(noData, pair.right, ok, params);
    ADD_FAILURE() << "an all-NaN left image was accepted";
  } catch (const core::Error& e) {
    EXPECT_EQ(e.code(), core::ErrorCode::UnsupportedInput) << e.what();
  }
  expectCode(ok, core::ErrorCode::UnsupportedInput, noData);
  DelineationRequest allExcluded = ok;
  allExcluded.excludeMask = cv::Mat(pair.left.size(), CV_8U, cv::Scalar(255));
  expectCode(allExcluded, core::ErrorCode::InvalidParameter, pair.right);
  EXPECT_NO_THROW(regionOfInterest(pair.left, pair.right, ok, params));
  // The cost box filter is centred: an even side is rejected.
  DelineationParams even;
  even.costAggregation = 4;
  EXPECT_THROW(even.validate(), core::Error);
  even.costAggregation = 1;
  EXPECT_NO_THROW(even.validate());
}

TEST(Delineate, BalancedCostIntervalsHaveEqualWidthsAndGrowAwayFromEachOther) {
  // Flat roof above the ground: the roof interval grows upwards to the ground's 7 disparities.
  auto [roof, ground] = costIntervals({40, 41}, {5, 11}, true);
  EXPECT_EQ(roof.min, 40);
  EXPECT_EQ(roof.max, 46);
  EXPECT_EQ(ground.min, 5);
  EXPECT_EQ(ground.max, 11);
  // Gable roof wider than the ground interval: the ground grows downwards.
  std::tie(roof, ground) = costIntervals({30, 41}, {5, 11}, true);
  EXPECT_EQ(roof.min, 30);
  EXPECT_EQ(roof.max, 41);
  EXPECT_EQ(ground.max - ground.min, roof.max - roof.min);
  EXPECT_EQ(ground.max, 11);
  // Roof below the ground (x_right = x_left - d with negative heights): directions reverse.
  std::tie(roof, ground) = costIntervals({-20, -20}, {0, 4}, true);
  EXPECT_EQ(roof.min, -24);
  EXPECT_EQ(roof.max, -20);
  // Balance off: the intervals are returned as given.
  std::tie(roof, ground) = costIntervals({40, 41}, {5, 11}, false);
  EXPECT_EQ(roof.max, 41);
  EXPECT_EQ(ground.min, 5);
}

// A raised roof (disparity 14 over ground 4) with its grown-box request and the cost service of
// its ROI: the set-up of the tests that inspect the prepared cost images.
struct RaisedRoofCosts {
  Pair pair;
  DelineationRequest req;
  std::unique_ptr<stereo::CorrelationCostService> costs;
  PreparedEnergy prepare(const DelineationParams& params) const {
    return prepareEnergy(*costs, pair.left, pair.right, req, params);
  }
};

RaisedRoofCosts raisedRoofCosts(const DelineationParams& params) {
  const cv::Rect roof(50, 40, 60, 50);
  RaisedRoofCosts c{raisedRoof({170, 140}, roof, 14, 4), {}, nullptr};
  c.req.init = grownBox(roof, 8);
  c.req.roof = {13, 15};
  c.req.ground = DisparityInterval{3, 5};
  const cv::Rect roi = regionOfInterest(c.pair.left, c.pair.right, c.req, params);
  c.costs = stereo::CorrelationCostService::compute(c.pair.left, c.pair.right, roi, 3, 15);
  return c;
}

TEST(Delineate, CostCapClipsTheAreaCostsAndKeepsThePlainDifference) {
  DelineationParams plain;
  plain.costCap = 0;  // off
  const RaisedRoofCosts c = raisedRoofCosts(plain);
  const PreparedEnergy off = c.prepare(plain);
  EXPECT_TRUE(off.images.uncappedDifference.empty());
  DelineationParams capped = plain;
  capped.costCap = 1.0;
  capped.costCapFloor = 0;
  const PreparedEnergy on = c.prepare(capped);
  const double cap = on.images.noMatchCost;
  double maxRoof = 0, maxGround = 0, maxPlain = 0;
  cv::minMaxLoc(on.images.roofCost, nullptr, &maxRoof);
  cv::minMaxLoc(on.images.groundCost, nullptr, &maxGround);
  cv::minMaxLoc(cv::max(off.images.roofCost, off.images.groundCost), nullptr, &maxPlain);
  EXPECT_GT(maxPlain, cap);  // the wall strip matches neither interval: the cap has work to do
  EXPECT_LE(maxRoof, cap + 1e-6);
  EXPECT_LE(maxGround, cap + 1e-6);
  // Below the cap nothing changes; the gate, region stage and seeds keep the plain difference.
  const cv::Mat below = (off.images.roofCost < cap) & (off.images.groundCost < cap);
  EXPECT_EQ(cv::countNonZero((on.images.roofCost != off.images.roofCost) & below), 0);
  ASSERT_FALSE(on.images.uncappedDifference.empty());
  EXPECT_EQ(cv::norm(on.images.uncappedDifference, off.images.groundCost - off.images.roofCost, cv::NORM_INF), 0.0);
  EXPECT_EQ(on.init.outer, off.init.outer);  // the region stage compares outlines on the plain costs
  // The floor: on this clean pair NoMatchCost is far below it, so the floor sets the cap.
  capped.costCapFloor = 0.3;
  ASSERT_LT(cap, capped.costCapFloor);
  const PreparedEnergy floored = c.prepare(capped);
  cv::minMaxLoc(floored.images.roofCost, nullptr, &maxRoof);
  EXPECT_GT(maxRoof, cap + 0.05);
  EXPECT_LE(maxRoof, 0.3 + 1e-6);
  EXPECT_EQ(cv::countNonZero((floored.images.roofCost != off.images.roofCost) & (off.images.roofCost < 0.3)), 0);
}

TEST(Delineate, RegularizesTheOutlineAsItsLastStage) {
  const cv::Rect roof(50, 40, 60, 50);
  const Pair pair = raisedRoof({170, 140}, roof, 14, 4);
  DelineationRequest req = raisedRoofRequest(roof);
  const auto r = delineate(pair.left, pair.right, req, DelineationParams{});
  ASSERT_EQ(r.status, core::RunStatus::Completed);
  EXPECT_EQ(r.regularization.status, RegularizationStatus::Regularized) << r.regularization.reason;
  EXPECT_EQ(r.vertexCount, 4);
  EXPECT_EQ(r.polygon.outer.size(), 4u);
  EXPECT_GE(r.rawPolygon.outer.size(), 4u);
  EXPECT_GE(iou(r.polygon, pair.truth, pair.left.size()), iou(r.rawPolygon, pair.truth, pair.left.size()) - 0.01);
  EXPECT_GT(iou(r.polygon, pair.truth, pair.left.size()), 0.9);
  // `none` keeps the active polygon's own outline.
  DelineationParams none;
  none.regularization.mode = "none";
  const auto raw = delineate(pair.left, pair.right, req, none);
  EXPECT_EQ(raw.regularization.status, RegularizationStatus::Off);
  EXPECT_EQ(raw.polygon.outer, raw.rawPolygon.outer);
  EXPECT_EQ(raw.rawPolygon.outer, r.rawPolygon.outer);
}

TEST(Delineate, RegularizationTriesTighterTolerancesWhenAGateRefuses) {
  // A 20 px square roof: at 12 px its square lies within the round test's reach of a circle
  // (0.4 x tolerance), so the whole tolerance keeps the input; half of it squares the outline.
  const cv::Rect roof(60, 50, 20, 20);
  const Pair pair = raisedRoof({140, 120}, roof, 14, 4);
  DelineationRequest req = raisedRoofRequest(roof);
  core::Polygon outline;
  outline.outer = {{60, 50}, {80, 50}, {80, 60}, {81, 60}, {81, 70}, {60, 70}};
  DelineationParams params;
  params.regularization.tolerance = 12;
  EXPECT_EQ(regularizeOutline(outline, params.regularization, pair.left).status, RegularizationStatus::KeptRaw);
  const RegularizationOutcome r = regularizeBuildingOutline(pair.left, pair.right, req, params, outline);
  EXPECT_EQ(r.status, RegularizationStatus::Regularized) << r.reason;
  EXPECT_LT(r.tolerance, 12.0);
  EXPECT_EQ(r.polygon.outer.size(), 4u);
  // The smallest tolerance has no tighter tries, and runs.
  params.regularization.tolerance = RegularizationParams::kMinTolerance;
  EXPECT_NO_THROW(regularizeBuildingOutline(pair.left, pair.right, req, params, outline));
}

TEST(Delineate, TheEnergyGateKeepsAnOutlineWhoseRegularizationLeavesTheRoofEdge) {
  const cv::Rect roof(50, 40, 60, 50);
  const Pair pair = raisedRoof({170, 140}, roof, 14, 4);
  DelineationRequest req = raisedRoofRequest(roof);
  // The true outline except a 3 px bulge over the middle 30 px of the east side: its jogs are
  // shorter than min-edge, and regularizing merges the side into one line about 2 px out, off
  // the image edge over its whole length.
  core::Polygon outline;
  outline.outer = {{50, 40}, {110, 40}, {110, 50}, {113, 50}, {113, 80}, {110, 80}, {110, 90}, {50, 90}};
  DelineationParams strict;
  strict.regularization.energyMargin = 0;
  const RegularizationOutcome kept = regularizeBuildingOutline(pair.left, pair.right, req, strict, outline);
  EXPECT_EQ(kept.status, RegularizationStatus::KeptRaw);
  EXPECT_EQ(kept.reason.rfind("energy", 0), 0u) << kept.reason;
  EXPECT_GT(kept.energyChange, 0.0);
  EXPECT_EQ(kept.polygon.outer, outline.outer);
  const RegularizationOutcome taken = regularizeBuildingOutline(pair.left, pair.right, req, DelineationParams{}, outline);
  EXPECT_EQ(taken.status, RegularizationStatus::Regularized) << taken.reason;
  EXPECT_EQ(taken.polygon.outer.size(), 4u);
}
