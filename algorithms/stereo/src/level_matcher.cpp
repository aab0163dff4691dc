// One level of the adaptive-window NCC matcher.
//
// The image is cut into tiles; every pixel has its own search interval [lo, hi] (from the
// coarser level). The main line (dy = 0) is searched over the whole interval, the ±1 line shifts
// only around its peak (a local ascent on the 2D correlation surface that starts with the two
// neighbouring lines at the peak's d), which costs 2 correlations per pixel, a few tens when
// the ascent moves, instead of 2 × the interval.
//  - Pixels whose template window holds no contour pixel (or all pixels when adaptive shapes are
//    off) use a square window. A tile is swept disparity by disparity over the union of those
//    pixels' intervals: the product image of the tile is box-filtered (running column and row
//    sums), so a correlation costs O(1) per pixel and disparity. Pixels whose interval is much
//    wider than the tile's typical one (rejected at the coarser level) are correlated directly
//    when that is cheaper than widening the sweep.
//  - Pixels with a contour inside their window get the adaptive shape S (4-connected flood fill
//    from the centre that does not cross contour pixels) and a direct NCC over S, computed on
//    dense w x w rows (element-wise, vectorisable).
// Memory is bounded by a few tile-sized buffers per worker: no cost volume is stored.
//
// The matcher is built twice: for the x86-64 baseline (namespace `base`) and, as this file
// includes itself once more under #pragma GCC target("avx2"), for AVX2 (namespace
// `avx2build`); matchLevel() picks the AVX2 build when the CPU has it. Built for AVX2 as a
// whole, the driver inlines the AVX2 kernels and uses three-operand instructions. No FMA in
// either build: the same arithmetic, the same maps.
#ifndef DELINEO_LEVEL_MATCHER_AVX2_PASS
#include "level_matcher.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <thread>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "cpu_features.hpp"
#include "level_shape_int.hpp"
#include "workers.hpp"

#define DELINEO_LEVEL_MATCHER_BUILD base
// Functions also built for other instruction sets (target_clones) in the baseline build; plain
// AVX2 functions in the AVX2 build (a function under the AVX2 pragma cannot be cloned).
#define DELINEO_LEVEL_MATCHER_CLONES(...) DELINEO_TARGET_CLONES(__VA_ARGS__)
#else
#undef DELINEO_LEVEL_MATCHER_BUILD
#undef DELINEO_LEVEL_MATCHER_CLONES
#define DELINEO_LEVEL_MATCHER_BUILD avx2build
#define DELINEO_LEVEL_MATCHER_CLONES(...)
#endif

