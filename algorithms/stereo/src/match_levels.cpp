// The adaptive matcher's levels matched coarse to fine: at each level the left view, the right
// view on the pixels the left matches point to, the symmetric validation, and the step cut.
#include "match_levels.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "coarse_check.hpp"
#include "coarse_intervals.hpp"
#include "cpu_features.hpp"
#include "match_steps.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

cv::Mat flipped(const cv::Mat& m) {
  cv::Mat out;
  cv::flip(m, out, 1);
  return out;
}

// The right view's search intervals, mirrored like its images: out(y, x) = in(y, W − 1 − x). With
// `needed` (0/1, unmirrored), the pixels it does not mark get hi = lo − 1 (not searched). One
// pass instead of a clone, a masked copy and two flips; rows rowStart .. rowEnd − 1 of the outputs,
// which the caller has made.
void mirrorIntervals(const cv::Mat& lo, const cv::Mat& hi, const cv::Mat& needed, int rowStart,
                     int rowEnd, cv::Mat& outLo, cv::Mat& outHi) {
  const int W = lo.cols;
  for (int y = rowStart; y < rowEnd; ++y) {
    const int* __restrict l = lo.ptr<int>(y);
    const int* __restrict h = hi.ptr<int>(y);
    int* __restrict ol = outLo.ptr<int>(y);
    int* __restrict oh = outHi.ptr<int>(y);
    if (needed.empty()) {
      for (int x = 0; x < W; ++x) {
        ol[x] = l[W - 1 - x];
        oh[x] = h[W - 1 - x];
      }
    } else {
      const uchar* __restrict n = needed.ptr<uchar>(y);
      for (int x = 0; x < W; ++x) {
        const int xs = W - 1 - x;
        ol[x] = l[xs];
        oh[x] = n[xs] != 0 ? h[xs] : l[xs] - 1;
      }
    }
  }
}

// One row of validate(): `d` holds the row's disparities (a copy of the map's row), `dy` its
// line shifts; the inconsistent ones are set to NaN. Also built for AVX2 (one rounding
// instruction per floor instead of a library call; no FMA, so the same arithmetic).
DELINEO_TARGET_CLONES("avx2", "default") void validateRow(
    float* d, const float* dy, int xStart, int y, int W, int H, float sign, double tolerance2,
    const float* otherD, size_t otherStep, const float* otherS, size_t shiftStep) {
  const auto fw = static_cast<float>(W), fh = static_cast<float>(H);
  const float yf = static_cast<float>(y);
  for (int x = xStart; x < W; ++x) {
    const float dx = d[x];
    if (!std::isfinite(dx)) continue;
    // Where the match lands in the other map (float, as the map's values).
    const float xo = static_cast<float>(x) - sign * dx;
    const float shift = dy[x];
    const float yo = yf + shift;
    // A neighbour inside the other map: floor(xo) + 1 >= 0 and floor(xo) <= W - 1, i.e.
    // -1 <= xo < W (W exact in float); the same for yo (false for NaN).
    if (!(xo >= -1.0F && xo < fw && yo >= -1.0F && yo < fh)) {
      d[x] = kNaN;  // no neighbour inside the other map
      continue;
    }
    const int fx = static_cast<int>(std::floor(xo)), fy = static_cast<int>(std::floor(yo));
    // The four floor/ceil neighbours, clamped to the map: a clamped one repeats an inside one,
    // which leaves the "any of them" test unchanged. The first that passes decides (the test
    // is an OR); a NaN neighbour fails by itself.
    const int qx0 = std::max(0, fx), qx1 = std::min(W - 1, fx + 1);
    const int qy0 = std::max(0, fy), qy1 = std::min(H - 1, fy + 1);
    const float* d0 = otherD + static_cast<size_t>(qy0) * otherStep;
    const float* s0 = otherS + static_cast<size_t>(qy0) * shiftStep;
    auto near = [dx, shift, tolerance2](float dq, float sq) {
      const double ex = dx - dq;  // differences in float, their squares in double
      const double ey = shift + sq;
      return ex * ex + ey * ey <= tolerance2;
    };
    if (near(d0[qx0], s0[qx0]) || near(d0[qx1], s0[qx1])) continue;
    const float* d1 = otherD + static_cast<size_t>(qy1) * otherStep;
    const float* s1 = otherS + static_cast<size_t>(qy1) * shiftStep;
    if (near(d1[qx0], s1[qx0]) || near(d1[qx1], s1[qx1])) continue;
    d[x] = kNaN;
  }
}

