// Windows cut at the depth steps of the validated disparity map (see match_steps.hpp).
#include "match_steps.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <thread>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "cpu_features.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Grey levels² (images mapped to ~0..255): below this a half window is flat and not scored.
constexpr double kFlatVariance = 0.01;

// A cut window of the reference image, dense over its (2r+1)² bounding square with rows padded
// to a multiple of 8 columns: template values t = (a − mean) / sqrt(Σ (a − mean)²) on its
// pixels and 0 elsewhere (padding included), and a 0/1 mask, so that scoring it is a plain
// multiply-add over contiguous rows of whole vectors (vectorised by the compiler, no tails).
constexpr int kMaxStride = 32;  // ≥ the padded side of the largest window (31)

struct CutWindow {
  int x = 0, y = 0, r = 0, side = 0, stride = 0;
  std::vector<float> t, mask;
  float n = 0;
  bool usable = false;
};

// Mask and template of one row of a cut window, over Stride columns (a compile-time count, so
// the loops are whole vectors). Inputs are the image rows themselves or copies padded beyond
// the window's `n` columns; `inWindow` (0 beyond them) keeps whatever lies there out of the
// sums (grey values are finite: a masked column adds ±0, which leaves every sum unchanged).
template <int Stride>
struct CutRowSums {
  float a[Stride] = {}, aa[Stride] = {}, n[Stride] = {}, bad[Stride] = {};

  template <class Valid>
  void add(const float* __restrict grey, const Valid* __restrict valid, const float* __restrict sd,
           const float* __restrict val, const float* __restrict inWindow, float side, float centre,
           float* __restrict m) {
    for (int j = 0; j < Stride; ++j) {
      // NaN compares false: off the segments (sd NaN) the validated value decides.
      const bool onSegment = sd[j] == sd[j];
      const bool nearSide = std::abs(sd[j] - side) <= 1.0F;
      const bool nearValidated = std::abs(val[j] - side) <= 1.5F;
      const float mj = (onSegment & nearSide) | (!onSegment & nearValidated) ? inWindow[j] : 0.0F;
      const float c = grey[j] - centre;
      m[j] = mj;
      n[j] += mj;
      bad[j] += mj * (1.0F - static_cast<float>(valid[j]));
      a[j] += mj * c;
      aa[j] += mj * c * c;
    }
  }
};

// The window of (x, y) cut at the steps: the pixels whose side (sideD, of a step segment) is
// within 1 px of `side`, or, off the segments, whose validated value is within 1.5 px of it.
// Unusable when it leaves the image, touches nodata, has fewer than minPixels pixels or is flat.
template <int Stride>
DELINEO_TARGET_CLONES("avx2", "default") void buildCutWindowPadded(
    const cv::Mat& ref, const cv::Mat& refValid, const cv::Mat& sideD, const cv::Mat& validated,
    float side, int x, int y, int r, int minPixels, CutWindow& w) {
  const int n = w.side;
  // Where the padded rows lie inside the image the sums read them in place; else the rows are
  // copied into padded buffers. (Values relative to the centre pixel: small sums on flat
  // windows, where the variance test needs them exact.)
  const bool inPlace = x - r + Stride <= ref.cols;
  float grey[Stride], valid[Stride], sd[Stride], val[Stride], inWindow[Stride];
  for (int j = 0; j < Stride; ++j) {
    grey[j] = valid[j] = 0.0F;
    sd[j] = val[j] = kNaN;
    inWindow[j] = j < n ? 1.0F : 0.0F;
  }
  CutRowSums<Stride> sums;
  const float centre = ref.at<float>(y, x);
  for (int i = 0; i < n; ++i) {
    const int v = y - r + i;
    const float* a = ref.ptr<float>(v) + (x - r);
    const uchar* va = refValid.ptr<uchar>(v) + (x - r);
    const float* sdRow = sideD.ptr<float>(v) + (x - r);
    const float* valRow = validated.ptr<float>(v) + (x - r);
    float* m = w.mask.data() + static_cast<size_t>(i) * Stride;
    if (inPlace) {
      sums.add(a, va, sdRow, valRow, inWindow, side, centre, m);
      continue;
    }
    for (int j = 0; j < n; ++j) {
      grey[j] = a[j];
      valid[j] = va[j];
      sd[j] = sdRow[j];
      val[j] = valRow[j];
    }
    sums.add(grey, valid, sd, val, inWindow, side, centre, m);
  }
  float sa = 0, saa = 0, count = 0, bad = 0;
  for (int j = 0; j < Stride; ++j) {
    sa += sums.a[j];
    saa += sums.aa[j];
    count += sums.n[j];
    bad += sums.bad[j];
  }
  if (bad > 0 || count < static_cast<float>(minPixels)) return;
  const float var = saa - sa * sa / count;
  if (var < static_cast<float>(kFlatVariance) * count) return;
  const float mean = centre + sa / count, norm = 1.0F / std::sqrt(var);
  // 8-float vectors (GCC vector extension): the compiler left this fixed-size loop scalar.
  using Float8 = float __attribute__((vector_size(32)));
  const Float8 meanV = {mean, mean, mean, mean, mean, mean, mean, mean};
  const Float8 normV = {norm, norm, norm, norm, norm, norm, norm, norm};
  for (int i = 0; i < n; ++i) {
    const float* a = ref.ptr<float>(y - r + i) + (x - r);
    const size_t row = static_cast<size_t>(i) * Stride;
    const float* m = w.mask.data() + row;
    float* t = w.t.data() + row;
    if (inPlace) {
      // Whole rows: beyond the window the mask makes the template ±0 (no sum changes).
      for (int k = 0; k < Stride / 8; ++k) {
        Float8 av, mv;
        std::memcpy(&av, a + 8 * k, sizeof av);
        std::memcpy(&mv, m + 8 * k, sizeof mv);
        const Float8 tv = mv * ((av - meanV) * normV);
        std::memcpy(t + 8 * k, &tv, sizeof tv);
      }
      continue;
    }
    for (int j = 0; j < n; ++j) t[j] = m[j] * ((a[j] - mean) * norm);
    for (int j = n; j < Stride; ++j) t[j] = 0.0F;
  }
  w.n = count;
  w.usable = true;
}

