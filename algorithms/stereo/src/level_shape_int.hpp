#pragma once
// Integer kernels of the adaptive shape path (windows of ≤ 15 columns, internal to
// delineo_stereo).
//
// Grey levels are quantised to int16 (q = round(scale · grey), |q| ≤ kShapeQuantMax): a dense
// shape row of 16 columns is then one 256-bit vector, and the sums over a shape are exact
// integers accumulated with multiply-add of 16-bit pairs into 32-bit lanes. Against the float
// rows this halves the loads of the other image's windows (which bound the float kernels) and
// needs 7 vector operations per row and window instead of ~12. Bounds, for ≤ 15 rows of ≤ 15
// columns: Σ over a column of ≤ 15 masked values ≤ 15 · 2184 < 2^15 (so Σ B runs in 16-bit
// lanes), and every other sum ≤ 225 · 2184² < 2^31.
//
// Built for AVX2 (picked at run time) and for the x86-64 baseline (SSE2); a scalar version
// elsewhere.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "cpu_features.hpp"

namespace delineo::stereo::detail {

constexpr int kShapeQuantMax = 2184;  // 32767 / 15

// Sums of one window of the other image B over a shape S with grey levels A: Σ_S B, Σ_S B²,
// Σ_S A·B (quantised, exact).
struct ShapeSumsInt {
  int32_t b = 0, bb = 0, ab = 0;
};

// What the NCC of a window needs from the shape: n = |S|, Σ_S A, 1 / sqrt(n Σ A² − (Σ A)²),
// and n² times the variance under which a window is flat.
struct ShapeNccTerms {
  int n = 0;
  int32_t sumA = 0;
  float invNormA = 0;
  float flatN = 0;
};

// Most windows one call of shapeScoresInt scores at full speed (the vector registers hold
// their accumulators); it accepts up to kShapeMaxWindows.
constexpr int kShapeMaxWindows = 8;
inline int shapeBatchWindows() {
  if (cpuHasAvx512Vl()) return 8;
  if (cpuHasAvx2()) return 3;
  return 4;
}

// Main-line windows from the shape's spans. The windows d, d + 1, ... of a pixel lie one column
// apart on the same rows, so Σ_S B and Σ_S B² of up to 8 of them come from row prefix sums of the
// other image: a run of cells u0..u1 on row v adds P(v, x + u1 + 1) − P(v, x + u0) to window x,
// and the 8 windows' differences are two 8-lane loads. Only Σ A·B is summed per window (A is 0
// off S: no mask), one accumulator each, so AVX2 scores 8 windows a pass instead of 3 (the three
// accumulators per window filled its 16 registers), with the same integer sums.

// Terms of a shape's Σ B on each window row: + the prefix at `plus` − the prefix at `minus`
// (columns of the window). Level 0 holds the row's cells from its first to its last; level g > 0
// its g-th gap between them (a hole of S: most are contour pixels a shape leaves out), negated;
// rows with fewer gaps hold empty terms (plus = minus) there. `levels` counts the levels any row
// needs; gapRows[g] (g > 0) has bit 2v set where row v's term of level g is not empty (most rows
// have no gap: the kernel skips the empty terms). Built for all 16 rows at once in vector lanes:
// a loop over each row's runs cost as much as the kernel saved.
constexpr int kSpanLevels = 4;  // the outer span and up to 3 gaps a row
struct ShapeSpans {
  alignas(32) int16_t plus[kSpanLevels][16];
  alignas(32) int16_t minus[kSpanLevels][16];
  uint32_t gapRows[kSpanLevels] = {};
  int levels = 0;
};

// Portable version of shapeSpansAvx2 (also its reference): false when a row has more gaps.
inline bool shapeSpansScalar(const uint16_t* rows, ShapeSpans& spans) {
  spans.levels = 1;
  for (uint32_t& gapRows : spans.gapRows) gapRows = 0;
  for (int v = 0; v < 16; ++v) {
    const uint32_t cells = rows[v];
    const int first = __builtin_ctz(cells | (1U << 16));          // 16 for an empty row
    const int end = cells != 0 ? 32 - __builtin_clz(cells) : 0;  // past the last cell
    spans.plus[0][v] = static_cast<int16_t>(end);
    spans.minus[0][v] = static_cast<int16_t>(first < end ? first : end);
    uint32_t gaps = ~cells & ((1U << end) - 1U) & ~((1U << first) - 1U);
    for (int g = 1; g < kSpanLevels; ++g) {
      const int gap = __builtin_ctz(gaps | (1U << 16));  // 16 when none
      const int length = __builtin_ctz(~(gaps >> gap));  // 0 when none
      spans.plus[g][v] = static_cast<int16_t>(gap);
      spans.minus[g][v] = static_cast<int16_t>(gap + length);
      if (length > 0) spans.gapRows[g] |= 1U << (2 * v);
      if (length > 0 && g + 1 > spans.levels) spans.levels = g + 1;
      gaps &= ~(((1U << length) - 1U) << gap);
    }
    if (gaps != 0) return false;
  }
  return true;
}

// Entries a prefix row needs past the image's width for the 8-lane loads of the span kernel.
constexpr int kPrefixPad = 32;

// Row prefix sums of B and B²: p[x] = Σ_{x' < x} b[x'] for x ≤ width, then p[width] repeated
// over kPrefixPad more entries; the same of b² in pp. Wrapping 32-bit arithmetic (unsigned, then
// stored as int32): the sums of a row may pass 2^31, a run's difference (≤ 15 · 2184²) does not
// and comes out exact.
inline void rowPrefixSums(const int16_t* b, int width, int32_t* p, int32_t* pp) {
  uint32_t sum = 0, sumSquares = 0;
  for (int x = 0; x < width; ++x) {
    p[x] = static_cast<int32_t>(sum);
    pp[x] = static_cast<int32_t>(sumSquares);
    sum += static_cast<uint32_t>(static_cast<int32_t>(b[x]));
    sumSquares += static_cast<uint32_t>(static_cast<int32_t>(b[x]) * b[x]);
  }
  for (int x = width; x <= width + kPrefixPad; ++x) {
    p[x] = static_cast<int32_t>(sum);
    pp[x] = static_cast<int32_t>(sumSquares);
  }
}

#ifdef DELINEO_STEREO_X86

__attribute__((target("avx2"), always_inline)) inline int32_t laneSumAvx2(__m256i v) {
  __m128i s = _mm_add_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, 0x4E));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, 0xB1));
  return _mm_cvtsi128_si32(s);
}

// After a loop over rows: the accumulator v is in a vector register here (an empty asm, no
// instruction). Without it GCC computed each row's sum into a new register and copied it back,
// one move per accumulator and row (~20 % of the pair kernel's loop).
__attribute__((target("avx2"), always_inline)) inline void settledAvx2(__m256i& v) {
  __asm__("" : "+x"(v));
}