#ifdef DELINEO_STEREO_X86
// Bit k set when lane k of the 4 float pairs (ex, ey) has ex² + ey² <= tolerance2, the squares
// and their sum in double as in validateRow().
__attribute__((target("avx2"), always_inline)) inline int nearLanes4(__m128 ex, __m128 ey,
                                                                     __m256d tolerance2) {
  const __m256d x = _mm256_cvtps_pd(ex), y = _mm256_cvtps_pd(ey);
  const __m256d e = _mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y));
  return _mm256_movemask_pd(_mm256_cmp_pd(e, tolerance2, _CMP_LE_OQ));
}

// The same for one neighbour of 8 pixels (disparities dx, line shifts `shift`): its values
// gathered at rowD + qx in otherD and rowS + qx in otherS.
__attribute__((target("avx2"), always_inline)) inline int nearNeighbour(
    const float* otherD, const float* otherS, __m256i rowD, __m256i rowS, __m256i qx, __m256 dx,
    __m256 shift, __m256d tolerance2) {
  const __m256 dq = _mm256_i32gather_ps(otherD, _mm256_add_epi32(rowD, qx), 4);
  const __m256 sq = _mm256_i32gather_ps(otherS, _mm256_add_epi32(rowS, qx), 4);
  const __m256 ex = _mm256_sub_ps(dx, dq), ey = _mm256_add_ps(shift, sq);
  return nearLanes4(_mm256_castps256_ps128(ex), _mm256_castps256_ps128(ey), tolerance2) |
         (nearLanes4(_mm256_extractf128_ps(ex, 1), _mm256_extractf128_ps(ey, 1), tolerance2) << 4);
}

