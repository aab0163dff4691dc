// The vector builds of the integer shape kernels (AVX-512VL, AVX2, SSE2) against the portable
// reference: the machine picks one at run time, so each available one is called directly here
// and must give the same sums and bit-identical NCC values on random shapes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "level_shape_int.hpp"

namespace {

using namespace delineo::stereo::detail;

constexpr int kStride = 64;
constexpr int kImageRows = 24;

bool sameFloat(float a, float b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::memcmp(&a, &b, sizeof a) == 0;
}

struct RandomShape {
  int rows = 0;
  std::vector<uint32_t> bits;
  std::vector<int16_t> mask, am;  // rows of 16: −1 on S / A on S
  ShapeNccTerms terms;
};

// Test-local reference of the dense shape rows (mask −1 on S, A on S, 0 elsewhere) and the NCC
// terms, for row bits `bits` over the image `a` (row v of the shape = image row v).
RandomShape shapeFromBits(const std::vector<uint32_t>& bits, const std::vector<int16_t>& a) {
  RandomShape s;
  s.rows = static_cast<int>(bits.size());
  s.bits = bits;
  s.mask.assign(16 * s.rows, 0);
  s.am.assign(16 * s.rows, 0);
  int64_t n = 0, sumA = 0, sumAA = 0;
  for (int v = 0; v < s.rows; ++v) {
    for (int u = 0; u < 16; ++u) {
      if (((s.bits[v] >> u) & 1U) == 0) continue;
      const int16_t x = a[v * kStride + u];
      s.mask[16 * v + u] = -1;
      s.am[16 * v + u] = x;
      ++n;
      sumA += x;
      sumAA += static_cast<int64_t>(x) * x;
    }
  }
  s.terms.n = static_cast<int>(n);
  s.terms.sumA = static_cast<int32_t>(sumA);
  const double varN = static_cast<double>(n * sumAA - sumA * sumA);
  s.terms.invNormA = varN > 0 ? static_cast<float>(1.0 / std::sqrt(varN)) : 0.0f;
  s.terms.flatN = static_cast<float>(4.0 * n * n);  // var_S(B) < 4 quantised units²: flat
  return s;
}

// A shape of 1..15 random rows of 15 random cells.
RandomShape makeShape(std::mt19937& rng, const std::vector<int16_t>& a) {
  std::vector<uint32_t> bits(std::uniform_int_distribution<int>(1, 15)(rng));
  for (auto& row : bits) row = std::uniform_int_distribution<uint32_t>(0, 0x7FFF)(rng);
  return shapeFromBits(bits, a);
}

std::vector<int16_t> randomImage(std::mt19937& rng, bool flatPatch) {
  std::vector<int16_t> img(kStride * kImageRows);
  std::uniform_int_distribution<int> grey(-kShapeQuantMax, kShapeQuantMax);
  for (auto& v : img) v = static_cast<int16_t>(grey(rng));
  if (flatPatch) {  // a constant block: windows over it are flat (NaN)
    for (int y = 0; y < kImageRows; ++y) {
      for (int x = 0; x < 20; ++x) img[y * kStride + x] = 77;
    }
  }
  return img;
}

TEST(ShapeKernels, VectorBuildsAgreeWithThePortableReference) {
  std::mt19937 rng(12345);
  int compared = 0, flat = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const std::vector<int16_t> a = randomImage(rng, false);
    const std::vector<int16_t> b = randomImage(rng, trial % 4 == 0);
    const RandomShape s = makeShape(rng, a);
    if (s.terms.invNormA == 0.0f) continue;
    const int count = std::uniform_int_distribution<int>(1, kShapeMaxWindows)(rng);
    ptrdiff_t offsets[kShapeMaxWindows];
    for (int k = 0; k < count; ++k) {
      offsets[k] = std::uniform_int_distribution<int>(0, kStride - 16)(rng);
    }
    // Reference: scalar sums and NCC, one window at a time.
    float expected[kShapeMaxWindows];
    ShapeSumsInt refSums[kShapeMaxWindows];
    for (int k = 0; k < count; ++k) {
      shapeSumsIntScalar<1>(b.data(), kStride, offsets + k, s.mask.data(), s.am.data(), s.rows,
                            refSums + k);
      nccFromIntSums(refSums + k, 1, s.terms, expected + k);
      flat += std::isnan(expected[k]) ? 1 : 0;
    }
    // Whatever the machine dispatches to.
    float got[kShapeMaxWindows];
    shapeScoresInt(b.data(), kStride, offsets, s.mask.data(), s.am.data(), s.rows, count, s.terms,
                   got);
    for (int k = 0; k < count; ++k) {
      ASSERT_TRUE(sameFloat(expected[k], got[k]))
          << "dispatched, trial " << trial << " window " << k;
    }
#ifdef DELINEO_STEREO_X86
    for (int k = 0; k < count; k += 4) {
      const int part = std::min(4, count - k);
      ShapeSumsInt sums[4];
      switch (part) {
        case 1:
          shapeSumsIntSse2<1>(b.data(), kStride, offsets + k, s.mask.data(), s.am.data(), s.rows,
                              sums);
          break;
        case 2:
          shapeSumsIntSse2<2>(b.data(), kStride, offsets + k, s.mask.data(), s.am.data(), s.rows,
                              sums);
          break;
        case 3:
          shapeSumsIntSse2<3>(b.data(), kStride, offsets + k, s.mask.data(), s.am.data(), s.rows,
                              sums);
          break;
        default:
          shapeSumsIntSse2<4>(b.data(), kStride, offsets + k, s.mask.data(), s.am.data(), s.rows,
                              sums);
          break;
      }
      for (int j = 0; j < part; ++j) {
        ASSERT_EQ(sums[j].b, refSums[k + j].b) << "SSE2, trial " << trial;
        ASSERT_EQ(sums[j].bb, refSums[k + j].bb) << "SSE2, trial " << trial;
        ASSERT_EQ(sums[j].ab, refSums[k + j].ab) << "SSE2, trial " << trial;
      }
    }
    if (cpuHasAvx2()) {
      std::fill(got, got + kShapeMaxWindows, 0.0f);
      shapeScoresIntAvx2Dispatch(b.data(), kStride, offsets, s.mask.data(), s.am.data(), s.rows,
                                 count, s.terms, got);
      for (int k = 0; k < count; ++k) {
        ASSERT_TRUE(sameFloat(expected[k], got[k])) << "AVX2, trial " << trial << " window " << k;
      }
      // One window, and the ±1 line pair around the first window (rows −1 and +1 of the image
      // start at b + kStride).
      float single = 0.0f;
      shapeScoreIntAvx2(b.data(), offsets[0], s.mask.data(), s.am.data(), kStride, s.rows, s.terms,
                        &single);
      ASSERT_TRUE(sameFloat(expected[0], single)) << "AVX2 single, trial " << trial;
      if (s.rows + 2 <= kImageRows) {
        const ptrdiff_t lines[2] = {offsets[0], offsets[0] + 2 * kStride};
        float pairExpected[2], pair[2];
        for (int k = 0; k < 2; ++k) {
          ShapeSumsInt sums;
          shapeSumsIntScalar<1>(b.data(), kStride, lines + k, s.mask.data(), s.am.data(), s.rows,
                                &sums);
          nccFromIntSums(&sums, 1, s.terms, pairExpected + k);
        }
        shapeScoresPairAvx2(b.data() + kStride + offsets[0], kStride, s.mask.data(), s.am.data(),
                            s.rows, s.terms, pair);
        ASSERT_TRUE(sameFloat(pairExpected[0], pair[0])) << "AVX2 pair −1, trial " << trial;
        ASSERT_TRUE(sameFloat(pairExpected[1], pair[1])) << "AVX2 pair +1, trial " << trial;
      }
      // Dense rows built from the fill bits.
      std::vector<int16_t> mask(16 * s.rows), am(16 * s.rows);
      int32_t n = 0, sumA = 0, sumAA = 0;
      shapeRowsIntAvx2(s.bits.data(), s.rows, a.data(), kStride, mask.data(), am.data(), n, sumA,
                       sumAA);
      ASSERT_EQ(mask, s.mask);
      ASSERT_EQ(am, s.am);
      ASSERT_EQ(n, s.terms.n);
      ASSERT_EQ(sumA, s.terms.sumA);
    }
    if (cpuHasAvx512Vl()) {
      std::fill(got, got + kShapeMaxWindows, 0.0f);
      shapeScoresIntAvx512Dispatch(b.data(), kStride, offsets, s.mask.data(), s.am.data(), s.rows,
                                   count, s.terms, got);
      for (int k = 0; k < count; ++k) {
        ASSERT_TRUE(sameFloat(expected[k], got[k]))
            << "AVX-512, trial " << trial << " window " << k;
      }
    }
#endif
    compared += count;
  }
  EXPECT_GT(compared, 1000);
  EXPECT_GT(flat, 10);  // the flat-window rule was exercised
}