// One row of one window: B on S (A and the mask are 0 off S) into the three accumulators.
__attribute__((target("avx2"), always_inline)) inline void accumulateRowAvx2(
    const int16_t* x, __m256i m, __m256i a, __m256i& accB, __m256i& accBB, __m256i& accAB) {
  const __m256i xm = _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(x)), m);
  accB = _mm256_add_epi16(accB, xm);
  accBB = _mm256_add_epi32(accBB, _mm256_madd_epi16(xm, xm));
  accAB = _mm256_add_epi32(accAB, _mm256_madd_epi16(a, xm));
}

// The four lane sums of a, b, c, d (8 int32 each) as one vector.
__attribute__((target("avx2"), always_inline)) inline __m128i laneSums4Avx2(__m256i a, __m256i b,
                                                                           __m256i c, __m256i d) {
  const __m256i h = _mm256_hadd_epi32(_mm256_hadd_epi32(a, b), _mm256_hadd_epi32(c, d));
  return _mm_add_epi32(_mm256_castsi256_si128(h), _mm256_extracti128_si256(h, 1));
}

// NCC of up to 4 windows from their sums (one per lane): the terms n Σ B² − (Σ B)² and
// n Σ A·B − Σ A Σ B are exact in double (< 2^53), then rounded to float as in nccFromIntSums.
__attribute__((target("avx2"), always_inline)) inline void nccAvx2(__m128i sB, __m128i sBB,
                                                                  __m128i sAB,
                                                                  const ShapeNccTerms& terms,
                                                                  int count, float* scores) {
  const __m256d n = _mm256_set1_pd(terms.n);
  const __m256d b = _mm256_cvtepi32_pd(sB);
  const __m256d var = _mm256_sub_pd(_mm256_mul_pd(n, _mm256_cvtepi32_pd(sBB)), _mm256_mul_pd(b, b));
  const __m256d num = _mm256_sub_pd(_mm256_mul_pd(n, _mm256_cvtepi32_pd(sAB)),
                                    _mm256_mul_pd(_mm256_set1_pd(terms.sumA), b));
  const __m128 varF = _mm256_cvtpd_ps(var);
  const __m128 ncc = _mm_div_ps(_mm_mul_ps(_mm256_cvtpd_ps(num), _mm_set1_ps(terms.invNormA)),
                                _mm_sqrt_ps(varF));
  const __m128 flat = _mm_cmplt_ps(varF, _mm_set1_ps(terms.flatN));
  alignas(16) float out[4];
  _mm_store_ps(out, _mm_blendv_ps(ncc, _mm_set1_ps(std::numeric_limits<float>::quiet_NaN()), flat));
  for (int k = 0; k < count; ++k) scores[k] = out[k];
}

// NAME<K>: NCC of K (1..8) windows of B, the k-th at b + offsets[k], over a shape given as rows
// of 16 int16: mask (−1 on S, 0 elsewhere) and A on S (0 elsewhere); NAME##Dispatch picks K at
// run time. The shape rows are loaded once for the K windows, and each window keeps 3 vector
// accumulators: named variables, not arrays (GCC kept arrays of vectors partly on the stack).
// Generated for two instruction sets (TARGET): AVX2 with its 16 vector registers holds the
// accumulators of 3 windows without spills (4 windows spilled: 16.5 vs 12.2 ns per window,
// micro-benchmark); with AVX-512VL the same 256-bit code has 32 registers, room for 8.
#define DELINEO_STEREO_SHAPE_SCORES(NAME, TARGET)                                                \
  template <int K>                                                                              \
  __attribute__((target(TARGET), always_inline)) inline void NAME(                              \
      const int16_t* b, ptrdiff_t stride, const ptrdiff_t* offsets, const int16_t* mask,        \
      const int16_t* am, int rows, const ShapeNccTerms& terms, float* scores) {                 \
    const __m256i zero = _mm256_setzero_si256();                                                \
    __m256i b0 = zero, bb0 = zero, ab0 = zero, b1 = zero, bb1 = zero, ab1 = zero;               \
    __m256i b2 = zero, bb2 = zero, ab2 = zero, b3 = zero, bb3 = zero, ab3 = zero;               \
    __m256i b4 = zero, bb4 = zero, ab4 = zero, b5 = zero, bb5 = zero, ab5 = zero;               \
    __m256i b6 = zero, bb6 = zero, ab6 = zero, b7 = zero, bb7 = zero, ab7 = zero;               \
    for (int v = 0; v < rows; ++v) {                                                            \
      const int16_t* bv = b + v * stride;                                                       \
      const __m256i m = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(mask + 16 * v));    \
      const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(am + 16 * v));      \
      accumulateRowAvx2(bv + offsets[0], m, a, b0, bb0, ab0);                                   \
      if constexpr (K > 1) accumulateRowAvx2(bv + offsets[1], m, a, b1, bb1, ab1);              \
      if constexpr (K > 2) accumulateRowAvx2(bv + offsets[2], m, a, b2, bb2, ab2);              \
      if constexpr (K > 3) accumulateRowAvx2(bv + offsets[3], m, a, b3, bb3, ab3);              \
      if constexpr (K > 4) accumulateRowAvx2(bv + offsets[4], m, a, b4, bb4, ab4);              \
      if constexpr (K > 5) accumulateRowAvx2(bv + offsets[5], m, a, b5, bb5, ab5);              \
      if constexpr (K > 6) accumulateRowAvx2(bv + offsets[6], m, a, b6, bb6, ab6);              \
      if constexpr (K > 7) accumulateRowAvx2(bv + offsets[7], m, a, b7, bb7, ab7);              \
    }                                                                                           \
    settledAvx2(b0), settledAvx2(bb0), settledAvx2(ab0);                                        \
    if constexpr (K > 1) settledAvx2(b1), settledAvx2(bb1), settledAvx2(ab1);                   \
    if constexpr (K > 2) settledAvx2(b2), settledAvx2(bb2), settledAvx2(ab2);                   \
    if constexpr (K > 3) settledAvx2(b3), settledAvx2(bb3), settledAvx2(ab3);                   \
    if constexpr (K > 4) settledAvx2(b4), settledAvx2(bb4), settledAvx2(ab4);                   \
    if constexpr (K > 5) settledAvx2(b5), settledAvx2(bb5), settledAvx2(ab5);                   \
    if constexpr (K > 6) settledAvx2(b6), settledAvx2(bb6), settledAvx2(ab6);                   \
    if constexpr (K > 7) settledAvx2(b7), settledAvx2(bb7), settledAvx2(ab7);                   \
    /* Σ B widened from its 16-bit column sums. */                                              \
    const __m256i ones = _mm256_set1_epi16(1);                                                  \
    nccAvx2(laneSums4Avx2(_mm256_madd_epi16(b0, ones), _mm256_madd_epi16(b1, ones),             \
                          _mm256_madd_epi16(b2, ones), _mm256_madd_epi16(b3, ones)),            \
            laneSums4Avx2(bb0, bb1, bb2, bb3), laneSums4Avx2(ab0, ab1, ab2, ab3), terms,        \
            K < 4 ? K : 4, scores);                                                             \
    if constexpr (K > 4) {                                                                      \
      nccAvx2(laneSums4Avx2(_mm256_madd_epi16(b4, ones), _mm256_madd_epi16(b5, ones),           \
                            _mm256_madd_epi16(b6, ones), _mm256_madd_epi16(b7, ones)),          \
              laneSums4Avx2(bb4, bb5, bb6, bb7), laneSums4Avx2(ab4, ab5, ab6, ab7), terms,      \
              K - 4, scores + 4);                                                               \
    }                                                                                           \
  }                                                                                             \
  __attribute__((target(TARGET))) inline void NAME##Dispatch(                                   \
      const int16_t* b, ptrdiff_t stride, const ptrdiff_t* offsets, const int16_t* mask,        \
      const int16_t* am, int rows, int count, const ShapeNccTerms& terms, float* scores) {      \
    switch (count) {                                                                            \
      case 1: NAME<1>(b, stride, offsets, mask, am, rows, terms, scores); break;                \
      case 2: NAME<2>(b, stride, offsets, mask, am, rows, terms, scores); break;                \
      case 3: NAME<3>(b, stride, offsets, mask, am, rows, terms, scores); break;                \
      case 4: NAME<4>(b, stride, offsets, mask, am, rows, terms, scores); break;                \
      case 5: NAME<5>(b, stride, offsets, mask, am, rows, terms, scores); break;                \
      case 6: NAME<6>(b, stride, offsets, mask, am, rows, terms, scores); break;                \
      case 7: NAME<7>(b, stride, offsets, mask, am, rows, terms, scores); break;                \
      default: NAME<8>(b, stride, offsets, mask, am, rows, terms, scores); break;               \
    }                                                                                           \
  }

