#include <gtest/gtest.h>

#include <random>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/delineation/active_polygon.hpp"

using namespace delineo;
using namespace delineo::delineation;

namespace {

// Cost images of an ideal matcher for a building given as a mask: the roof interval matches on
// the roof, the ground interval elsewhere, with noise; image gradients from the mask edges.
EnergyImages idealImages(const cv::Mat& building, unsigned seed, float noise = 0.15f) {
  EnergyImages im;
  cv::Mat n1(building.size(), CV_32F), n2(building.size(), CV_32F);
  cv::RNG rng(seed);
  rng.fill(n1, cv::RNG::UNIFORM, 0.0, noise);
  rng.fill(n2, cv::RNG::UNIFORM, 0.0, noise);
  cv::Mat inside;
  building.convertTo(inside, CV_32F, 1.0 / 255);
  im.roofCost = 0.1f + 0.6f * (1.0f - inside) + n1;
  im.groundCost = 0.1f + 0.6f * inside + n2;
  im.noMatchCost = 0.7f;
  cv::Mat grey;
  cv::GaussianBlur(inside, grey, {0, 0}, 0.7);
  cv::Sobel(grey, im.leftGradX, CV_32F, 1, 0, 3, 1.0 / 8 * 4);
  cv::Sobel(grey, im.leftGradY, CV_32F, 0, 1, 3, 1.0 / 8 * 4);
  im.rightGradX = im.leftGradX.clone();
  im.rightGradY = im.leftGradY.clone();
  return im;
}

double iou(const IntPolygon& p, const cv::Mat& truth) {
  const cv::Mat m = core::rasterize(toPolygon(p), truth.size());
  const double inter = cv::countNonZero(m & truth);
  const double uni = cv::countNonZero(m | truth);
  return inter / uni;
}

IntPolygon rectangle(int x0, int y0, int x1, int y1) {
  return IntPolygon{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, {}};
}

}  // namespace

TEST(ActivePolygon, ConvergesOnARectangleFromAGrownBox) {
  cv::Mat truth(120, 140, CV_8U, cv::Scalar(0));
  cv::rectangle(truth, cv::Rect(30, 25, 70, 60), cv::Scalar(255), cv::FILLED);
  const auto im = idealImages(truth, 1);
  const auto r = optimiseActivePolygon(im, rectangle(22, 17, 108, 93), DelineationParams{});
  EXPECT_EQ(r.status, core::RunStatus::Completed);
  EXPECT_GT(iou(r.polygon, truth), 0.97);
  EXPECT_TRUE(isValidPolygon(r.polygon));
  EXPECT_LE(r.polygon.outer.size(), 8u);  // deletions leave few vertices on straight edges
}

TEST(ActivePolygon, ConvergesOnAnLShape) {
  cv::Mat truth(130, 130, CV_8U, cv::Scalar(0));
  std::vector<cv::Point> l{{25, 20}, {70, 20}, {70, 70}, {105, 70}, {105, 105}, {25, 105}};
  cv::fillPoly(truth, std::vector<std::vector<cv::Point>>{l}, cv::Scalar(255));
  // fillPoly paints closed pixel ranges; our polygon covers [x0, x1): match that convention.
  truth = core::rasterize(
      core::Polygon{{{25, 20}, {70, 20}, {70, 70}, {105, 70}, {105, 105}, {25, 105}}, {}},
      truth.size());
  const auto im = idealImages(truth, 2);
  const auto r = optimiseActivePolygon(im, rectangle(17, 12, 113, 113), DelineationParams{});
  EXPECT_GT(iou(r.polygon, truth), 0.95);
  EXPECT_TRUE(isValidPolygon(r.polygon));
}

TEST(ActivePolygon, FindsACourtyard) {
  core::Polygon building{{{20, 20}, {110, 20}, {110, 110}, {20, 110}},
                         {{{50, 50}, {80, 50}, {80, 80}, {50, 80}}}};
  const cv::Mat truth = core::rasterize(building, {130, 130});
  const auto im = idealImages(truth, 3);
  const auto r = optimiseActivePolygon(im, rectangle(12, 12, 118, 118), DelineationParams{});
  ASSERT_EQ(r.polygon.holes.size(), 1u);
  EXPECT_GT(iou(r.polygon, truth), 0.95);
  EXPECT_TRUE(isValidPolygon(r.polygon));

  DelineationParams without;
  without.courtyards = false;
  const auto r2 = optimiseActivePolygon(im, rectangle(12, 12, 118, 118), without);
  EXPECT_TRUE(r2.polygon.holes.empty());
  EXPECT_LT(r.terms.total(), r2.terms.total());
}

