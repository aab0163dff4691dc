#include "slanted_facets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "components.hpp"
#include "cpu_features.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// d(x, y) = a + gx·(x − cx) + gy·(y − cy): centred on the region, so that `a` and the slopes
// are searched independently of where the region lies.
struct Plane {
  double a = 0, gx = 0, gy = 0;
  double cx = 0, cy = 0;
  double at(double x, double y) const { return a + gx * (x - cx) + gy * (y - cy); }
};

// Left grey levels of a set of pixels, centred on their mean (NCC then needs only Σ a·b), with
// what every plane's score reads of them alone, computed once: the pixels' offsets from the
// planes' centre and, per band of kBandRows rows, Σa, Σa² and the count (summed in the order the
// scores summed them).
struct Samples {
  std::vector<cv::Point> points;
  std::vector<double> centred;
  std::vector<double> fromCx, fromCy;  // x − cx, y − cy
  std::vector<int> band;               // (y − top) / kBandRows
  std::vector<double> bandSumA, bandSumAA, bandCount;
  double sumSquares = 0;
  int top = 0, bands = 1;  // the points' bands of kBandRows rows, from row `top`
};

constexpr int kBandRows = 12;

Samples samplesOf(const cv::Mat& left, const std::vector<cv::Point>& points, double cx, double cy) {
  Samples s;
  double sum = 0;
  for (const cv::Point& p : points) {
    const float v = left.at<float>(p);
    if (!std::isfinite(v)) continue;
    s.points.push_back(p);
    s.centred.push_back(v);
    sum += v;
  }
  if (s.points.empty()) return s;
  int bottom = s.points.front().y;
  s.top = bottom;
  for (const cv::Point& p : s.points) {
    s.top = std::min(s.top, p.y);
    bottom = std::max(bottom, p.y);
  }
  s.bands = (bottom - s.top) / kBandRows + 1;
  const double mean = sum / static_cast<double>(s.points.size());
  for (double& v : s.centred) {
    v -= mean;
    s.sumSquares += v * v;
  }
  const auto bands = static_cast<size_t>(s.bands);
  s.bandSumA.assign(bands, 0.0);
  s.bandSumAA.assign(bands, 0.0);
  s.bandCount.assign(bands, 0.0);
  for (size_t i = 0; i < s.points.size(); ++i) {
    const cv::Point p = s.points[i];
    s.fromCx.push_back(p.x - cx);
    s.fromCy.push_back(p.y - cy);
    const int k = (p.y - s.top) / kBandRows;
    s.band.push_back(k);
    const double a = s.centred[i];
    s.bandSumA[static_cast<size_t>(k)] += a;
    s.bandSumAA[static_cast<size_t>(k)] += a * a;
    s.bandCount[static_cast<size_t>(k)] += 1;
  }
  return s;
}

// The right view at (x − d, y), linearly interpolated along the row; NaN outside it.
double rightAt(const cv::Mat& right, int x, int y, double d) {
  const double xr = x - d;
  // std::floor is a library call in the baseline build (no SSE4.1): this is the same value for
  // any xr that lands in the image, and rejects the others as it did (NaN compares false).
  if (!(xr >= 0.0 && xr < static_cast<double>(right.cols - 1))) return kNaN;
  const int x0 = static_cast<int>(xr);  // truncation is the floor of a non-negative value
  const double whole = x0;
  const float* row = right.ptr<float>(y);
  const double t = xr - whole;
  return (1 - t) * row[x0] + t * row[x0 + 1];
}

// NCC of the samples against the right view at the plane; -2 when a sample maps outside the
// right image or onto an invalid pixel, or either side is constant.
double nccOverAll(const cv::Mat& right, const Samples& s, const Plane& plane);