void buildCutWindow(const cv::Mat& ref, const cv::Mat& refValid, const cv::Mat& sideD,
                    const cv::Mat& validated, float side, int x, int y, int r, int minPixels,
                    CutWindow& w) {
  w.usable = false;
  w.x = x;
  w.y = y;
  w.r = r;
  w.side = 2 * r + 1;
  w.stride = (w.side + 7) / 8 * 8;
  const size_t area = static_cast<size_t>(w.side) * static_cast<size_t>(w.stride);
  w.t.resize(area);  // every element written
  w.mask.resize(area);
  if (x - r < 0 || x + r >= ref.cols || y - r < 0 || y + r >= ref.rows) return;
  switch (w.stride) {
    case 8:
      return buildCutWindowPadded<8>(ref, refValid, sideD, validated, side, x, y, r, minPixels, w);
    case 16:
      return buildCutWindowPadded<16>(ref, refValid, sideD, validated, side, x, y, r, minPixels, w);
    case 24:
      return buildCutWindowPadded<24>(ref, refValid, sideD, validated, side, x, y, r, minPixels, w);
    default:
      return buildCutWindowPadded<kMaxStride>(ref, refValid, sideD, validated, side, x, y, r,
                                              minPixels, w);
  }
}

// Count of nodata pixels of `valid` in a rectangle, from its integral image (CV_32S).
int invalidIn(const cv::Mat& invalidSum, int x0, int y0, int x1, int y1) {
  return invalidSum.at<int>(y1 + 1, x1 + 1) - invalidSum.at<int>(y0, x1 + 1) -
         invalidSum.at<int>(y1 + 1, x0) + invalidSum.at<int>(y0, x0);
}