DELINEO_STEREO_SHAPE_SCORES(shapeScoresIntAvx2, "avx2")
DELINEO_STEREO_SHAPE_SCORES(shapeScoresIntAvx512, "avx2,avx512vl,avx512bw")
#undef DELINEO_STEREO_SHAPE_SCORES

// One window and the ±1 line pair straight to the AVX2 kernel (the matcher's most frequent
// calls besides the main line): shapeScoresInt's dispatch and batching loop cost more than a
// tenth of these calls.
__attribute__((target("avx2"))) inline void shapeScoreIntAvx2(const int16_t* b, ptrdiff_t offset,
                                                              const int16_t* mask,
                                                              const int16_t* am, ptrdiff_t stride,
                                                              int rows, const ShapeNccTerms& terms,
                                                              float* score) {
  shapeScoresIntAvx2<1>(b, stride, &offset, mask, am, rows, terms, score);
}
__attribute__((target("avx2"))) inline void shapeScoresPairAvx2(const int16_t* b, ptrdiff_t stride,
                                                                const int16_t* mask,
                                                                const int16_t* am, int rows,
                                                                const ShapeNccTerms& terms,
                                                                float* scores) {
  const ptrdiff_t lines[2] = {-stride, stride};
  shapeScoresIntAvx2<2>(b, stride, lines, mask, am, rows, terms, scores);
}

// Bits set in each 16-bit lane of v.
__attribute__((target("avx2"), always_inline)) inline __m256i popcount16Avx2(__m256i v) {
  const __m256i table = _mm256_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4, 0, 1, 1, 2,
                                         1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4);
  const __m256i nibble = _mm256_set1_epi8(0x0F);
  const __m256i perByte =
      _mm256_add_epi8(_mm256_shuffle_epi8(table, _mm256_and_si256(v, nibble)),
                      _mm256_shuffle_epi8(table, _mm256_and_si256(_mm256_srli_epi16(v, 4), nibble)));
  return _mm256_maddubs_epi16(perByte, _mm256_set1_epi8(1));
}

// shapeSpansScalar for the 16 rows at once, one row per 16-bit lane: the lowest cell and the
// lowest gap cell isolated by x & −x, the cells up to the last one by smearing the bits down, a
// gap as the run its lowest bit starts (gaps & ~(gaps + lowest)), positions by counting bits.
__attribute__((target("avx2"))) inline bool shapeSpansAvx2(const uint16_t* rows,
                                                           ShapeSpans& spans) {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i one = _mm256_set1_epi16(1);
  const __m256i cells = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rows));
  const __m256i lowest = _mm256_and_si256(cells, _mm256_sub_epi16(zero, cells));
  const __m256i belowFirst = _mm256_sub_epi16(lowest, one);  // all 16 bits for an empty row
  __m256i upToLast = _mm256_or_si256(cells, _mm256_srli_epi16(cells, 1));
  upToLast = _mm256_or_si256(upToLast, _mm256_srli_epi16(upToLast, 2));
  upToLast = _mm256_or_si256(upToLast, _mm256_srli_epi16(upToLast, 4));
  upToLast = _mm256_or_si256(upToLast, _mm256_srli_epi16(upToLast, 8));
  const __m256i first = popcount16Avx2(belowFirst);
  const __m256i end = popcount16Avx2(upToLast);
  _mm256_store_si256(reinterpret_cast<__m256i*>(spans.plus[0]), end);
  _mm256_store_si256(reinterpret_cast<__m256i*>(spans.minus[0]), _mm256_min_epi16(first, end));
  __m256i gaps = _mm256_andnot_si256(cells, _mm256_andnot_si256(belowFirst, upToLast));
  spans.levels = 1;
  for (int g = 1; g < kSpanLevels; ++g) {
    if (_mm256_testz_si256(gaps, gaps) != 0) return true;
    const __m256i gapLowest = _mm256_and_si256(gaps, _mm256_sub_epi16(zero, gaps));
    const __m256i gap = _mm256_andnot_si256(_mm256_add_epi16(gaps, gapLowest), gaps);
    const __m256i start = popcount16Avx2(_mm256_sub_epi16(gapLowest, one));  // 16 when none
    const __m256i stop = _mm256_add_epi16(start, popcount16Avx2(gap));
    _mm256_store_si256(reinterpret_cast<__m256i*>(spans.plus[g]), start);
    _mm256_store_si256(reinterpret_cast<__m256i*>(spans.minus[g]), stop);
    spans.gapRows[g] =
        ~static_cast<uint32_t>(_mm256_movemask_epi8(_mm256_cmpeq_epi16(start, stop))) & 0x55555555U;
    gaps = _mm256_andnot_si256(gap, gaps);
    spans.levels = g + 1;
  }
  return _mm256_testz_si256(gaps, gaps) != 0;
}