namespace delineo::stereo::detail::DELINEO_LEVEL_MATCHER_BUILD {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kNegInf = -std::numeric_limits<float>::infinity();
constexpr int kTileRows = 32;
constexpr int kTileCols = 64;
// Steps of the local ascent over line shifts: the dy = ±1 peak lies next to the dy = 0 one.
constexpr int kMaxAscentSteps = 4;
// Steps a main-line peak may move outside its guided interval (following a slope).
constexpr int kMaxIntervalExtension = 1;
// NCC gain a neighbouring line must bring over the current one for the ascent to move there.
constexpr float kLineShiftGain = 0.05F;
// Variance (grey levels², images normalised to ~0..255) under which a window is flat: its NCC
// is meaningless.
constexpr double kFlatVariance = 0.01;

// Mean and standard deviation of every square window that lies inside the image and holds only
// valid pixels and is not flat; usable = 0 elsewhere.
// Also built for AVX2 (the column sums 4 doubles a vector; no FMA, so the same arithmetic).
DELINEO_LEVEL_MATCHER_CLONES("avx2", "default")
WindowMoments windowStats(const cv::Mat& img, const cv::Mat& valid, int window) {
  // Running sums (double): per column over the window's rows, slid down one row at a time,
  // then along the row. Two passes over the image instead of three integral images.
  const int r = window / 2;
  const double n = static_cast<double>(window) * window;
  const int W = img.cols, H = img.rows;
  WindowMoments s{cv::Mat(img.size(), CV_32F, cv::Scalar(0)),
                  cv::Mat(img.size(), CV_32F, cv::Scalar(0)),
                  cv::Mat(img.size(), CV_8U, cv::Scalar(0))};
  if (W < window || H < window) return s;
  std::vector<double> colSum(static_cast<size_t>(W), 0.0), colSq(static_cast<size_t>(W), 0.0);
  std::vector<int> colCount(static_cast<size_t>(W), 0);
  auto addRow = [&](int y, double sign) {
    const float* p = img.ptr<float>(y);
    const uchar* v = valid.ptr<uchar>(y);
    const int c = sign > 0 ? 1 : -1;
    for (int x = 0; x < W; ++x) {
      const double value = p[x];
      colSum[static_cast<size_t>(x)] += sign * value;
      colSq[static_cast<size_t>(x)] += sign * value * value;
      colCount[static_cast<size_t>(x)] += v[x] ? c : 0;
    }
  };
  for (int y = 0; y < window - 1; ++y) addRow(y, 1.0);
  const int full = window * window;
  // A row's window sums first (the sliding sums, a chain of additions), then its moments from
  // them in loops without that chain, vectorised (the divisions and square roots one pixel at a
  // time took about half of the ~8 ms of one image at 1 Mpx). The same arithmetic.
  std::vector<double> rowSum(static_cast<size_t>(W), 0.0), rowSq(static_cast<size_t>(W), 0.0);
  std::vector<int> rowCount(static_cast<size_t>(W), 0);
  cv::Mat rootRow;
  for (int y = r; y < H - r; ++y) {
    addRow(y + r, 1.0);
    double sum = 0, sq = 0;
    int count = 0;
    for (int x = 0; x < window - 1; ++x) {
      sum += colSum[static_cast<size_t>(x)];
      sq += colSq[static_cast<size_t>(x)];
      count += colCount[static_cast<size_t>(x)];
    }
    for (int x = r; x < W - r; ++x) {
      const auto in = static_cast<size_t>(x + r), out = static_cast<size_t>(x - r);
      sum += colSum[in];
      sq += colSq[in];
      count += colCount[in];
      rowSum[static_cast<size_t>(x)] = sum;
      rowSq[static_cast<size_t>(x)] = sq;
      rowCount[static_cast<size_t>(x)] = count;
      sum -= colSum[out];
      sq -= colSq[out];
      count -= colCount[out];
    }
    // In place: the sums become the means and the squares the variances, then their roots (by
    // OpenCV's vectorised square root: the library's sets errno, which keeps the compiler from
    // vectorising it).
    const int inner = W - 2 * r;
    double* __restrict means = rowSum.data() + r;
    double* __restrict variances = rowSq.data() + r;
    for (int i = 0; i < inner; ++i) {
      const double m = means[i] / n;
      variances[i] = variances[i] / n - m * m;
      means[i] = m;
    }
    const cv::Mat varianceRow(1, inner, CV_64F, variances);
    cv::sqrt(varianceRow, rootRow);  // NaN where negative: not usable below
    const double* __restrict roots = rootRow.ptr<double>(0);
    const int* __restrict counts = rowCount.data() + r;
    float* __restrict mean = s.mean.ptr<float>(y) + r;
    float* __restrict sd = s.sd.ptr<float>(y) + r;
    uchar* __restrict ok = s.usable.ptr<uchar>(y) + r;
    for (int i = 0; i < inner; ++i) {
      const bool usable = counts[i] == full && variances[i] >= kFlatVariance;
      mean[i] = usable ? static_cast<float>(means[i]) : 0.0F;
      sd[i] = usable ? static_cast<float>(roots[i]) : 0.0F;
      ok[i] = usable ? 1 : 0;
    }
    addRow(y - r, -1.0);
  }
  return s;
}

// Sums over the rows of a shape: Σ M·B, Σ M·B², Σ T·B, with M and T stored as rows of P floats
// (P a compile-time 16 or 32 ≥ window: fixed-length loops that vectorise fully; the entries
// past the window are 0, and the images are padded on the right so that reading P columns
// stays inside them).
template <int P>
inline void shapeSums(const float* b, const float* b2, size_t stride, const float* mask,
                      const float* templ, int rows, float out[3]) {
  float accB[P] = {}, accBB[P] = {}, accTB[P] = {};
  for (int v = 0; v < rows; ++v) {
    const float* bv = b + static_cast<size_t>(v) * stride;
    const float* qv = b2 + static_cast<size_t>(v) * stride;
    const float* m = mask + static_cast<size_t>(v) * P;
    const float* t = templ + static_cast<size_t>(v) * P;
    for (int u = 0; u < P; ++u) {
      accB[u] += m[u] * bv[u];
      accBB[u] += m[u] * qv[u];
      accTB[u] += t[u] * bv[u];
    }
  }
  float sB = 0, sBB = 0, sTB = 0;
  for (int u = 0; u < P; ++u) {
    sB += accB[u];
    sBB += accBB[u];
    sTB += accTB[u];
  }
  out[0] = sB;
  out[1] = sBB;
  out[2] = sTB;
}

// Windows wider than 15 columns (the narrower ones take the integer kernels of
// level_shape_int.hpp), also built for AVX2 (picked at run time when the CPU has it).
DELINEO_LEVEL_MATCHER_CLONES("avx2", "default")
void shapeSums32(const float* b, const float* b2, size_t stride, const float* mask,
                 const float* templ, int rows, float out[3]) {
  shapeSums<32>(b, b2, stride, mask, templ, rows, out);
}

using Float8 = float __attribute__((vector_size(32)));

// By reference: returning a 32-byte vector from a function built without AVX changes the ABI.
__attribute__((always_inline)) inline void load8(Float8& v, const float* p) {
  __builtin_memcpy(&v, p, sizeof v);
}

using Float4 = float __attribute__((vector_size(16)));

// Sum of the 8 lanes by halving (3 vector adds instead of 7 scalar ones).
__attribute__((always_inline)) inline float laneSum(const Float8& v) {
  const Float4 h =
      __builtin_shufflevector(v, v, 0, 1, 2, 3) + __builtin_shufflevector(v, v, 4, 5, 6, 7);
  const Float4 q = h + __builtin_shufflevector(h, h, 2, 3, 0, 1);
  return q[0] + q[1];
}

// Main-line windows d, d + 1, ... (one column further left each), scored several per pass over
// the shape (shapeBatchWindows(): as many as the vector registers hold).
constexpr ptrdiff_t kMainLine[kShapeMaxWindows] = {0, -1, -2, -3, -4, -5, -6, -7};

// Σ A·B over `rows` rows of two windows ≤ 16 columns wide; `lanes` weighs the 16 columns read
// (1 inside the window, 0 past it).
DELINEO_LEVEL_MATCHER_CLONES("avx2", "default")
float windowDot16(const float* a, size_t aStride, const float* b, size_t bStride, int rows,
                  const float* lanes) {
  Float8 acc0{}, acc1{}, w0, w1;
  load8(w0, lanes);
  load8(w1, lanes + 8);
  for (int v = 0; v < rows; ++v) {
    Float8 a0, a1, b0, b1;
    load8(a0, a + static_cast<size_t>(v) * aStride);
    load8(a1, a + static_cast<size_t>(v) * aStride + 8);
    load8(b0, b + static_cast<size_t>(v) * bStride);
    load8(b1, b + static_cast<size_t>(v) * bStride + 8);
    acc0 += a0 * b0;
    acc1 += a1 * b1;
  }
  return laneSum(acc0 * w0 + acc1 * w1);
}

// The products of a 16-column template row (a0, a1) with the row of the other image at `b`,
// added to (sum0, sum1).
__attribute__((always_inline)) inline void addRowProducts(const Float8& a0, const Float8& a1,
                                                          const float* b, Float8& sum0,
                                                          Float8& sum1) {
  Float8 b0, b1;
  load8(b0, b);
  load8(b1, b + 8);
  sum0 += a0 * b0;
  sum1 += a1 * b1;
}

// windowDot16 of the two windows at `b` and `c` (the lines above and below, the ±1 line probes)
// in one pass: the rows of `a` are loaded once for the two (the same sums, in the same order, as
// two calls).
DELINEO_LEVEL_MATCHER_CLONES("avx2", "default")
void windowDot16Pair(const float* a, size_t aStride, const float* b, const float* c, size_t bStride,
                     int rows, const float* lanes, float out[2]) {
  Float8 p0{}, p1{}, q0{}, q1{}, w0, w1;
  load8(w0, lanes);
  load8(w1, lanes + 8);
  for (int v = 0; v < rows; ++v) {
    Float8 a0, a1;
    load8(a0, a + static_cast<size_t>(v) * aStride);
    load8(a1, a + static_cast<size_t>(v) * aStride + 8);
    addRowProducts(a0, a1, b + static_cast<size_t>(v) * bStride, p0, p1);
    addRowProducts(a0, a1, c + static_cast<size_t>(v) * bStride, q0, q1);
  }
  out[0] = laneSum(p0 * w0 + p1 * w1);
  out[1] = laneSum(q0 * w0 + q1 * w1);
}

// windowDot16 of the 4 windows b, b − 1, b − 2, b − 3 (main-line disparities d .. d + 3) in
// one pass: the rows of `a` are loaded once for the four (the same sums, in the same order, as
// four calls).
DELINEO_LEVEL_MATCHER_CLONES("avx2", "default")
void windowDots16x4(const float* a, size_t aStride, const float* b, size_t bStride, int rows,
                    const float* lanes, float out[4]) {
  // Named accumulators (arrays of vectors were partly kept on the stack).
  Float8 p0{}, p1{}, q0{}, q1{}, r0{}, r1{}, s0{}, s1{};
  for (int v = 0; v < rows; ++v) {
    const float* av = a + static_cast<size_t>(v) * aStride;
    const float* bv = b + static_cast<size_t>(v) * bStride;
    Float8 a0, a1;
    load8(a0, av);
    load8(a1, av + 8);
    addRowProducts(a0, a1, bv, p0, p1);
    addRowProducts(a0, a1, bv - 1, q0, q1);
    addRowProducts(a0, a1, bv - 2, r0, r1);
    addRowProducts(a0, a1, bv - 3, s0, s1);
  }
  Float8 w0, w1;
  load8(w0, lanes);
  load8(w1, lanes + 8);
  out[0] = laneSum(p0 * w0 + p1 * w1);
  out[1] = laneSum(q0 * w0 + q1 * w1);
  out[2] = laneSum(r0 * w0 + r1 * w1);
  out[3] = laneSum(s0 * w0 + s1 * w1);
}

// Bit count without the library call the baseline x86-64 target makes of __builtin_popcount.
inline int popcount64(uint64_t v) {
  v = v - ((v >> 1) & 0x5555555555555555ULL);
  v = (v & 0x3333333333333333ULL) + ((v >> 2) & 0x3333333333333333ULL);
  v = (v + (v >> 4)) & 0x0F0F0F0F0F0F0F0FULL;
  return static_cast<int>((v * 0x0101010101010101ULL) >> 56);
}

// A window of ≤ 15 columns as one 256-bit board: row v in bits 16v .. 16v + 14 (of four 64-bit
// words), bit 16v + 15 always 0. That zero separator stops horizontal shifts at the row ends,
// so a flood fill runs on the whole window at once: runs along rows by shift-and-mask doubling
// (shifts 1..8), runs along columns the same way with shifts of 16..128 bits.
// The board's four words are one 256-bit vector (one AVX2 register; two SSE registers in the
// baseline build).
using Word4 = uint64_t __attribute__((vector_size(32)));

// Helpers take and give vectors by reference: passing a 32-byte vector by value from code built
// without AVX changes the ABI.
// Towards higher rows by 16·n bits: n = 1, 2 shift inside and across words, n = 4, 8 move whole
// words.
template <int N>
__attribute__((always_inline)) inline void downRows(Word4& out, const Word4& v) {
  const Word4 zero{};
  if constexpr (N == 4) {
    out = __builtin_shufflevector(v, zero, 4, 0, 1, 2);
  } else if constexpr (N == 8) {
    out = __builtin_shufflevector(v, zero, 4, 4, 0, 1);
  } else {
    constexpr int kBits = 16 * N;
    out = (v << kBits) | (__builtin_shufflevector(v, zero, 4, 0, 1, 2) >> (64 - kBits));
  }
}
template <int N>
__attribute__((always_inline)) inline void upRows(Word4& out, const Word4& v) {
  const Word4 zero{};
  if constexpr (N == 4) {
    out = __builtin_shufflevector(v, zero, 1, 2, 3, 4);
  } else if constexpr (N == 8) {
    out = __builtin_shufflevector(v, zero, 2, 3, 4, 4);
  } else {
    constexpr int kBits = 16 * N;
    out = (v >> kBits) | (__builtin_shufflevector(v, zero, 1, 2, 3, 4) << (64 - kBits));
  }
}
__attribute__((always_inline)) inline bool sameWords(const Word4& a, const Word4& b) {
  const Word4 x = a ^ b;
  return (x[0] | x[1] | x[2] | x[3]) == 0;
}

#ifndef DELINEO_LEVEL_MATCHER_AVX2_PASS
// The shape S of a window of ≤ 15 columns: `freeRows` are the window's 16 row words (bit u of
// row v: cell (u, v) is neither contour nor nodata; bit 15 is 0), `inWindow` keeps the rows
// v < window. The 4-connected component of the centre (r, r) in the free cells plus the centre
// (a centre on a contour propagates to both sides) goes to `reach` (16 row words). Returns true
// when a free cell is left unreached, i.e. S cuts part of the window off. The rows are read
// from a column-major copy of the row words, so the board is one 32-byte load. The AVX-512
// clone does each doubling step's AND-OR in one three-input logic instruction (the fill's share
// of the matcher's samples fell by ~17 %).
DELINEO_TARGET_CLONES("arch=x86-64-v4", "avx2", "default") bool fillWindow15(
    const uint16_t* freeRows, const uint64_t* inWindow, int r, uint16_t* reach) {
  Word4 free, rowMask, t;
  __builtin_memcpy(&free, freeRows, sizeof free);
  __builtin_memcpy(&rowMask, inWindow, sizeof rowMask);
  free &= rowMask;
  Word4 seed{};
  seed[r >> 2] = uint64_t{1} << (16 * (r & 3) + r);
  const Word4 open = free | seed;
  // Runs of open cells 2^i long in each direction: the masks of the doubling steps, which
  // depend on `open` only. Along rows the row-end separator bits (always 0) stop the runs.
  const Word4 gL1 = open & (open >> 1), gL2 = gL1 & (gL1 >> 2), gL3 = gL2 & (gL2 >> 4);
  Word4 gD1, gD2, gD3, gU1, gU2, gU3;
  downRows<1>(t, open);
  gD1 = open & t;
  downRows<2>(t, gD1);
  gD2 = gD1 & t;
  downRows<4>(t, gD2);
  gD3 = gD2 & t;
  upRows<1>(t, open);
  gU1 = open & t;
  upRows<2>(t, gU1);
  gU2 = gU1 & t;
  upRows<4>(t, gU2);
  gU3 = gU2 & t;
  for (bool first = true;; first = false) {
    // Along rows towards higher bits by one addition: adding the seeds to the open cells
    // carries through each open run from its lowest seed up to the blocked cell ending the run
    // (the row-end separator bits are 0, so no carry leaves a row or a 64-bit word); the
    // changed bits are that run. Towards lower bits by doubling (shifts 1, 2, 4, 8).
    Word4 a = (((open + seed) ^ open) & open) | seed;
    Word4 b = seed;
    b |= open & (b >> 1);
    b |= gL1 & (b >> 2);
    b |= gL2 & (b >> 4);
    b |= gL3 & (b >> 8);
    Word4 filled = a | b;
    if (!first && sameWords(filled, seed)) break;  // closed along both directions
    seed = filled;
    // Along columns, both directions.
    a = seed;
    b = seed;
    downRows<1>(t, a);
    a |= open & t;
    upRows<1>(t, b);
    b |= open & t;
    downRows<2>(t, a);
    a |= gD1 & t;
    upRows<2>(t, b);
    b |= gU1 & t;
    downRows<4>(t, a);
    a |= gD2 & t;
    upRows<4>(t, b);
    b |= gU2 & t;
    downRows<8>(t, a);
    a |= gD3 & t;
    upRows<8>(t, b);
    b |= gU3 & t;
    filled = a | b;
    if (sameWords(filled, seed)) break;  // closed along both directions
    seed = filled;
  }
  __builtin_memcpy(reach, &seed, sizeof seed);
  const Word4 cut = free & ~seed;
  return (cut[0] | cut[1] | cut[2] | cut[3]) != 0;
}
#else
// The AVX2 build calls the baseline build's fill (and with it its AVX-512 clone).
using base::fillWindow15;
#endif

// subpixelPeak() (level_matcher.hpp), inlined in the matcher.
inline cv::Point2f subpixelOffset(const float s[3][3]) {
  // Separable parabolas through the peak row and column.
  auto parabola = [](float m, float c0, float p) -> float {
    if (!std::isfinite(m) || !std::isfinite(p)) return 0.0F;
    const float denom = m - 2.0F * c0 + p;
    if (!(denom < 0.0F)) return 0.0F;
    return std::clamp(0.5F * (m - p) / denom, -1.0F, 1.0F);
  };
  return {parabola(s[0][1], s[1][1], s[2][1]), parabola(s[1][0], s[1][1], s[1][2])};
}

// Main-line (dy = 0) peak of one pixel, built while its interval is visited in increasing d.
struct LinePeak {
  float best = kNegInf;
  int bestD = 0;
  float below = kNaN;  // score at bestD - 1
  float above = kNaN;  // score at bestD + 1
  float prev = kNaN;   // score at the previous d
  // With `trackSecond`, `second` is the best score 3 or more disparities away from the peak
  // (the uniqueness test of wide intervals, LevelSettings::uniqueMinInterval). The updates then
  // must come at consecutive d and are scalar.
  bool trackSecond = false;
  float second = kNegInf;
  float prev2 = kNaN, prev3 = kNaN;  // scores at d − 2 and d − 3
  float upToPrev3 = kNegInf;         // the best score at d − 3 or below

  void update(int d, float s) {
    if (trackSecond) {
      upToPrev3 = std::max(upToPrev3, prev3);  // (std::max keeps its first operand for NaN)
      if (s > best) {
        second = upToPrev3;
      } else if (d - bestD >= 3 && s > second) {
        second = s;
      }
      prev3 = prev2;
      prev2 = prev;
    }
    if (d == bestD + 1) above = s;
    if (s > best) {  // NaN never wins
      best = s;
      bestD = d;
      below = prev;
      above = kNaN;
    }
    prev = s;
  }

