// The adaptive matcher's pipeline (pyramids and contours, the levels coarse to fine, the steps
// after them) and the SGBM backend.
#include "delineo/stereo/match.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "contour_gaps.hpp"
#include "delineo/core/error.hpp"
#include "delineo/core/nan_mask.hpp"
#include "match_fill.hpp"
#include "match_levels.hpp"
#include "match_snap.hpp"
#include "match_snap_rows.hpp"
#include "match_tiles.hpp"
#include "ordering.hpp"
#include "roof_planes.hpp"
#include "slanted_facets.hpp"
#include "smoothing.hpp"
#include "speckles.hpp"
#include "weak_matches.hpp"
#include "workers.hpp"

namespace delineo::stereo {

using core::Error;
using core::ErrorCode;

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr double kCoarsestRange = 20.0;  // ΔP_N of the paper, px
constexpr int kMinLevelSide = 32;        // px, coarsest level kept at least this large
constexpr int kMinTile = 64;             // px, smallest kept part of a tile

int floorDiv(int a, int b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}
int ceilDiv(int a, int b) {
  return -floorDiv(-a, b);
}

// The driver's own per-level work (preparation, Canny; the validation and intervals of
// match_levels.cpp) runs on the match's threads (workers.hpp): serial, ~0.17 s CPU of the
// 1000²/128 d run.
using detail::forRowBands;
using detail::runTasks;

// Grey mapping shared by both images: 1st..99th percentile of their valid pixels to 0..255, so
// Canny thresholds and SGBM penalties mean the same on 8-bit, 16-bit and float inputs.
struct GreyMapping {
  double offset = 0, scale = 1;
};

GreyMapping greyMapping(const cv::Mat& a, const cv::Mat& b, int threads) {
  // Each image's samples on a worker (strided reads, a cache miss each), then a's before b's.
  std::vector<float> samples, fromB;
  auto sample = [](const cv::Mat& m, std::vector<float>& out) {
    const size_t total = m.total();
    const size_t step = std::max<size_t>(1, total / 10000);
    out.reserve(total / step + 1);
    const float* p = m.ptr<float>();
    for (size_t i = 0; i < total; i += step) {
      if (std::isfinite(p[i])) out.push_back(p[i]);
    }
  };
  runTasks({[&] { sample(a, samples); }, [&] { sample(b, fromB); }}, threads);
  samples.insert(samples.end(), fromB.begin(), fromB.end());
  GreyMapping g;
  if (samples.empty()) return g;
  auto at = [&](double q) {
    const size_t k = static_cast<size_t>(q * static_cast<double>(samples.size() - 1));
    std::nth_element(samples.begin(), samples.begin() + static_cast<long>(k), samples.end());
    return static_cast<double>(samples[k]);
  };
  const double lo = at(0.01), hi = at(0.99);
  g.offset = lo;
  g.scale = hi > lo ? 255.0 / (hi - lo) : 1.0;
  return g;
}

// Values mapped to the grey scale with nodata filled by 0 after centring, and a validity mask.
void prepare(const cv::Mat& src, const GreyMapping& g, cv::Mat& values, cv::Mat& valid) {
  values.create(src.size(), CV_32F);
  valid.create(src.size(), CV_8U);
  const double offset = g.offset, scale = g.scale;
  const int cols = src.cols;
  for (int y = 0; y < src.rows; ++y) {
    const float* __restrict s = src.ptr<float>(y);
    float* __restrict v = values.ptr<float>(y);
    uchar* __restrict m = valid.ptr<uchar>(y);
    for (int x = 0; x < cols; ++x) {
      // isfinite as an exponent test, the mapping computed everywhere and nodata set to +0 by a
      // mask of its bits: a loop without branches that the compiler vectorises (the same double
      // arithmetic per pixel).
      const uint32_t ok = (std::bit_cast<uint32_t>(s[x]) & 0x7F800000U) != 0x7F800000U ? 1U : 0U;
      m[x] = static_cast<uchar>(ok);
      // Centred on mid-grey: smaller magnitudes keep the float running sums accurate.
      const float mapped = static_cast<float>((s[x] - offset) * scale - 127.5);
      v[x] = std::bit_cast<float>(std::bit_cast<uint32_t>(mapped) & (0U - ok));
    }
  }
}

// The validity (0/1) of the next coarser level: a coarse pixel holds data only when the whole
// 5x5 footprint of cv::pyrDown did, i.e. the AND of fine rows 2y − 2..2y + 2 and columns
// 2x − 2..2x + 2 clipped to the image (every kernel weight is positive, and the reflected border
// repeats only pixels of that clipped footprint). The same as pyrDown of the mask as floats
// > 0.999 (exact sums: one missing pixel leaves at most 255/256) without the float passes.
cv::Mat coarseValid(const cv::Mat& fine) {
  const int fw = fine.cols, fh = fine.rows, cw = (fw + 1) / 2, ch = (fh + 1) / 2;
  cv::Mat out(ch, cw, CV_8U);
  std::vector<uchar> rows(static_cast<size_t>(fw));
  for (int y = 0; y < ch; ++y) {
    const int y0 = std::max(0, 2 * y - 2), y1 = std::min(fh - 1, 2 * y + 2);
    uchar* __restrict acc = rows.data();
    std::copy_n(fine.ptr<uchar>(y0), fw, acc);
    for (int v = y0 + 1; v <= y1; ++v) {
      const uchar* __restrict f = fine.ptr<uchar>(v);
      for (int x = 0; x < fw; ++x) acc[x] &= f[x];
    }
    uchar* __restrict o = out.ptr<uchar>(y);
    // Inside the row, the AND of acc[2x − 2 .. 2x + 2]: unrolled; at its ends, clipped.
    auto clipped = [&](int x) {
      const int x0 = std::max(0, 2 * x - 2), x1 = std::min(fw - 1, 2 * x + 2);
      uchar a = 1;
      for (int u = x0; u <= x1; ++u) a &= acc[u];
      o[x] = a;
    };
    const int inner0 = std::min(cw, 1), inner1 = std::max(inner0, (fw - 3) / 2 + 1);
    for (int x = 0; x < inner0; ++x) clipped(x);
    for (int x = inner0; x < inner1; ++x) {
      const uchar* a = acc + 2 * x - 2;
      o[x] = a[0] & a[1] & a[2] & a[3] & a[4];
    }
    for (int x = inner1; x < cw; ++x) clipped(x);
  }
  return out;
}

cv::Mat edgeMap(const cv::Mat& values, const MatchParams& p) {
  cv::Mat grey;
  values.convertTo(grey, CV_8U, 1.0, 127.5);
  if (p.edgeSigma > 0) cv::GaussianBlur(grey, grey, cv::Size(0, 0), p.edgeSigma);
  cv::Mat edges;
  cv::Canny(grey, edges, p.edgeLow, p.edgeHigh, 3, true);
  detail::bridgeContourGaps(edges, p.edgeGap);
  return edges;
}

int threadCount(const MatchParams& p) {
  if (p.threads > 0) return p.threads;
  return std::max(1U, std::thread::hardware_concurrency());
}

// The fill's settings, with the whole pair's statistics for a tile (null: the pair is whole).
detail::RegionFillSettings fillSettingsFor(const detail::WholePairStatistics* whole) {
  detail::RegionFillSettings s;
  if (whole != nullptr) {
    s.wholePixels = whole->pixels;
    s.wholeLeftMedianGrey = whole->leftMedianGrey;
    s.wholeGreyMap = whole->greyMap;
  }
  return s;
}

// The pyramid's levels: as asked or from the range, the coarsest kept at least kMinLevelSide.
int levelCount(const cv::Mat& image, const MatchParams& p) {
  int levels = p.levels > 0 ? p.levels : autoLevels(p.dmin, p.dmax);
  while (levels > 1 && std::min(image.cols, image.rows) / (1 << (levels - 1)) < kMinLevelSide) {
    --levels;
  }
  return levels;
}

// The adaptive matcher's state from the pyramids to the final map; runStages() lists its stages.
struct AdaptiveMatch {
  AdaptiveMatch(const cv::Mat& left, const cv::Mat& right, const MatchParams& p,
                core::Progress* progress, int threads, const detail::WholePairStatistics* whole);
  bool runStages();
  void buildPyramids();
  void buildPyramidSide(bool isLeft, const GreyMapping& g);
  void findEdgesAndFlatPixels();
  bool matchLevels();
  bool reachedButCanceled(double fraction);
  void takeFinestLevelMap();
  void fillFlatRegions();
  void prepareImages();
  void releaseLevels();
  void rejectWeakMatchesBesideSteps();
  void rejectWeakPlainMatchesBesideSteps();
  void rejectWeakMatchesBesideUnmatchedPlain();
  void recoverSlantedFacets();
  void removeSpeckles(core::StageId stage);
  void snapDepthSteps();
  void rejectOrderingViolations();
  void smoothSurfaces();
  void fitRoofPlanes();