// A shape row of 15 cells: one run with up to `maxGaps` random gaps (a contour crossing it), or
// empty.
uint32_t runWithGaps(std::mt19937& rng, int maxGaps) {
  std::uniform_int_distribution<int> cell(0, 14);
  int first = cell(rng), last = cell(rng);
  if (first > last) std::swap(first, last);
  uint32_t row = ((1U << (last + 1)) - 1U) & ~((1U << first) - 1U);
  const int gaps = std::uniform_int_distribution<int>(0, maxGaps)(rng);
  for (int g = 0; g < gaps; ++g) row &= ~(1U << cell(rng));
  return std::uniform_int_distribution<int>(0, 9)(rng) == 0 ? 0U : row;
}

TEST(ShapeKernels, SpansOfAShapeSumItsCellsAndTheSpanKernelMatchesTheReference) {
  std::mt19937 rng(777);
  int shapes = 0, fallbacks = 0, windows = 0;
  for (int trial = 0; trial < 600; ++trial) {
    uint16_t rows[16] = {};
    const int rowCount = std::uniform_int_distribution<int>(1, 15)(rng);
    const int firstRow = std::uniform_int_distribution<int>(0, 15 - rowCount)(rng);
    for (int v = firstRow; v < firstRow + rowCount; ++v) {
      rows[v] = static_cast<uint16_t>(runWithGaps(rng, trial % 3 == 0 ? 8 : 3));
    }
    if (trial % 10 == 0) rows[firstRow] = 0x5555;  // every other cell: 7 gaps, more than held
    // The portable spans: each row's cells are level 0 minus the gap levels.
    ShapeSpans spans;
    const bool fits = shapeSpansScalar(rows, spans);
    for (int v = 0; v < 16 && fits; ++v) {
      uint32_t covered = 0;
      for (int g = 0; g < spans.levels; ++g) {
        const uint32_t span = ((1U << spans.plus[g][v]) - 1U) ^ ((1U << spans.minus[g][v]) - 1U);
        covered = g == 0 ? span : covered & ~span;
      }
      ASSERT_EQ(covered, rows[v]) << "trial " << trial << " row " << v;
    }
    fallbacks += fits ? 0 : 1;
#ifdef DELINEO_STEREO_X86
    if (!cpuHasAvx2()) continue;
    ShapeSpans vectorSpans;
    ASSERT_EQ(shapeSpansAvx2(rows, vectorSpans), fits) << "trial " << trial;
    if (!fits) continue;
    ASSERT_EQ(vectorSpans.levels, spans.levels) << "trial " << trial;
    for (int g = 1; g < spans.levels; ++g) {
      // The rows the kernel visits on a gap level: exactly those with a non-empty term.
      uint32_t nonEmpty = 0;
      for (int v = 0; v < 16; ++v) {
        if (spans.plus[g][v] != spans.minus[g][v]) nonEmpty |= 1U << (2 * v);
      }
      ASSERT_EQ(spans.gapRows[g], nonEmpty) << "trial " << trial << " level " << g;
      ASSERT_EQ(vectorSpans.gapRows[g], nonEmpty) << "trial " << trial << " level " << g;
    }
    for (int g = 0; g < spans.levels; ++g) {
      for (int v = 0; v < 16; ++v) {
        ASSERT_EQ(vectorSpans.plus[g][v] - vectorSpans.minus[g][v],
                  spans.plus[g][v] - spans.minus[g][v]);
        if (spans.plus[g][v] != spans.minus[g][v]) {
          ASSERT_EQ(vectorSpans.plus[g][v], spans.plus[g][v]);
        }
      }
    }
    // The span kernel against the reference sums, on the shape's rows of a random image, for
    // 1..8 main-line windows (window k one column left of window k − 1).
    const std::vector<int16_t> a = randomImage(rng, false);
    const std::vector<int16_t> b = randomImage(rng, trial % 5 == 0);
    const RandomShape shape =
        shapeFromBits(std::vector<uint32_t>(rows + firstRow, rows + firstRow + rowCount), a);
    if (shape.terms.n < 2 || shape.terms.invNormA == 0.0f) continue;
    std::vector<int32_t> prefixB(kImageRows * (kStride + 1 + kPrefixPad));
    std::vector<int32_t> prefixBB(prefixB.size());
    const int prefixStride = kStride + 1 + kPrefixPad;
    for (int y = 0; y < kImageRows; ++y) {
      rowPrefixSums(&b[y * kStride], kStride, &prefixB[y * prefixStride],
                    &prefixBB[y * prefixStride]);
    }
    const int count = std::uniform_int_distribution<int>(1, kShapeMaxWindows)(rng);
    // More passes after the first (the several-pass kernel).
    const int passes = std::uniform_int_distribution<int>(1, kSpanPassesMax)(rng);
    int counts[kSpanPassesMax] = {count};
    int total = count;
    for (int n = 1; n < passes; ++n) {
      counts[n] = std::uniform_int_distribution<int>(1, kShapeMaxWindows)(rng);
      total += counts[n];
    }
    const int x0 = std::uniform_int_distribution<int>(total - 1, kStride - 16)(rng);
    float expected[kSpanPassesMax * kShapeMaxWindows], got[kSpanPassesMax * kShapeMaxWindows];
    for (int k = 0; k < total; ++k) {
      const ptrdiff_t offset = x0 - k;
      ShapeSumsInt sums;
      shapeSumsIntScalar<1>(b.data(), kStride, &offset, shape.mask.data(), shape.am.data(),
                            rowCount, &sums);
      nccFromIntSums(&sums, 1, shape.terms, expected + k);
    }
    int32_t rowOffsets[16];
    for (int v = 0; v < 16; ++v) rowOffsets[v] = v * prefixStride;
    ShapeSpanTerms spanTerms;
    shapeSpanTermsAvx2(vectorSpans, firstRow, rowCount, rowOffsets, spanTerms);
    shapeScoresSpansAvx2Dispatch(b.data() + x0, kStride, prefixB.data() + x0, prefixBB.data() + x0,
                                 spanTerms, shape.am.data(), rowCount, count, shape.terms, got);
    for (int k = 0; k < count; ++k) {
      ASSERT_TRUE(sameFloat(expected[k], got[k])) << "trial " << trial << " window " << k;
    }
    windows += count;
    shapeScoresSpansPassesAvx2(b.data() + x0, kStride, prefixB.data() + x0, prefixBB.data() + x0,
                               spanTerms, shape.am.data(), rowCount, counts, passes, shape.terms,
                               got);
    for (int k = 0; k < total; ++k) {
      ASSERT_TRUE(sameFloat(expected[k], got[k]))
          << "trial " << trial << " " << passes << " passes, window " << k;
    }
#endif
    ++shapes;
  }
  EXPECT_GT(shapes, 300);
  EXPECT_GE(fallbacks, 60);  // rows with more gaps than the levels hold were met
#ifdef DELINEO_STEREO_X86
  if (cpuHasAvx2()) {
    EXPECT_GT(windows, 1000);
  }
#endif
}