  // update(d + k, s[k]) for k = 0 .. count − 1, with the same outcome: the pass's first
  // highest score replaces the peak when it beats it (later updates would erase the earlier
  // ones' effects), and only the scores next to the final peak are kept. `s` holds 8 readable
  // floats (those past `count` are ignored).
  void updatePass(int d, const float* s, int count) {
    if (trackSecond) {
      for (int k = 0; k < count; ++k) update(d + k, s[k]);
      return;
    }
    int top = -1;
    float topScore = best;
#ifdef DELINEO_STEREO_X86
    // The first of the pass's highest scores is where the scan above stops: the maximum of the
    // lanes (NaN and the lanes past `count` left out as −inf), then its first lane (branches
    // and a compare a window cost ~50 instructions a pass).
    const __m128i n = _mm_set1_epi32(count);
    const __m128 negInf = _mm_set1_ps(kNegInf);
    const __m128 in0 = _mm_castsi128_ps(_mm_cmpgt_epi32(n, _mm_setr_epi32(0, 1, 2, 3)));
    const __m128 in1 = _mm_castsi128_ps(_mm_cmpgt_epi32(n, _mm_setr_epi32(4, 5, 6, 7)));
    const __m128 s0 = _mm_or_ps(_mm_and_ps(in0, _mm_loadu_ps(s)), _mm_andnot_ps(in0, negInf));
    const __m128 s1 = _mm_or_ps(_mm_and_ps(in1, _mm_loadu_ps(s + 4)), _mm_andnot_ps(in1, negInf));
    // maxps gives its second operand where the first is NaN.
    __m128 m = _mm_max_ps(s1, _mm_max_ps(s0, negInf));
    m = _mm_max_ps(m, _mm_shuffle_ps(m, m, 0x4E));
    m = _mm_max_ps(m, _mm_shuffle_ps(m, m, 0xB1));
    if (_mm_cvtss_f32(m) > best) {
      const int equal =
          _mm_movemask_ps(_mm_cmpeq_ps(s0, m)) | (_mm_movemask_ps(_mm_cmpeq_ps(s1, m)) << 4);
      top = __builtin_ctz(static_cast<unsigned>(equal));
      topScore = s[top];
    }
#else
    for (int k = 0; k < count; ++k) {
      if (s[k] > topScore) {  // NaN never wins
        topScore = s[k];
        top = k;
      }
    }
#endif
    if (top < 0) {
      if (d == bestD + 1) above = s[0];
    } else {
      best = topScore;
      bestD = d + top;
      below = top > 0 ? s[top - 1] : prev;
      above = top + 1 < count ? s[top + 1] : kNaN;
    }
    prev = s[count - 1];
  }
};

// The main-line peak as the border test settles it: at d, with its score and those at d ± 1.
struct MainLinePeak {
  int d;
  float below, best, above;
};

// The peak on the 2D correlation surface as the ascent over line shifts moves it: at (d, dy),
// with its 3x3 neighbourhood s[i][j] at (d + i − 1, dy + j − 1) (NaN where not evaluated;
// s[1][1] is the peak's score).
struct SurfacePeak {
  int d, dy;
  float s[3][3];
};

// Dense rows of an adaptive shape S.
//  - Windows ≤ 15 columns: quantised grey levels, rows of 16 int16: mask (−1 on S) and A on S
//    (0 elsewhere); NCC(d, dy) = (n Σ A·B − Σ A Σ B) / sqrt((n Σ A² − (Σ A)²)(n Σ B² − (Σ B)²))
//    from exact integer sums (n = |S|).
//  - Wider windows: float rows of 32, template T = (A - mean_S) / sd_S on S and 0 elsewhere,
//    and the indicator M of S; NCC(d, dy) = Σ T·B / (|S| sd_S(B)).
struct ShapeTemplate {
  alignas(32) int16_t maskQ[16 * 16] = {};
  alignas(32) int16_t aQ[16 * 16] = {};
  ShapeNccTerms terms;  // n, Σ_S A, ... (quantised)
  std::vector<float> templ, mask;
  ShapeSpans spans;                // S as spans of its window rows (windows ≤ 15 columns)
  ShapeSpanTerms spanTerms;        // the spans as prefix offsets (when hasSpans)
  bool hasSpans = false;           // false: a row has more gaps than the spans hold
  uint32_t rowBits[32] = {};       // S as bits: bit u of row v = window cell (u, v)
  int rowFirst = 0, rowLast = -1;  // window rows holding part of S
  int count = 0;
};

// A padded buffer of one view turned, in place, into the other view's: `inner` (the image)
// mirrored left to right, the padding left as it is (the moments and quantised copies are 0
// there in both views: a window reaching into the padding holds nodata). In place: fresh
// buffers cost as much as computing them again (their pages are new to the process).
template <class T>
void mirrorRows(cv::Mat& m, const cv::Rect& inner) {
  for (int y = inner.y; y < inner.br().y; ++y) {
    T* row = m.ptr<T>(y) + inner.x;
    std::reverse(row, row + inner.width);
  }
}
void mirrorInner(cv::Mat& m, const cv::Rect& inner) {
  switch (m.elemSize()) {
    case 1:
      mirrorRows<uint8_t>(m, inner);
      break;
    case 2:
      mirrorRows<uint16_t>(m, inner);
      break;
    default:
      CV_Assert(m.elemSize() == 4);
      mirrorRows<uint32_t>(m, inner);
  }
}

// Per-worker buffers, reused from tile to tile.
struct Scratch {
  ShapeTemplate shape;
  std::vector<LinePeak> peaks;       // per tile pixel (square path)
  std::vector<uchar> square;         // 1 where the tile pixel takes the square path
  std::vector<uchar> swept;          // 1 where the square pixel is served by the sweep
  std::vector<float> product, cols;  // sweep: product rows of the tile and running column sums
  std::vector<std::pair<int, int>> byWidth, byWidthSorted;  // square pixels: (width, index)
  std::vector<int> widthStarts;                             // their counting sort's offsets
};

class LevelMatcher {
 public:
  // `in` is padded; the outputs cover `inner`, the unpadded image, and are written at
  // (x, y) − inner.tl() (only inner pixels are searched: the padding's intervals are empty).
  LevelMatcher(const LevelInput& in, const LevelSettings& s, LevelOutput& out, cv::Rect inner,
               LevelPreparations* shared, LevelScratch& scratch)
      : in_(in),
        s_(s),
        out_(out),
        W_(in.ref.cols),
        H_(in.ref.rows),
        r_(s.window / 2),
        n_(s.window * s.window),
        L_(s.lineShift),
        outX_(inner.x),
        outY_(inner.y),
        rowStride_(s.window <= 16 ? 16 : 32) {
    takeBuffers(scratch);
    // Independent preparations, run on the level's threads (serial, they took ~12 % of the
    // matcher's time).
    std::vector<std::function<void()>> tasks;
    // The other view's preparations, mirrored, when it left them (see LevelPreparations).
    const bool mirrored = shared != nullptr && !shared->empty();
    if (mirrored) {
      takePreparations(*shared);
      for (cv::Mat* m : {&refStats_.mean, &refStats_.sd, &refStats_.usable, &otherStats_.mean,
                         &otherStats_.sd, &otherStats_.usable}) {
        tasks.emplace_back([m, inner] { mirrorInner(*m, inner); });
      }
    } else {
      tasks.emplace_back([&] { refStats_ = windowStats(in.ref, in.refValid, s.window); });
      tasks.emplace_back([&] { otherStats_ = windowStats(in.other, in.otherValid, s.window); });
    }
    tasks.emplace_back([&] {
      if (mirrored) {
        // (Here, before the prefix sums read otherQ_.)
        mirrorInner(refQ_, inner);
        mirrorInner(otherQ_, inner);
        scale_ = shared->scale;
      } else {
        scale_ = quantiseImages();
      }
      prepareOtherImage();
    });
    tasks.emplace_back([&] { prepareBlockedPixels(); });
    tasks.emplace_back([&] { out.disparity = cv::Mat(inner.size(), CV_32F, cv::Scalar(kNaN)); });
    tasks.emplace_back([&] { out.lineShift = cv::Mat(inner.size(), CV_32F, cv::Scalar(kNaN)); });
    tasks.emplace_back([&] { out.score = cv::Mat(inner.size(), CV_32F, cv::Scalar(kNaN)); });
    runTasks(tasks, s.threads);
    if (shared != nullptr && !mirrored) {
      shared->scale = scale_;
      shared->ref = refStats_;
      shared->other = otherStats_;
      shared->refQ = refQ_;
      shared->otherQ = otherQ_;
    }
    preparePerPixelAccess();
  }

  // Rows of the other image's buffers by plain arithmetic (cv::Mat::ptr reads the data pointer
  // and the step at every call: ~0.5 % of the match).
  const uchar* otherOkRow(int y) const { return otherOk_ + static_cast<ptrdiff_t>(y) * okStride_; }
  uchar otherOk(int y, int x) const { return otherOkRow(y)[x]; }
  const int16_t* otherQRow(int y) const {
    return otherQData_ + static_cast<ptrdiff_t>(y) * otherQStride_;
  }
  const int32_t* prefixBRow(int y) const {
    return prefixBData_ + static_cast<ptrdiff_t>(y) * prefixStride_;
  }
  const int32_t* prefixBBRow(int y) const {
    return prefixBBData_ + static_cast<ptrdiff_t>(y) * prefixStride_;
  }

  // The buffers this view leaves to the other view of the level (see LevelScratch).
  void leaveBuffers(LevelScratch& scratch) {
    scratch.blocked = std::move(blocked_);
    scratch.blockedBits = std::move(blockedBits_);
    scratch.nearEdge = std::move(nearEdge_);
    scratch.otherInvalidBits = std::move(otherInvalidBits_);
    scratch.prefixB = std::move(otherPrefixB_);
    scratch.prefixBB = std::move(otherPrefixBB_);
    scratch.otherSq = std::move(otherSq_);
    scratch.freeColumns = std::move(freeColumns_);
  }

  // Per pixel, the row of its window as one word (into `out`, CV_32S): bit u set when
  // (x - r + u, y) is marked in `mask` (CV_8U: non-zero, or zero with `markedWhenZero`) or lies
  // outside the image.
  void rowWindowBits(const cv::Mat& mask, bool markedWhenZero, cv::Mat& out) const {
    out.create(mask.size(), CV_32S);  // every element is written below
    const uint32_t whenZero = markedWhenZero ? 1U : 0U;
    const int w = s_.window;
    for (int y = 0; y < H_; ++y) {
      const uchar* b = mask.ptr<uchar>(y);
      int* bits = out.ptr<int>(y);
      uint32_t word = w == 32 ? ~0U : (1U << w) - 1U;  // columns left of the image: marked
      // After the step at x, word covers columns x - r .. x + r. Three loops: the column
      // entering at x lies in the image up to x = W - r - 1, and x < 0 stores nothing (one
      // loop with both tests cost ~20 instructions a pixel).
      const int inside = W_ - r_;
      int x = -r_;
      for (; x < std::min(0, inside); ++x) {
        word = (word >> 1) | (((b[x + r_] ? 1U : 0U) ^ whenZero) << (w - 1));
      }
      for (; x < inside; ++x) {
        word = (word >> 1) | (((b[x + r_] ? 1U : 0U) ^ whenZero) << (w - 1));
        bits[x] = static_cast<int>(word);
      }
      for (; x < W_; ++x) {
        word = (word >> 1) | (1U << (w - 1));
        if (x >= 0) bits[x] = static_cast<int>(word);
      }
    }
  }

  bool run(core::Progress* progress) {
    const int tilesX = (W_ + kTileCols - 1) / kTileCols;
    const int tiles = tilesX * ((H_ + kTileRows - 1) / kTileRows);
    std::atomic<int> next{0}, done{0};
    std::atomic<bool> canceled{false};
    auto worker = [&] {
      Scratch scratch;
      for (int t = next++; t < tiles; t = next++) {
        if (canceled.load() || core::isCanceled(progress)) {
          canceled.store(true);
          return;
        }
        const int x0 = (t % tilesX) * kTileCols, y0 = (t / tilesX) * kTileRows;
        matchTile(cv::Rect(x0, y0, std::min(kTileCols, W_ - x0), std::min(kTileRows, H_ - y0)),
                  scratch);
        core::report(progress, static_cast<double>(++done) / tiles);
      }
    };
    runOnWorkers(worker, std::max(1, std::min(s_.threads, tiles)) - 1);
    return !canceled.load() && !core::isCanceled(progress);
  }