  const cv::Mat& left;
  const cv::Mat& right;
  const MatchParams& p;
  core::Progress* const progress;
  const detail::WholePairStatistics* const whole;  // a tile's; null: the pair is whole
  const int threads, levels;
  const bool plainPass;  // the weak-match passes over plain pixels run (they read `plain`)
  const detail::RegionFillSettings fillSettings;  // with a tile's whole-pair statistics
  MatchResult result;
  std::vector<detail::PyramidLevel> pyramid;
  detail::LocalMoments leftMoments;  // for the steps after the levels
  cv::Mat rightFlat;                 // the right image's flat pixels, for the fill
  detail::LevelMaps maps;
  detail::StepContrast contrast;  // for the snapping
  cv::Mat plain;                  // the left image's plain pixels, for the weak-match passes
};

AdaptiveMatch::AdaptiveMatch(const cv::Mat& left, const cv::Mat& right, const MatchParams& p,
                             core::Progress* progress, int threads,
                             const detail::WholePairStatistics* whole)
    : left(left),
      right(right),
      p(p),
      progress(progress),
      whole(whole),
      threads(threads),
      levels(levelCount(left, p)),
      plainPass(p.adaptive && (p.plainStepMinScore > 0 || p.unmatchedPlainMinScore > 0)),
      fillSettings(fillSettingsFor(whole)) {
  result.levelsUsed = levels;
}

// The stages in order. False when canceled between them (status Canceled, no maps); a cancel
// within a step throws (workers.hpp).
bool AdaptiveMatch::runStages() {
  buildPyramids();
  findEdgesAndFlatPixels();
  if (!matchLevels()) return false;
  // The steps after the levels report their share and are polled too: a cancel is honoured
  // between them.
  if (reachedButCanceled(0.85)) return false;
  takeFinestLevelMap();
  fillFlatRegions();
  if (p.adaptive && p.stepMinScore > 0) rejectWeakMatchesBesideSteps();
  if (plainPass && p.plainStepMinScore > 0) rejectWeakPlainMatchesBesideSteps();
  if (plainPass && p.unmatchedPlainMinScore > 0) rejectWeakMatchesBesideUnmatchedPlain();
  if (p.adaptive && p.facetMaxSlope > 0) recoverSlantedFacets();
  if (reachedButCanceled(0.9)) return false;
  if (p.speckleSize > 0) {
    removeSpeckles(core::StageId::RemovingSpeckles);
    if (reachedButCanceled(0.92)) return false;
  }
  if (p.snapSteps && p.adaptive) {
    snapDepthSteps();
    if (reachedButCanceled(0.98)) return false;
  }
  if (p.speckleSize > 0 && p.snapSteps && p.adaptive) {
    removeSpeckles(core::StageId::RemovingSnappingSpeckles);
  }
  if (p.orderingCheck) rejectOrderingViolations();
  if (p.smoothWindow > 0) smoothSurfaces();
  if (p.planeResidual > 0) {
    if (reachedButCanceled(0.99)) return false;
    fitRoofPlanes();
  }
  return true;
}

// Both images grey-mapped alike, then halved level by level. Left and right are independent up
// to the matching: each side's preparation and pyramid is one task.
void AdaptiveMatch::buildPyramids() {
  core::setStage(progress, core::StageId::PreparingPyramids);
  const GreyMapping g = whole != nullptr ? GreyMapping{whole->greyOffset, whole->greyScale}
                                         : greyMapping(left, right, threads);
  pyramid.resize(static_cast<size_t>(levels));
  runTasks({[&] { buildPyramidSide(true, g); }, [&] { buildPyramidSide(false, g); }}, threads);
  for (int k = 0; k < levels; ++k) {
    detail::PyramidLevel& lv = pyramid[static_cast<size_t>(k)];
    lv.dmin = floorDiv(p.dmin, 1 << k);
    lv.dmax = ceilDiv(p.dmax, 1 << k);
  }
}

void AdaptiveMatch::buildPyramidSide(bool isLeft, const GreyMapping& g) {
  detail::PyramidLevel& base = pyramid[0];
  prepare(isLeft ? left : right, g, isLeft ? base.left : base.right,
          isLeft ? base.leftValid : base.rightValid);
  for (int k = 1; k < levels; ++k) {
    detail::throwIfCanceled();
    detail::PyramidLevel& fine = pyramid[static_cast<size_t>(k - 1)];
    detail::PyramidLevel& coarse = pyramid[static_cast<size_t>(k)];
    cv::pyrDown(isLeft ? fine.left : fine.right, isLeft ? coarse.left : coarse.right);
    // A coarse pixel holds data only when its whole footprint did.
    (isLeft ? coarse.leftValid : coarse.rightValid) =
        coarseValid(isLeft ? fine.leftValid : fine.rightValid);
  }
}

// The Canny edges of every level and side, one task each, and among them the flat tests' inputs.
void AdaptiveMatch::findEdgesAndFlatPixels() {
  // The left image's 5x5 moments and noise, for the steps after the levels (the fill's flat
  // regions, the plain pixels, the snapping's contrast): one more task here, where the edges
  // leave a worker idle at times, instead of three computations of them after the levels.
  const bool afterSteps = p.adaptive && (p.fillRegions || p.snapSteps || p.plainStepMinScore > 0 ||
                                         p.unmatchedPlainMinScore > 0);
  // The right image's flat pixels, for the fill's right flat regions, which its regions wait for:
  // made here, where they lengthen the stage by less than they did the fill's wait (1000² /
  // 128 d, ~6 ms); the mask only is kept (the moments took 32 MB more at 2000² up to the fill).
  const bool fillsRegions = p.adaptive && p.fillRegions;
  std::vector<std::function<void()>> edgeTasks;
  for (int k = 0; k < levels; ++k) {
    detail::PyramidLevel& lv = pyramid[static_cast<size_t>(k)];
    edgeTasks.emplace_back([&lv, this] { lv.leftEdges = edgeMap(lv.left, p); });
    edgeTasks.emplace_back([&lv, this] { lv.rightEdges = edgeMap(lv.right, p); });
    // The tasks are taken in order, the longest first: the moments (full size, about 60 % of a
    // finest edge map's time) right after the finest level's edges, not last, where they ran
    // alone on one worker (~10 ms at 1000²).
    if (k == 0 && afterSteps) {
      edgeTasks.emplace_back([this] {
        leftMoments = detail::localMoments(left, whole != nullptr ? whole->leftNoise : -1);
      });
    }
    if (k == 0 && fillsRegions) {
      edgeTasks.emplace_back([this] {
        const detail::LocalMoments moments =
            detail::localMoments(right, whole != nullptr ? whole->rightNoise : -1);
        rightFlat = detail::plainPixels(right, fillSettings.flatSigmas, &moments);
      });
    }
  }
  runTasks(edgeTasks, threads);
}

// The levels, coarse to fine. False when canceled (status Canceled, no maps).
bool AdaptiveMatch::matchLevels() {
  // The steps after the levels' matching (the finest level's refinement, fill, speckles,
  // snapping) take ~20 % of the time at 1 Mpx: the bar does not sit at 100 % meanwhile.
  const bool postSteps =
      (p.adaptive && (p.stepCut || p.fillRegions || p.snapSteps)) || p.speckleSize > 0;
  const double levelsShare = postSteps ? 0.8 : 1.0;
  if (detail::matchLevelsCoarseToFine(pyramid, p, threads, levelsShare, progress, maps)) {
    return true;
  }
  result.status = core::RunStatus::Canceled;
  return false;
}

// Reports `fraction`; when canceled, the status says so and the maps are released (as when
// canceled during the levels).
bool AdaptiveMatch::reachedButCanceled(double fraction) {
  core::report(progress, fraction);
  if (!core::isCanceled(progress)) return false;
  result.disparity.release();
  result.score.release();
  result.status = core::RunStatus::Canceled;
  return true;
}

// The finest level's validated left map, and its scores where the disparity is a number (NaN
// elsewhere), in one pass by bands.
void AdaptiveMatch::takeFinestLevelMap() {
  result.disparity = maps.validatedLeft;
  result.score.create(maps.leftOut.score.size(), CV_32F);
  forRowBands(result.score.rows, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const float* __restrict d = result.disparity.ptr<float>(y);
      const float* __restrict sc = maps.leftOut.score.ptr<float>(y);
      float* __restrict out = result.score.ptr<float>(y);
      for (int x = 0; x < result.score.cols; ++x) out[x] = d[x] == d[x] ? sc[x] : kNaN;
    }
  });
}