// The flood fill of a window of ≤ 15 columns (fillWindow15 of level_matcher.cpp) for AVX2:
// the 16 rows of 16 bits as one 256-bit board, row v in bytes 2v, 2v + 1, bit 15 of a row
// always 0 (it stops the shifts along rows). A shift by whole rows is a byte shift of the
// board: a lane swap and an alignr (2 instructions instead of ~5 on 64-bit words), and a
// board test is one vptest.
template <int N>
__attribute__((target("avx2"), always_inline)) inline __m256i downRowsAvx2(__m256i v) {
  const __m256i low = _mm256_permute2x128_si256(v, v, 0x08);  // (0, v.lo)
  if constexpr (N == 8) {
    return low;
  } else {
    return _mm256_alignr_epi8(v, low, 16 - 2 * N);
  }
}
template <int N>
__attribute__((target("avx2"), always_inline)) inline __m256i upRowsAvx2(__m256i v) {
  const __m256i high = _mm256_permute2x128_si256(v, v, 0x81);  // (v.hi, 0)
  if constexpr (N == 8) {
    return high;
  } else {
    return _mm256_alignr_epi8(high, v, 2 * N);
  }
}

// Masks of the doubling steps: runs of open cells 2^i long along rows (towards lower bits),
// towards higher rows (down) and towards lower rows (up).
struct FillMasksAvx2 {
  __m256i open, l1, l2, l3, d1, d2, u1, u2;
};

// Along rows: towards higher bits by one addition (the carry runs through each open run from
// its lowest seed up to the blocked cell ending it; the row-end bits are 0, so no carry leaves
// a row), towards lower bits by doubling.
__attribute__((target("avx2"), always_inline)) inline __m256i fillAlongRowsAvx2(
    const FillMasksAvx2& g, __m256i s) {
  const __m256i a = _mm256_or_si256(
      _mm256_and_si256(_mm256_xor_si256(_mm256_add_epi64(g.open, s), g.open), g.open), s);
  __m256i b = s;
  b = _mm256_or_si256(b, _mm256_and_si256(g.open, _mm256_srli_epi64(b, 1)));
  b = _mm256_or_si256(b, _mm256_and_si256(g.l1, _mm256_srli_epi64(b, 2)));
  b = _mm256_or_si256(b, _mm256_and_si256(g.l2, _mm256_srli_epi64(b, 4)));
  b = _mm256_or_si256(b, _mm256_and_si256(g.l3, _mm256_srli_epi64(b, 8)));
  return _mm256_or_si256(a, b);
}

// Along columns, both directions, up to 7 rows (steps of 1, 2 and 4 rows; the fill repeats
// until closed: a fourth step of 8 rows cost more than the extra rounds it saved).
__attribute__((target("avx2"), always_inline)) inline __m256i fillAlongColumnsAvx2(
    const FillMasksAvx2& g, __m256i s) {
  __m256i a = s, b = s;
  a = _mm256_or_si256(a, _mm256_and_si256(g.open, downRowsAvx2<1>(a)));
  b = _mm256_or_si256(b, _mm256_and_si256(g.open, upRowsAvx2<1>(b)));
  a = _mm256_or_si256(a, _mm256_and_si256(g.d1, downRowsAvx2<2>(a)));
  b = _mm256_or_si256(b, _mm256_and_si256(g.u1, upRowsAvx2<2>(b)));
  a = _mm256_or_si256(a, _mm256_and_si256(g.d2, downRowsAvx2<4>(a)));
  b = _mm256_or_si256(b, _mm256_and_si256(g.u2, upRowsAvx2<4>(b)));
  return _mm256_or_si256(a, b);
}

// `freeRows`, `inWindow`: the window's 16 row words (bit u of row v: cell (u, v) free; the
// rows v < window). The 4-connected component of the centre (r, r) in the free cells plus the
// centre goes to `reach`; returns true when a free cell is left unreached.
__attribute__((target("avx2"))) inline bool fillWindow15Avx2(const uint16_t* freeRows,
                                                             const uint64_t* inWindow, int r,
                                                             uint16_t* reach) {
  const __m256i free =
      _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(freeRows)),
                       _mm256_loadu_si256(reinterpret_cast<const __m256i*>(inWindow)));
  const __m256i rowIndex = _mm256_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  __m256i seed =
      _mm256_and_si256(_mm256_cmpeq_epi16(rowIndex, _mm256_set1_epi16(static_cast<short>(r))),
                       _mm256_set1_epi16(static_cast<short>(1 << r)));
  FillMasksAvx2 g;
  g.open = _mm256_or_si256(free, seed);
  g.l1 = _mm256_and_si256(g.open, _mm256_srli_epi64(g.open, 1));
  g.l2 = _mm256_and_si256(g.l1, _mm256_srli_epi64(g.l1, 2));
  g.l3 = _mm256_and_si256(g.l2, _mm256_srli_epi64(g.l2, 4));
  g.d1 = _mm256_and_si256(g.open, downRowsAvx2<1>(g.open));
  g.d2 = _mm256_and_si256(g.d1, downRowsAvx2<2>(g.d1));
  g.u1 = _mm256_and_si256(g.open, upRowsAvx2<1>(g.open));
  g.u2 = _mm256_and_si256(g.u1, upRowsAvx2<2>(g.u1));
  // Both steps only add cells. The step along rows is complete (every run of a row is filled
  // from its seeds), the one along columns reaches 7 rows: the fill is closed when a column
  // step after a row step adds no cell (~seed & filled = 0). The result is the component
  // whatever the steps, so the same as the baseline fill's.
  seed = fillAlongRowsAvx2(g, seed);
  for (;;) {
    __m256i filled = fillAlongColumnsAvx2(g, seed);
    if (_mm256_testc_si256(seed, filled) != 0) break;
    seed = fillAlongRowsAvx2(g, filled);
  }
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(reach), seed);
  return _mm256_testc_si256(seed, free) == 0;  // a free cell outside the fill
}

// acc + the 8 values at p + plus − the 8 at p + minus (32-bit lanes).
__attribute__((target("avx2"), always_inline)) inline __m256i addSpanAvx2(__m256i acc,
                                                                         const int32_t* p,
                                                                         ptrdiff_t plus,
                                                                         ptrdiff_t minus) {
  return _mm256_add_epi32(
      acc, _mm256_sub_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + plus)),
                            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + minus))));
}