// validateRow() for 8 pixels at a time (the rest by validateRow()): the same floats, floors,
// clamps and double tests per pixel, the four neighbours gathered. Indices of the other maps
// as int32: the caller checks that they fit.
__attribute__((target("avx2"))) void validateRowAvx2(float* d, const float* dy, int y, int W, int H,
                                                     float sign, double tolerance2,
                                                     const float* otherD, size_t otherStep,
                                                     const float* otherS, size_t shiftStep) {
  const __m256 fw = _mm256_set1_ps(static_cast<float>(W));
  const __m256 fh = _mm256_set1_ps(static_cast<float>(H));
  const __m256 minusOne = _mm256_set1_ps(-1.0F);
  const __m256 yf = _mm256_set1_ps(static_cast<float>(y));
  const __m256 signV = _mm256_set1_ps(sign);
  const __m256 nan = _mm256_set1_ps(kNaN);
  const __m256i zero = _mm256_setzero_si256(), one = _mm256_set1_epi32(1);
  const __m256i lastX = _mm256_set1_epi32(W - 1), lastY = _mm256_set1_epi32(H - 1);
  const __m256i stepD = _mm256_set1_epi32(static_cast<int>(otherStep));
  const __m256i stepS = _mm256_set1_epi32(static_cast<int>(shiftStep));
  const __m256i exponent = _mm256_set1_epi32(0x7F800000);
  const __m256d tol2 = _mm256_set1_pd(tolerance2);
  const __m256i lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  int x = 0;
  for (; x + 8 <= W; x += 8) {
    const __m256 dx = _mm256_loadu_ps(d + x);
    // Finite lanes (exponent not all ones), as std::isfinite.
    const __m256i finite = _mm256_xor_si256(
        _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_castps_si256(dx), exponent), exponent),
        _mm256_set1_epi32(-1));
    if (_mm256_testz_si256(finite, finite) != 0) continue;
    const __m256 xs = _mm256_cvtepi32_ps(_mm256_add_epi32(_mm256_set1_epi32(x), lanes));
    const __m256 xo = _mm256_sub_ps(xs, _mm256_mul_ps(signV, dx));
    const __m256 shift = _mm256_loadu_ps(dy + x);
    const __m256 yo = _mm256_add_ps(yf, shift);
    const __m256 inside = _mm256_and_ps(
        _mm256_and_ps(_mm256_cmp_ps(xo, minusOne, _CMP_GE_OQ), _mm256_cmp_ps(xo, fw, _CMP_LT_OQ)),
        _mm256_and_ps(_mm256_cmp_ps(yo, minusOne, _CMP_GE_OQ), _mm256_cmp_ps(yo, fh, _CMP_LT_OQ)));
    const __m256i tested = _mm256_and_si256(finite, _mm256_castps_si256(inside));
    // Floors of the tested lanes (the others: 0, any index inside the maps).
    const __m256i fx = _mm256_and_si256(
        _mm256_cvttps_epi32(_mm256_round_ps(xo, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)),
        tested);
    const __m256i fy = _mm256_and_si256(
        _mm256_cvttps_epi32(_mm256_round_ps(yo, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)),
        tested);
    const __m256i qx0 = _mm256_max_epi32(zero, fx);
    const __m256i qx1 = _mm256_min_epi32(lastX, _mm256_add_epi32(fx, one));
    const __m256i qy0 = _mm256_max_epi32(zero, fy);
    const __m256i qy1 = _mm256_min_epi32(lastY, _mm256_add_epi32(fy, one));
    const __m256i rowD0 = _mm256_mullo_epi32(qy0, stepD), rowD1 = _mm256_mullo_epi32(qy1, stepD);
    const __m256i rowS0 = _mm256_mullo_epi32(qy0, stepS), rowS1 = _mm256_mullo_epi32(qy1, stepS);
    const int passed = nearNeighbour(otherD, otherS, rowD0, rowS0, qx0, dx, shift, tol2) |
                       nearNeighbour(otherD, otherS, rowD0, rowS0, qx1, dx, shift, tol2) |
                       nearNeighbour(otherD, otherS, rowD1, rowS1, qx0, dx, shift, tol2) |
                       nearNeighbour(otherD, otherS, rowD1, rowS1, qx1, dx, shift, tol2);
    // NaN: finite lanes outside the other map, and tested lanes no neighbour passed.
    const int finiteBits = _mm256_movemask_ps(_mm256_castsi256_ps(finite));
    const int testedBits = _mm256_movemask_ps(_mm256_castsi256_ps(tested));
    const int rejected = (finiteBits & ~testedBits) | (testedBits & ~passed);
    if (rejected == 0) continue;
    const __m256i bits =
        _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(rejected), lanes), one);
    _mm256_storeu_ps(d + x,
                     _mm256_blendv_ps(dx, nan, _mm256_castsi256_ps(_mm256_cmpeq_epi32(bits, one))));
  }
  validateRow(d, dy, x, y, W, H, sign, tolerance2, otherD, otherStep, otherS, shiftStep);
}
#endif

// Keeps the matches of `map` (with line shifts) whose match in the other map points back
// within `tolerance` for at least one of the four floor/ceil neighbours. `sign`: +1 when `map` is
// the left map (x_other = x - d), -1 for the right map (x_other = x + d).
cv::Mat validate(const LevelOutput& map, const LevelOutput& other, int sign, double tolerance,
                 int threads) {
  cv::Mat out(map.disparity.size(), CV_32F);
  const int W = out.cols, H = out.rows;
  const double tolerance2 = tolerance * tolerance;  // compared with ex² + ey² (hypot's cost)
  // The other map's rows by plain arithmetic (the per-pixel Mat calls kept the loop's values on
  // the stack).
  const auto* otherD = other.disparity.ptr<float>(0);
  const auto* otherS = other.lineShift.ptr<float>(0);
  const size_t otherStep = other.disparity.step1(), shiftStep = other.lineShift.step1();
#ifdef DELINEO_STEREO_X86
  // The AVX2 rows gather with int32 indices.
  const bool avx2 =
      cpuHasAvx2() &&
      static_cast<double>(H) * static_cast<double>(std::max(otherStep, shiftStep)) < 2e9;
#else
  const bool avx2 = false;
#endif
  forRowBands(
      H, threads,
      [&, W, H, sign, tolerance2, otherD, otherS, otherStep, shiftStep](int rowStart, int rowEnd) {
        for (int y = rowStart; y < rowEnd; ++y) {
          float* d = out.ptr<float>(y);
          std::copy_n(map.disparity.ptr<float>(y), W, d);
          const float* dy = map.lineShift.ptr<float>(y);
#ifdef DELINEO_STEREO_X86
          if (avx2) {
            validateRowAvx2(d, dy, y, W, H, static_cast<float>(sign), tolerance2, otherD, otherStep,
                            otherS, shiftStep);
            continue;
          }
#endif
          validateRow(d, dy, 0, y, W, H, static_cast<float>(sign), tolerance2, otherD, otherStep,
                      otherS, shiftStep);
        }
      });
  return out;
}