// The fill runs on one worker; the snapping's contrast map and the plain pixels of the weak
// matches' wider pass (images only) are prepared on the other meanwhile, after the fill's own
// preparations there.
void AdaptiveMatch::fillFlatRegions() {
  core::setStage(progress, core::StageId::FillingFlatRegions);
  if (p.fillRegions && p.adaptive) {
    detail::fillFlatRegions(
        left, right, fillSettings, p.dmin, p.dmax, static_cast<float>(p.minScore), result.disparity,
        result.score, threads, [this] { prepareImages(); }, &leftMoments,
        [this] { releaseLevels(); }, &rightFlat);
  } else {
    prepareImages();
    releaseLevels();
  }
}

void AdaptiveMatch::prepareImages() {
  if (p.snapSteps && p.adaptive) contrast = detail::stepContrast(left, right, leftMoments.noise);
  if (plainPass) plain = detail::plainPixels(left, 3.0, &leftMoments);
}

// The levels' maps and images are no longer needed (but the finest left edges, for the facets):
// released by the fill's second worker once the regions are decided, where their pages' return
// to the system (~5 ms at 1 Mpx) fills the gaps of the regions' extension instead of running
// alone at the end.
void AdaptiveMatch::releaseLevels() {
  const cv::Mat finestLeftEdges = pyramid[0].leftEdges;
  pyramid.assign(1, detail::PyramidLevel{});
  pyramid[0].leftEdges = finestLeftEdges;
  maps.leftOut = {};
  maps.rightOut = {};
  maps.validatedRight.release();
  maps.finestBuffers = {};
  rightFlat.release();  // the right flat regions are made by then
}