// acc + the pairwise products of a and the 16 values at x, summed in pairs (32-bit lanes).
__attribute__((target("avx2"), always_inline)) inline __m256i addDotAvx2(__m256i acc, __m256i a,
                                                                        const int16_t* x) {
  return _mm256_add_epi32(
      acc, _mm256_madd_epi16(a, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(x))));
}

// The span terms of a shape as one list: per term, the prefix entries it adds (plus) and takes
// away (minus) as offsets from the prefix at the window's left column on its first row (row v
// of the window at (v − firstRow) · pStride). The rows' level-0 terms first, then the non-empty
// gap terms. Built once per shape: the kernel's passes then run one plain loop (visiting the gap
// levels row by row, with their offsets computed anew at every pass, cost a third of it).
struct ShapeSpanTerms {
  static constexpr int kFirst = 16;  // the list starts here (room for the level-0 stores)
  // (8 more: the gap terms are stored 8 lanes at a time.)
  alignas(32) int32_t plus[kFirst + 16 + 16 * (kSpanLevels - 1) + 8];
  alignas(32) int32_t minus[kFirst + 16 + 16 * (kSpanLevels - 1) + 8];
  int count = 0;
};

// out[v] = level[v] + the row offset of row v (16 rows: row0 holds rows 0..7, row8 rows 8..15).
__attribute__((target("avx2"), always_inline)) inline void storeSpanLevelAvx2(const int16_t* level,
                                                                             __m256i row0,
                                                                             __m256i row8,
                                                                             int32_t* out) {
  const __m128i* in = reinterpret_cast<const __m128i*>(level);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out),
                      _mm256_add_epi32(_mm256_cvtepi16_epi32(_mm_load_si128(in)), row0));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 8),
                      _mm256_add_epi32(_mm256_cvtepi16_epi32(_mm_load_si128(in + 1)), row8));
}

// For each 8-bit set of lanes: the lanes in order, packed to the front (a permutation of 8
// 32-bit lanes), and how many they are.
struct SpanTermsPacking {
  alignas(32) int32_t order[256][8];
  uint8_t count[256];
};
constexpr SpanTermsPacking spanTermsPacking() {
  SpanTermsPacking p{};
  for (int set = 0; set < 256; ++set) {
    int n = 0;
    for (int lane = 0; lane < 8; ++lane) {
      if ((set >> lane) & 1) p.order[set][n++] = lane;
    }
    p.count[set] = static_cast<uint8_t>(n);
  }
  return p;
}
inline constexpr SpanTermsPacking kSpanTermsPacking = spanTermsPacking();

// `rowOffsets[v]` = v · pStride (v = 0..15); rows firstRow .. firstRow + rows − 1 hold S.
__attribute__((target("avx2"))) inline void shapeSpanTermsAvx2(const ShapeSpans& spans,
                                                               int firstRow, int rows,
                                                               const int32_t* rowOffsets,
                                                               ShapeSpanTerms& terms) {
  // Level 0 of all 16 rows in vector lanes, stored so that row firstRow lands on kFirst (the
  // entries past the last row are overwritten by the gap terms or not read).
  const __m256i base = _mm256_set1_epi32(rowOffsets[firstRow]);
  const __m256i row0 =
      _mm256_sub_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(rowOffsets)), base);
  const __m256i row8 =
      _mm256_sub_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(rowOffsets + 8)), base);
  storeSpanLevelAvx2(spans.plus[0], row0, row8, terms.plus + ShapeSpanTerms::kFirst - firstRow);
  storeSpanLevelAvx2(spans.minus[0], row0, row8, terms.minus + ShapeSpanTerms::kFirst - firstRow);
  // The gap levels, 8 rows at a time: the non-empty terms packed to the front of the lanes by a
  // permutation from a table (the scalar loop over each level's rows cost ~10 instructions a
  // term, ~13 terms a shape).
  int n = ShapeSpanTerms::kFirst + rows;
  for (int g = 1; g < spans.levels; ++g) {
    for (int half = 0; half < 2; ++half) {
      const __m128i plus = _mm_load_si128(reinterpret_cast<const __m128i*>(spans.plus[g]) + half);
      const __m128i minus = _mm_load_si128(reinterpret_cast<const __m128i*>(spans.minus[g]) + half);
      const unsigned used =
          ~static_cast<unsigned>(_mm_movemask_epi8(
              _mm_packs_epi16(_mm_cmpeq_epi16(plus, minus), _mm_setzero_si128()))) & 0xFFU;
      if (used == 0) continue;
      const __m256i rowOffset = half == 0 ? row0 : row8;
      const __m256i order =
          _mm256_load_si256(reinterpret_cast<const __m256i*>(kSpanTermsPacking.order[used]));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(terms.plus + n),
                          _mm256_permutevar8x32_epi32(
                              _mm256_add_epi32(_mm256_cvtepi16_epi32(plus), rowOffset), order));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(terms.minus + n),
                          _mm256_permutevar8x32_epi32(
                              _mm256_add_epi32(_mm256_cvtepi16_epi32(minus), rowOffset), order));
      n += kSpanTermsPacking.count[used];
    }
  }
  terms.count = n - ShapeSpanTerms::kFirst;
}