// How well the samples line up at the plane: the NCC of each band of kBandRows rows, the worst
// quarter of the bands dropped, averaged (fewer than 3 bands of 8 samples: one NCC over all; -2
// as nccOverAll). A region often holds some unmatched pixels of another surface beside its facet
// (the ground beyond an eave Canny does not see over a few rows: seeds 33 and 38 600²), whose
// contrast can rule one NCC over all of it: seed 33's region scored 0.48 at its facet's true
// plane, against 0.90 on the facet alone; its best banded score is 0.81.
double planeScore(const cv::Mat& right, const Samples& s, const Plane& plane) {
  if (s.bands < 3) return nccOverAll(right, s, plane);
  thread_local std::vector<double> sums;  // per band: Σb, Σb², Σab
  sums.assign(static_cast<size_t>(s.bands) * 3, 0.0);
  for (size_t i = 0; i < s.points.size(); ++i) {
    // plane.at(x, y), from the offsets computed once.
    const double d = plane.a + plane.gx * s.fromCx[i] + plane.gy * s.fromCy[i];
    const double b = rightAt(right, s.points[i].x, s.points[i].y, d);
    if (!std::isfinite(b)) return -2;
    const double a = s.centred[i];
    double* q = &sums[static_cast<size_t>(s.band[i]) * 3];
    q[0] += b;
    q[1] += b * b;
    q[2] += a * b;
  }
  thread_local std::vector<double> scores;
  scores.clear();
  for (size_t k = 0; k < static_cast<size_t>(s.bands); ++k) {
    const double* q = &sums[k * 3];
    const double n = s.bandCount[k], sa = s.bandSumA[k];
    if (n < 8) continue;
    const double va = s.bandSumAA[k] - sa * sa / n, vb = q[1] - q[0] * q[0] / n;
    if (va <= 0 || vb <= 0) continue;
    scores.push_back((q[2] - sa * q[0] / n) / std::sqrt(va * vb));
  }
  if (scores.size() < 3) return nccOverAll(right, s, plane);
  std::sort(scores.begin(), scores.end());
  const size_t dropped = scores.size() / 4;  // the worst quarter of the bands
  double sum = 0;
  for (size_t k = dropped; k < scores.size(); ++k) sum += scores[k];
  return sum / static_cast<double>(scores.size() - dropped);
}

double nccOverAll(const cv::Mat& right, const Samples& s, const Plane& plane) {
  double sb = 0, sbb = 0, sab = 0;
  const size_t n = s.points.size();
  for (size_t i = 0; i < n; ++i) {
    const double d = plane.a + plane.gx * s.fromCx[i] + plane.gy * s.fromCy[i];
    const double b = rightAt(right, s.points[i].x, s.points[i].y, d);
    if (!std::isfinite(b)) return -2;
    sb += b;
    sbb += b * b;
    sab += s.centred[i] * b;
  }
  const double varB = sbb - sb * sb / static_cast<double>(n);
  if (varB <= 0 || s.sumSquares <= 0) return -2;
  return sab / std::sqrt(varB * s.sumSquares);
}

struct Scored {
  Plane plane;
  double score = -2;
};

constexpr double kSlopeStep = 0.15;  // px/px, the coarse grid's
// The coarse grid's best sparse score below minRegionScore by more than this ends the search: the
// 47 regions accepted on sims 1000² / 128 d and seeds 33, 38 and 41 600² had 0.74 or more there,
// and 98 of the 700 searched reach 0.70 (166 reach 0.60).
constexpr double kHopeless = 0.05;

struct Fit {
  Scored best;
  double elsewhere = -2;  // the best sparse score at its slopes 2 px or more from it (centre)
};