 private:
  // ---- preparations ----------------------------------------------------------------------

  // The buffers the other view left (empty for the first view), overwritten by the
  // preparations.
  void takeBuffers(LevelScratch& scratch) {
    blocked_ = std::move(scratch.blocked);
    blockedBits_ = std::move(scratch.blockedBits);
    nearEdge_ = std::move(scratch.nearEdge);
    otherInvalidBits_ = std::move(scratch.otherInvalidBits);
    otherPrefixB_ = std::move(scratch.prefixB);
    otherPrefixBB_ = std::move(scratch.prefixBB);
    otherSq_ = std::move(scratch.otherSq);
    freeColumns_ = std::move(scratch.freeColumns);
  }

  // The other view's moments and quantised copies, taken over (it is done with them; they are
  // mirrored in place afterwards): its ref is this view's other image and vice versa. `shared`
  // keeps only the scale.
  void takePreparations(LevelPreparations& shared) {
    refStats_ = shared.other;
    otherStats_ = shared.ref;
    refQ_ = shared.otherQ;
    otherQ_ = shared.refQ;
    const double scale = shared.scale;
    shared = LevelPreparations{};
    shared.scale = scale;
  }

  // Quantised copies for the integer shape kernels: one scale for both images, the largest
  // that keeps |q| ≤ kShapeQuantMax (the images are mapped to ~±128: a step of < 0.1 grey).
  // Returns the scale.
  double quantiseImages() {
    double refMin = 0, refMax = 0, otherMin = 0, otherMax = 0;
    cv::minMaxLoc(in_.ref, &refMin, &refMax);
    cv::minMaxLoc(in_.other, &otherMin, &otherMax);
    const double maxAbs = std::max(
        {std::abs(refMin), std::abs(refMax), std::abs(otherMin), std::abs(otherMax), 1e-6});
    const double scale = std::floor(kShapeQuantMax / maxAbs * 1e6) / 1e6;  // round(scale·v) ≤ max
    in_.ref.convertTo(refQ_, CV_16S, scale);
    in_.other.convertTo(otherQ_, CV_16S, scale);
    return scale;
  }

  // What the shape kernels read of the other image besides its quantised copy (scale_ set).
  void prepareOtherImage() {
    if (useSpans_) {
      // Row prefix sums of B and B² for the main-line span kernel.
      otherPrefixB_.create(H_, W_ + 1 + kPrefixPad, CV_32S);
      otherPrefixBB_.create(H_, W_ + 1 + kPrefixPad, CV_32S);
      for (int y = 0; y < H_; ++y) {
        rowPrefixSums(otherQ_.ptr<int16_t>(y), W_, otherPrefixB_.ptr<int32_t>(y),
                      otherPrefixBB_.ptr<int32_t>(y));
      }
    }
    flatQ_ = kFlatVariance * scale_ * scale_;
    // Float rows of the wider windows take B² from this image.
    if (s_.window > 15) cv::multiply(in_.other, in_.other, otherSq_);
    // Nodata of the other image as row words (see blockedBits_): a shape window touches
    // nodata when one of its rows shares a bit with these (one AND per row).
    rowWindowBits(in_.otherValid, /*markedWhenZero=*/true, otherInvalidBits_);
  }

  // Pixels a shape never enters: contours and nodata. blockedBits_(y, x): bit u set when
  // (x - r + u, y) is blocked, the row of a window as one word for the bit-parallel fill.
  // nearEdge_: where a window holds a blocked pixel (the shapes' pixels).
  void prepareBlockedPixels() {
    blocked_.create(in_.ref.size(), CV_8U);
    for (int y = 0; y < H_; ++y) {
      const uchar* edge = in_.refEdges.ptr<uchar>(y);
      const uchar* valid = in_.refValid.ptr<uchar>(y);
      uchar* b = blocked_.ptr<uchar>(y);
      for (int x = 0; x < W_; ++x) b[x] = (edge[x] != 0) | (valid[x] == 0) ? 255 : 0;
    }
    rowWindowBits(blocked_, /*markedWhenZero=*/false, blockedBits_);
    if (s_.window <= 15) prepareFreeColumns();
    if (s_.adaptive) {
      // Shapes also serve pixels whose window holds nodata or leaves the image (the input is
      // padded with nodata): S stops there as it stops at contours.
      cv::dilate(blocked_, nearEdge_,
                 cv::getStructuringElement(cv::MORPH_RECT, cv::Size(s_.window, s_.window)));
    } else {
      nearEdge_.create(in_.ref.size(), CV_8U);
      nearEdge_.setTo(0);
    }
  }

  // Windows ≤ 15 columns: a column-major copy of the free (not blocked) row words, so that the
  // 16 rows of a window are contiguous, one load for the fill. 16 spare rows keep every
  // window's read inside.
  void prepareFreeColumns() {
    const auto full = static_cast<uint32_t>((1U << s_.window) - 1U);
    columnStride_ = static_cast<size_t>(H_) + 16;
    freeColumns_.assign(static_cast<size_t>(W_) * columnStride_, 0);
    for (int y = 0; y < H_; ++y) {
      const int* bits = blockedBits_.ptr<int>(y);
      for (int x = 0; x < W_; ++x) {
        freeColumns_[static_cast<size_t>(x) * columnStride_ + static_cast<size_t>(y)] =
            static_cast<uint16_t>(~static_cast<uint32_t>(bits[x]) & full);
      }
    }
    for (int v = 0; v < s_.window; ++v) {
      windowRows_[v >> 2] |= uint64_t{0xFFFF} << (16 * (v & 3));
    }
  }

  // The strides and row-0 pointers the per-pixel paths read (see their members), and the
  // square window's lanes.
  void preparePerPixelAccess() {
    otherQStride_ = static_cast<ptrdiff_t>(otherQ_.step1());
    refQStride_ = static_cast<ptrdiff_t>(refQ_.step1());
    refStride_ = in_.ref.step1();
    otherStride_ = in_.other.step1();
    invalidStride_ = static_cast<ptrdiff_t>(otherInvalidBits_.step1());
    if (useSpans_) {
      prefixStride_ = static_cast<ptrdiff_t>(otherPrefixB_.step1());
      prefixBData_ = otherPrefixB_.ptr<int32_t>(0);
      prefixBBData_ = otherPrefixBB_.ptr<int32_t>(0);
    }
    otherOk_ = otherStats_.usable.ptr<uchar>(0);
    okStride_ = static_cast<ptrdiff_t>(otherStats_.usable.step1());
    otherQData_ = otherQ_.ptr<int16_t>(0);
    for (int v = 0; v < 16; ++v) prefixRowOffsets_[v] = static_cast<int32_t>(v * prefixStride_);
    for (int u = 0; u < std::min(16, s_.window); ++u) squareLanes_[u] = 1.0F;
  }
  void matchTile(const cv::Rect& tile, Scratch& sc) {
    const size_t area = static_cast<size_t>(tile.area());
    sc.square.assign(area, 0);
    for (int y = tile.y; y < tile.br().y; ++y) {
      const int* lo = in_.lo.ptr<int>(y);
      const int* hi = in_.hi.ptr<int>(y);
      const uchar* ok = refStats_.usable.ptr<uchar>(y);
      const uchar* near = nearEdge_.ptr<uchar>(y);
      const uchar* refValid = in_.refValid.ptr<uchar>(y);
      const uchar* one = in_.oneSurface.empty() ? nullptr : in_.oneSurface.ptr<uchar>(y);
      for (int x = tile.x; x < tile.br().x; ++x) {
        if (lo[x] > hi[x] || !refValid[x]) continue;
        // On one surface the contours in the window are texture, not depth steps: the square
        // window (when usable) matches it as well, for the price of a box filter.
        const bool oneSurface = one != nullptr && one[x] && ok[x];
        if (near[x] && !oneSurface && buildShape(x, y, sc.shape, ok[x] != 0)) {
          matchShapePixel(x, y, sc.shape);
          continue;
        }
        if (ok[x]) sc.square[static_cast<size_t>(y - tile.y) * tile.width + (x - tile.x)] = 1;
      }
    }
    matchSquarePixels(tile, sc);
  }

  // ---- square windows --------------------------------------------------------------------

  // NCC of the square window at (x, y) against (x - d, y + dy); NaN where the other window is
  // missing or flat.
  float squareScore(int x, int y, int d, int dy) const {
    const int yb = y + dy, xb = x - d;
    if (yb < 0 || yb >= H_ || xb < 0 || xb >= W_ || !otherOk(yb, xb)) return kNaN;
    float sab = 0;
    if (s_.window <= 16) {
      // Reads 16 columns: the inputs are padded on the right.
      sab = windowDot16(in_.ref.ptr<float>(y - r_) + x - r_, refStride_,
                        in_.other.ptr<float>(yb - r_) + xb - r_, otherStride_, s_.window,
                        squareLanes_);
    } else {
      for (int v = -r_; v <= r_; ++v) {
        const float* a = in_.ref.ptr<float>(y + v) + x - r_;
        const float* b = in_.other.ptr<float>(yb + v) + xb - r_;
        float acc = 0;
        for (int u = 0; u < s_.window; ++u) acc += a[u] * b[u];
        sab += acc;
      }
    }
    return squareNcc(sab, refStats_.mean.at<float>(y, x), refStats_.sd.at<float>(y, x),
                     otherStats_.mean.at<float>(yb, xb), otherStats_.sd.at<float>(yb, xb));
  }

  // squareScore(x, y, d, −1) and squareScore(x, y, d, +1) (windows ≤ 16 columns) in one pass over
  // the template rows; false when either other window is missing or flat (scored one by one
  // then).
  bool squareScorePair(int x, int y, int d, float& minus, float& plus) const {
    const int xb = x - d;
    if (s_.window > 16 || y - 1 < 0 || y + 1 >= H_ || xb < 0 || xb >= W_ || !otherOk(y - 1, xb) ||
        !otherOk(y + 1, xb)) {
      return false;
    }
    float sab[2];
    windowDot16Pair(
        in_.ref.ptr<float>(y - r_) + x - r_, refStride_, in_.other.ptr<float>(y - 1 - r_) + xb - r_,
        in_.other.ptr<float>(y + 1 - r_) + xb - r_, otherStride_, s_.window, squareLanes_, sab);
    const float meanA = refStats_.mean.at<float>(y, x), sdA = refStats_.sd.at<float>(y, x);
    minus = squareNcc(sab[0], meanA, sdA, otherStats_.mean.at<float>(y - 1, xb),
                      otherStats_.sd.at<float>(y - 1, xb));
    plus = squareNcc(sab[1], meanA, sdA, otherStats_.mean.at<float>(y + 1, xb),
                     otherStats_.sd.at<float>(y + 1, xb));
    return true;
  }

  // NCC of a square window from its sum of products and both windows' means and deviations.
  float squareNcc(float sab, float meanA, float sdA, float meanB, float sdB) const {
    return (sab / static_cast<float>(n_) - meanA * meanB) / (sdA * sdB);
  }