// Pixels of the other map that the matches of `map` point to (the floor/ceil neighbours the
// validation reads), CV_8U 0/1; x_other = x − d. By bands of output rows: a band scans the
// source rows whose line shift (|dy| <= lineShift + 1) can reach it and writes only its own rows.
// Bands of 64 rows: each scans 2 · (lineShift + 2) rows beyond its own.
constexpr int kPointedBandRows = 64;
// One source row of pointedTo(): marks the pointed pixels in output rows rowStart..rowEnd − 1
// (`needed` is row 0 of the map), except from the pixels `skip` marks (null: none). Also built
// for AVX2 (floor in one instruction).
DELINEO_TARGET_CLONES("avx2", "default") void pointedRow(const float* d, const float* dy,
                                                                  const uchar* skip, int y, int W,
                                                                  int rowStart, int rowEnd,
                                                                  uchar* needed, size_t step) {
  const auto yf = static_cast<float>(y);
  for (int x = 0; x < W; ++x) {
    if (!std::isfinite(d[x]) || (skip && skip[x])) continue;
    const int fx = static_cast<int>(std::floor(static_cast<float>(x) - d[x]));
    const int fy = static_cast<int>(std::floor(yf + dy[x]));
    for (int m = 0; m <= 1; ++m) {
      const int qy = fy + m;
      if (qy < rowStart || qy >= rowEnd) continue;
      uchar* row = needed + static_cast<size_t>(qy) * step;
      if (fx >= 0 && fx < W) row[fx] = 1;
      if (fx + 1 >= 0 && fx + 1 < W) row[fx + 1] = 1;
    }
  }
}

// The matches that `kept` (CV_8U, may be empty) marks keep the coarser level's check: they point
// to nothing.
cv::Mat pointedTo(const LevelOutput& map, const cv::Mat& kept, int lineShift, int threads) {
  cv::Mat needed = cv::Mat::zeros(map.disparity.size(), CV_8U);
  const int reach = lineShift + 2;
  forRowBands(
      needed.rows, threads,
      [&](int rowStart, int rowEnd) {
        for (int y = std::max(0, rowStart - reach); y < std::min(needed.rows, rowEnd + reach);
             ++y) {
          pointedRow(map.disparity.ptr<float>(y), map.lineShift.ptr<float>(y),
                     kept.empty() ? nullptr : kept.ptr<uchar>(y), y, needed.cols, rowStart, rowEnd,
                     needed.ptr<uchar>(0), needed.step1());
        }
      },
      kPointedBandRows);
  return needed;
}

// One level's two views: their inputs (the right view's mirrored: right -> left), the right
// view's intervals (unmirrored) and matches (mirrored), and the coarser level's checks that the
// finest level's matches on smooth surfaces keep.
struct LevelViews {
  LevelViews(const PyramidLevel& lv, int k) : level(lv), k(k) {
    left.ref = lv.left;
    left.other = lv.right;
    left.refValid = lv.leftValid;
    left.otherValid = lv.rightValid;
    left.refEdges = lv.leftEdges;
    left.dmin = right.dmin = lv.dmin;
    left.dmax = right.dmax = lv.dmax;
  }
  const PyramidLevel& level;
  const int k;  // pyramid index, 0 = finest
  LevelInput left, right;
  cv::Mat rightLo, rightHi, rightOneSurface;
  LevelPreparations shared;  // the left view's, for the right view
  LevelOutput mirrored;      // the right view's output
  cv::Mat parentLeft;        // the coarser level's validated left map (empty at the coarsest)
  bool inheritChecks = false;
  cv::Mat kept;  // CV_8U, may be empty: the matches that keep the coarser level's check
};

