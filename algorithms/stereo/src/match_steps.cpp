// Windows cut at the depth steps of the validated disparity map (see match_steps.hpp).
#include "match_steps.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/core/utility.hpp>

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Grey levels² (images mapped to ~0..255): below this a half window is flat and not scored.
constexpr double kFlatVariance = 0.01;

// A cut window of the reference image: its pixels and their normalised template values
// (a − mean) / sqrt(Σ (a − mean)²), built once per pixel and scored at every disparity.
struct CutWindow {
  std::vector<int> u, v;
  std::vector<float> t;
  bool usable = false;
};

template <class InShape>
void buildCutWindow(const cv::Mat& ref, const cv::Mat& refValid, int x, int y, int r,
                    int minPixels, const InShape& inShape, CutWindow& w) {
  w.u.clear();
  w.v.clear();
  w.t.clear();
  w.usable = false;
  if (x - r < 0 || x + r >= ref.cols || y - r < 0 || y + r >= ref.rows) return;
  double sa = 0, saa = 0;
  for (int v = y - r; v <= y + r; ++v) {
    const float* a = ref.ptr<float>(v);
    const uchar* va = refValid.ptr<uchar>(v);
    for (int u = x - r; u <= x + r; ++u) {
      if (!inShape(u, v)) continue;
      if (!va[u]) return;
      w.u.push_back(u);
      w.v.push_back(v);
      w.t.push_back(a[u]);
      sa += a[u];
      saa += static_cast<double>(a[u]) * a[u];
    }
  }
  const double n = static_cast<double>(w.t.size());
  if (static_cast<int>(w.t.size()) < minPixels) return;
  const double var = saa - sa * sa / n;
  if (var < kFlatVariance * n) return;
  const double mean = sa / n, norm = 1.0 / std::sqrt(var);
  for (float& t : w.t) t = static_cast<float>((t - mean) * norm);
  w.usable = true;
}

// NCC of a cut window against other at (u − d, v + dy); NaN when it leaves the image, touches
// nodata, or the other window is flat.
float cutWindowNcc(const CutWindow& w, const cv::Mat& other, const cv::Mat& otherValid, int d,
                   int dy) {
  if (!w.usable) return kNaN;
  double sb = 0, sbb = 0, stb = 0;
  for (size_t i = 0; i < w.t.size(); ++i) {
    const int u = w.u[i] - d, v = w.v[i] + dy;
    if (u < 0 || u >= other.cols || v < 0 || v >= other.rows) return kNaN;
    if (!otherValid.at<uchar>(v, u)) return kNaN;
    const double b = other.at<float>(v, u);
    sb += b;
    sbb += b * b;
    stb += w.t[i] * b;  // Σ t = 0: Σ t (b − mean_b) = Σ t b
  }
  const double n = static_cast<double>(w.t.size());
  const double varb = sbb - sb * sb / n;
  if (varb < kFlatVariance * n) return kNaN;
  return static_cast<float>(stb / std::sqrt(varb));
}

// Photometric error of ref column x (rows y - r .. y + r) against other at (x - d, y + dy), d
// real (linear interpolation along x); NaN when out of the image or on nodata.
float columnError(const cv::Mat& ref, const cv::Mat& other, const cv::Mat& refValid,
                  const cv::Mat& otherValid, int x, int y, int r, float d, int dy) {
  const int W = ref.cols, H = ref.rows;
  const float xo = static_cast<float>(x) - d;
  const int x0 = static_cast<int>(std::floor(xo));
  const float t = xo - static_cast<float>(x0);
  if (x0 < 0 || x0 + 1 >= W || y - r < 0 || y + r >= H || y + dy - r < 0 || y + dy + r >= H) {
    return kNaN;
  }
  float e = 0;
  for (int v = -r; v <= r; ++v) {
    if (!refValid.at<uchar>(y + v, x) || !otherValid.at<uchar>(y + dy + v, x0) ||
        !otherValid.at<uchar>(y + dy + v, x0 + 1)) {
      return kNaN;
    }
    const float* b = other.ptr<float>(y + dy + v);
    const float diff = ref.at<float>(y + v, x) - ((1 - t) * b[x0] + t * b[x0 + 1]);
    e += diff * diff;
  }
  return e;
}

// Best disparity within ±2 px of `side` over a shape, with a parabola sub-pixel fit; NaN score
// when the peak is on the border of that search (a slope).
struct Hypothesis {
  float disparity = kNaN, score = kNaN;
};