  // squareScore(x, y, d + j, 0) for j = 0..3 (windows ≤ 16 columns) in one pass over the rows;
  // false when one of the four windows is missing or flat (scored one by one then).
  bool squareScores4(int x, int y, int d, float* scores) const {
    const int xb = x - d;
    if (xb - 3 < 0 || xb >= W_) return false;
    const uchar* ok = otherOkRow(y);
    if (!ok[xb] || !ok[xb - 1] || !ok[xb - 2] || !ok[xb - 3]) return false;
    float sab[4];
    windowDots16x4(in_.ref.ptr<float>(y - r_) + x - r_, refStride_,
                   in_.other.ptr<float>(y - r_) + xb - r_, otherStride_, s_.window, squareLanes_,
                   sab);
    const float meanA = refStats_.mean.at<float>(y, x), sdA = refStats_.sd.at<float>(y, x);
    const float* meanB = otherStats_.mean.ptr<float>(y);
    const float* sdB = otherStats_.sd.ptr<float>(y);
    for (int j = 0; j < 4; ++j) {
      scores[j] = squareNcc(sab[j], meanA, sdA, meanB[xb - j], sdB[xb - j]);
    }
    return true;
  }

  // The square path's pixels of `tile` (sc.square): main-line peaks by the box-filter sweep or
  // by direct correlation, then the peaks finished.
  void matchSquarePixels(const cv::Rect& tile, Scratch& sc) {
    const size_t area = static_cast<size_t>(tile.area());
    sc.peaks.assign(area, LinePeak{});
    sc.swept.assign(area, 0);
    const int widest = collectSquarePixels(tile, sc);
    if (sc.byWidth.empty()) return;
    sortByWidth(widest, sc);
    const size_t swept = sweptPixelCount(tile, sc.byWidth);
    sweepPixels(tile, swept, sc);
    correlateDirectly(tile, swept, sc);
    for (const auto& [width, i] : sc.byWidth) {
      const int x = tile.x + i % tile.width, y = tile.y + i / tile.width;
      finish(
          x, y, in_.lo.at<int>(y, x), in_.hi.at<int>(y, x), sc.peaks[static_cast<size_t>(i)],
          [&](int d, int dy) { return squareScore(x, y, d, dy); },
          [&](int d, float& minus, float& plus) { return squareScorePair(x, y, d, minus, plus); },
          [](int, int, float*) { return false; });
    }
  }

  // The square path's pixels of `tile` as (interval width, tile index) in sc.byWidth, in index
  // order, their peaks told whether to track the uniqueness test; returns the widest width.
  int collectSquarePixels(const cv::Rect& tile, Scratch& sc) const {
    const size_t area = static_cast<size_t>(tile.area());
    std::vector<std::pair<int, int>>& byWidth = sc.byWidth;
    byWidth.clear();
    int widest = 0;
    for (size_t i = 0; i < area; ++i) {
      if (!sc.square[i]) continue;
      const int x = tile.x + static_cast<int>(i) % tile.width;
      const int y = tile.y + static_cast<int>(i) / tile.width;
      const int lo = in_.lo.at<int>(y, x), hi = in_.hi.at<int>(y, x);
      sc.peaks[i].trackSecond = testsUniqueness(lo, hi);
      byWidth.emplace_back(hi - lo + 1, static_cast<int>(i));
      widest = std::max(widest, hi - lo + 1);
    }
    return widest;
  }

  // sc.byWidth in increasing order of (width, tile index): a counting sort by width of the
  // pixels taken in index order (std::sort of the pairs gave the same order, ~5 % of
  // matchSquarePixels).
  static void sortByWidth(int widest, Scratch& sc) {
    std::vector<std::pair<int, int>>& byWidth = sc.byWidth;
    std::vector<int>& starts = sc.widthStarts;
    starts.assign(static_cast<size_t>(widest) + 2, 0);
    for (const auto& entry : byWidth) ++starts[static_cast<size_t>(entry.first) + 1];
    for (size_t w = 1; w < starts.size(); ++w) starts[w] += starts[w - 1];
    std::vector<std::pair<int, int>>& sorted = sc.byWidthSorted;
    sorted.resize(byWidth.size());
    for (const auto& entry : byWidth) {
      sorted[static_cast<size_t>(starts[static_cast<size_t>(entry.first)]++)] = entry;
    }
    byWidth.swap(sorted);
  }

  // How many of the square pixels (`byWidth`, by increasing width) the box-filter sweep
  // serves: the sweep costs ~5 operations per tile pixel and disparity of the union of the
  // served intervals, a direct correlation (correlateDirectly) per disparity of the pixel's
  // own interval. The narrowest pixels are swept, as many as make the total cheapest.
  size_t sweptPixelCount(const cv::Rect& tile,
                         const std::vector<std::pair<int, int>>& byWidth) const {
    const double sweepUnit = 5.0 * (tile.width + 2 * r_) * (tile.height + 2 * r_);
    // A direct correlation: n_ / 2 per disparity, as the four windows of a pass share the loads
    // of the template rows (squareScores4; with n_ the sweep served more pixels than paid off:
    // 600² match 4.158 G instructions, 4.118 G with n_ / 2, 4.113 G with 0.3 n_).
    const double directUnit = 0.5 * n_;
    double directRemaining = 0;
    for (const auto& [width, i] : byWidth) directRemaining += directUnit * width;
    int uLo = std::numeric_limits<int>::max(), uHi = std::numeric_limits<int>::min();
    double bestTotal = directRemaining;  // nothing swept
    size_t bestCount = 0;
    for (size_t k = 0; k < byWidth.size(); ++k) {
      const int i = byWidth[k].second;
      const int x = tile.x + i % tile.width, y = tile.y + i / tile.width;
      uLo = std::min(uLo, in_.lo.at<int>(y, x));
      uHi = std::max(uHi, in_.hi.at<int>(y, x));
      directRemaining -= directUnit * byWidth[k].first;
      const double total = sweepUnit * (uHi - uLo + 1) + directRemaining;
      if (total <= bestTotal) {
        bestTotal = total;
        bestCount = k + 1;
      }
    }
    return bestCount;
  }

  // The first `count` square pixels of sc.byWidth, marked in sc.swept, and the sweep of the
  // union of their intervals.
  void sweepPixels(const cv::Rect& tile, size_t count, Scratch& sc) {
    int uLo = std::numeric_limits<int>::max(), uHi = std::numeric_limits<int>::min();
    for (size_t k = 0; k < count; ++k) {
      const int i = sc.byWidth[k].second;
      const int x = tile.x + i % tile.width, y = tile.y + i / tile.width;
      sc.swept[static_cast<size_t>(i)] = 1;
      uLo = std::min(uLo, in_.lo.at<int>(y, x));
      uHi = std::max(uHi, in_.hi.at<int>(y, x));
    }
    if (count > 0) sweepTile(tile, uLo, uHi, sc);
  }

  // Main-line peaks of the square pixels of sc.byWidth from `first` on, correlated directly
  // (four disparities a pass where the windows allow).
  void correlateDirectly(const cv::Rect& tile, size_t first, Scratch& sc) const {
    for (size_t k = first; k < sc.byWidth.size(); ++k) {
      const int i = sc.byWidth[k].second;
      const int x = tile.x + i % tile.width, y = tile.y + i / tile.width;
      LinePeak& peak = sc.peaks[static_cast<size_t>(i)];
      const int hi = in_.hi.at<int>(y, x);
      int d = in_.lo.at<int>(y, x);
      if (s_.window <= 16) {
        float four[4];
        for (; d + 3 <= hi; d += 4) {
          if (!squareScores4(x, y, d, four)) break;
          for (int j = 0; j < 4; ++j) peak.update(d + j, four[j]);
        }
      }
      for (; d <= hi; ++d) peak.update(d, squareScore(x, y, d, 0));
    }
  }

  // Main-line scores of the swept pixels of `tile` for every d in [dLo, dHi]: per d, the
  // product A(x', y') B(x' - d, y') over the tile grown by the window radius is box-filtered
  // with running column sums and a running row sum. Inlined in matchSquarePixels: out of line,
  // the square path took ~3 % more instructions (400² scene).
  __attribute__((always_inline)) void sweepTile(const cv::Rect& tile, int dLo, int dHi,
                                                Scratch& sc) {
    const int gx0 = tile.x - r_, gw = tile.width + 2 * r_;  // grown tile columns
    const int gy0 = tile.y - r_, gh = tile.height + 2 * r_;
    sc.product.assign(static_cast<size_t>(gw) * gh, 0.0F);
    sc.cols.resize(static_cast<size_t>(gw));
    const float invN = 1.0F / static_cast<float>(n_);
    // Per tile row, the disparities its swept pixels search: the row's running window sums are
    // skipped at the others (the sweep covers the tile's union of intervals).
    int rowLo[kTileRows], rowHi[kTileRows];
    for (int ty = 0; ty < tile.height; ++ty) {
      const int y = tile.y + ty;
      const int* lo = in_.lo.ptr<int>(y);
      const int* hi = in_.hi.ptr<int>(y);
      const uchar* swept = &sc.swept[static_cast<size_t>(ty) * tile.width];
      rowLo[ty] = std::numeric_limits<int>::max();
      rowHi[ty] = std::numeric_limits<int>::min();
      for (int tx = 0; tx < tile.width; ++tx) {
        if (!swept[tx]) continue;
        rowLo[ty] = std::min(rowLo[ty], lo[tile.x + tx]);
        rowHi[ty] = std::max(rowHi[ty], hi[tile.x + tx]);
      }
    }
    for (int d = dLo; d <= dHi; ++d) {
      // Product rows (0 outside either image: such windows are never scored).
      for (int j = 0; j < gh; ++j) {
        float* p = &sc.product[static_cast<size_t>(j) * gw];
        const int y = gy0 + j;
        if (y < 0 || y >= H_) {
          std::fill(p, p + gw, 0.0F);
          continue;
        }
        const float* a = in_.ref.ptr<float>(y);
        const float* b = in_.other.ptr<float>(y);
        const int xs = std::max({gx0, 0, d}), xe = std::min({gx0 + gw, W_, W_ + d});
        for (int x = gx0; x < std::min(xs, gx0 + gw); ++x) p[x - gx0] = 0.0F;
        for (int x = xs; x < xe; ++x) p[x - gx0] = a[x] * b[x - d];
        for (int x = std::max(xe, gx0); x < gx0 + gw; ++x) p[x - gx0] = 0.0F;
      }
      float* cols = sc.cols.data();
      std::fill(cols, cols + gw, 0.0F);
      for (int j = 0; j < s_.window; ++j) {
        const float* p = &sc.product[static_cast<size_t>(j) * gw];
        for (int c = 0; c < gw; ++c) cols[c] += p[c];
      }
      for (int ty = 0; ty < tile.height; ++ty) {
        if (ty > 0) {
          const float* add = &sc.product[static_cast<size_t>(ty + 2 * r_) * gw];
          const float* sub = &sc.product[static_cast<size_t>(ty - 1) * gw];
          for (int c = 0; c < gw; ++c) cols[c] += add[c] - sub[c];
        }
        if (d < rowLo[ty] || d > rowHi[ty]) continue;
        const int y = tile.y + ty;
        const int* lo = in_.lo.ptr<int>(y);
        const int* hi = in_.hi.ptr<int>(y);
        const float* meanA = refStats_.mean.ptr<float>(y);
        const float* sdA = refStats_.sd.ptr<float>(y);
        const float* meanB = otherStats_.mean.ptr<float>(y);
        const float* sdB = otherStats_.sd.ptr<float>(y);
        const uchar* okB = otherOkRow(y);
        const uchar* swept = &sc.swept[static_cast<size_t>(ty) * tile.width];
        LinePeak* peaks = &sc.peaks[static_cast<size_t>(ty) * tile.width];
        double window = 0;  // running row sum: double keeps it exact enough over a tile row
        for (int c = 0; c < s_.window - 1; ++c) window += cols[c];
        for (int tx = 0; tx < tile.width; ++tx) {
          window += cols[tx + 2 * r_];
          const auto sab = static_cast<float>(window);
          window -= cols[tx];
          const int x = tile.x + tx;
          if (!swept[tx] || d < lo[x] || d > hi[x]) continue;
          const int xb = x - d;
          const float s = (xb >= 0 && xb < W_ && okB[xb])
                              ? (sab * invN - meanA[x] * meanB[xb]) / (sdA[x] * sdB[xb])
                              : kNaN;
          peaks[tx].update(d, s);
        }
      }
    }
  }