// The AVX2 flood fill of a window of ≤ 15 columns against a breadth-first fill: the
// 4-connected component of the centre in the free cells plus the centre, on random boards of
// every window size (densities from mostly blocked to mostly free; the rows past the window
// hold random cells, as the column-major copy of the matcher gives them: the fill ignores them).
TEST(ShapeKernels, Avx2FillMatchesABreadthFirstFill) {
#ifdef DELINEO_STEREO_X86
  if (!cpuHasAvx2()) GTEST_SKIP() << "no AVX2";
  std::mt19937 rng(1234);
  for (int r = 1; r <= 7; ++r) {
    const int w = 2 * r + 1;
    alignas(32) uint64_t inWindow[4] = {0, 0, 0, 0};
    for (int v = 0; v < w; ++v) inWindow[v >> 2] |= uint64_t{0xFFFF} << (16 * (v & 3));
    const auto columns = static_cast<uint16_t>((1U << w) - 1U);
    for (int trial = 0; trial < 3000; ++trial) {
      const unsigned density = 2 + trial % 13;  // a cell is blocked with probability 1/density
      alignas(32) uint16_t rows[16];
      for (int v = 0; v < 16; ++v) {
        uint16_t word = 0;
        for (int u = 0; u < 15; ++u) {
          if (rng() % density != 0) word = static_cast<uint16_t>(word | (1U << u));
        }
        rows[v] = v < w ? static_cast<uint16_t>(word & columns) : word;
      }
      // Reference: breadth-first from the centre over free window cells.
      uint16_t expect[16] = {};
      expect[r] = static_cast<uint16_t>(1U << r);
      std::vector<std::pair<int, int>> queue{{r, r}};
      for (size_t k = 0; k < queue.size(); ++k) {
        const auto [u, v] = queue[k];
        const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
        for (int n = 0; n < 4; ++n) {
          const int uu = u + du[n], vv = v + dv[n];
          if (uu < 0 || uu >= w || vv < 0 || vv >= w) continue;
          if ((rows[vv] >> uu & 1U) == 0 || (expect[vv] >> uu & 1U) != 0) continue;
          expect[vv] = static_cast<uint16_t>(expect[vv] | (1U << uu));
          queue.emplace_back(uu, vv);
        }
      }
      bool expectCut = false;
      for (int v = 0; v < w; ++v) expectCut |= (rows[v] & ~expect[v] & columns) != 0;
      alignas(32) uint16_t reach[16];
      const bool cut = fillWindow15Avx2(rows, inWindow, r, reach);
      ASSERT_EQ(cut, expectCut) << "r " << r << " trial " << trial;
      for (int v = 0; v < 16; ++v) {
        ASSERT_EQ(reach[v], expect[v]) << "r " << r << " trial " << trial << " row " << v;
      }
    }
  }
#else
  GTEST_SKIP() << "x86 only";
#endif
}

}  // namespace