// Σ_S B and Σ_S B² of the 8 windows whose prefix rows start at pb − 7 .. pb (lane j: the
// window at pb − 7 + j) and, when `pb2` is not null, the same of those at pb2 − 7 .. pb2, from the
// shape's span terms: one loop over the terms for both sets (their offsets read once).
__attribute__((target("avx2"), always_inline)) inline void spanSumsAvx2(
    const ShapeSpanTerms& spanTerms, const int32_t* pb, const int32_t* pbb, __m256i& sb,
    __m256i& sbb) {
  // Every shape has a level-0 term (the sums start from the first one's: starting from zero, GCC
  // copied both sums at every term).
  const int32_t* plus = spanTerms.plus + ShapeSpanTerms::kFirst;
  const int32_t* minus = spanTerms.minus + ShapeSpanTerms::kFirst;
  sb = addSpanAvx2(_mm256_setzero_si256(), pb, plus[0], minus[0]);
  sbb = addSpanAvx2(_mm256_setzero_si256(), pbb, plus[0], minus[0]);
  for (int i = 1; i < spanTerms.count; ++i) {
    sb = addSpanAvx2(sb, pb, plus[i], minus[i]);
    sbb = addSpanAvx2(sbb, pbb, plus[i], minus[i]);
  }
}
// The same for N (2..4) sets of 8 windows, at pb[n] − 7 .. pb[n] (their prefixes of B² at
// pbb[n]), in one loop over the terms.
template <int N>
__attribute__((target("avx2"), always_inline)) inline void spanSumsManyAvx2(
    const ShapeSpanTerms& spanTerms, const int32_t* const* pb, const int32_t* const* pbb,
    __m256i* sb, __m256i* sbb) {
  const int32_t* plus = spanTerms.plus + ShapeSpanTerms::kFirst;
  const int32_t* minus = spanTerms.minus + ShapeSpanTerms::kFirst;
  // Named accumulators (GCC kept arrays of vectors partly on the stack).
  const __m256i zero = _mm256_setzero_si256();
  __m256i b0 = addSpanAvx2(zero, pb[0], plus[0], minus[0]);
  __m256i bb0 = addSpanAvx2(zero, pbb[0], plus[0], minus[0]);
  __m256i b1 = addSpanAvx2(zero, pb[1], plus[0], minus[0]);
  __m256i bb1 = addSpanAvx2(zero, pbb[1], plus[0], minus[0]);
  __m256i b2 = zero, bb2 = zero, b3 = zero, bb3 = zero;
  if constexpr (N > 2) {
    b2 = addSpanAvx2(zero, pb[2], plus[0], minus[0]);
    bb2 = addSpanAvx2(zero, pbb[2], plus[0], minus[0]);
  }
  if constexpr (N > 3) {
    b3 = addSpanAvx2(zero, pb[3], plus[0], minus[0]);
    bb3 = addSpanAvx2(zero, pbb[3], plus[0], minus[0]);
  }
  for (int i = 1; i < spanTerms.count; ++i) {
    b0 = addSpanAvx2(b0, pb[0], plus[i], minus[i]);
    bb0 = addSpanAvx2(bb0, pbb[0], plus[i], minus[i]);
    b1 = addSpanAvx2(b1, pb[1], plus[i], minus[i]);
    bb1 = addSpanAvx2(bb1, pbb[1], plus[i], minus[i]);
    if constexpr (N > 2) {
      b2 = addSpanAvx2(b2, pb[2], plus[i], minus[i]);
      bb2 = addSpanAvx2(bb2, pbb[2], plus[i], minus[i]);
    }
    if constexpr (N > 3) {
      b3 = addSpanAvx2(b3, pb[3], plus[i], minus[i]);
      bb3 = addSpanAvx2(bb3, pbb[3], plus[i], minus[i]);
    }
  }
  sb[0] = b0, sbb[0] = bb0, sb[1] = b1, sbb[1] = bb1;
  if constexpr (N > 2) sb[2] = b2, sbb[2] = bb2;
  if constexpr (N > 3) sb[3] = b3, sbb[3] = bb3;
}

// NCC of the K (1..8) main-line windows at b, b − 1, ..., b − (K − 1) (window k = disparity d + k)
// over the shape given by its rows of A (0 off S, `rows` rows from the first), from their Σ_S B
// and Σ_S B² (lane j: window K − 1 − j; spanSumsAvx2 from the prefixes at b's column − (K − 1)).
template <int K>
__attribute__((target("avx2"), always_inline)) inline void spanScoresAvx2(
    const int16_t* b, ptrdiff_t stride, __m256i sb, __m256i sbb, const int16_t* am, int rows,
    const ShapeNccTerms& terms, float* scores) {
  // The dot products after the span sums: their 8 accumulators then go straight to the
  // reductions (before the span sums, GCC copied each accumulator at every row).
  const __m256i zero = _mm256_setzero_si256();
  __m256i ab0 = zero, ab1 = zero, ab2 = zero, ab3 = zero, ab4 = zero, ab5 = zero, ab6 = zero,
          ab7 = zero;
  for (int v = 0; v < rows; ++v) {
    const int16_t* bv = b + v * stride;
    const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(am + 16 * v));
    ab0 = addDotAvx2(ab0, a, bv);
    if constexpr (K > 1) ab1 = addDotAvx2(ab1, a, bv - 1);
    if constexpr (K > 2) ab2 = addDotAvx2(ab2, a, bv - 2);
    if constexpr (K > 3) ab3 = addDotAvx2(ab3, a, bv - 3);
    if constexpr (K > 4) ab4 = addDotAvx2(ab4, a, bv - 4);
    if constexpr (K > 5) ab5 = addDotAvx2(ab5, a, bv - 5);
    if constexpr (K > 6) ab6 = addDotAvx2(ab6, a, bv - 6);
    if constexpr (K > 7) ab7 = addDotAvx2(ab7, a, bv - 7);
  }
  settledAvx2(ab0);
  if constexpr (K > 1) settledAvx2(ab1);
  if constexpr (K > 2) settledAvx2(ab2);
  if constexpr (K > 3) settledAvx2(ab3);
  if constexpr (K > 4) settledAvx2(ab4);
  if constexpr (K > 5) settledAvx2(ab5);
  if constexpr (K > 6) settledAvx2(ab6);
  if constexpr (K > 7) settledAvx2(ab7);
  // Window order (lanes past K are not used).
  const __m256i order = _mm256_setr_epi32(K - 1, K - 2, K - 3, K - 4, K - 5, K - 6, K - 7, K - 8);
  sb = _mm256_permutevar8x32_epi32(sb, order);
  sbb = _mm256_permutevar8x32_epi32(sbb, order);
  nccAvx2(_mm256_castsi256_si128(sb), _mm256_castsi256_si128(sbb),
          laneSums4Avx2(ab0, ab1, ab2, ab3), terms, K < 4 ? K : 4, scores);
  if constexpr (K > 4) {
    nccAvx2(_mm256_extracti128_si256(sb, 1), _mm256_extracti128_si256(sbb, 1),
            laneSums4Avx2(ab4, ab5, ab6, ab7), terms, K - 4, scores + 4);
  }
}

__attribute__((target("avx2"), always_inline)) inline void spanScoresAvx2Dispatch(
    const int16_t* b, ptrdiff_t stride, __m256i sb, __m256i sbb, const int16_t* am, int rows,
    int count, const ShapeNccTerms& terms, float* scores) {
  switch (count) {
    case 1: spanScoresAvx2<1>(b, stride, sb, sbb, am, rows, terms, scores); break;
    case 2: spanScoresAvx2<2>(b, stride, sb, sbb, am, rows, terms, scores); break;
    case 3: spanScoresAvx2<3>(b, stride, sb, sbb, am, rows, terms, scores); break;
    case 4: spanScoresAvx2<4>(b, stride, sb, sbb, am, rows, terms, scores); break;
    case 5: spanScoresAvx2<5>(b, stride, sb, sbb, am, rows, terms, scores); break;
    case 6: spanScoresAvx2<6>(b, stride, sb, sbb, am, rows, terms, scores); break;
    case 7: spanScoresAvx2<7>(b, stride, sb, sbb, am, rows, terms, scores); break;
    default: spanScoresAvx2<8>(b, stride, sb, sbb, am, rows, terms, scores); break;
  }
}