// After the fill, whose candidates are the matches around a region (before it, a roof's weak
// edge matches went and the fill took a box on it for the whole roof: sim seed 15 600², roof
// RMS 0.290 -> 0.432 px), and before the speckles and the snapping, which close the gaps left.
void AdaptiveMatch::rejectWeakMatchesBesideSteps() {
  detail::WeakMatchSettings weak;
  weak.minScore = p.stepMinScore;
  weak.threads = threads;
  detail::rejectWeakMatchesBesideSteps(weak, static_cast<float>(p.minScore), result.disparity,
                                       result.score);
}

// Then a wider pass over plain pixels (5x5 standard deviation below 3 noise sigmas): a plain
// roof's pixels up to 7 px from a step whose windows reached the ground across a contour Canny
// missed (seed 28 600²: an 8 px patch 62 px off, 4-7 px inside the roof, scoring 0.53-0.59;
// roof RMS 0.919 -> 0.210 px). Textured pixels are left alone: on the Dublin tile the same pass
// over every pixel removed 3.8 points of density whose bad-2 was below the rest's.
void AdaptiveMatch::rejectWeakPlainMatchesBesideSteps() {
  detail::WeakMatchSettings wide;
  wide.minScore = p.plainStepMinScore;
  wide.radius = 7;
  wide.threads = threads;
  detail::rejectWeakMatchesBesideSteps(wide, static_cast<float>(p.minScore), result.disparity,
                                       result.score, plain);
}