// The best plane for the region, in four stages:
// 1. a coarse grid (slopes every kSlopeStep up to maxSlope, `a` every 0.5 px over [lo, hi]) scored
//    on about 64 of its pixels (`sparse`), only where the plane agrees within 1 px with at least
//    `ringShare` of the matches around the region (`ring`: x, y, d), as the accepted plane must:
//    that skips most of the grid. When its best scores below `hopeless`, the search stops there
//    (most regions: occluded ground, plain surfaces);
// 2. its 12 best planes scored on about 256 pixels (`medium`);
// 3. the best one refined on all the pixels by a pattern search over its 26 neighbours (moving
//    while one is better, then halving the steps): coarser samples settled on another slope on
//    the periodic texture of sim seed 41 600²'s facet;
// 4. the range scanned again at its slopes, on the sparse pixels, for how well the region lines
//    up 2 px or more away (`elsewhere`).
// Also built for AVX2: the ring test's floor and ceil, a few instructions each without SSE4.1,
// are one each there (the test was the largest part of the facets' time).
DELINEO_TARGET_CLONES("avx2", "default") Fit bestPlane(
    const cv::Mat& right, const Samples& sparse, const Samples& medium, const Samples& all,
    const std::vector<cv::Point3d>& ring, double ringShare, double cx, double cy, double lo,
    double hi, double maxSlope, double hopeless) {
  constexpr size_t kKept = 12;
  std::vector<Scored> grid;
  const int slopeSteps = static_cast<int>(std::floor(maxSlope / kSlopeStep + 1e-9));
  const size_t needed = std::max<size_t>(
      1, static_cast<size_t>(std::ceil(ringShare * static_cast<double>(ring.size()))));
  const int steps = static_cast<int>(std::floor((hi - lo) / 0.5 + 1e-9)) + 1;  // a = lo + 0.5 k
  std::vector<int> agreeing(static_cast<size_t>(steps) + 1);  // ring matches per `a`, as steps
  for (int i = -slopeSteps; i <= slopeSteps; ++i) {
    for (int j = -slopeSteps; j <= slopeSteps; ++j) {
      const double gx = kSlopeStep * i, gy = kSlopeStep * j;
      // A ring match agrees within 1 px with every `a` within 1 px of its own at the slopes.
      std::fill(agreeing.begin(), agreeing.end(), 0);
      for (const cv::Point3d& q : ring) {
        const double own = q.z - gx * (q.x - cx) - gy * (q.y - cy);
        const int from = std::max(0, static_cast<int>(std::ceil((own - 1 - lo) / 0.5 - 1e-9)));
        const int to =
            std::min(steps - 1, static_cast<int>(std::floor((own + 1 - lo) / 0.5 + 1e-9)));
        if (from > to) continue;
        ++agreeing[static_cast<size_t>(from)];
        --agreeing[static_cast<size_t>(to) + 1];
      }
      int running = 0;
      for (int t = 0; t < steps; ++t) {
        running += agreeing[static_cast<size_t>(t)];
        if (static_cast<size_t>(running) < needed) continue;
        const Plane plane{lo + 0.5 * t, gx, gy, cx, cy};
        grid.push_back(Scored{plane, planeScore(right, sparse, plane)});
      }
    }
  }
  const size_t kept = std::min(kKept, grid.size());
  std::partial_sort(grid.begin(), grid.begin() + static_cast<std::ptrdiff_t>(kept), grid.end(),
                    [](const Scored& p, const Scored& q) { return p.score > q.score; });
  Fit fit;
  Scored& best = fit.best;
  if (kept == 0 || grid.front().score < hopeless) return fit;
  for (size_t k = 0; k < kept; ++k) {
    const double s = planeScore(right, medium, grid[k].plane);
    if (s > best.score) best = Scored{grid[k].plane, s};
  }
  // Pattern search on all the pixels, from the best one's score there: move to the best of the
  // 26 neighbours while one is better, then halve.
  best.score = planeScore(right, all, best.plane);
  double step = 0.25, slopeStep = kSlopeStep / 2;
  for (int round = 0; round < 4; ++round, step /= 2, slopeStep /= 2) {
    for (int move = 0; move < 6; ++move) {
      const Scored from = best;
      for (int i = -1; i <= 1; ++i) {
        for (int j = -1; j <= 1; ++j) {
          for (int k = -1; k <= 1; ++k) {
            if (i == 0 && j == 0 && k == 0) continue;
            const Plane plane{from.plane.a + step * i, from.plane.gx + slopeStep * j,
                              from.plane.gy + slopeStep * k, cx, cy};
            if (std::abs(plane.gx) > maxSlope || std::abs(plane.gy) > maxSlope) continue;
            const double s = planeScore(right, all, plane);
            if (s > best.score) best = Scored{plane, s};
          }
        }
      }
      if (best.score <= from.score) break;
    }
  }
  for (double a = lo; a <= hi + 1e-9; a += 0.5) {
    if (std::abs(a - best.plane.a) < 2) continue;
    const Plane plane{a, best.plane.gx, best.plane.gy, cx, cy};
    fit.elsewhere = std::max(fit.elsewhere, planeScore(right, sparse, plane));
  }
  return fit;
}