// What the levels share: the settings, the progress made, and the maps of the level matched
// last, which guide the next.
struct CoarseToFine {
  CoarseToFine(const std::vector<PyramidLevel>& pyramid, const MatchParams& p, int threads,
               double levelsShare, core::Progress* progress, LevelMaps& maps);
  bool matchOneLevel(int k);
  void setSearchIntervals(LevelViews& v) const;
  void setOneSurfacePixels(LevelViews& v) const;
  bool matchLeftView(LevelViews& v, double w);
  void prepareRightView(LevelViews& v) const;
  bool matchRightView(LevelViews& v, double w);
  void validateViews(const LevelViews& v);
  void refineDepthSteps(LevelViews& v);
  void unmirrorRightView(const LevelOutput& mirrored);
  void validateLeft(const cv::Mat& kept);
  void keepFinestBuffers(LevelViews& v);

  const std::vector<PyramidLevel>& pyramid;
  const MatchParams& p;
  const int threads, levels;
  const double levelsShare;  // of the match's progress
  core::Progress* const progress;
  LevelMaps& maps;
  LevelSettings settings;
  std::vector<double> weight;  // progress weight of each level ∝ its area
  double total = 0;            // the weights' sum
  double done = 0;             // progress of the levels matched
};

CoarseToFine::CoarseToFine(const std::vector<PyramidLevel>& pyramid, const MatchParams& p,
                           int threads, double levelsShare, core::Progress* progress,
                           LevelMaps& maps)
    : pyramid(pyramid),
      p(p),
      threads(threads),
      levels(static_cast<int>(pyramid.size())),
      levelsShare(levelsShare),
      progress(progress),
      maps(maps),
      weight(static_cast<size_t>(levels)) {
  for (int k = 0; k < levels; ++k) total += (weight[static_cast<size_t>(k)] = std::pow(0.25, k));
  settings.window = p.window;
  settings.lineShift = p.lineShift;
  settings.minShape = p.minShape;
  settings.minScore = p.minScore;
  settings.subpixel = p.subpixel;
  settings.adaptive = p.adaptive;
  settings.threads = threads;
}

// Level k: the left view, the right view on the pixels the left matches point to, both
// validated, then the step cut. False when canceled.
bool CoarseToFine::matchOneLevel(int k) {
  LevelViews v(pyramid[static_cast<size_t>(k)], k);
  // "level 1/4" is the coarsest.
  const int levelNumber = levels - k;
  core::setStage(progress, core::StageId::MatchingLevel, levelNumber, levels);
  setSearchIntervals(v);
  const double w = levelsShare * weight[static_cast<size_t>(k)] / total;
  if (!matchLeftView(v, w)) return false;
  core::setStage(progress, core::StageId::MatchingLevelRightView, levelNumber, levels);
  prepareRightView(v);
  if (!matchRightView(v, w)) return false;
  done += w;
  core::setStage(progress, core::StageId::ValidatingLevel, levelNumber, levels);
  validateViews(v);
  if (p.adaptive && p.stepCut && k <= p.stepCutLevel) {
    core::setStage(progress, core::StageId::RefiningDepthSteps, levelNumber, levels);
    refineDepthSteps(v);
  }
  if (k == 0) keepFinestBuffers(v);
  return true;
}

// Both views' search intervals: the level's whole range at the coarsest level, else around the
// coarser level's validated maps.
void CoarseToFine::setSearchIntervals(LevelViews& v) const {
  const PyramidLevel& lv = v.level;
  LevelInput& inL = v.left;
  if (maps.validatedLeft.empty()) {
    inL.lo = cv::Mat(lv.left.size(), CV_32S, cv::Scalar(lv.dmin));
    inL.hi = cv::Mat(lv.left.size(), CV_32S, cv::Scalar(lv.dmax));
    v.rightLo = inL.lo;
    v.rightHi = inL.hi;
    return;
  }
  const bool widenNearRejected = v.k > 0;
  intervalsFromCoarse(maps.validatedLeft, lv.left.size(), lv.dmin, lv.dmax, p.margin,
                      widenNearRejected, threads, inL.lo, inL.hi);
  intervalsFromCoarse(maps.validatedRight, lv.left.size(), lv.dmin, lv.dmax, p.margin,
                      widenNearRejected, threads, v.rightLo, v.rightHi);
  // The two finest levels (above them, the coarser map is too coarse for the test to find
  // many such windows: 15 % of level 3's pixels at 1000² / 128 d, 35 % of level 4's).
  if (v.k <= 1 && p.adaptive && p.squareOnOneSurface) setOneSurfacePixels(v);
}