// Then the weak matches on plain pixels beside a plain region the fill could not decide (a roof
// and the ground of one grey): the windows of the surface beside it that reached into it (sim
// seed 15 1000²: roof RMS 0.260 -> 0.134 px; see docs/stereo.md, step 11).
void AdaptiveMatch::rejectWeakMatchesBesideUnmatchedPlain() {
  detail::UnmatchedPlainSettings beside;
  beside.minScore = p.unmatchedPlainMinScore;
  beside.threads = threads;
  detail::rejectWeakMatchesBesideUnmatchedPlain(beside, static_cast<float>(p.minScore), plain,
                                                result.disparity, result.score);
}

// Then the steep facets left unmatched, matched region by region on slanted planes; before the
// speckles, the snapping and the ordering check, which treat their matches like any other.
void AdaptiveMatch::recoverSlantedFacets() {
  detail::SlantedFacetSettings facets;
  facets.maxSlope = p.facetMaxSlope;
  facets.threads = threads;
  detail::recoverSlantedFacets(left, right, pyramid[0].leftEdges, facets, p.dmin, p.dmax,
                               result.disparity, result.score);
}

// Speckles are removed after the fill (before it, the fill lost its seeds: 600² edge 66.1 %
// against 74.7 % removed last) and before the snapping, whose steps a wrong island inside the
// gap between a roof and the ground split (sim 400² edge 88.1 → 90.7 %, seed 3 600² 76.1 →
// 79.5 %); and again last, for the islands the snapping's cuts leave.
void AdaptiveMatch::removeSpeckles(core::StageId stage) {
  core::setStage(progress, stage);
  detail::removeSpeckles(result.disparity, result.score, p.speckleSize, p.speckleRange, threads);
}