TEST(ActivePolygon, CarvesANotchBehindAStripThatMatchesNeitherInterval) {
  // An L-shaped roof inside a box init; in the notch an 8 px strip along the box (a wall or a
  // tree: roof and ground intervals match equally badly) separates the notch's ground from the
  // outside. Moving the outline across the strip changes nothing, so local moves stop at the
  // box; the notch search carves the ground region and the strip with it.
  const core::Polygon l{{{25, 20}, {70, 20}, {70, 70}, {105, 70}, {105, 105}, {25, 105}}, {}};
  const cv::Mat truth = core::rasterize(l, {130, 130});
  EnergyImages im = idealImages(truth, 5);
  const cv::Rect notch(70, 20, 35, 50);
  cv::Mat strip(truth.size(), CV_8U, cv::Scalar(0));
  strip(notch).setTo(255);
  strip(cv::Rect(notch.x, notch.y + 8, notch.width - 8, notch.height - 8)).setTo(0);
  im.roofCost.setTo(0.5f, strip);
  im.groundCost.setTo(0.5f, strip);
  for (cv::Mat* g : {&im.leftGradX, &im.leftGradY, &im.rightGradX, &im.rightGradY})
    g->setTo(0.f, strip);
  const IntPolygon box = rectangle(25, 20, 105, 105);
  const auto carved = optimiseActivePolygon(im, box, DelineationParams{});
  DelineationParams without;
  without.notches = false;
  const auto kept = optimiseActivePolygon(im, box, without);
  EXPECT_TRUE(carved.polygon.holes.empty());
  EXPECT_TRUE(isValidPolygon(carved.polygon));
  EXPECT_LT(carved.terms.total(), kept.terms.total());
  // The notch's ground (27 x 42 px) is out of the carved polygon.
  cv::Mat notchGround(truth.size(), CV_8U, cv::Scalar(0));
  notchGround(notch).setTo(255);
  notchGround &= (strip == 0);
  const double groundPixels = cv::countNonZero(notchGround);
  const auto share = [&](const IntPolygon& p) {
    return cv::countNonZero(core::rasterize(toPolygon(p), truth.size()) & notchGround) /
           groundPixels;
  };
  EXPECT_LT(share(carved.polygon), 0.05);
  EXPECT_GT(iou(carved.polygon, truth), 0.98);
  // Without the notch search the ground becomes a courtyard and the strip stays roof (0.954).
  EXPECT_LT(iou(kept.polygon, truth), iou(carved.polygon, truth) - 0.03);
}

TEST(ActivePolygon, DeterministicAndObservable) {
  cv::Mat truth(100, 100, CV_8U, cv::Scalar(0));
  cv::rectangle(truth, cv::Rect(20, 30, 55, 40), cv::Scalar(255), cv::FILLED);
  const auto im = idealImages(truth, 4);
  std::vector<double> energies;
  const auto a = optimiseActivePolygon(im, rectangle(12, 22, 83, 78), DelineationParams{},
                                       [&](const IterationReport& rep) {
                                         energies.push_back(rep.terms.total());
                                         EXPECT_TRUE(isValidPolygon(rep.polygon));
                                       });
  const auto b = optimiseActivePolygon(im, rectangle(12, 22, 83, 78), DelineationParams{});
  EXPECT_EQ(a.polygon.outer, b.polygon.outer);
  EXPECT_EQ(a.terms.total(), b.terms.total());
  ASSERT_GT(energies.size(), 2u);
  // Energy never increases from sweep to sweep except when insertion rounds vertices.
  EXPECT_NEAR(energies.back(), a.terms.total(), 1e-9);
}

TEST(ActivePolygon, CancelReturnsTheBestPolygonSoFar) {
  cv::Mat truth(100, 100, CV_8U, cv::Scalar(0));
  cv::rectangle(truth, cv::Rect(20, 30, 55, 40), cv::Scalar(255), cv::FILLED);
  const auto im = idealImages(truth, 5);
  core::Progress progress;
  progress.cancelAfterReports(2);
  const auto init = rectangle(12, 22, 83, 78);
  const auto r = optimiseActivePolygon(im, init, DelineationParams{}, {}, &progress);
  EXPECT_EQ(r.status, core::RunStatus::Canceled);
  EXPECT_TRUE(isValidPolygon(r.polygon));
  EXPECT_LE(r.iterations, 3);
  EXPECT_LT(r.terms.total(), referenceEnergy(im, {5.0, 15.0}, init).total());
}

TEST(ActivePolygon, IncrementalAndReferenceRunsAgree) {
  cv::Mat truth(60, 60, CV_8U, cv::Scalar(0));
  cv::rectangle(truth, cv::Rect(15, 12, 30, 34), cv::Scalar(255), cv::FILLED);
  const auto im = idealImages(truth, 6);
  DelineationParams p;
  p.courtyards = false;
  const auto fast = optimiseActivePolygon(im, rectangle(8, 6, 52, 52), p);
  const auto ref =
      optimiseActivePolygon(im, rectangle(8, 6, 52, 52), p, {}, nullptr, EnergyMode::Reference);
  EXPECT_EQ(fast.polygon.outer, ref.polygon.outer);
  EXPECT_NEAR(fast.terms.total(), ref.terms.total(), 1e-6);
}

TEST(ActivePolygon, RejectsDegenerateInit) {
  cv::Mat truth(50, 50, CV_8U, cv::Scalar(0));
  const auto im = idealImages(truth, 7);
  EXPECT_THROW(optimiseActivePolygon(im, IntPolygon{{{1, 1}, {5, 5}, {9, 9}}, {}}, {}),
               core::Error);
  EXPECT_THROW(optimiseActivePolygon(im, IntPolygon{{{1, 1}, {5, 1}}, {}}, {}), core::Error);
  EXPECT_THROW(optimiseActivePolygon(im, rectangle(10, 10, 80, 20), {}), core::Error);
  DelineationParams bad;
  bad.occlusionPercent = -1;
  EXPECT_THROW(optimiseActivePolygon(im, rectangle(10, 10, 20, 20), bad), core::Error);
}
