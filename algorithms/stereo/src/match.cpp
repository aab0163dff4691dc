// Coarse-to-fine driver of the adaptive matcher, symmetric validation, and the SGBM backend.
#include "delineo/stereo/match.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "coarse_check.hpp"
#include "coarse_intervals.hpp"
#include "contour_gaps.hpp"
#include "cpu_features.hpp"
#include "delineo/core/error.hpp"
#include "delineo/core/nan_mask.hpp"
#include "level_matcher.hpp"
#include "match_fill.hpp"
#include "match_snap.hpp"
#include "match_snap_rows.hpp"
#include "match_steps.hpp"
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

int floorDiv(int a, int b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}
int ceilDiv(int a, int b) {
  return -floorDiv(-a, b);
}

// The driver's own per-level work (preparation, Canny, validation, intervals) runs on the
// level's threads (workers.hpp); serial, it was ~0.17 s CPU of the 1000²/128 d run.
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

struct Level {
  cv::Mat left, right, leftValid, rightValid, leftEdges, rightEdges;
  int dmin = 0, dmax = 0;
};

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
cv::Mat validate(const detail::LevelOutput& map, const detail::LevelOutput& other, int sign,
                 double tolerance, int threads) {
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
      detail::cpuHasAvx2() &&
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
cv::Mat pointedTo(const detail::LevelOutput& map, const cv::Mat& kept, int lineShift, int threads) {
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

int threadCount(const MatchParams& p) {
  if (p.threads > 0) return p.threads;
  return std::max(1U, std::thread::hardware_concurrency());
}

MatchResult matchAdaptiveSteps(const cv::Mat& left, const cv::Mat& right, const MatchParams& p,
                               core::Progress* progress) {
  MatchResult result;
  int levels = p.levels > 0 ? p.levels : autoLevels(p.dmin, p.dmax);
  while (levels > 1 && std::min(left.cols, left.rows) / (1 << (levels - 1)) < kMinLevelSide) {
    --levels;
  }
  result.levelsUsed = levels;

  const int threads = threadCount(p);
  // Its helpers serve the match's parallel steps (see WorkerPool).
  detail::WorkerPool workerPool(threads - 1);
  const detail::WorkerPool::Scope poolScope(workerPool);
  core::setStage(progress, core::StageId::PreparingPyramids);
  const GreyMapping g = greyMapping(left, right, threads);
  std::vector<Level> pyramid(static_cast<size_t>(levels));
  // Left and right are independent up to the matching: each side's preparation and pyramid is
  // one task, then the Canny edges of every level and side are one task each.
  auto buildSide = [&](bool isLeft) {
    Level& base = pyramid[0];
    prepare(isLeft ? left : right, g, isLeft ? base.left : base.right,
            isLeft ? base.leftValid : base.rightValid);
    for (int k = 1; k < levels; ++k) {
      detail::throwIfCanceled();
      Level& fine = pyramid[static_cast<size_t>(k - 1)];
      Level& coarse = pyramid[static_cast<size_t>(k)];
      cv::pyrDown(isLeft ? fine.left : fine.right, isLeft ? coarse.left : coarse.right);
      // A coarse pixel holds data only when its whole footprint did.
      (isLeft ? coarse.leftValid : coarse.rightValid) =
          coarseValid(isLeft ? fine.leftValid : fine.rightValid);
    }
  };
  runTasks({[&] { buildSide(true); }, [&] { buildSide(false); }}, threads);
  // The left image's 5x5 moments and noise, for the steps after the levels (the fill's flat
  // regions, the plain pixels, the snapping's contrast): one more task here, where the edges
  // leave a worker idle at times, instead of three computations of them after the levels.
  const bool afterSteps = p.adaptive && (p.fillRegions || p.snapSteps || p.plainStepMinScore > 0 ||
                                         p.unmatchedPlainMinScore > 0);
  detail::LocalMoments leftMoments;
  // The right image's flat pixels, for the fill's right flat regions, which its regions wait for:
  // made here, where they lengthen the stage by less than they did the fill's wait (1000² /
  // 128 d, ~6 ms); the mask only is kept (the moments took 32 MB more at 2000² up to the fill).
  const bool fillsRegions = p.adaptive && p.fillRegions;
  const detail::RegionFillSettings fillSettings;
  cv::Mat rightFlat;
  std::vector<std::function<void()>> edgeTasks;
  for (int k = 0; k < levels; ++k) {
    Level& lv = pyramid[static_cast<size_t>(k)];
    edgeTasks.emplace_back([&lv, &p] { lv.leftEdges = edgeMap(lv.left, p); });
    edgeTasks.emplace_back([&lv, &p] { lv.rightEdges = edgeMap(lv.right, p); });
    lv.dmin = floorDiv(p.dmin, 1 << k);
    lv.dmax = ceilDiv(p.dmax, 1 << k);
    // The tasks are taken in order, the longest first: the moments (full size, about 60 % of a
    // finest edge map's time) right after the finest level's edges. Last, they ran alone on one
    // worker for ~10 ms at 1000² while the other waited.
    if (k == 0 && afterSteps) {
      edgeTasks.emplace_back([&] { leftMoments = detail::localMoments(left); });
    }
    if (k == 0 && fillsRegions) {
      edgeTasks.emplace_back(
          [&] { rightFlat = detail::plainPixels(right, fillSettings.flatSigmas); });
    }
  }
  runTasks(edgeTasks, threads);

  // Progress weight of each level ∝ its area.
  std::vector<double> weight(static_cast<size_t>(levels));
  double total = 0;
  for (int k = 0; k < levels; ++k) total += (weight[static_cast<size_t>(k)] = std::pow(0.25, k));
  // The steps after the levels' matching (the finest level's refinement, fill, speckles,
  // snapping) take ~20 % of the time at 1 Mpx: the bar does not sit at 100 % meanwhile.
  const bool postSteps =
      (p.adaptive && (p.stepCut || p.fillRegions || p.snapSteps)) || p.speckleSize > 0;
  const double levelsShare = postSteps ? 0.8 : 1.0;

  detail::LevelSettings s;
  s.window = p.window;
  s.lineShift = p.lineShift;
  s.minShape = p.minShape;
  s.minScore = p.minScore;
  s.subpixel = p.subpixel;
  s.adaptive = p.adaptive;
  s.threads = threads;

  cv::Mat coarseLeft, coarseRight;  // validated disparities of the previous (coarser) level
  double done = 0;
  detail::LevelOutput leftOut, rightOut;
  // The finest level's working buffers, kept past the loop to be released beside the fill (see
  // releaseLevels below) rather than alone at the end of the loop's last pass.
  struct FinestLevelBuffers {
    detail::LevelInput left, right;
    cv::Mat rightLo, rightHi;
    detail::LevelPreparations shared;
    detail::LevelOutput mirrored;
  } finestBuffers;
  for (int k = levels - 1; k >= 0; --k) {
    const Level& lv = pyramid[static_cast<size_t>(k)];
    // "level 1/4" is the coarsest.
    const int levelNumber = levels - k;
    core::setStage(progress, core::StageId::MatchingLevel, levelNumber, levels);
    detail::LevelInput inL, inR;
    inL.ref = lv.left;
    inL.other = lv.right;
    inL.refValid = lv.leftValid;
    inL.otherValid = lv.rightValid;
    inL.refEdges = lv.leftEdges;
    inL.dmin = inR.dmin = lv.dmin;
    inL.dmax = inR.dmax = lv.dmax;
    cv::Mat loR, hiR, oneR;
    if (coarseLeft.empty()) {
      inL.lo = cv::Mat(lv.left.size(), CV_32S, cv::Scalar(lv.dmin));
      inL.hi = cv::Mat(lv.left.size(), CV_32S, cv::Scalar(lv.dmax));
      loR = inL.lo;
      hiR = inL.hi;
    } else {
      const bool widenNearRejected = k > 0;
      detail::intervalsFromCoarse(coarseLeft, lv.left.size(), lv.dmin, lv.dmax, p.margin,
                                  widenNearRejected, threads, inL.lo, inL.hi);
      detail::intervalsFromCoarse(coarseRight, lv.left.size(), lv.dmin, lv.dmax, p.margin,
                                  widenNearRejected, threads, loR, hiR);
      // The two finest levels (above them, the coarser map is too coarse for the test to find
      // many such windows: 15 % of level 3's pixels at 1000² / 128 d, 35 % of level 4's).
      if (k <= 1 && p.adaptive && p.squareOnOneSurface) {
        // The coarse pixels under the window (half its side) and 2 more: at the coarser level
        // a surface's values reach a pixel or two beyond its outline (sim seed 16 1000²: with
        // 4, a roof edge's pixels took the ground's value, roof RMS 0.161 -> 0.215 px), and a
        // facade seen by one view only sits beside a roof (seed 33 600²: 0.064 px without, 0.099
        // with 5, 0.076 with 6). Values within 1 px at the finest level.
        const int radius = (p.window / 2 + 1) / 2 + 2;
        constexpr float kOneSurfaceSpread = 0.5F;  // coarse px
        runTasks({[&] {
                    inL.oneSurface = detail::oneSurfacePixels(coarseLeft, lv.left.size(), radius,
                                                              kOneSurfaceSpread, 1);
                  },
                  [&] {
                    oneR = detail::oneSurfacePixels(coarseRight, lv.left.size(), radius,
                                                    kOneSurfaceSpread, 1);
                  }},
                 threads);
      }
    }
    const double w = levelsShare * weight[static_cast<size_t>(k)] / total;
    detail::LevelPreparations shared;  // the left view's, for the right view
    core::Progress::Range leftRange(progress, done, done + 0.5 * w);
    if (!detail::matchLevel(inL, s, leftOut, progress ? &leftRange : nullptr, &shared) ||
        core::isCanceled(progress)) {
      result.status = core::RunStatus::Canceled;
      return result;
    }
    core::setStage(progress, core::StageId::MatchingLevelRightView, levelNumber, levels);
    // Only the right pixels that a left match checked here points to (the floor/ceil neighbours
    // the validation reads) are matched: the left map's validation is the same as with them all,
    // the unmatched and occluded areas less. Above the finest level the validated right map also
    // guides the next level's right view; the pixels no left match points to (mostly what the
    // left view does not see) then guide it from their neighbours' values instead (battery of
    // 101 scenes: means unchanged, edge met 93 -> 94; level 3's right view 0.041 -> 0.036 s at
    // 1000² / 128 d).
    // Matches on smooth surfaces may keep the coarser level's check (coarse-check-score).
    const cv::Mat parentLeft = coarseLeft;
    const bool inheritChecks = k == 0 && !parentLeft.empty() && p.coarseCheckScore > 0;
    cv::Mat kept;
    if (inheritChecks) {
      kept = detail::coarselyChecked(parentLeft, leftOut, p.coarseCheckScore, threads);
    }
    const cv::Mat needed = pointedTo(leftOut, kept, p.lineShift, threads);
    // Right -> left: mirrored images turn x_left = x_right + d into x'_other = x'_ref - d.
    // The intervals (the longest, ~4 ms at 1000²) first, in two halves.
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

    core::Progress::Range rightRange(progress, done + 0.5 * w, done + w);
    detail::LevelOutput mirrored;
    if (!detail::matchLevel(inR, s, mirrored, progress ? &rightRange : nullptr, &shared) ||
        core::isCanceled(progress)) {
      result.status = core::RunStatus::Canceled;
      return result;
    }
    done += w;
    core::setStage(progress, core::StageId::ValidatingLevel, levelNumber, levels);
    auto unmirror = [&] {
      // (The right scores are not used: validate() reads disparities and line shifts.)
      runTasks({[&] { rightOut.disparity = flipped(mirrored.disparity); },
                [&] { rightOut.lineShift = flipped(mirrored.lineShift); }},
               threads);
    };
    unmirror();
    coarseLeft = validate(leftOut, rightOut, +1, p.tolerance, threads);
    if (!kept.empty()) leftOut.disparity.copyTo(coarseLeft, kept);
    coarseRight = validate(rightOut, leftOut, -1, p.tolerance, threads);
    if (p.adaptive && p.stepCut && k <= p.stepCutLevel) {
      // Depth steps of the validated maps (most have no image contour): each pixel near one is
      // given a side and matched again on the window cut at the step (both maps, the right one
      // mirrored like its matching), then both are validated again. Part of the adaptive shapes:
      // off with plain square windows.
      core::setStage(progress, core::StageId::RefiningDepthSteps, levelNumber, levels);
      detail::StepRefineSettings rs;
      rs.window = p.window;
      rs.minScore = p.minScore;
      rs.minShape = p.minShape;
      rs.threads = s.threads;
      detail::refineDepthSteps(inL.ref, inL.other, inL.refValid, inL.otherValid, coarseLeft, rs,
                               leftOut);
      // The right pixels that no left match points to are not matched again (as above).
      // The step cut may have matched kept pixels again: the kept ones are decided anew.
      if (inheritChecks) {
        kept = detail::coarselyChecked(parentLeft, leftOut, p.coarseCheckScore, threads);
      }
      const cv::Mat pointed = pointedTo(leftOut, kept, p.lineShift, threads);
      cv::Mat rightNeeded, rightValidated;  // mirrored, both flipped at once
      runTasks(
          {[&] { rightNeeded = flipped(pointed); }, [&] { rightValidated = flipped(coarseRight); }},
          threads);
      detail::refineDepthSteps(inR.ref, inR.other, inR.refValid, inR.otherValid, rightValidated, rs,
                               mirrored, rightNeeded);
      unmirror();
      coarseLeft = validate(leftOut, rightOut, +1, p.tolerance, threads);
      if (!kept.empty()) leftOut.disparity.copyTo(coarseLeft, kept);
      // The validated right map guides the next finer level only.
      if (k > 0) coarseRight = validate(rightOut, leftOut, -1, p.tolerance, threads);
    }
    if (k == 0) {
      finestBuffers.left = std::move(inL);
      finestBuffers.right = std::move(inR);
      finestBuffers.rightLo = std::move(loR);
      finestBuffers.rightHi = std::move(hiR);
      finestBuffers.shared = std::move(shared);
      finestBuffers.mirrored = std::move(mirrored);
    }
  }
  // The steps after the levels report their share and are polled too: a cancel is honoured
  // between them.
  const auto reachedButCanceled = [&](double fraction) {
    core::report(progress, fraction);
    if (!core::isCanceled(progress)) return false;
    // As when canceled during the levels: no maps.
    result.disparity.release();
    result.score.release();
    result.status = core::RunStatus::Canceled;
    return true;
  };
  if (reachedButCanceled(0.85)) return result;
  result.disparity = coarseLeft;
  // The left scores where the disparity is a number (NaN elsewhere), in one pass by bands.
  result.score.create(leftOut.score.size(), CV_32F);
  forRowBands(result.score.rows, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const float* __restrict d = result.disparity.ptr<float>(y);
      const float* __restrict sc = leftOut.score.ptr<float>(y);
      float* __restrict out = result.score.ptr<float>(y);
      for (int x = 0; x < result.score.cols; ++x) out[x] = d[x] == d[x] ? sc[x] : kNaN;
    }
  });
  // The fill runs on one worker; the snapping's contrast map and the plain pixels of the weak
  // matches' wider pass (images only) are prepared on the other meanwhile, after the fill's own
  // preparations there.
  core::setStage(progress, core::StageId::FillingFlatRegions);
  detail::StepContrast contrast;
  cv::Mat plain;
  const bool plainPass = p.adaptive && (p.plainStepMinScore > 0 || p.unmatchedPlainMinScore > 0);
  const auto prepareImages = [&] {
    if (p.snapSteps && p.adaptive) contrast = detail::stepContrast(left, right, leftMoments.noise);
    if (plainPass) plain = detail::plainPixels(left, 3.0, &leftMoments);
  };
  // The levels' maps and images are no longer needed (but the finest left edges, for the
  // facets): released by the fill's second worker once the regions are decided, where their
  // pages' return to the system (~5 ms at 1 Mpx) fills the gaps of the regions' extension instead
  // of running alone at the end.
  const auto releaseLevels = [&] {
    const cv::Mat finestLeftEdges = pyramid[0].leftEdges;
    pyramid.assign(1, Level{});
    pyramid[0].leftEdges = finestLeftEdges;
    leftOut = {};
    rightOut = {};
    coarseRight.release();
    finestBuffers = {};
    rightFlat.release();  // the right flat regions are made by then
  };
  if (p.fillRegions && p.adaptive) {
    detail::fillFlatRegions(left, right, fillSettings, p.dmin, p.dmax,
                            static_cast<float>(p.minScore), result.disparity, result.score, threads,
                            prepareImages, &leftMoments, releaseLevels, &rightFlat);
  } else {
    prepareImages();
    releaseLevels();
  }
  // After the fill, whose candidates are the matches around a region (before it, a roof's weak
  // edge matches went and the fill took a box on it for the whole roof: sim seed 15 600², roof
  // RMS 0.290 -> 0.432 px), and before the speckles and the snapping, which close the gaps left.
  if (p.adaptive && p.stepMinScore > 0) {
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
  if (plainPass && p.plainStepMinScore > 0) {
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
  if (plainPass && p.unmatchedPlainMinScore > 0) {
    detail::UnmatchedPlainSettings beside;
    beside.minScore = p.unmatchedPlainMinScore;
    beside.threads = threads;
    detail::rejectWeakMatchesBesideUnmatchedPlain(beside, static_cast<float>(p.minScore), plain,
                                                  result.disparity, result.score);
  }
  // Then the steep facets left unmatched, matched region by region on slanted planes; before the
  // speckles, the snapping and the ordering check, which treat their matches like any other.
  if (p.adaptive && p.facetMaxSlope > 0) {
    detail::SlantedFacetSettings facets;
    facets.maxSlope = p.facetMaxSlope;
    facets.threads = threads;
    detail::recoverSlantedFacets(left, right, pyramid[0].leftEdges, facets, p.dmin, p.dmax,
                                 result.disparity, result.score);
  }
  if (reachedButCanceled(0.9)) return result;
  // Speckles are removed after the fill (before it, the fill lost its seeds: 600² edge 66.1 %
  // against 74.7 % removed last) and before the snapping, whose steps a wrong island inside the
  // gap between a roof and the ground split (sim 400² edge 88.1 → 90.7 %, seed 3 600² 76.1 →
  // 79.5 %); and again last, for the islands the snapping's cuts leave.
  if (p.speckleSize > 0) {
    core::setStage(progress, core::StageId::RemovingSpeckles);
    detail::removeSpeckles(result.disparity, result.score, p.speckleSize, p.speckleRange, threads);
    if (reachedButCanceled(0.92)) return result;
  }
  if (p.snapSteps && p.adaptive) {
    // Last, after the fill: a filled roof's edges are snapped like matched ones.
    core::setStage(progress, core::StageId::SnappingDepthSteps);
    detail::StepSnapSettings snap;
    snap.threads = threads;
    detail::snapStepsToContours(left, right, contrast, snap, static_cast<float>(p.minScore),
                                result.disparity, result.score);
    detail::RowStepSnapSettings rows;
    rows.threads = threads;
    detail::snapStepsAcrossRows(left, right, contrast.sigma, rows, static_cast<float>(p.minScore),
                                result.disparity, result.score);
    if (reachedButCanceled(0.98)) return result;
  }
  if (p.speckleSize > 0 && p.snapSteps && p.adaptive) {
    core::setStage(progress, core::StageId::RemovingSnappingSpeckles);
    detail::removeSpeckles(result.disparity, result.score, p.speckleSize, p.speckleRange, threads);
  }
  // On the final map, after every step that sets matches (the fill's matches can be hidden too)
  // and before the smoothing, which would average a hidden match into the surface hiding it.
  // (600² roof RMS over all matches 2.121 -> 0.226 px; see docs/stereo.md, step 16.)
  if (p.orderingCheck) {
    detail::OrderingSettings ordering;
    ordering.threads = threads;
    detail::rejectOrderingViolations(result.disparity, result.score, ordering);
  }
  // Last: on the final map, where the fill, the snapping and the speckle removal have set the
  // steps that the smoothing must not cross. (Flat-roof RMS of the matches within 1 px, 5x5 and
  // 1 px: sim seed 6 600² 0.255 -> 0.220, 600² 0.233 -> 0.205; see docs/stereo.md.)
  if (p.smoothWindow > 0) {
    detail::smoothSurfaces(result.disparity, p.smoothWindow, p.smoothTolerance, threads);
  }
  // After the smoothing: a roof's matches are noisy at the scale of the correlation window, which
  // a 5x5 mean cannot average out; a plane over the whole roof does (see docs/stereo.md, step
  // 18).
  if (p.planeResidual > 0) {
    if (reachedButCanceled(0.99)) return result;
    core::setStage(progress, core::StageId::FittingRoofPlanes);
    detail::RoofPlaneSettings planes;
    planes.maxResidual = p.planeResidual;
    planes.minPixels = p.planeMinArea;
    planes.threads = threads;
    detail::fitRoofPlanes(result.disparity, planes);
  }
  core::report(progress, 1.0);
  return result;
}

// The steps poll the cancel within (workers.hpp): a cancel ends the match from any of them.
MatchResult matchAdaptive(const cv::Mat& left, const cv::Mat& right, const MatchParams& p,
                          core::Progress* progress) {
  const detail::CancelScope cancelScope(progress);
  try {
    return matchAdaptiveSteps(left, right, p, progress);
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
                      core::Progress* progress) {
  MatchResult result;
  core::setStage(progress, core::StageId::MatchingSgbm);
  core::report(progress, 0.0);
  if (core::isCanceled(progress)) {
    result.status = core::RunStatus::Canceled;
    return result;
  }
  const GreyMapping g = greyMapping(left, right, threadCount(p));
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
  if (params.method == "sgbm") return matchSgbm(left, right, params, progress);
  return matchAdaptive(left, right, params, progress);
}

}  // namespace delineo::stereo