// Along the rows, then across them. After the fill: a filled roof's edges are snapped like
// matched ones.
void AdaptiveMatch::snapDepthSteps() {
  core::setStage(progress, core::StageId::SnappingDepthSteps);
  detail::StepSnapSettings snap;
  snap.threads = threads;
  detail::snapStepsToContours(left, right, contrast, snap, static_cast<float>(p.minScore),
                              result.disparity, result.score);
  detail::RowStepSnapSettings rows;
  rows.threads = threads;
  detail::snapStepsAcrossRows(left, right, contrast.sigma, rows, static_cast<float>(p.minScore),
                              result.disparity, result.score);
}

// On the final map, after every step that sets matches (the fill's matches can be hidden too)
// and before the smoothing, which would average a hidden match into the surface hiding it.
// (600² roof RMS over all matches 2.121 -> 0.226 px; see docs/stereo.md, step 16.)
void AdaptiveMatch::rejectOrderingViolations() {
  detail::OrderingSettings ordering;
  ordering.threads = threads;
  detail::rejectOrderingViolations(result.disparity, result.score, ordering);
}

// On the final map, where the fill, the snapping and the speckle removal have set the steps
// that the smoothing must not cross. (Flat-roof RMS of the matches within 1 px, 5x5 and 1 px:
// sim seed 6 600² 0.255 -> 0.220, 600² 0.233 -> 0.205; see docs/stereo.md.)
void AdaptiveMatch::smoothSurfaces() {
  detail::smoothSurfaces(result.disparity, p.smoothWindow, p.smoothTolerance, threads);
}

// After the smoothing: a roof's matches are noisy at the scale of the correlation window, which
// a 5x5 mean cannot average out; a plane over the whole roof does (see docs/stereo.md, step 18).
void AdaptiveMatch::fitRoofPlanes() {
  core::setStage(progress, core::StageId::FittingRoofPlanes);
  detail::RoofPlaneSettings planes;
  planes.maxResidual = p.planeResidual;
  planes.minPixels = p.planeMinArea;
  planes.threads = threads;
  detail::fitRoofPlanes(result.disparity, planes);
}

MatchResult matchAdaptiveSteps(const cv::Mat& left, const cv::Mat& right, const MatchParams& p,
                               core::Progress* progress,
                               const detail::WholePairStatistics* whole) {
  const int threads = threadCount(p);
  // Its helpers serve the match's parallel steps (see WorkerPool).
  detail::WorkerPool workerPool(threads - 1);
  const detail::WorkerPool::Scope poolScope(workerPool);
  AdaptiveMatch match(left, right, p, progress, threads, whole);
  if (match.runStages()) core::report(progress, 1.0);
  return std::move(match.result);
}