// Σ m·c, Σ m·c², Σ t·c over a window's rows, c = b − offset, with whole rows of Stride columns
// (compile-time: whole vectors); `rows` points at the other image under row 0, `step` floats
// apart.
template <int Stride>
DELINEO_TARGET_CLONES("avx2", "default") void cutWindowSumsPadded(const CutWindow& w,
                                                                           const float* rows,
                                                                           size_t step,
                                                                           float offset, float& sb,
                                                                           float& sbb, float& stb) {
  // 8-float vectors (GCC vector extension; two SSE registers in the baseline clone).
  using Float8 = float __attribute__((vector_size(32)));
  constexpr int kVectors = Stride / 8;
  Float8 colB[kVectors] = {}, colBB[kVectors] = {}, colTB[kVectors] = {};
  const Float8 off = {offset, offset, offset, offset, offset, offset, offset, offset};
  for (int i = 0; i < w.side; ++i) {
    const float* b = rows + static_cast<size_t>(i) * step;
    const float* m = w.mask.data() + static_cast<size_t>(i) * Stride;
    const float* t = w.t.data() + static_cast<size_t>(i) * Stride;
    for (int k = 0; k < kVectors; ++k) {
      Float8 bv, mv, tv;
      std::memcpy(&bv, b + 8 * k, sizeof bv);
      std::memcpy(&mv, m + 8 * k, sizeof mv);
      std::memcpy(&tv, t + 8 * k, sizeof tv);
      const Float8 c = bv - off;
      const Float8 mc = mv * c;
      colB[k] += mc;
      colBB[k] += mc * c;
      colTB[k] += tv * c;  // Σ t = 0: Σ t (b − mean_b) = Σ t b
    }
  }
  sb = sbb = stb = 0;
  for (int k = 0; k < kVectors; ++k) {
    for (int j = 0; j < 8; ++j) {
      sb += colB[k][j];
      sbb += colBB[k][j];
      stb += colTB[k][j];
    }
  }
}

// NCC of a cut window against other at (u − d, v + dy); NaN when it leaves the image, touches
// nodata, or the other window is flat. Values are taken relative to the other window's centre:
// the float sums then stay small on flat windows, where the variance test needs them exact.
float cutWindowNcc(const CutWindow& w, const cv::Mat& other, const cv::Mat& otherValid,
                   const cv::Mat& otherInvalidSum, int d, int dy) {
  if (!w.usable) return kNaN;
  const int r = w.r, side = w.side, stride = w.stride;
  const int x0 = w.x - r - d, y0 = w.y - r + dy;
  const float offset = other.at<float>(std::clamp(w.y + dy, 0, other.rows - 1),
                                       std::clamp(w.x - d, 0, other.cols - 1));
  float sb = 0, sbb = 0, stb = 0;
  // Fast path: the padded rows lie inside the image and the window holds no nodata.
  const bool inside = x0 >= 0 && x0 + stride <= other.cols && y0 >= 0 && y0 + side <= other.rows;
  if (inside && invalidIn(otherInvalidSum, x0, y0, x0 + side - 1, y0 + side - 1) == 0) {
    const float* rows = other.ptr<float>(y0) + x0;
    const size_t step = other.step1();
    switch (stride) {
      case 8:
        cutWindowSumsPadded<8>(w, rows, step, offset, sb, sbb, stb);
        break;
      case 16:
        cutWindowSumsPadded<16>(w, rows, step, offset, sb, sbb, stb);
        break;
      case 24:
        cutWindowSumsPadded<24>(w, rows, step, offset, sb, sbb, stb);
        break;
      default:
        cutWindowSumsPadded<kMaxStride>(w, rows, step, offset, sb, sbb, stb);
        break;
    }
  } else {
    // Edge of the image or nodata nearby: only the window's own pixels must be usable.
    for (int i = 0; i < side; ++i) {
      const size_t row = static_cast<size_t>(i) * static_cast<size_t>(stride);
      for (int j = 0; j < side; ++j) {
        if (w.mask[row + static_cast<size_t>(j)] == 0.0F) continue;
        const int u = x0 + j, v = y0 + i;
        if (u < 0 || u >= other.cols || v < 0 || v >= other.rows) return kNaN;
        if (!otherValid.at<uchar>(v, u)) return kNaN;
        const float c = other.at<float>(v, u) - offset;
        sb += c;
        sbb += c * c;
        stb += w.t[row + static_cast<size_t>(j)] * c;
      }
    }
  }
  const float varb = sbb - sb * sb / w.n;
  if (varb < static_cast<float>(kFlatVariance) * w.n) return kNaN;
  return stb / std::sqrt(varb);
}