// The pixels whose window lies on one surface by the coarser level's validated maps, both views.
void CoarseToFine::setOneSurfacePixels(LevelViews& v) const {
  // The coarse pixels under the window (half its side) and 2 more: at the coarser level a
  // surface's values reach a pixel or two beyond its outline (sim seed 16 1000²: with 4, a roof
  // edge's pixels took the ground's value, roof RMS 0.161 -> 0.215 px), and a facade seen by one
  // view only sits beside a roof (seed 33 600²: 0.064 px without, 0.099 with 5, 0.076 with 6).
  // Values within 1 px at the finest level.
  const int radius = (p.window / 2 + 1) / 2 + 2;
  constexpr float kOneSurfaceSpread = 0.5F;  // coarse px
  const cv::Size size = v.level.left.size();
  runTasks({[&] {
              v.left.oneSurface =
                  oneSurfacePixels(maps.validatedLeft, size, radius, kOneSurfaceSpread, 1);
            },
            [&] {
              v.rightOneSurface =
                  oneSurfacePixels(maps.validatedRight, size, radius, kOneSurfaceSpread, 1);
            }},
           threads);
}

bool CoarseToFine::matchLeftView(LevelViews& v, double w) {
  core::Progress::Range leftRange(progress, done, done + 0.5 * w);
  return matchLevel(v.left, settings, maps.leftOut, progress ? &leftRange : nullptr, &v.shared) &&
         !core::isCanceled(progress);
}

// Only the right pixels that a left match checked here points to (the floor/ceil neighbours the
// validation reads) are matched: the left map's validation is the same as with them all, the
// unmatched and occluded areas less. Above the finest level the validated right map also guides
// the next level's right view; the pixels no left match points to (mostly what the left view
// does not see) then guide it from their neighbours' values instead (battery of 101 scenes:
// means unchanged, edge met 93 -> 94; level 3's right view 0.041 -> 0.036 s at 1000² / 128 d).
void CoarseToFine::prepareRightView(LevelViews& v) const {
  // Matches on smooth surfaces may keep the coarser level's check (coarse-check-score).
  v.parentLeft = maps.validatedLeft;
  v.inheritChecks = v.k == 0 && !v.parentLeft.empty() && p.coarseCheckScore > 0;
  if (v.inheritChecks) {
    v.kept = coarselyChecked(v.parentLeft, maps.leftOut, p.coarseCheckScore, threads);
  }
  const cv::Mat needed = pointedTo(maps.leftOut, v.kept, p.lineShift, threads);
  // Right -> left: mirrored images turn x_left = x_right + d into x'_other = x'_ref - d.
  // The intervals (the longest, ~4 ms at 1000²) first, in two halves.
  const PyramidLevel& lv = v.level;
  const cv::Mat &loR = v.rightLo, &hiR = v.rightHi, &oneR = v.rightOneSurface;
  LevelInput& inR = v.right;
  inR.lo.create(loR.size(), CV_32S);
  inR.hi.create(loR.size(), CV_32S);
  const int halfRows = loR.rows / 2;
  runTasks({[&] { mirrorIntervals(loR, hiR, needed, 0, halfRows, inR.lo, inR.hi); },
            [&] { mirrorIntervals(loR, hiR, needed, halfRows, loR.rows, inR.lo, inR.hi); },
            [&] { inR.ref = flipped(lv.right); }, [&] { inR.other = flipped(lv.left); },
            [&] { inR.refValid = flipped(lv.rightValid); },
            [&] { inR.otherValid = flipped(lv.leftValid); },
            [&] { inR.refEdges = flipped(lv.rightEdges); },
            [&] {
              if (!oneR.empty()) inR.oneSurface = flipped(oneR);
            }},
           threads);
}

