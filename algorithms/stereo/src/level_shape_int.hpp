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

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define DELINEO_STEREO_X86 1
#endif

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

inline bool cpuHasAvx2() {
#ifdef DELINEO_STEREO_X86
  static const bool has = __builtin_cpu_supports("avx2") != 0;
  return has;
#else
  return false;
#endif
}
inline bool cpuHasAvx512Vl() {
#ifdef DELINEO_STEREO_X86
  static const bool has = cpuHasAvx2() && __builtin_cpu_supports("avx512vl") != 0 &&
                          __builtin_cpu_supports("avx512bw") != 0;
  return has;
#else
  return false;
#endif
}

// Most windows one call of shapeScoresInt scores at full speed (the vector registers hold
// their accumulators); it accepts up to kShapeMaxWindows.
constexpr int kShapeMaxWindows = 8;
inline int shapeBatchWindows() {
  if (cpuHasAvx512Vl()) return 8;
  if (cpuHasAvx2()) return 3;
  return 4;
}

#ifdef DELINEO_STEREO_X86

__attribute__((target("avx2"), always_inline)) inline int32_t laneSumAvx2(__m256i v) {
  __m128i s = _mm_add_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, 0x4E));
  s = _mm_add_epi32(s, _mm_shuffle_epi32(s, 0xB1));
  return _mm_cvtsi128_si32(s);
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