  // ---- adaptive shapes -------------------------------------------------------------------

  // Windows wider than 15 columns: the same fill on one word per row (a row's reach grows
  // from the rows above and below, then along the row by doubling), until no row changes.
  void fillRows(const uint32_t* free, uint32_t* reach) const {
    const int w = s_.window;
    const uint32_t full = w == 32 ? ~0U : (1U << w) - 1U;
    auto fillRow = [full](uint32_t seeds, uint32_t open) {
      uint32_t up = seeds, g = open;
      up |= g & (up << 1);
      g &= g << 1;
      up |= g & (up << 2);
      g &= g << 2;
      up |= g & (up << 4);
      g &= g << 4;
      up |= g & (up << 8);
      g &= g << 8;
      up |= g & (up << 16);
      uint32_t down = seeds;
      g = open;
      down |= g & (down >> 1);
      g &= g >> 1;
      down |= g & (down >> 2);
      g &= g >> 2;
      down |= g & (down >> 4);
      g &= g >> 4;
      down |= g & (down >> 8);
      g &= g >> 8;
      down |= g & (down >> 16);
      return (up | down) & full;
    };
    // The centre belongs to S even on a contour, and propagates to both sides.
    reach[r_] = fillRow(1U << r_, free[r_]) | (1U << r_);
    for (bool changed = true; changed;) {
      changed = false;
      for (int pass = 0; pass < 2; ++pass) {
        for (int k = 0; k < w; ++k) {
          const int v = pass == 0 ? k : w - 1 - k;
          const uint32_t nb = (v > 0 ? reach[v - 1] : 0U) | (v < w - 1 ? reach[v + 1] : 0U);
          const uint32_t seeds = (reach[v] | nb) & free[v];
          if ((seeds & ~reach[v]) == 0) continue;
          reach[v] |= fillRow(seeds, free[v]);
          changed = true;
        }
      }
    }
  }

  // Window pixels 4-connected to the centre without crossing a contour pixel. Contour pixels
  // themselves are left out: a step edge's contour pixel usually carries the brighter side's
  // grey level, and keeping it would let the step dominate the correlation of the other side.
  // A centre on a contour propagates to both sides (its side is undecidable). Fills the dense
  // template; returns false when the shape is the full square (the square path serves it),
  // smaller than minShape, or flat.
  bool buildShape(int x, int y, ShapeTemplate& t, bool squareServes) const {
    // Bit-parallel flood fill on w-bit rows: a row's reach grows from the rows above and below
    // and is then filled along the row through free pixels (shift-and-mask doubling, the
    // "occluded fill" of bitboards), until no row changes. The rows of S go to t.rowBits.
    alignas(32) uint16_t rows16[16];  // windows ≤ 15 columns: the fill's 16 row words
    const bool cut = s_.window <= 15 ? fillNarrowWindow(x, y, rows16) : fillWideWindow(x, y, t);
    // When S is the whole window minus its contour pixels (no free pixel left unreached: no
    // part of the window is cut off) and the square window is usable, the square serves the
    // pixel: the few contour pixels change its NCC little, and the square path is much cheaper.
    if (squareServes && !cut) return false;
    if (s_.window <= 15) {
      takeNarrowShapeRows(rows16, t);
    } else {
      findShapeRows(t);
    }
    if (rowStride_ == 16) return quantisedShapeTemplate(x, y, rows16, t);
    return floatShapeTemplate(x, y, t);
  }

  // Windows ≤ 15 columns: the fill (fillWindow15) into `rows16`; true when S cuts part of the
  // window off.
  bool fillNarrowWindow(int x, int y, uint16_t* rows16) const {
    const uint16_t* freeRows = &freeColumns_[static_cast<size_t>(x) * columnStride_ + (y - r_)];
#ifdef DELINEO_STEREO_X86
    return fillAvx2_ ? fillWindow15Avx2(freeRows, windowRows_, r_, rows16)
                     : fillWindow15(freeRows, windowRows_, r_, rows16);
#else
    return fillWindow15(freeRows, windowRows_, r_, rows16);
#endif
  }

  // Wider windows: the fill (fillRows) into t.rowBits; true when S cuts part of the window off.
  bool fillWideWindow(int x, int y, ShapeTemplate& t) const {
    const int w = s_.window;
    const uint32_t full = w == 32 ? ~0U : (1U << w) - 1U;
    uint32_t* reach = t.rowBits;
    uint32_t free[32];
    for (int v = 0; v < w; ++v) {
      free[v] = ~static_cast<uint32_t>(blockedBits_.at<int>(y + v - r_, x)) & full;
      reach[v] = 0;
    }
    fillRows(free, reach);
    uint32_t unreached = 0;
    for (int v = 0; v < w; ++v) unreached |= free[v] & ~reach[v];
    return unreached != 0;
  }

  // Windows ≤ 15 columns: the fill's row words as t.rowBits, and the window rows holding part
  // of S.
  void takeNarrowShapeRows(const uint16_t* rows16, ShapeTemplate& t) const {
    // All 16 rows (those past the window are 0): a fixed count the compiler widens in vectors.
    for (int v = 0; v < 16; ++v) t.rowBits[v] = rows16[v];
#ifdef DELINEO_STEREO_X86
    // The rows holding part of S from one mask of the empty rows (the scans of findShapeRows
    // cost ~20 instructions a shape).
    const __m128i zero = _mm_setzero_si128();
    const auto* words = reinterpret_cast<const __m128i*>(rows16);
    const auto empty = static_cast<uint32_t>(
        _mm_movemask_epi8(_mm_packs_epi16(_mm_cmpeq_epi16(_mm_load_si128(words), zero),
                                          _mm_cmpeq_epi16(_mm_load_si128(words + 1), zero))));
    const uint32_t used = ~empty & 0xFFFFU;  // the centre row is never empty
    t.rowFirst = __builtin_ctz(used);
    t.rowLast = 31 - __builtin_clz(used);
#else
    findShapeRows(t);
#endif
  }

  // The window rows holding part of S (t.rowBits).
  void findShapeRows(ShapeTemplate& t) const {
    t.rowFirst = 0;
    while (t.rowBits[t.rowFirst] == 0) ++t.rowFirst;  // the centre row is never empty
    t.rowLast = s_.window - 1;
    while (t.rowBits[t.rowLast] == 0) --t.rowLast;
  }

  // Windows ≤ 16 columns: the template's quantised rows and NCC terms (and S's spans for the
  // span kernel, from the fill's `rows16`); false when S is smaller than minShape, the whole
  // window, or flat.
  bool quantisedShapeTemplate(int x, int y, [[maybe_unused]] const uint16_t* rows16,
                              ShapeTemplate& t) const {
    const int rows = t.rowLast - t.rowFirst + 1;
    // The rows first: they give |S| too (cheaper than counting bits without popcnt).
    int32_t count = 0, sumA = 0, sumAA = 0;
    shapeRowsInt(&t.rowBits[t.rowFirst], rows, refQ_.ptr<int16_t>(y + t.rowFirst - r_) + x - r_,
                 refQStride_, &t.maskQ[16 * t.rowFirst], &t.aQ[16 * t.rowFirst], count, sumA,
                 sumAA);
    t.count = count;
    if (t.count < s_.minShape || t.count >= n_) return false;
#ifdef DELINEO_STEREO_X86
    t.hasSpans = useSpans_ && shapeSpansAvx2(rows16, t.spans);
#endif
    const double n = t.count;
    // n² var_S(A), exact (< 2^53).
    const double varN = n * sumAA - static_cast<double>(sumA) * sumA;
    if (varN < flatQ_ * n * n) return false;
    t.terms.n = count;
    t.terms.sumA = sumA;
    t.terms.invNormA = static_cast<float>(1.0 / std::sqrt(varN));
    t.terms.flatN = static_cast<float>(flatQ_ * n * n);
#ifdef DELINEO_STEREO_X86
    if (t.hasSpans) shapeSpanTermsAvx2(t.spans, t.rowFirst, rows, prefixRowOffsets_, t.spanTerms);
#endif
    return true;
  }

  // Wider windows: the template's float rows, T = (A - mean_S) / sd_S on S, and the indicator
  // M of S; false when S is smaller than minShape, the whole window, or flat.
  bool floatShapeTemplate(int x, int y, ShapeTemplate& t) const {
    const int w = s_.window, P = rowStride_;
    const int rows = t.rowLast - t.rowFirst + 1;
    t.count = 0;
    for (int v = 0; v < w; ++v) t.count += popcount64(t.rowBits[v]);
    if (t.count < s_.minShape || t.count >= n_) return false;
    t.mask.resize(static_cast<size_t>(w * P));
    t.templ.resize(static_cast<size_t>(w * P));
    float* mask = &t.mask[static_cast<size_t>(t.rowFirst * P)];
    float* templ = &t.templ[static_cast<size_t>(t.rowFirst * P)];
    const float* a = in_.ref.ptr<float>(y + t.rowFirst - r_) + x - r_;
    const size_t stride = in_.ref.step1();
    float sum = 0, sq = 0;  // ≤ 961 values of magnitude ≤ ~128: float is exact enough
    std::fill(mask, mask + static_cast<size_t>(rows * P), 0.0F);
    for (int v = 0; v < rows; ++v) {
      const float* av = a + static_cast<size_t>(v) * stride;
      float* m = mask + static_cast<size_t>(v * P);
      for (uint32_t bits = t.rowBits[t.rowFirst + v]; bits != 0; bits &= bits - 1) {
        const int u = __builtin_ctz(bits);
        m[u] = 1.0F;
        sum += av[u];
        sq += av[u] * av[u];
      }
    }
    const float mean = sum / static_cast<float>(t.count);
    const float var = sq / static_cast<float>(t.count) - mean * mean;
    if (var < static_cast<float>(kFlatVariance)) return false;
    const float invSd = 1.0F / std::sqrt(var);
    for (int v = 0; v < rows; ++v) {
      const float* av = a + static_cast<size_t>(v) * stride;
      const float* m = mask + static_cast<size_t>(v * P);
      float* tt = templ + static_cast<size_t>(v * P);
      for (int u = 0; u < P; ++u) tt[u] = m[u] * ((av[u] - mean) * invSd);
    }
    return true;
  }

  // NCC over the shape at (x, y) against (x - d, y + dy); NaN where the other window is
  // missing or flat on S.
  float shapeScore(int x, int y, int d, int dy, const ShapeTemplate& t) const {
    const int yb = y + dy, xb = x - d;
    if (yb < r_ || yb >= H_ - r_ || xb < r_ || xb >= W_ - r_) return kNaN;
    if (!otherOk(yb, xb)) {
      // Window partly nodata (or flat: the variance test below decides): S must avoid nodata.
      // Most such windows lie on the padding, where the first row of S already touches it.
      const int* invalid = otherInvalidBits_.ptr<int>(yb + t.rowFirst - r_) + xb;
      for (int v = t.rowFirst; v <= t.rowLast; ++v, invalid += invalidStride_) {
        if ((static_cast<uint32_t>(*invalid) & t.rowBits[v]) != 0) return kNaN;
      }
    }
    const int rows = t.rowLast - t.rowFirst + 1;
    const int top = yb + t.rowFirst - r_;
    if (rowStride_ == 16) {
      const ptrdiff_t here = 0;
      float score;
#ifdef DELINEO_STEREO_X86
      if (avx2_) {
        shapeScoreIntAvx2(otherQRow(top) + xb - r_, here, &t.maskQ[16 * t.rowFirst],
                          &t.aQ[16 * t.rowFirst], otherQStride_, rows, t.terms, &score);
        return score;
      }
#endif
      shapeScoresInt(otherQRow(top) + xb - r_, otherQStride_, &here, &t.maskQ[16 * t.rowFirst],
                     &t.aQ[16 * t.rowFirst], rows, 1, t.terms, &score);
      return score;
    }
    const size_t first = static_cast<size_t>(t.rowFirst * rowStride_);
    float sums[3];
    shapeSums32(in_.other.ptr<float>(top) + xb - r_, otherSq_.ptr<float>(top) + xb - r_,
                in_.other.step1(), &t.mask[first], &t.templ[first], rows, sums);
    return scoreFromSums(sums, t.count);
  }