// NCC of the 7 x 7 window around (x, y), region pixels only, at the plane; -2 with fewer than
// 12 of them or a constant side.
double pixelScore(const cv::Mat& left, const cv::Mat& right, const cv::Mat& labels, int label,
                  const Plane& plane, int x, int y) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  int n = 0;
  for (int v = std::max(0, y - 3); v <= std::min(left.rows - 1, y + 3); ++v) {
    const int* l = labels.ptr<int>(v);
    const float* a = left.ptr<float>(v);
    for (int u = std::max(0, x - 3); u <= std::min(left.cols - 1, x + 3); ++u) {
      if (l[u] != label) continue;
      const double b = rightAt(right, u, v, plane.at(u, v));
      if (!std::isfinite(b) || !std::isfinite(a[u])) continue;
      sa += a[u];
      sb += b;
      saa += static_cast<double>(a[u]) * a[u];
      sbb += b * b;
      sab += a[u] * b;
      ++n;
    }
  }
  if (n < 12) return -2;
  const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  if (va <= 0 || vb <= 0) return -2;
  return (sab - sa * sb / n) / std::sqrt(va * vb);
}

// The unmatched pixels with data off the contours, in one pass by bands of rows (a match is a
// number: NaN is the only value unequal to itself).
cv::Mat unmatchedOffContours(const cv::Mat& left, const cv::Mat& edges, const cv::Mat& disparity,
                             int threads) {
  cv::Mat unmatched(disparity.size(), CV_8U);
  forRowBands(disparity.rows, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const float* d = disparity.ptr<float>(y);
      const float* a = left.ptr<float>(y);
      const uchar* e = edges.ptr<uchar>(y);
      uchar* u = unmatched.ptr<uchar>(y);
      for (int x = 0; x < disparity.cols; ++x) {
        u[x] = d[x] != d[x] && a[x] == a[x] && e[x] == 0 ? 255 : 0;
      }
    }
  });
  return unmatched;
}

// What the regions' tasks share: the views, the settings, the unmatched regions
// (componentsWithStats) and the matches as they were before any region took a plane.
struct FacetRegions {
  const cv::Mat& left;
  const cv::Mat& right;
  const SlantedFacetSettings& settings;
  int dmin, dmax;
  const cv::Mat& labels;
  const cv::Mat& stats;
  const cv::Mat& centroids;
  const cv::Mat& matchedBefore;
  cv::Mat& disparity;
  cv::Mat& score;
};

// One unmatched region matched on a plane (docs/stereo.md step 12), in its steps: its pixels
// (at construction); the matches around it (readRing); the best plane (bestPlane, on samples of
// its pixels); the tests the plane must pass (linesUp, continuesSurface, mostPixelsPass); the
// plane written (write).
struct SlantedRegion : FacetRegions {
  SlantedRegion(const FacetRegions& shared, int label);

  int match();
  bool readRing();
  std::vector<cv::Point> scattered(double target) const;
  bool linesUp(const Fit& fit) const;
  bool continuesSurface(const Plane& plane) const;
  std::vector<float> pixelScores(const Plane& plane) const;
  bool mostPixelsPass(const std::vector<float>& scores) const;
  int write(const Plane& plane, const std::vector<float>& scores) const;

  const int r;                       // the region's label
  const cv::Rect box;                // its bounding box
  std::vector<cv::Point> points;     // its pixels, in raster order
  std::vector<cv::Point3d> ringAll;  // the matches within 2 px of it: x, y, d
  std::vector<cv::Point3d> ring;     // those that guide the search
  double lo = 1e30, hi = -1e30;      // the range searched for its plane's value at its centre
};