// Photometric errors of ref columns xStart .. xStart + n − 1 (rows y − r .. y + r) against
// other at (x − d, y + dy), d real (linear interpolation along x), into errors[0 .. n − 1];
// false (errors partly written) when one leaves the image or touches nodata.
bool columnErrors(const cv::Mat& ref, const cv::Mat& other, const cv::Mat& refValid,
                  const cv::Mat& otherValid, int xStart, int n, int y, int r, float d, int dy,
                  float* errors) {
  const int W = ref.cols, H = ref.rows;
  if (y - r < 0 || y + r >= H || y + dy - r < 0 || y + dy + r >= H) return false;
  for (int k = 0; k < n; ++k) {
    const int x = xStart + k;
    const float xo = static_cast<float>(x) - d;
    const int x0 = static_cast<int>(std::floor(xo));
    const float t = xo - static_cast<float>(x0);
    if (x0 < 0 || x0 + 1 >= W) return false;
    float e = 0;
    for (int v = -r; v <= r; ++v) {
      const uchar* bValid = otherValid.ptr<uchar>(y + dy + v);
      if (!refValid.ptr<uchar>(y + v)[x] || !bValid[x0] || !bValid[x0 + 1]) return false;
      const float* b = other.ptr<float>(y + dy + v);
      const float diff = ref.ptr<float>(y + v)[x] - ((1 - t) * b[x0] + t * b[x0 + 1]);
      e += diff * diff;
    }
    if (!std::isfinite(e)) return false;
    errors[k] = e;
  }
  return true;
}

// std::lround(v) as an int without the libm call: halves away from zero (v − trunc(v) is exact
// in float); NaN and values beyond the int range still go through std::lround.
int roundHalfAway(float v) {
  if (!(std::abs(v) < 2147483648.0F)) return static_cast<int>(std::lround(v));
  const int i = static_cast<int>(v);
  const float f = v - static_cast<float>(i);
  return i + (f >= 0.5F ? 1 : 0) - (f <= -0.5F ? 1 : 0);
}

// Best disparity within ±2 px of `side` over a shape, with a parabola sub-pixel fit; NaN score
// when the peak is on the border of that search (a slope).
struct Hypothesis {
  float disparity = kNaN, score = kNaN;
};

Hypothesis bestNear(const CutWindow& w, const cv::Mat& other, const cv::Mat& otherValid,
                    const cv::Mat& otherInvalidSum, float side, int dy) {
  Hypothesis best;
  const int centre = roundHalfAway(side);
  // Centre ±1 first; ±2 only on the side where the maximum of those three lies on the border.
  float sc[5] = {kNaN, kNaN, kNaN, kNaN, kNaN};
  int bestK = -1;
  auto eval = [&](int k) {
    sc[k] = cutWindowNcc(w, other, otherValid, otherInvalidSum, centre - 2 + k, dy);
    if (std::isfinite(sc[k]) && (bestK < 0 || sc[k] > sc[bestK])) bestK = k;
  };
  for (int k = 1; k <= 3; ++k) eval(k);
  if (bestK == 1) eval(0);
  if (bestK == 3) eval(4);
  if (bestK <= 0 || bestK >= 4) return best;
  const float l = sc[bestK - 1], c = sc[bestK], rr = sc[bestK + 1];
  float offset = 0;
  const float curv = l - 2 * c + rr;
  if (std::isfinite(l) && std::isfinite(rr) && curv < 0) {
    offset = std::clamp(0.5F * (l - rr) / curv, -0.5F, 0.5F);
  }
  best.disparity = static_cast<float>(centre - 2 + bestK) + offset;
  best.score = c;
  return best;
}

// A step of a line (row or column) of the validated map between its consecutive validated
// pixels p < q: the segment [s0, s1] re-decided and the two sides' disparities da, db read at
// the first validated pixels beyond it (ua, ub). The validated step may sit up to half a window
// (h) off the true one (fattening): the segment spans h beyond both ends of the step, from
// `done` + 1 at least (the previous segment's end). False when the line has no step there, no
// side beyond the segment, or a validated value on neither side inside it (a third surface).
struct StepSegment {
  int s0 = 0, s1 = 0, ua = -1, ub = -1;
  float da = 0, db = 0;
};