// The steps poll the cancel within (workers.hpp): a cancel ends the match from any of them.
MatchResult matchAdaptive(const cv::Mat& left, const cv::Mat& right, const MatchParams& p,
                          core::Progress* progress,
                          const detail::WholePairStatistics* whole = nullptr) {
  const detail::CancelScope cancelScope(progress);
  try {
    return matchAdaptiveSteps(left, right, p, progress, whole);
  } catch (const detail::Canceled&) {
    MatchResult canceled;
    canceled.status = core::RunStatus::Canceled;
    return canceled;
  }
}

// NCC of the square window at the rounded disparity: the score map of the SGBM backend.
cv::Mat squareScore(const cv::Mat& left, const cv::Mat& right, const cv::Mat& disparity,
                    int window) {
  const int r = window / 2;
  cv::Mat score(disparity.size(), CV_32F, cv::Scalar(kNaN));
  cv::parallel_for_(cv::Range(r, disparity.rows - r), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      for (int x = r; x < disparity.cols - r; ++x) {
        const float d = disparity.at<float>(y, x);
        if (!std::isfinite(d)) continue;
        const int xr = x - static_cast<int>(std::lround(d));
        if (xr - r < 0 || xr + r >= disparity.cols) continue;
        double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
        for (int v = -r; v <= r; ++v) {
          const float* a = left.ptr<float>(y + v) + x;
          const float* b = right.ptr<float>(y + v) + xr;
          for (int u = -r; u <= r; ++u) {
            sa += a[u];
            sb += b[u];
            saa += a[u] * a[u];
            sbb += b[u] * b[u];
            sab += a[u] * b[u];
          }
        }
        const double n = static_cast<double>(window) * window;
        const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
        if (va > 1e-6 && vb > 1e-6) {
          score.at<float>(y, x) = static_cast<float>((sab - sa * sb / n) / std::sqrt(va * vb));
        }
      }
    }
  });
  return score;
}

MatchResult matchSgbm(const cv::Mat& left, const cv::Mat& right, const MatchParams& p,
                      core::Progress* progress,
                      const detail::WholePairStatistics* whole = nullptr) {
  MatchResult result;
  core::setStage(progress, core::StageId::MatchingSgbm);
  core::report(progress, 0.0);
  if (core::isCanceled(progress)) {
    result.status = core::RunStatus::Canceled;
    return result;
  }
  const GreyMapping g = whole != nullptr ? GreyMapping{whole->greyOffset, whole->greyScale}
                                         : greyMapping(left, right, threadCount(p));
  cv::Mat lv, rv, lvalid, rvalid, l8, r8;
  prepare(left, g, lv, lvalid);
  prepare(right, g, rv, rvalid);
  lv.convertTo(l8, CV_8U, 1.0, 127.5);
  rv.convertTo(r8, CV_8U, 1.0, 127.5);
  // SGBM searches [minDisparity, minDisparity + numDisparities) with numDisparities a multiple
  // of 16; its minDisparity may be negative, so any integer range maps directly.
  const int range = p.dmax - p.dmin + 1;
  const int numDisparities = ((range + 15) / 16) * 16;
  const int block = 5;  // SGBM's own aggregation does the smoothing: a small block is customary
  auto sgbm =
      cv::StereoSGBM::create(p.dmin, numDisparities, block, 8 * block * block, 32 * block * block,
                             std::max(1, static_cast<int>(std::ceil(p.tolerance))), 0, 10, 100, 2,
                             cv::StereoSGBM::MODE_SGBM_3WAY);
  cv::Mat raw;
  sgbm->compute(l8, r8, raw);
  if (core::isCanceled(progress)) {
    result.status = core::RunStatus::Canceled;
    return result;
  }
  result.disparity = cv::Mat(left.size(), CV_32F, cv::Scalar(kNaN));
  for (int y = 0; y < raw.rows; ++y) {
    const short* s = raw.ptr<short>(y);
    float* d = result.disparity.ptr<float>(y);
    for (int x = 0; x < raw.cols; ++x) {
      const float v = s[x] / 16.0F;
      if (s[x] < p.dmin * 16 || v > static_cast<float>(p.dmax) || !lvalid.at<uchar>(y, x)) continue;
      const int xr = x - static_cast<int>(std::lround(v));
      if (xr < 0 || xr >= raw.cols || !rvalid.at<uchar>(y, xr)) continue;
      d[x] = v;
    }
  }
  result.score = squareScore(lv, rv, result.disparity, p.window);
  result.disparity.setTo(kNaN, core::nanMask(result.score));
  core::report(progress, 1.0);
  return result;
}