  static float scoreFromSums(const float sums[3], int count) {
    const float sB = sums[0], sBB = sums[1], sTB = sums[2];
    const float invCount = 1.0F / static_cast<float>(count);
    const float meanB = sB * invCount;
    const float varB = sBB * invCount - meanB * meanB;
    if (varB < static_cast<float>(kFlatVariance)) return kNaN;
    return sTB * invCount / std::sqrt(varB);
  }

  // Main-line scores for d .. d + count - 1 (count ≤ kShapeMaxWindows) in one pass over the
  // shape; false when one of the windows is not a plain inside-the-image, nodata-free one (then
  // scored one by one).
  // Whether the main-line windows xb − count + 1 .. xb (count ≤ 8) of row y are plain ones:
  // inside the image, nodata-free, not flat.
  bool plainMainLine(int y, int xb, int count) const {
    if (y < r_ || y >= H_ - r_ || xb - (count - 1) < r_ || xb >= W_ - r_) return false;
    // The `count` ok flags (0 or 1) as one 8-byte word: the 8 bytes stay inside the image's
    // rows (y + 1 is a row of it).
    static_assert(kShapeMaxWindows <= 8);
    uint64_t flags;
    __builtin_memcpy(&flags, otherOkRow(y) + xb - (count - 1), sizeof flags);
    const uint64_t all = 0x0101010101010101ULL >> (8 * (kShapeMaxWindows - count));
    return (flags & all) == all;
  }

#ifdef DELINEO_STEREO_X86
  // Main-line scores from d on as `passes` (2..kSpanPassesMax) passes of counts[n] windows that
  // read the span terms once (the same scores as a call of shapeScoresBatch per pass); false
  // when not all are plain windows.
  bool shapeScoresBatches(int x, int y, int d, const ShapeTemplate& t, float* scores,
                          const int* counts, int passes) const {
    const int xb = x - d;
    for (int n = 0, k = 0; n < passes; k += counts[n], ++n) {
      if (!plainMainLine(y, xb - k, counts[n])) return false;
    }
    const int top = y + t.rowFirst - r_;
    shapeScoresSpansPassesAvx2(otherQRow(top) + xb - r_, otherQStride_, prefixBRow(top) + xb - r_,
                               prefixBBRow(top) + xb - r_, t.spanTerms, &t.aQ[16 * t.rowFirst],
                               t.rowLast - t.rowFirst + 1, counts, passes, t.terms, scores);
    return true;
  }
#endif

  bool shapeScoresBatch(int x, int y, int d, const ShapeTemplate& t, float* scores,
                        int count) const {
    if (rowStride_ != 16) return false;
    const int xb = x - d;
    if (!plainMainLine(y, xb, count)) return false;
    const int top = y + t.rowFirst - r_;
    const int rows = t.rowLast - t.rowFirst + 1;
#ifdef DELINEO_STEREO_X86
    if (t.hasSpans) {
      shapeScoresSpansAvx2Dispatch(otherQRow(top) + xb - r_, otherQStride_,
                                   prefixBRow(top) + xb - r_, prefixBBRow(top) + xb - r_,
                                   t.spanTerms, &t.aQ[16 * t.rowFirst], rows, count, t.terms,
                                   scores);
      return true;
    }
#endif
    shapeScoresInt(otherQRow(top) + xb - r_, otherQStride_, kMainLine, &t.maskQ[16 * t.rowFirst],
                   &t.aQ[16 * t.rowFirst], rows, count, t.terms, scores);
    return true;
  }

  // Scores at (d .. d + 2, dy) in one pass; false when a window is not a plain one.
  bool shapeScoresLine(int x, int y, int d, int dy, const ShapeTemplate& t, float* scores) const {
    if (rowStride_ != 16) return false;
    const int xb = x - d, yb = y + dy;  // windows xb, xb − 1, xb − 2
    if (yb < r_ || yb >= H_ - r_ || xb - 2 < r_ || xb >= W_ - r_) return false;
    const uchar* ok = otherOkRow(yb);
    if (!ok[xb] || !ok[xb - 1] || !ok[xb - 2]) return false;
    shapeScoresInt(otherQRow(yb + t.rowFirst - r_) + xb - r_, otherQStride_, kMainLine,
                   &t.maskQ[16 * t.rowFirst], &t.aQ[16 * t.rowFirst], t.rowLast - t.rowFirst + 1, 3,
                   t.terms, scores);
    return true;
  }

  // Scores at (d, -1) and (d, +1) in one pass; false when a window is not a plain one.
  bool shapeScorePair(int x, int y, int d, const ShapeTemplate& t, float& minus,
                      float& plus) const {
    if (rowStride_ != 16) return false;
    const int xb = x - d;
    if (y - 1 < r_ || y + 1 >= H_ - r_ || xb < r_ || xb >= W_ - r_) return false;
    if (!otherOk(y - 1, xb) || !otherOk(y + 1, xb)) return false;
    const int top = y + t.rowFirst - r_;
    const ptrdiff_t stride = otherQStride_;
    float scores[2];
#ifdef DELINEO_STEREO_X86
    if (avx2_) {
      shapeScoresPairAvx2(otherQRow(top) + xb - r_, stride, &t.maskQ[16 * t.rowFirst],
                          &t.aQ[16 * t.rowFirst], t.rowLast - t.rowFirst + 1, t.terms, scores);
      minus = scores[0];
      plus = scores[1];
      return true;
    }
#endif
    const ptrdiff_t lines[2] = {-stride, stride};
    shapeScoresInt(otherQRow(top) + xb - r_, stride, lines, &t.maskQ[16 * t.rowFirst],
                   &t.aQ[16 * t.rowFirst], t.rowLast - t.rowFirst + 1, 2, t.terms, scores);
    minus = scores[0];
    plus = scores[1];
    return true;
  }

  void matchShapePixel(int x, int y, const ShapeTemplate& t) {
    LinePeak peak;
    const int lo = in_.lo.at<int>(y, x), hi = in_.hi.at<int>(y, x);
    peak.trackSecond = testsUniqueness(lo, hi);
    // As few passes as the batch size allows, of balanced sizes (an interval of 7 with batches
    // of 6: 4 + 3, not 6 + 1).
    float batch[kSpanPassesMax * kShapeMaxWindows];
    const int perPass = t.hasSpans ? kShapeMaxWindows : batchWindows_;
    auto passSize = [perPass](int left) {
      // (Most intervals take one pass: no integer divisions for them.)
      const int passes = left <= perPass ? 1 : (left + perPass - 1) / perPass;
      return passes == 1 ? left : (left + passes - 1) / passes;
    };
    for (int d = lo; d <= hi;) {
      const int left = hi - d + 1;
      const int count = passSize(left);
#ifdef DELINEO_STEREO_X86
      if (t.hasSpans && count < left) {
        // The next passes, as the loop would size them.
        int counts[kSpanPassesMax] = {count};
        int passes = 1, taken = count;
        for (; passes < kSpanPassesMax && taken < left; ++passes) {
          counts[passes] = passSize(left - taken);
          taken += counts[passes];
        }
        if (shapeScoresBatches(x, y, d, t, batch, counts, passes)) {
          for (int n = 0, k = 0; n < passes; k += counts[n], ++n) {
            peak.updatePass(d + k, batch + k, counts[n]);
          }
          d += taken;
          continue;
        }
      }
#endif
      if (shapeScoresBatch(x, y, d, t, batch, count)) {
        peak.updatePass(d, batch, count);
      } else {
        for (int k = 0; k < count; ++k) peak.update(d + k, shapeScore(x, y, d + k, 0, t));
      }
      d += count;
    }
    finish(
        x, y, lo, hi, peak, [&](int dd, int dy) { return shapeScore(x, y, dd, dy, t); },
        [&](int dd, float& minus, float& plus) { return shapeScorePair(x, y, dd, t, minus, plus); },
        [&](int dd, int dy, float* scores) { return shapeScoresLine(x, y, dd, dy, t, scores); });
  }

  // ---- peak ------------------------------------------------------------------------------

  bool testsUniqueness(int lo, int hi) const {
    return s_.uniqueMinInterval > 0 && hi - lo + 1 >= s_.uniqueMinInterval;
  }

  // From the main-line peak: rejection tests (uniqueness, border peaks), local ascent over the
  // line shifts (3x3 neighbourhoods of the 2D surface, d within the pixel's interval,
  // |dy| <= lineShift), score floor, sub-pixel offset, output.
  // `pair(d, minus, plus)` may give the scores at (d, ∓1) in one go (returns false when not),
  // `line(d, dy, scores)` those at (d .. d + 2, dy) (the same values as `score`, or false).
  // [lo, hi]: the pixel's interval (in_.lo, in_.hi at (x, y)).
  template <class Score, class Pair, class Line>
  void finish(int x, int y, int lo, int hi, const LinePeak& peak, Score&& score, Pair&& pair,
              Line&& line) {
    if (!(peak.best > kNegInf) || repeatedElsewhere(peak)) return;
    MainLinePeak mainPeak{peak.bestD, peak.below, peak.best, peak.above};
    if (!settleBorderPeak(mainPeak, lo, hi, score)) return;
    // The parabola and the ascent may use the scores just outside the interval.
    lo = std::max(in_.dmin, std::min(lo, mainPeak.d - 1));
    hi = std::min(in_.dmax, std::max(hi, mainPeak.d + 1));
    SurfacePeak surfacePeak{
        mainPeak.d,
        0,
        {{kNaN, mainPeak.below, kNaN}, {kNaN, mainPeak.best, kNaN}, {kNaN, mainPeak.above, kNaN}}};
    if (L_ > 0) ascendLineShifts(surfacePeak, lo, hi, score, pair, line);
    if (!(surfacePeak.s[1][1] >= static_cast<float>(s_.minScore))) return;
    // The ascent may have ended on the border of the (extended) interval: a slope again.
    if ((surfacePeak.d == lo && lo > in_.dmin) || (surfacePeak.d == hi && hi < in_.dmax)) return;
    writeMatch(x, y, surfacePeak);
  }

  // The uniqueness test of wide intervals (LevelSettings::uniqueMinInterval): true when another
  // disparity explains the window about as well.
  bool repeatedElsewhere(const LinePeak& peak) const {
    return peak.trackSecond && peak.second > kNegInf &&
           (1.0F - peak.best) * (1.0F + static_cast<float>(s_.uniqueMargin)) >= 1.0F - peak.second;
  }