// NCC of the `count` (1..8) main-line windows at b, b − 1, ... over the shape given by its span
// terms and its rows of A. `pb` / `pbb`: the prefix rows of B and B² at the column of b (same
// rows as b), the terms' offsets from there; they must be readable from −7 to 16 + 8.
__attribute__((target("avx2"))) inline void shapeScoresSpansAvx2Dispatch(
    const int16_t* b, ptrdiff_t stride, const int32_t* pb, const int32_t* pbb,
    const ShapeSpanTerms& spanTerms, const int16_t* am, int rows, int count,
    const ShapeNccTerms& terms, float* scores) {
  __m256i sb, sbb;
  spanSumsAvx2(spanTerms, pb - (count - 1), pbb - (count - 1), sb, sbb);
  spanScoresAvx2Dispatch(b, stride, sb, sbb, am, rows, count, terms, scores);
}

// Up to kSpanPassesMax passes in one: passes n = 0 .. passes − 1 of counts[n] (1..8) windows
// each, following each other from b, b − 1, ... (the scores one after the other); the span
// terms are read once for all (a pixel's interval wider than 8 takes several passes; the terms
// cost about half of a pass). Readable as above, from −(Σ counts − 1).
constexpr int kSpanPassesMax = 4;
__attribute__((target("avx2"))) inline void shapeScoresSpansPassesAvx2(
    const int16_t* b, ptrdiff_t stride, const int32_t* pb, const int32_t* pbb,
    const ShapeSpanTerms& spanTerms, const int16_t* am, int rows, const int* counts, int passes,
    const ShapeNccTerms& terms, float* scores) {
  const int32_t* pbs[kSpanPassesMax];
  const int32_t* pbbs[kSpanPassesMax];
  int first[kSpanPassesMax];  // each pass's first window
  for (int n = 0, k = 0; n < passes; k += counts[n], ++n) {
    first[n] = k;
    pbs[n] = pb - (k + counts[n] - 1);
    pbbs[n] = pbb - (k + counts[n] - 1);
  }
  __m256i sb[kSpanPassesMax], sbb[kSpanPassesMax];
  switch (passes) {
    case 1: spanSumsAvx2(spanTerms, pbs[0], pbbs[0], sb[0], sbb[0]); break;
    case 2: spanSumsManyAvx2<2>(spanTerms, pbs, pbbs, sb, sbb); break;
    case 3: spanSumsManyAvx2<3>(spanTerms, pbs, pbbs, sb, sbb); break;
    default: spanSumsManyAvx2<4>(spanTerms, pbs, pbbs, sb, sbb); break;
  }
  for (int n = 0; n < passes; ++n) {
    spanScoresAvx2Dispatch(b - first[n], stride, sb[n], sbb[n], am, rows, counts[n], terms,
                           scores + first[n]);
  }
}

// Dense rows of a shape from its row bits (bit u of row v = cell (u, v)): mask, A on S, and
// |S|, Σ_S A, Σ_S A².
__attribute__((target("avx2"))) inline void shapeRowsIntAvx2(const uint32_t* bits, int rows,
                                                             const int16_t* a, ptrdiff_t stride,
                                                             int16_t* mask, int16_t* am,
                                                             int32_t& count, int32_t& sumA,
                                                             int32_t& sumAA) {
  const __m256i select = _mm256_setr_epi16(
      0x0001, 0x0002, 0x0004, 0x0008, 0x0010, 0x0020, 0x0040, 0x0080, 0x0100, 0x0200, 0x0400,
      0x0800, 0x1000, 0x2000, 0x4000, static_cast<int16_t>(0x8000));
  __m256i accA = _mm256_setzero_si256(), accAA = _mm256_setzero_si256();
  __m256i accN = _mm256_setzero_si256();  // − cells of S per column
  for (int v = 0; v < rows; ++v) {
    const __m256i row = _mm256_set1_epi16(static_cast<int16_t>(bits[v] & 0xFFFFU));
    const __m256i m = _mm256_cmpeq_epi16(_mm256_and_si256(row, select), select);
    const __m256i x = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + v * stride));
    const __m256i xm = _mm256_and_si256(x, m);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(mask + 16 * v), m);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(am + 16 * v), xm);
    accN = _mm256_add_epi16(accN, m);
    accA = _mm256_add_epi16(accA, xm);
    accAA = _mm256_add_epi32(accAA, _mm256_madd_epi16(xm, xm));
  }
  settledAvx2(accN);
  settledAvx2(accA);
  settledAvx2(accAA);
  count = -laneSumAvx2(_mm256_madd_epi16(accN, _mm256_set1_epi16(1)));
  sumA = laneSumAvx2(_mm256_madd_epi16(accA, _mm256_set1_epi16(1)));
  sumAA = laneSumAvx2(accAA);
}

// Baseline x86-64 (SSE2): the same on two 128-bit halves.
inline int32_t laneSumSse2(__m128i s) {
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, 0x4E));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, 0xB1));
  return _mm_cvtsi128_si32(s);
}

template <int K>
inline void shapeSumsIntSse2(const int16_t* b, ptrdiff_t stride, const ptrdiff_t* offsets,
                             const int16_t* mask, const int16_t* am, int rows,
                             ShapeSumsInt* out) {
  __m128i accB0[K], accB1[K], accBB[K], accAB[K];
  for (int k = 0; k < K; ++k) accB0[k] = accB1[k] = accBB[k] = accAB[k] = _mm_setzero_si128();
  for (int v = 0; v < rows; ++v) {
    const int16_t* bv = b + v * stride;
    const auto* mp = reinterpret_cast<const __m128i*>(mask + 16 * v);
    const auto* ap = reinterpret_cast<const __m128i*>(am + 16 * v);
    const __m128i m0 = _mm_loadu_si128(mp), m1 = _mm_loadu_si128(mp + 1);
    const __m128i a0 = _mm_loadu_si128(ap), a1 = _mm_loadu_si128(ap + 1);
    for (int k = 0; k < K; ++k) {
      const auto* xp = reinterpret_cast<const __m128i*>(bv + offsets[k]);
      const __m128i x0 = _mm_loadu_si128(xp), x1 = _mm_loadu_si128(xp + 1);
      const __m128i xm0 = _mm_and_si128(x0, m0), xm1 = _mm_and_si128(x1, m1);
      accB0[k] = _mm_add_epi16(accB0[k], xm0);
      accB1[k] = _mm_add_epi16(accB1[k], xm1);
      accBB[k] = _mm_add_epi32(accBB[k], _mm_add_epi32(_mm_madd_epi16(xm0, x0),
                                                       _mm_madd_epi16(xm1, x1)));
      accAB[k] = _mm_add_epi32(accAB[k], _mm_add_epi32(_mm_madd_epi16(a0, x0),
                                                       _mm_madd_epi16(a1, x1)));
    }
  }
  const __m128i ones = _mm_set1_epi16(1);
  for (int k = 0; k < K; ++k) {
    out[k].b = laneSumSse2(
        _mm_add_epi32(_mm_madd_epi16(accB0[k], ones), _mm_madd_epi16(accB1[k], ones)));
    out[k].bb = laneSumSse2(accBB[k]);
    out[k].ab = laneSumSse2(accAB[k]);
  }
}