bool CoarseToFine::matchRightView(LevelViews& v, double w) {
  core::Progress::Range rightRange(progress, done + 0.5 * w, done + w);
  return matchLevel(v.right, settings, v.mirrored, progress ? &rightRange : nullptr, &v.shared) &&
         !core::isCanceled(progress);
}

void CoarseToFine::validateViews(const LevelViews& v) {
  unmirrorRightView(v.mirrored);
  validateLeft(v.kept);
  maps.validatedRight = validate(maps.rightOut, maps.leftOut, -1, p.tolerance, threads);
}

// Depth steps of the validated maps (most have no image contour): each pixel near one is given a
// side and matched again on the window cut at the step (both maps, the right one mirrored like
// its matching), then both are validated again. Part of the adaptive shapes: off with plain
// square windows.
void CoarseToFine::refineDepthSteps(LevelViews& v) {
  StepRefineSettings rs;
  rs.window = p.window;
  rs.minScore = p.minScore;
  rs.minShape = p.minShape;
  rs.threads = settings.threads;
  const LevelInput &inL = v.left, &inR = v.right;
  detail::refineDepthSteps(inL.ref, inL.other, inL.refValid, inL.otherValid, maps.validatedLeft, rs,
                           maps.leftOut);
  // The right pixels that no left match points to are not matched again (as above).
  // The step cut may have matched kept pixels again: the kept ones are decided anew.
  if (v.inheritChecks) {
    v.kept = coarselyChecked(v.parentLeft, maps.leftOut, p.coarseCheckScore, threads);
  }
  const cv::Mat pointed = pointedTo(maps.leftOut, v.kept, p.lineShift, threads);
  cv::Mat rightNeeded, rightValidated;  // mirrored, both flipped at once
  runTasks({[&] { rightNeeded = flipped(pointed); },
            [&] { rightValidated = flipped(maps.validatedRight); }},
           threads);
  detail::refineDepthSteps(inR.ref, inR.other, inR.refValid, inR.otherValid, rightValidated, rs,
                           v.mirrored, rightNeeded);
  unmirrorRightView(v.mirrored);
  validateLeft(v.kept);
  // The validated right map guides the next finer level only.
  if (v.k > 0) {
    maps.validatedRight = validate(maps.rightOut, maps.leftOut, -1, p.tolerance, threads);
  }
}

void CoarseToFine::unmirrorRightView(const LevelOutput& mirrored) {
  // (The right scores are not used: validate() reads disparities and line shifts.)
  runTasks({[&] { maps.rightOut.disparity = flipped(mirrored.disparity); },
            [&] { maps.rightOut.lineShift = flipped(mirrored.lineShift); }},
           threads);
}

// The left matches that pass the validation, and the kept ones.
void CoarseToFine::validateLeft(const cv::Mat& kept) {
  maps.validatedLeft = validate(maps.leftOut, maps.rightOut, +1, p.tolerance, threads);
  if (!kept.empty()) maps.leftOut.disparity.copyTo(maps.validatedLeft, kept);
}

void CoarseToFine::keepFinestBuffers(LevelViews& v) {
  maps.finestBuffers.left = std::move(v.left);
  maps.finestBuffers.right = std::move(v.right);
  maps.finestBuffers.rightLo = std::move(v.rightLo);
  maps.finestBuffers.rightHi = std::move(v.rightHi);
  maps.finestBuffers.shared = std::move(v.shared);
  maps.finestBuffers.mirrored = std::move(v.mirrored);
}

}  // namespace

bool matchLevelsCoarseToFine(const std::vector<PyramidLevel>& pyramid, const MatchParams& p,
                             int threads, double levelsShare, core::Progress* progress,
                             LevelMaps& maps) {
  CoarseToFine coarseToFine(pyramid, p, threads, levelsShare, progress, maps);
  for (int k = coarseToFine.levels - 1; k >= 0; --k) {
    if (!coarseToFine.matchOneLevel(k)) return false;
  }
  return true;
}

}  // namespace delineo::stereo::detail