  // A maximum on the border of a guided interval may be a slope: the coarser level's
  // disparities are biased by a px or two next to depth steps, and the interval can stop just
  // short of the true peak. The score one step outside decides: lower, the border is a peak
  // and is kept; higher, the peak moves there (at most kMaxIntervalExtension steps, [lo, hi]
  // with it); still rising after that, the pixel is rejected (returns false). (Rejecting every
  // border peak lost roof pixels along outlines: this test, measured on the sim 600² scene,
  // edge 55.1 -> 57.3 %, density 85.3 -> 85.7 %; more steps added errors for little gain.)
  template <class Score>
  bool settleBorderPeak(MainLinePeak& p, int& lo, int& hi, Score& score) const {
    for (int step = 0; step < kMaxIntervalExtension && p.d == lo && lo > in_.dmin; ++step) {
      const float next = score(p.d - 1, 0);
      if (!(next > p.best)) {
        p.below = next;
        break;
      }
      p.above = p.best;
      p.best = next;
      p.below = kNaN;
      lo = --p.d;
    }
    for (int step = 0; step < kMaxIntervalExtension && p.d == hi && hi < in_.dmax; ++step) {
      const float next = score(p.d + 1, 0);
      if (!(next > p.best)) {
        p.above = next;
        break;
      }
      p.below = p.best;
      p.best = next;
      p.above = kNaN;
      hi = ++p.d;
    }
    if (p.d == lo && lo > in_.dmin && std::isnan(p.below)) p.below = score(p.d - 1, 0);
    if (p.d == hi && hi < in_.dmax && std::isnan(p.above)) p.above = score(p.d + 1, 0);
    // Still rising at the border after the extension: no peak found.
    const bool slope = (p.d == lo && lo > in_.dmin && !(p.below < p.best)) ||
                       (p.d == hi && hi < in_.dmax && !(p.above < p.best));
    return !slope;
  }

  // The local ascent over the line shifts from the main-line peak `p` (dy = 0, its scores along
  // d known): moves to the best of the centre's neighbours while one beats it, at most
  // kMaxAscentSteps steps.
  template <class Score, class Pair, class Line>
  void ascendLineShifts(SurfacePeak& p, int lo, int hi, Score& score, Pair& pair,
                        Line& line) const {
    for (int step = 0;; ++step) {
      if (step == 0) {
        // The main line is known; the neighbouring lines at the peak's d decide whether the
        // ascent leaves it (and give the sub-pixel line shift when it does not).
        if (L_ < 1 || p.d < lo || p.d > hi || !pair(p.d, p.s[1][0], p.s[1][2])) {
          p.s[1][0] = scoreInRange(score, lo, hi, p.d, -1);
          p.s[1][2] = scoreInRange(score, lo, hi, p.d, 1);
        }
      } else {
        scoreNeighbours(p, lo, hi, score, line);
      }
      int bi = 1, bj = 1;
      ascentStep(p.s, step == 0, bi, bj);
      if ((bi == 1 && bj == 1) || step == kMaxAscentSteps) break;
      p.d += bi - 1;
      p.dy += bj - 1;
      p.s[1][1] = p.s[bi][bj];
    }
  }

  // The 8 neighbours of the centre of `p`, by line: the three windows of a line in one pass
  // when they all lie in the interval and the line in range (scoreInRange gives the same
  // values then).
  template <class Score, class Line>
  void scoreNeighbours(SurfacePeak& p, int lo, int hi, Score& score, Line& line) const {
    for (int j = 0; j < 3; ++j) {
      const int dy = p.dy + j - 1;
      float three[3];
      const bool batched =
          p.d - 1 >= lo && p.d + 1 <= hi && dy >= -L_ && dy <= L_ && line(p.d - 1, dy, three);
      for (int i = 0; i < 3; ++i) {
        if (i == 1 && j == 1) continue;
        p.s[i][j] = batched ? three[i] : scoreInRange(score, lo, hi, p.d + i - 1, dy);
      }
    }
  }

  // score(d, dy) within the ascent's reach (d in [lo, hi], |dy| <= lineShift), NaN outside.
  template <class Score>
  float scoreInRange(Score& score, int lo, int hi, int d, int dy) const {
    if (d < lo || d > hi || dy < -L_ || dy > L_) return kNaN;
    return score(d, dy);
  }

  // The neighbour (bi, bj) of the centre s[1][1] the ascent moves to; (1, 1) to stay. On the
  // `first` step only the main line's and the two lines' scores at the centre's d are known.
  static void ascentStep(const float (&s)[3][3], bool first, int& bi, int& bj) {
    // Leaving the current line needs a clear gain: on weakly textured surfaces the
    // neighbouring lines correlate almost as well and noise would pick among them.
    auto consider = [&](int i, int j) {
      const float gain = j != 1 ? kLineShiftGain : 0.0F;
      if (s[i][j] > s[bi][bj] + gain) {
        bi = i;
        bj = j;
      }
    };
    if (first) {
      // Same order and outcome as the loop below: the corners are still NaN (never win),
      // and the centre never beats a neighbour that beat it.
      consider(0, 1);
      consider(1, 0);
      consider(1, 2);
      consider(2, 1);
    } else {
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) consider(i, j);
      }
    }
  }

  // The match at (x, y): the peak's disparity and line shift with the sub-pixel offset of its
  // neighbourhood, and its score.
  void writeMatch(int x, int y, const SurfacePeak& p) {
    float du = 0, dv = 0;
    if (s_.subpixel) {
      const cv::Point2f off = subpixelOffset(p.s);
      du = off.x;
      dv = off.y;
    }
    out_.disparity.at<float>(y - outY_, x - outX_) = static_cast<float>(p.d) + du;
    out_.lineShift.at<float>(y - outY_, x - outX_) = static_cast<float>(p.dy) + dv;
    out_.score.at<float>(y - outY_, x - outX_) = std::min(p.s[1][1], 1.0F);
  }

  const LevelInput& in_;
  const LevelSettings& s_;
  LevelOutput& out_;
  const int W_, H_, r_, n_, L_;
  const int outX_, outY_;  // the outputs' origin in the padded input
  const int rowStride_;    // floats per dense shape row (16 or 32, ≥ window)
  // The main-line span kernel (AVX2, windows ≤ 15 columns): 8 windows a pass.
  const bool useSpans_ = cpuHasAvx2() && s_.window <= 15;
  const bool avx2_ = cpuHasAvx2();  // single windows and the ±1 pair straight to AVX2
  // The fill's AVX2 version where AVX-512 is missing (fillWindow15's AVX-512 clone does each
  // doubling step's AND-OR in one instruction).
  const bool fillAvx2_ = cpuHasAvx2() && !cpuHasAvx512Vl();
  const int batchWindows_ = shapeBatchWindows();  // main-line windows per pass without spans
  cv::Mat otherPrefixB_, otherPrefixBB_;  // CV_32S, row prefix sums of otherQ_ and its squares
  WindowMoments refStats_, otherStats_;
  cv::Mat otherSq_;
  cv::Mat refQ_, otherQ_;  // CV_16S, grey levels quantised for the integer shape kernels
  ptrdiff_t otherQStride_ = 0, prefixStride_ = 0;  // their row strides, in elements
  int32_t prefixRowOffsets_[16] = {};     // v · prefixStride_: the span terms' row offsets
  const int32_t* prefixBData_ = nullptr;  // row 0 of otherPrefixB_, otherPrefixBB_
  const int32_t* prefixBBData_ = nullptr;
  const uchar* otherOk_ = nullptr;  // row 0 of otherStats_.usable
  ptrdiff_t okStride_ = 0;
  const int16_t* otherQData_ = nullptr;  // row 0 of otherQ_
  // cv::Mat::step1 is a library call, not inlined: the strides the per-pixel paths use.
  ptrdiff_t refQStride_ = 0;
  size_t refStride_ = 0, otherStride_ = 0;
  ptrdiff_t invalidStride_ = 0;  // of otherInvalidBits_
  double flatQ_ = 0;             // kFlatVariance in quantised units
  double scale_ = 0;             // quantisation scale of refQ_ and otherQ_
  float squareLanes_[16] = {};   // 1 for the columns of a square window, 0 past it
  cv::Mat nearEdge_;
  cv::Mat blocked_;      // CV_8U, non-zero on contour and nodata pixels of ref
  cv::Mat blockedBits_;  // CV_32S, blocked pixels of the window row centred on each pixel
  std::vector<uint16_t> freeColumns_;  // windows ≤ 15: ~blockedBits_, column-major
  size_t columnStride_ = 0;
  uint64_t windowRows_[4] = {0, 0, 0, 0};  // the rows v < window of a 16-row board
  cv::Mat otherInvalidBits_;               // CV_32S, nodata pixels of the other image's window rows
};

}  // namespace

bool matchLevelBuild(const LevelInput& in, const LevelSettings& settings, LevelOutput& out,
                     core::Progress* progress, LevelPreparations* shared) {
  // Padding every input by the window radius with nodata lets adaptive shapes serve the pixels
  // whose window leaves the image (their shape stops at the border), and keeps every window
  // access inside the buffers.
  // The right side gets 32 more columns: dense shape rows read up to 32 floats from a window's
  // left column.
  const int r = settings.window / 2;
  // The first view of a level leaves its buffers to the second, which overwrites them.
  const bool leaving = shared != nullptr && shared->empty();
  LevelScratch scratch;
  if (shared != nullptr && !shared->empty()) scratch = std::move(shared->scratch);
  LevelInput& padded = scratch.padded;
  auto pad = [r](const cv::Mat& m, double value, cv::Mat& to) {
    cv::copyMakeBorder(m, to, r, r, r, r + 32, cv::BORDER_CONSTANT, cv::Scalar(value));
  };
  // The padded copies run on the level's threads too (serial, the copies in and out were ~4 %
  // of the level's wall time with two threads).
  runTasks({[&] { pad(in.ref, 0, padded.ref); }, [&] { pad(in.other, 0, padded.other); },
            [&] { pad(in.refValid, 0, padded.refValid); },
            [&] { pad(in.otherValid, 0, padded.otherValid); },
            [&] { pad(in.refEdges, 0, padded.refEdges); },
            [&] { pad(in.lo, 1, padded.lo); },  // lo > hi: not searched
            [&] { pad(in.hi, 0, padded.hi); },
            [&] {
              if (in.oneSurface.empty()) {
                padded.oneSurface.release();
              } else {
                pad(in.oneSurface, 0, padded.oneSurface);
              }
            }},
           settings.threads);
  padded.dmin = in.dmin;
  padded.dmax = in.dmax;
  // The matcher writes the unpadded outputs directly (no copy out).
  LevelMatcher matcher(padded, settings, out, cv::Rect(r, r, in.ref.cols, in.ref.rows), shared,
                       scratch);
  const bool finished = matcher.run(progress);
  if (leaving) {
    matcher.leaveBuffers(shared->scratch);
    shared->scratch.padded = std::move(scratch.padded);
  }
  return finished;
}

}  // namespace delineo::stereo::detail::DELINEO_LEVEL_MATCHER_BUILD

#ifndef DELINEO_LEVEL_MATCHER_AVX2_PASS
// The AVX2 build needs GCC's target pragma (other compilers: the baseline build only).
#if defined(DELINEO_STEREO_X86) && defined(__GNUC__) && !defined(__clang__)
#define DELINEO_LEVEL_MATCHER_HAS_AVX2_BUILD 1
#define DELINEO_LEVEL_MATCHER_AVX2_PASS 1
#pragma GCC push_options
#pragma GCC target("avx2")
#include "level_matcher.cpp"  // NOLINT(bugprone-suspicious-include): the AVX2 build
#pragma GCC pop_options
#endif

namespace delineo::stereo::detail {

cv::Point2f subpixelPeak(const float s[3][3]) {
  return base::subpixelOffset(s);
}

bool matchLevel(const LevelInput& in, const LevelSettings& settings, LevelOutput& out,
                core::Progress* progress, LevelPreparations* shared) {
#ifdef DELINEO_LEVEL_MATCHER_HAS_AVX2_BUILD
  if (cpuHasAvx2()) return avx2build::matchLevelBuild(in, settings, out, progress, shared);
#endif
  return base::matchLevelBuild(in, settings, out, progress, shared);
}

}  // namespace delineo::stereo::detail
#endif