bool stepSegment(const float* val, int length, int p, int q, int h, int done, float minStep,
                 StepSegment& seg) {
  if (std::abs(val[p] - val[q]) < minStep) return false;
  seg.s0 = std::max(p - h, done + 1);
  seg.s1 = std::min(q + h, length - 1);
  if (seg.s1 - seg.s0 < 1) return false;
  seg.ua = seg.ub = -1;
  for (int u = seg.s0 - 1; u >= std::max(0, seg.s0 - 2 * h); --u) {
    if (std::isfinite(val[u])) {
      seg.ua = u;
      break;
    }
  }
  for (int u = seg.s1 + 1; u <= std::min(length - 1, seg.s1 + 2 * h); ++u) {
    if (std::isfinite(val[u])) {
      seg.ub = u;
      break;
    }
  }
  if (seg.ua < 0 || seg.ub < 0) return false;
  seg.da = val[seg.ua];
  seg.db = val[seg.ub];
  if (std::abs(seg.da - seg.db) < minStep) return false;
  for (int u = seg.s0; u <= seg.s1; ++u) {
    if (std::isfinite(val[u]) && std::abs(val[u] - seg.da) > 1.0F &&
        std::abs(val[u] - seg.db) > 1.0F) {
      return false;
    }
  }
  return true;
}

// Boundary β of a segment starting at s0: positions ≤ β on side A, > β + strip on side B, at
// the least total photometric error (both hypotheses scored on the same pixels, so texture
// strength does not bias the choice as it does when two windows' NCCs are compared). The
// `strip` positions after β belong to neither side; every β scores the same n − strip ones.
int stepBoundary(const std::vector<float>& costA, const std::vector<float>& costB, int s0,
                 int strip) {
  const int n = static_cast<int>(costA.size());
  float total = 0;
  for (int k = strip; k < n; ++k) total += costB[static_cast<size_t>(k)];
  float bestTotal = total;
  int beta = s0 - 1;
  for (int k = 0; k + strip < n; ++k) {
    total += costA[static_cast<size_t>(k)] - costB[static_cast<size_t>(k + strip)];
    if (total < bestTotal) {
      bestTotal = total;
      beta = s0 + k;
    }
  }
  return beta;
}

// Steps along the columns are scored on each pixel's error summed over x ± 2 of its row (the
// pixel alone was too noisy to place a boundary across the rows; those pixels lie on the same
// side of an outline that runs with the rows).
constexpr int kColumnCostHalf = 2;

// The step cut of one map (refineDepthSteps, docs/stereo.md step 9) in its stages: the side of
// each pixel of a row's step segments and gaps (chooseRowSides), then of the columns' segments
// the rows did not decide (chooseColumnSides), then each pixel given a side matched again on
// its window cut at the steps (matchAgain).
struct StepCut {
  void chooseRowSides(int rowStart, int rowEnd);
  void markRowStepsNear(int y, const std::vector<int>& valid);
  bool decideRowSegment(int y, const StepSegment& seg, std::vector<float>& costA,
                        std::vector<float>& costB);
  void chooseGapSides(int y, const std::vector<int>& valid);
  void chooseColumnSides(int colStart, int colEnd);
  bool rowsDecided(int x, int p, int q) const;
  bool rowCost(int x, int y, float d, int dy, float& cost) const;
  bool decideColumnSegment(int x, const float* val, const StepSegment& seg,
                           std::vector<float>& costA, std::vector<float>& costB);
  void matchAgain(int rowStart, int rowEnd);

  const cv::Mat& ref;
  const cv::Mat& other;
  const cv::Mat& refValid;
  const cv::Mat& otherValid;
  const cv::Mat& validated;  // the map after the left/right check
  const StepRefineSettings& s;
  LevelOutput& raw;          // the map before it, matched again in place
  const cv::Mat& matchOnly;  // (optional) the pixels that may be matched again
  const int W = ref.cols, H = ref.rows;
  const int h = s.window / 2;  // half window: the fattening reaches this far past a step
  // Line shifts of the sides' source pixels: only matchAgain writes raw.lineShift, after the
  // sides have read them (no copy needed).
  const cv::Mat& shifts = raw.lineShift;
  // Side chosen for each pixel of a step segment: its surface's disparity and line shift (each
  // band of rows initialises its own rows).
  cv::Mat sideD = cv::Mat(ref.size(), CV_32F);
  cv::Mat sideDy = cv::Mat(ref.size(), CV_8S);
  cv::Mat inStrip = cv::Mat(ref.size(), CV_8U);  // occluded strips of the rows' segments
  // Pixels with a step of their row (consecutive validated pixels ≥ minStep apart) within half a
  // window on both sides: the column pass leaves the steps those pixels lie on to the rows.
  cv::Mat rowStepNear = cv::Mat(ref.size(), CV_8U);
  cv::Mat otherInvalidSum{};  // integral image of the other image's nodata pixels (matchAgain)
  std::atomic<long> changed{0};
};