SlantedRegion::SlantedRegion(const FacetRegions& shared, int label)
    : FacetRegions(shared),
      r(label),
      box(stats.at<int>(r, cv::CC_STAT_LEFT), stats.at<int>(r, cv::CC_STAT_TOP),
          stats.at<int>(r, cv::CC_STAT_WIDTH), stats.at<int>(r, cv::CC_STAT_HEIGHT)) {
  // The region's pixels in raster order, from its box (in the task: one pass over the whole
  // map for every region before took ~1 ms on one worker at 1000²).
  points.reserve(static_cast<size_t>(stats.at<int>(r, cv::CC_STAT_AREA)));
  for (int y = box.y; y < box.br().y; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = box.x; x < box.br().x; ++x) {
      if (l[x] == r) points.push_back({x, y});
    }
  }
}

// The region matched on its best plane when that passes the tests; the pixels matched.
int SlantedRegion::match() {
  if (!readRing()) return 0;
  const double cx = centroids.at<double>(r, 0), cy = centroids.at<double>(r, 1);
  const Samples all = samplesOf(left, points, cx, cy);
  // About 64 pixels (12 a band, for tall regions) score the coarse planes, about 256 choose
  // among the best of them.
  const double bands = static_cast<double>(box.height / kBandRows + 1);
  const Samples sparse = samplesOf(left, scattered(std::max(64.0, 12 * bands)), cx, cy);
  const Samples medium = samplesOf(left, scattered(256), cx, cy);
  if (sparse.points.size() < 8) return 0;
  const Fit fit = bestPlane(right, sparse, medium, all, ring, settings.minRingShare, cx, cy, lo, hi,
                            settings.maxSlope, settings.minRegionScore - kHopeless);
  const Plane& plane = fit.best.plane;
  if (!linesUp(fit) || !continuesSurface(plane)) return 0;
  const std::vector<float> scores = pixelScores(plane);
  if (!mostPixelsPass(scores)) return 0;
  return write(plane, scores);
}

// The matches within 2 px of the region (ringAll, and at most about 96 of them in `ring`, which
// guide the search); their disparities bound its plane's value at its centre (lo, hi): a facet
// lies between its ridge and the ground beside its eave. False when there are none.
bool SlantedRegion::readRing() {
  const cv::Rect around =
      (box + cv::Size(4, 4) - cv::Point(2, 2)) & cv::Rect(0, 0, left.cols, left.rows);
  const cv::Mat inRegion = labels(around) == r;
  cv::Mat near;
  cv::dilate(inRegion, near, cv::Mat::ones(5, 5, CV_8U));
  near &= ~inRegion;
  for (int y = 0; y < around.height; ++y) {
    for (int x = 0; x < around.width; ++x) {
      if (!near.at<uchar>(y, x)) continue;
      const float d = matchedBefore.at<float>(around.y + y, around.x + x);
      if (!std::isfinite(d)) continue;
      ringAll.emplace_back(around.x + x, around.y + y, d);
      lo = std::min(lo, static_cast<double>(d));
      hi = std::max(hi, static_cast<double>(d));
    }
  }
  if (ringAll.empty()) return false;
  const size_t ringStride = (ringAll.size() + 95) / 96;
  for (size_t k = 0; k < ringAll.size(); k += ringStride) ring.push_back(ringAll[k]);
  lo = std::max(lo - 1, static_cast<double>(dmin));
  hi = std::min(hi + 1, static_cast<double>(dmax));
  return true;
}

// About `target` of the region's pixels, scattered by a hash of their position (a regular
// grid aliases with periodic texture: seed 33 600²'s facet, period 4 px, sampled every
// 6 px, scored 0.48 at its best plane against 0.90 at the truth).
std::vector<cv::Point> SlantedRegion::scattered(double target) const {
  const auto every = static_cast<uint32_t>(std::max(1.0, std::floor(points.size() / target)));
  std::vector<cv::Point> kept;
  for (const cv::Point& p : points) {
    const uint32_t h =
        (static_cast<uint32_t>(p.x) * 73856093U) ^ (static_cast<uint32_t>(p.y) * 19349663U);
    if ((h >> 7) % every == 0) kept.push_back(p);
  }
  return kept;
}