// Tile by tile with the whole pair's grey mapping, noise and pyramid depth, so that each tile's
// kept part is matched as in the whole pair as far as its crop allows (docs/stereo.md, "Large
// pairs: tiles").
MatchResult matchTiled(const cv::Mat& left, const cv::Mat& right, const MatchParams& params,
                       core::Progress* progress) {
  detail::WholePairStatistics whole =
      detail::wholePairStatistics(left, right, params.dmin, params.dmax, threadCount(params));
  const GreyMapping grey = greyMapping(left, right, threadCount(params));
  whole.greyOffset = grey.offset;
  whole.greyScale = grey.scale;
  MatchParams tileParams = params;
  tileParams.levels = levelCount(left, params);
  const int alignment = 1 << (tileParams.levels - 1);  // the coarsest level's pixel
  const int context = detail::matchTileContext(tileParams.levels);
  const std::vector<detail::MatchTile> tiles = detail::matchTileGrid(
      left.size(), params.tile, context, params.dmin, params.dmax, alignment);
  const bool sgbm = params.method == "sgbm";
  return detail::matchInTiles(
      left, right, tiles,
      [&](const cv::Mat& l, const cv::Mat& r, core::Progress* share) {
        return sgbm ? matchSgbm(l, r, tileParams, share, &whole)
                    : matchAdaptive(l, r, tileParams, share, &whole);
      },
      progress);
}

}  // namespace

void MatchParams::validate() const {
  core::checkDeclaredRanges(*this);
  if (std::abs(dmin) > 100000 || std::abs(dmax) > 100000) {
    throw Error(ErrorCode::InvalidParameter, "disparity range [" + std::to_string(dmin) + ", " +
                                                 std::to_string(dmax) + "] is outside [-100000, 100000] px");
  }
  if (dmin > dmax) {
    throw Error(ErrorCode::InvalidParameter,
                "empty disparity range: dmin = " + std::to_string(dmin) +
                    " > dmax = " + std::to_string(dmax));
  }
  if (window % 2 == 0) {
    throw Error(ErrorCode::InvalidParameter, "window = " + std::to_string(window) + " must be odd");
  }
  if (smoothWindow != 0 && (smoothWindow < 3 || smoothWindow % 2 == 0)) {
    throw Error(ErrorCode::InvalidParameter, "smooth-window = " + std::to_string(smoothWindow) +
                                                 " must be 0 (off) or odd and >= 3");
  }
  if (tile != 0 && tile < kMinTile) {
    throw Error(ErrorCode::InvalidParameter, "tile = " + std::to_string(tile) + " must be 0 (whole image) or at least " + std::to_string(kMinTile));
  }
  if (edgeLow > edgeHigh) {
    throw Error(ErrorCode::InvalidParameter, "edge-low must not exceed edge-high");
  }
}

int autoLevels(int dmin, int dmax) {
  const double range = static_cast<double>(dmax) - dmin;
  if (range <= kCoarsestRange) return 1;
  return static_cast<int>(std::ceil(1.0 + std::log(range / kCoarsestRange) / std::log(2.0)));
}

MatchResult matchStereo(const cv::Mat& left, const cv::Mat& right, const MatchParams& params,
                        core::Progress* progress) {
  params.validate();
  if (left.empty() || right.empty() || left.type() != CV_32FC1 || right.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput,
                "stereo matching needs non-empty single-channel float32 images");
  }
  if (left.size() != right.size()) {
    throw Error(ErrorCode::MismatchedInputs,
                "left image is " + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
                    " but right image is " + std::to_string(right.cols) + "x" +
                    std::to_string(right.rows));
  }
  if (detail::matchesInTiles(left.size(), params.tile)) {
    return matchTiled(left, right, params, progress);
  }
  if (params.method == "sgbm") return matchSgbm(left, right, params, progress);
  return matchAdaptive(left, right, params, progress);
}

}  // namespace delineo::stereo