// The rows' step segments and gaps, row by row: the row's sides cleared, its steps near each
// pixel marked (for the column pass), each segment's side chosen, then its gaps'.
void StepCut::chooseRowSides(int rowStart, int rowEnd) {
  std::vector<int> valid;
  std::vector<float> costA, costB;
  for (int y = rowStart; y < rowEnd; ++y) {
    std::fill_n(sideD.ptr<float>(y), W, kNaN);
    std::fill_n(sideDy.ptr<schar>(y), W, schar{0});
    std::fill_n(inStrip.ptr<uchar>(y), W, uchar{0});
    const float* val = validated.ptr<float>(y);
    valid.clear();
    for (int x = 0; x < W; ++x) {
      if (std::isfinite(val[x])) valid.push_back(x);
    }
    markRowStepsNear(y, valid);
    int done = -1;  // last column re-decided in this row
    for (size_t i = 0; i + 1 < valid.size(); ++i) {
      const int p = valid[i], q = valid[i + 1];
      // (Most pairs are no step: tested here, the call is made for the others only.)
      if (std::abs(val[p] - val[q]) < static_cast<float>(s.minStep)) continue;
      StepSegment seg;
      if (!stepSegment(val, W, p, q, h, done, static_cast<float>(s.minStep), seg)) continue;
      if (decideRowSegment(y, seg, costA, costB)) done = seg.s1;
    }
    if (s.gapFill > 0) chooseGapSides(y, valid);
  }
}

// rowStepNear on row y (its validated pixels `valid`): the pixels with a step of the row within
// half a window on both sides (none without columnSteps).
void StepCut::markRowStepsNear(int y, const std::vector<int>& valid) {
  const float* val = validated.ptr<float>(y);
  uchar* near = rowStepNear.ptr<uchar>(y);
  std::fill_n(near, W, uchar{0});
  for (size_t i = 0; s.columnSteps && i + 1 < valid.size(); ++i) {
    const int p = valid[i], q = valid[i + 1];
    if (q - p > 2 * h || std::abs(val[p] - val[q]) < static_cast<float>(s.minStep)) continue;
    // x − h ≤ p and q ≤ x + h.
    for (int x = std::max(0, q - h); x <= std::min(W - 1, p + h); ++x) near[x] = 1;
  }
}

// The sides of a row's step segment: the boundary β between them, the occluded strip after it
// left unmatched. False (nothing written) when a side's error cannot be scored.
bool StepCut::decideRowSegment(int y, const StepSegment& seg, std::vector<float>& costA,
                               std::vector<float>& costB) {
  const int s0 = seg.s0, s1 = seg.s1;
  const float da = seg.da, db = seg.db;
  const float* shift = shifts.ptr<float>(y);
  const int dyA = roundHalfAway(shift[seg.ua]);
  const int dyB = roundHalfAway(shift[seg.ub]);
  // Boundary β: columns ≤ β on the −x surface, > β on the +x one.
  const int n = s1 - s0 + 1;
  costA.resize(static_cast<size_t>(n));
  costB.resize(static_cast<size_t>(n));
  if (!columnErrors(ref, other, refValid, otherValid, s0, n, y, s.costRadius, da, dyA,
                    costA.data()) ||
      !columnErrors(ref, other, refValid, otherValid, s0, n, y, s.costRadius, db, dyB,
                    costB.data())) {
    return false;
  }
  // Occluded strip: when the +x surface is nearer, the `strip` columns before it are not
  // seen in the other view; the boundary then has the strip between the two sides.
  const int strip = s.occlusionStrip && db > da ? roundHalfAway(db - da) : 0;
  if (n - strip < 2) return false;
  const int beta = stepBoundary(costA, costB, s0, strip);
  float* rawRow = raw.disparity.ptr<float>(y);
  for (int x = s0; x <= s1; ++x) {
    if (x > beta && x <= beta + strip) {
      rawRow[x] = kNaN;             // occluded in the other view
      inStrip.at<uchar>(y, x) = 1;  // decided: the column pass leaves it
      continue;
    }
    const bool sideA = x <= beta;
    sideD.at<float>(y, x) = sideA ? da : db;
    sideDy.at<schar>(y, x) = static_cast<schar>(sideA ? dyA : dyB);
  }
  return true;
}