// Lines up well, and clearly better than anywhere 2 px away (periodic texture, plain or
// occluded regions line up about as well at several places).
bool SlantedRegion::linesUp(const Fit& fit) const {
  return fit.best.score >= settings.minRegionScore &&
         fit.elsewhere <= fit.best.score - settings.uniqueness;
}

// Continues the surface beside it somewhere: a facet meets its roof's other facets at the ridge
// and hips (its eave is a step down to the ground).
bool SlantedRegion::continuesSurface(const Plane& plane) const {
  int agree = 0;
  for (const cv::Point3d& q : ringAll) agree += std::abs(q.z - plane.at(q.x, q.y)) <= 1 ? 1 : 0;
  return agree >= settings.minRingShare * static_cast<double>(ringAll.size());
}

// Each pixel's score at the plane on its own 7 x 7 window (pixelScore).
std::vector<float> SlantedRegion::pixelScores(const Plane& plane) const {
  std::vector<float> scores(points.size(), -2.0F);
  for (size_t i = 0; i < points.size(); ++i) {
    scores[i] =
        static_cast<float>(pixelScore(left, right, labels, r, plane, points[i].x, points[i].y));
  }
  return scores;
}

// Most of its pixels line up there on their own too.
bool SlantedRegion::mostPixelsPass(const std::vector<float>& scores) const {
  int passing = 0;
  for (const float s : scores) passing += s >= settings.minPixelScore ? 1 : 0;
  return passing >= settings.minPixelShare * static_cast<double>(points.size());
}

// The pixels that line up at the plane on their own take it, with their score; the pixels
// written.
int SlantedRegion::write(const Plane& plane, const std::vector<float>& scores) const {
  int matched = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const double d = plane.at(points[i].x, points[i].y);
    // A plane may run out of the searched range at a region's far end: left unmatched there.
    if (scores[i] < settings.minPixelScore || d < dmin || d > dmax) continue;
    disparity.at<float>(points[i]) = static_cast<float>(d);
    score.at<float>(points[i]) = scores[i];
    ++matched;
  }
  return matched;
}

}  // namespace

int recoverSlantedFacets(const cv::Mat& left, const cv::Mat& right, const cv::Mat& edges,
                         const SlantedFacetSettings& settings, int dmin, int dmax,
                         cv::Mat& disparity, cv::Mat& score) {
  CV_Assert(left.type() == CV_32F && right.type() == CV_32F && left.size() == right.size());
  CV_Assert(disparity.type() == CV_32F && disparity.size() == left.size());
  CV_Assert(score.type() == CV_32F && score.size() == left.size());
  CV_Assert(edges.type() == CV_8U && edges.size() == left.size());
  if (settings.maxSlope <= 0) return 0;
  const cv::Mat unmatched = unmatchedOffContours(left, edges, disparity, settings.threads);
  // Each region's result is written by its own task into its own pixels: no two tasks touch the
  // same pixel, and the matches read around a region are ones no task writes (copied meanwhile).
  cv::Mat labels, stats, centroids, matchedBefore;
  int count = 0;
  runTasks({[&] {
              count = componentsWithStats(unmatched, labels, stats, centroids, 4, settings.threads);
            },
            [&] { matchedBefore = disparity.clone(); }},
           settings.threads);
  const FacetRegions shared{.left = left,
                            .right = right,
                            .settings = settings,
                            .dmin = dmin,
                            .dmax = dmax,
                            .labels = labels,
                            .stats = stats,
                            .centroids = centroids,
                            .matchedBefore = matchedBefore,
                            .disparity = disparity,
                            .score = score};
  std::vector<int> matchedPerRegion(static_cast<size_t>(count), 0);
  std::vector<std::function<void()>> tasks;
  for (int r = 1; r < count; ++r) {
    if (stats.at<int>(r, cv::CC_STAT_AREA) < settings.minArea) continue;
    tasks.emplace_back(
        [&, r] { matchedPerRegion[static_cast<size_t>(r)] = SlantedRegion(shared, r).match(); });
  }
  runTasks(tasks, settings.threads);
  int total = 0;
  for (const int m : matchedPerRegion) total += m;
  return total;
}

}  // namespace delineo::stereo::detail