#endif  // DELINEO_STEREO_X86

// Portable version (also the reference of the vector ones).
template <int K>
inline void shapeSumsIntScalar(const int16_t* b, ptrdiff_t stride, const ptrdiff_t* offsets,
                               const int16_t* mask, const int16_t* am, int rows,
                               ShapeSumsInt* out) {
  for (int k = 0; k < K; ++k) {
    int32_t sb = 0, sbb = 0, sab = 0;
    for (int v = 0; v < rows; ++v) {
      const int16_t* bv = b + v * stride + offsets[k];
      for (int u = 0; u < 16; ++u) {
        const int32_t x = bv[u];
        const int32_t xm = mask[16 * v + u] != 0 ? x : 0;
        sb += xm;
        sbb += xm * x;
        sab += static_cast<int32_t>(am[16 * v + u]) * x;
      }
    }
    out[k] = {sb, sbb, sab};
  }
}

// `count` (1..4) windows of B at b + offsets[k] over the shape given by its rows.
inline void shapeSumsInt(const int16_t* b, ptrdiff_t stride, const ptrdiff_t* offsets,
                         const int16_t* mask, const int16_t* am, int rows, int count,
                         ShapeSumsInt* out) {
#ifdef DELINEO_STEREO_X86
  switch (count) {
    case 1: shapeSumsIntSse2<1>(b, stride, offsets, mask, am, rows, out); break;
    case 2: shapeSumsIntSse2<2>(b, stride, offsets, mask, am, rows, out); break;
    case 3: shapeSumsIntSse2<3>(b, stride, offsets, mask, am, rows, out); break;
    default: shapeSumsIntSse2<4>(b, stride, offsets, mask, am, rows, out); break;
  }
#else
  switch (count) {
    case 1: shapeSumsIntScalar<1>(b, stride, offsets, mask, am, rows, out); break;
    case 2: shapeSumsIntScalar<2>(b, stride, offsets, mask, am, rows, out); break;
    case 3: shapeSumsIntScalar<3>(b, stride, offsets, mask, am, rows, out); break;
    default: shapeSumsIntScalar<4>(b, stride, offsets, mask, am, rows, out); break;
  }
#endif
}

// Dense rows of a shape: mask (−1 on S), A on S, |S|, Σ_S A and Σ_S A².
inline void shapeRowsInt(const uint32_t* bits, int rows, const int16_t* a, ptrdiff_t stride,
                         int16_t* mask, int16_t* am, int32_t& count, int32_t& sumA,
                         int32_t& sumAA) {
#ifdef DELINEO_STEREO_X86
  if (cpuHasAvx2()) {
    shapeRowsIntAvx2(bits, rows, a, stride, mask, am, count, sumA, sumAA);
    return;
  }
#endif
  count = 0;
  sumA = 0;
  sumAA = 0;
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < 16; ++u) {
      const bool in = ((bits[v] >> u) & 1U) != 0;
      const int16_t x = in ? a[v * stride + u] : int16_t{0};
      mask[16 * v + u] = in ? int16_t{-1} : int16_t{0};
      count += in ? 1 : 0;
      am[16 * v + u] = x;
      sumA += x;
      sumAA += static_cast<int32_t>(x) * x;
    }
  }
}

// NCC of `count` (1..4) windows from their sums over a shape of n cells with Σ_S A = sumA:
// (n Σ A·B − Σ A Σ B) · invNormA / sqrt(n Σ B² − (Σ B)²), NaN where B is flat on S
// (n² var_S(B) < flatN). The integer parts are exact; the rest in float, 4 windows at a time.
inline void nccFromIntSums(const ShapeSumsInt* sums, int count, const ShapeNccTerms& terms,
                           float* scores) {
  const int64_t n = terms.n;
  const int64_t sumA = terms.sumA;
  const float invNormA = terms.invNormA, flatN = terms.flatN;
  alignas(16) float num[4] = {0, 0, 0, 0}, var[4] = {1, 1, 1, 1};
  for (int k = 0; k < count; ++k) {
    const int64_t b = sums[k].b;
    var[k] = static_cast<float>(n * static_cast<int64_t>(sums[k].bb) - b * b);
    num[k] = static_cast<float>(n * static_cast<int64_t>(sums[k].ab) - sumA * b);
  }
#ifdef DELINEO_STEREO_X86
  alignas(16) float out[4];
  const __m128 v = _mm_load_ps(var);
  const __m128 r = _mm_div_ps(_mm_mul_ps(_mm_load_ps(num), _mm_set1_ps(invNormA)), _mm_sqrt_ps(v));
  _mm_store_ps(out, r);
  for (int k = 0; k < count; ++k) {
    scores[k] = var[k] < flatN ? std::numeric_limits<float>::quiet_NaN() : out[k];
  }
#else
  for (int k = 0; k < count; ++k) {
    scores[k] = var[k] < flatN ? std::numeric_limits<float>::quiet_NaN()
                               : num[k] * invNormA / std::sqrt(var[k]);
  }
#endif
}

// NCC of `count` (1..kShapeMaxWindows) windows of B at b + offsets[k] over the shape given by
// its rows (NaN where B is flat on S).
inline void shapeScoresInt(const int16_t* b, ptrdiff_t stride, const ptrdiff_t* offsets,
                           const int16_t* mask, const int16_t* am, int rows, int count,
                           const ShapeNccTerms& terms, float* scores) {
#ifdef DELINEO_STEREO_X86
  if (cpuHasAvx512Vl()) {
    shapeScoresIntAvx512Dispatch(b, stride, offsets, mask, am, rows, count, terms, scores);
    return;
  }
  if (cpuHasAvx2()) {
    for (int k = 0; k < count; k += 3) {
      shapeScoresIntAvx2Dispatch(b, stride, offsets + k, mask, am, rows, count - k < 3 ? count - k : 3,
                                 terms, scores + k);
    }
    return;
  }
#endif
  for (int k = 0; k < count; k += 4) {
    const int part = count - k < 4 ? count - k : 4;
    ShapeSumsInt sums[4];
    shapeSumsInt(b, stride, offsets + k, mask, am, rows, part, sums);
    nccFromIntSums(sums, part, terms, scores + k);
  }
}

}  // namespace delineo::stereo::detail