// Gaps of one surface on row y: unmatched pixels between two validated pixels of the same
// surface (no step), at most gapFill px apart, matched again around that surface.
void StepCut::chooseGapSides(int y, const std::vector<int>& valid) {
  const float* val = validated.ptr<float>(y);
  const float* shift = shifts.ptr<float>(y);
  float* sideRow = sideD.ptr<float>(y);
  schar* sideDyRow = sideDy.ptr<schar>(y);
  for (size_t i = 0; i + 1 < valid.size(); ++i) {
    const int p = valid[i], q = valid[i + 1];
    if (q - p < 2 || q - p > s.gapFill + 1) continue;
    if (std::abs(val[p] - val[q]) > s.gapTolerance) continue;
    const float surface = 0.5F * (val[p] + val[q]);
    const schar dySurface = static_cast<schar>(roundHalfAway(shift[p]));
    for (int x = p + 1; x < q; ++x) {
      if (std::isfinite(sideRow[x])) continue;  // part of a step segment
      sideRow[x] = surface;
      sideDyRow[x] = dySurface;
    }
  }
}

// Steps along the columns colStart .. colEnd − 1 (outlines that run with the rows: no row
// crosses them), after the rows' segments, which keep their sides. The same boundary search, on
// errors summed along the rows (kColumnCostHalf); no occluded strip (the views are displaced
// along the rows only).
void StepCut::chooseColumnSides(int colStart, int colEnd) {
  // The band's columns, each contiguous (one pass over the rows).
  const int bandWidth = colEnd - colStart;
  std::vector<float> columns(static_cast<size_t>(bandWidth) * H), costA, costB;
  for (int y = 0; y < H; ++y) {
    const float* row = validated.ptr<float>(y);
    for (int c = 0; c < bandWidth; ++c) {
      columns[static_cast<size_t>(c) * H + y] = row[colStart + c];
    }
  }
  std::vector<int> valid;
  for (int x = colStart; x < colEnd; ++x) {
    const float* val = &columns[static_cast<size_t>(x - colStart) * H];
    valid.clear();
    for (int y = 0; y < H; ++y) {
      if (std::isfinite(val[y])) valid.push_back(y);
    }
    int done = -1;
    for (size_t i = 0; i + 1 < valid.size(); ++i) {
      const int p = valid[i], q = valid[i + 1];
      if (std::abs(val[p] - val[q]) < static_cast<float>(s.minStep)) continue;
      StepSegment seg;
      if (!stepSegment(val, H, p, q, h, done, static_cast<float>(s.minStep), seg)) continue;
      if (rowsDecided(x, p, q)) continue;
      if (decideColumnSegment(x, val, seg, costA, costB)) done = seg.s1;
    }
  }
}

// Only outlines that run with the rows: where a row steps within half a window of the column's
// step p .. q, the outline crosses the rows and the rows decided it (a diagonal outline decided
// by both passes moved by 2-8 px).
bool StepCut::rowsDecided(int x, int p, int q) const {
  bool crossesRows = false;
  for (int y = p; y <= q && !crossesRows; ++y) crossesRows = rowStepNear.at<uchar>(y, x) != 0;
  return crossesRows;
}

// The error of pixel (x, y) under disparity d for the column pass: summed over x ± 2 of its row.
bool StepCut::rowCost(int x, int y, float d, int dy, float& cost) const {
  float rowErr[2 * kColumnCostHalf + 1];
  if (!columnErrors(ref, other, refValid, otherValid, x - kColumnCostHalf, 2 * kColumnCostHalf + 1,
                    y, 0, d, dy, rowErr)) {
    return false;
  }
  cost = 0;
  for (float e : rowErr) cost += e;
  return true;
}