Hypothesis bestNear(const CutWindow& w, const cv::Mat& other, const cv::Mat& otherValid,
                    float side, int dy) {
  Hypothesis best;
  const int centre = static_cast<int>(std::lround(side));
  // Centre ±1 first; ±2 only on the side where the maximum of those three lies on the border.
  float sc[5] = {kNaN, kNaN, kNaN, kNaN, kNaN};
  int bestK = -1;
  auto eval = [&](int k) {
    sc[k] = cutWindowNcc(w, other, otherValid, centre - 2 + k, dy);
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

}  // namespace

long refineDepthSteps(const cv::Mat& ref, const cv::Mat& other, const cv::Mat& refValid,
                      const cv::Mat& otherValid, const cv::Mat& validated,
                      const StepRefineSettings& s, LevelOutput& raw) {
  const int W = ref.cols, H = ref.rows;
  const int h = s.window / 2;
  std::atomic<long> changed{0};
  const cv::Mat shifts = raw.lineShift.clone();  // line shifts of the sides' source pixels
  // Side chosen for each pixel of a step segment: its surface's disparity and line shift.
  cv::Mat sideD(ref.size(), CV_32F, cv::Scalar(kNaN));
  cv::Mat sideDy(ref.size(), CV_8S, cv::Scalar(0));
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
    std::vector<int> valid;
    std::vector<float> costA, costB;
    for (int y = rows.start; y < rows.end; ++y) {
      const float* val = validated.ptr<float>(y);
      const float* shift = shifts.ptr<float>(y);
      valid.clear();
      for (int x = 0; x < W; ++x) {
        if (std::isfinite(val[x])) valid.push_back(x);
      }
      int done = -1;  // last column re-decided in this row
      for (size_t i = 0; i + 1 < valid.size(); ++i) {
        const int p = valid[i], q = valid[i + 1];
        if (std::abs(val[p] - val[q]) < static_cast<float>(s.minStep)) continue;
        // The validated step may sit up to half a window off the true one (fattening): the
        // segment re-decided spans half a window beyond both ends of the step.
        const int s0 = std::max(p - h, done + 1), s1 = std::min(q + h, W - 1);
        if (s1 - s0 < 1) continue;
        int ua = -1, ub = -1;
        for (int u = s0 - 1; u >= std::max(0, s0 - 2 * h); --u) {
          if (std::isfinite(val[u])) {
            ua = u;
            break;
          }
        }
        for (int u = s1 + 1; u <= std::min(W - 1, s1 + 2 * h); ++u) {
          if (std::isfinite(val[u])) {
            ub = u;
            break;
          }
        }
        if (ua < 0 || ub < 0) continue;
        const float da = val[ua], db = val[ub];
        if (std::abs(da - db) < static_cast<float>(s.minStep)) continue;
        bool thirdSurface = false;
        for (int x = s0; x <= s1 && !thirdSurface; ++x) {
          thirdSurface = std::isfinite(val[x]) && std::abs(val[x] - da) > 1.0F &&
                         std::abs(val[x] - db) > 1.0F;
        }
        if (thirdSurface) continue;
        const int dyA = static_cast<int>(std::lround(shift[ua]));
        const int dyB = static_cast<int>(std::lround(shift[ub]));
        // Boundary β: columns ≤ β on the −x surface, > β on the +x one, at the least total
        // photometric error (both hypotheses scored on the same pixels, so texture strength
        // does not bias the choice as it does when two windows' NCCs are compared).
        const int n = s1 - s0 + 1;
        costA.assign(static_cast<size_t>(n), 0.0F);
        costB.assign(static_cast<size_t>(n), 0.0F);
        bool usable = true;
        for (int k = 0; k < n && usable; ++k) {
          costA[static_cast<size_t>(k)] =
              columnError(ref, other, refValid, otherValid, s0 + k, y, s.costRadius, da, dyA);
          costB[static_cast<size_t>(k)] =
              columnError(ref, other, refValid, otherValid, s0 + k, y, s.costRadius, db, dyB);
          usable = std::isfinite(costA[static_cast<size_t>(k)]) &&
                   std::isfinite(costB[static_cast<size_t>(k)]);
        }
        if (!usable) continue;
        float total = 0;
        for (float c : costB) total += c;
        float bestTotal = total;
        int beta = s0 - 1;
        for (int k = 0; k < n; ++k) {
          total += costA[static_cast<size_t>(k)] - costB[static_cast<size_t>(k)];
          if (total < bestTotal) {
            bestTotal = total;
            beta = s0 + k;
          }
        }
        for (int x = s0; x <= s1; ++x) {
          const bool sideA = x <= beta;
          sideD.at<float>(y, x) = sideA ? da : db;
          sideDy.at<schar>(y, x) = static_cast<schar>(sideA ? dyA : dyB);
        }
        done = s1;
      }
    }
  });
  // Each pixel given a side is matched again on the window cut by the steps: the pixels of its
  // own side (same side value), and the validated pixels off the segments on that surface.
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
    CutWindow window;
    for (int y = rows.start; y < rows.end; ++y) {
      float* outD = raw.disparity.ptr<float>(y);
      float* outS = raw.lineShift.ptr<float>(y);
      float* outScore = raw.score.ptr<float>(y);
      for (int x = 0; x < W; ++x) {
        const float side = sideD.at<float>(y, x);
        if (!std::isfinite(side)) continue;
        // A validated value already on this side stays: re-matching it costs the most (most
        // segment pixels) and changed little.
        const float kept = validated.at<float>(y, x);
        if (std::isfinite(kept) && std::abs(kept - side) <= 1.0F) continue;
        const int dy = sideDy.at<schar>(y, x);
        auto inShape = [&](int u, int v) {
          const float su = sideD.at<float>(v, u);
          if (std::isfinite(su)) return std::abs(su - side) <= 1.0F;
          const float vu = validated.at<float>(v, u);
          return std::isfinite(vu) && std::abs(vu - side) <= 1.5F;
        };
        buildCutWindow(ref, refValid, x, y, h, s.minShape, inShape, window);
        const Hypothesis hyp = bestNear(window, other, otherValid, side, dy);
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
  });
  return changed.load();
}

}  // namespace delineo::stereo::detail