// The sides of a column's step segment (column x, validated values `val`): its validated pixels
// the rows did not decide take the side of the boundary they lie on; unmatched pixels take none.
// False (nothing written) when an error cannot be scored.
bool StepCut::decideColumnSegment(int x, const float* val, const StepSegment& seg,
                                  std::vector<float>& costA, std::vector<float>& costB) {
  const int s0 = seg.s0, s1 = seg.s1;
  const float da = seg.da, db = seg.db;
  const int dyA = roundHalfAway(shifts.at<float>(seg.ua, x));
  const int dyB = roundHalfAway(shifts.at<float>(seg.ub, x));
  const int n = s1 - s0 + 1;
  costA.resize(static_cast<size_t>(n));
  costB.resize(static_cast<size_t>(n));
  bool scored = x - kColumnCostHalf >= 0 && x + kColumnCostHalf < W;
  for (int k = 0; k < n && scored; ++k) {
    scored = rowCost(x, s0 + k, da, dyA, costA[static_cast<size_t>(k)]) &&
             rowCost(x, s0 + k, db, dyB, costB[static_cast<size_t>(k)]);
  }
  if (!scored) return false;
  const int beta = stepBoundary(costA, costB, s0, 0);  // last row of the upper side
  for (int y = s0; y <= s1; ++y) {
    float& side = sideD.at<float>(y, x);
    if (!std::isnan(side) || inStrip.at<uchar>(y, x)) continue;  // a row's segment decided it
    if (!std::isfinite(val[y])) continue;
    const bool sideA = y <= beta;
    side = sideA ? da : db;
    sideDy.at<schar>(y, x) = static_cast<schar>(sideA ? dyA : dyB);
  }
  return true;
}

// Each pixel given a side is matched again on the window cut by the steps: the pixels of its
// own side (same side value), and the validated pixels off the segments on that surface.
void StepCut::matchAgain(int rowStart, int rowEnd) {
  CutWindow window;
  for (int y = rowStart; y < rowEnd; ++y) {
    float* outD = raw.disparity.ptr<float>(y);
    float* outS = raw.lineShift.ptr<float>(y);
    float* outScore = raw.score.ptr<float>(y);
    const float* sides = sideD.ptr<float>(y);
    const float* val = validated.ptr<float>(y);
    const schar* sideShift = sideDy.ptr<schar>(y);
    const uchar* wanted = matchOnly.empty() ? nullptr : matchOnly.ptr<uchar>(y);
    for (int x = 0; x < W; ++x) {
      const float side = sides[x];
      if (!std::isfinite(side) || (wanted != nullptr && !wanted[x])) continue;
      // A validated value already on this side stays: re-matching it costs the most (most
      // segment pixels) and changed little.
      const float kept = val[x];
      if (std::isfinite(kept) && std::abs(kept - side) <= 1.0F) continue;
      const int dy = sideShift[x];
      buildCutWindow(ref, refValid, sideD, validated, side, x, y, h, s.minShape, window);
      const Hypothesis hyp = bestNear(window, other, otherValid, otherInvalidSum, side, dy);
      const float before = outD[x];
      if (hyp.score >= static_cast<float>(s.minScore)) {
        outD[x] = hyp.disparity;
        outS[x] = static_cast<float>(dy);
        outScore[x] = hyp.score;
      } else {
        outD[x] = kNaN;
      }
      if (!(before == outD[x])) ++changed;
    }
  }
}

}  // namespace

long refineDepthSteps(const cv::Mat& ref, const cv::Mat& other, const cv::Mat& refValid,
                      const cv::Mat& otherValid, const cv::Mat& validated,
                      const StepRefineSettings& s, LevelOutput& raw, const cv::Mat& matchOnly) {
  StepCut cut{ref, other, refValid, otherValid, validated, s, raw, matchOnly};
  const int W = ref.cols, H = ref.rows;
  // Bands of 8 rows as tasks, with the integral image of the other image's nodata pixels (for
  // matchAgain) one more task among them.
  constexpr int kBandRows = 8;
  std::vector<std::function<void()>> tasks;
  tasks.emplace_back([&] { cv::integral(1 - otherValid, cut.otherInvalidSum, CV_32S); });
  for (int y0 = 0; y0 < H; y0 += kBandRows) {
    tasks.emplace_back([&, y0] { cut.chooseRowSides(y0, std::min(H, y0 + kBandRows)); });
  }
  runTasks(tasks, s.threads);
  if (s.columnSteps) {
    std::vector<std::function<void()>> columnTasks;
    for (int x0 = 0; x0 < W; x0 += 16) {
      columnTasks.emplace_back([&, x0] { cut.chooseColumnSides(x0, std::min(W, x0 + 16)); });
    }
    runTasks(columnTasks, s.threads);
  }
  forRowBands(
      H, s.threads, [&](int rowStart, int rowEnd) { cut.matchAgain(rowStart, rowEnd); },
      /*bandRows=*/8);
  return cut.changed.load();
}

}  // namespace delineo::stereo::detail
