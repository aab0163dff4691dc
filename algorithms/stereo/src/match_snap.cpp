#include "match_snap.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <tuple>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/nan_mask.hpp"
#include "radiometry.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
// Longest segment a checked cut scores: the near side's reach, the gap and the far pixel.
constexpr int kMaxCutSpan = 64;
}  // namespace

StepContrast stepContrast(const cv::Mat& left) {
  CV_Assert(left.type() == CV_32F);
  StepContrast out;
  const int w = left.cols, h = left.rows;
  if (w < 3 || h < 1) return out;
  cv::Mat filled = left.clone();
  filled.setTo(0.0f, core::nanMask(left));
  cv::Mat step(h, w - 1, CV_32F);
  for (int y = 0; y < h; ++y) {
    const float* row = filled.ptr<float>(y);
    float* s = step.ptr<float>(y);
    for (int x = 0; x + 1 < w; ++x) s[x] = std::abs(row[x + 1] - row[x]);
  }
  cv::blur(step, out.contrast, {1, 3}, {-1, -1}, cv::BORDER_REPLICATE);
  out.sigma = noiseSigma(filled);
  return out;
}

int snapStepsToContours(const cv::Mat& left, const cv::Mat& right, const StepSnapSettings& settings,
                        float fillScore, cv::Mat& disparity, cv::Mat& score) {
  return snapStepsToContours(left, right, stepContrast(left), settings, fillScore, disparity,
                             score);
}

int snapStepsToContours(const cv::Mat& left, const cv::Mat& right, const StepContrast& prepared,
                        const StepSnapSettings& settings, float fillScore, cv::Mat& disparity,
                        cv::Mat& score) {
  CV_Assert(left.type() == CV_32F && disparity.type() == CV_32F && left.size() == disparity.size());
  CV_Assert(settings.cutReach >= 0 && settings.cutReach + settings.maxGap + 4 <= kMaxCutSpan);
  const int w = left.cols, h = left.rows;
  if (w < 3 || h < 1) return 0;
  CV_Assert(prepared.contrast.size() == cv::Size(w - 1, h));
  const float kNaN = std::numeric_limits<float>::quiet_NaN();
  const cv::Mat& contrast = prepared.contrast;
  const double sigma = prepared.sigma;
  const float minContrast = static_cast<float>(settings.edgeSigmas * sigma);
  // Photometric check (when `right` is given): mean |left − mapped right| of the pixel and its
  // two vertical neighbours at disparity d, right view read with linear interpolation.
  const bool checked = !right.empty() && settings.checkSigmas > 0;
  double gain = 1, offset = 0;
  if (checked) {
    int dlo = 0, dhi = 0;
    double mn = 0, mx = 0;
    cv::minMaxIdx(disparity, &mn, &mx, nullptr, nullptr, disparity == disparity);
    dlo = static_cast<int>(std::floor(mn));
    dhi = static_cast<int>(std::ceil(mx));
    std::tie(gain, offset) = radiometricMap(left, right, dlo, dhi);
  }
  const auto error = [&](int y, int x, float d) {
    double sum = 0;
    int n = 0;
    for (int v = std::max(0, y - 1); v <= std::min(h - 1, y + 1); ++v) {
      const float xr = static_cast<float>(x) - d;
      const int x0 = static_cast<int>(std::floor(xr));
      if (x0 < 0 || x0 + 1 >= w) continue;
      const float t = xr - static_cast<float>(x0);
      const float* r = right.ptr<float>(v);
      const float a = left.at<float>(v, x);
      const float b = (1 - t) * r[x0] + t * r[x0 + 1];
      if (!std::isfinite(a) || !std::isfinite(b)) continue;
      sum += std::abs(a - (gain * b + offset));
      ++n;
    }
    return n > 0 ? sum / n / sigma : 1e30;
  };
  // Contour position e (between pixels e and e + 1) of the strongest contrast in [e0, e1] of a
  // row's contrast `c`, when it is at least minContrast; -1 otherwise.
  const auto strongestContour = [&](const float* c, int e0, int e1) {
    int best = -1;
    float bestContrast = minContrast;
    for (int e = e0; e <= e1; ++e) {
      if (c[e] >= bestContrast) {
        bestContrast = c[e];
        best = e;
      }
    }
    return best;
  };
  const auto fitsFarBetter = [&](int y, int x, float dNear, float dFar) {
    return !checked || error(y, x, dFar) < error(y, x, dNear);
  };

  // Checked cut of a near side on the left (a roof's +x edge: both views see the ground there):
  // the near side's last pixel e over [s0 - 1, b] is the one of least total error, near pixels
  // scored at the near disparity up to e, far ones at the far disparity from e + 2 (pixel e + 1
  // mixes both surfaces through the blur, and in the right view its roof part is missing: it
  // biased the cut towards the ground), minus contourWeight × the contrast between e and e + 1.
  // s0 goes back over the near side's pixels by up to cutReach (fattened roofs). Errors are
  // capped so that one outlier pixel does not decide. Pixels up to e take the near disparity,
  // the near pixels after it become unmatched; the far side is left alone.
  const auto cutNearSide = [&](int y, int a, int b, const float* d, const float* c, float* out,
                               float* sc) {
    const float dNear = d[a], dFar = d[b];
    int s0 = a;
    while (s0 - 1 >= std::max(0, a - settings.cutReach) && std::isfinite(d[s0 - 1]) &&
           std::abs(d[s0 - 1] - dNear) <= 1.0F) {
      --s0;
    }
    // Far pixels are scored up to b + 2 whatever they hold: every cut then scores the same
    // number of pixels (n − 1), and the first far pixel may still turn out to be near.
    const int s1 = std::min(w - 1, b + 2);
    const int n = s1 - s0 + 1;
    // Prefix sums of the capped errors: near[k] over [s0, s0 + k), far likewise.
    double nearSum[kMaxCutSpan + 1], farSum[kMaxCutSpan + 1];
    nearSum[0] = farSum[0] = 0;
    for (int k = 0; k < n; ++k) {
      nearSum[k + 1] = nearSum[k] + std::min(settings.errorCap, error(y, s0 + k, dNear));
      farSum[k + 1] = farSum[k] + std::min(settings.errorCap, error(y, s0 + k, dFar));
    }
    double bestCost = std::numeric_limits<double>::infinity();
    int cut = a;
    for (int e = s0 - 1; e <= std::min(b, s1 - 1); ++e) {
      const int nearEnd = e - s0 + 1;                 // near pixels: [0, nearEnd)
      const int farStart = std::min(n, nearEnd + 1);  // far pixels: [farStart, n)
      const double cost = nearSum[nearEnd] + farSum[n] - farSum[farStart] -
                          settings.contourWeight * (e >= 0 ? c[e] / sigma : 0.0);
      if (cost < bestCost) {
        bestCost = cost;
        cut = e;
      }
    }
    int changes = 0;
    for (int x = s0; x <= std::min(b, s1 - 1); ++x) {
      const bool nearValued = std::isfinite(out[x]) && std::abs(out[x] - dNear) <= 1.0F;
      if (x <= cut && !nearValued) {
        out[x] = dNear;
        if (sc) sc[x] = fillScore;
        ++changes;
      } else if (x > cut && nearValued) {
        out[x] = kNaN;
        if (sc) sc[x] = kNaN;
        ++changes;
      }
    }
    return changes;
  };

  const cv::Mat source = disparity.clone();
  // Rows are independent (each writes only its own): bands of rows on the workers.
  std::atomic<int> changedTotal{0};
  forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
    int changed = 0;
    std::vector<int> matched;
    for (int y = rowStart; y < rowEnd; ++y) {
      const float* d = source.ptr<float>(y);
      const float* c = contrast.ptr<float>(y);
      float* out = disparity.ptr<float>(y);
      float* sc = score.empty() ? nullptr : score.ptr<float>(y);
      matched.clear();
      for (int x = 0; x < w; ++x) {
        if (std::isfinite(d[x])) matched.push_back(x);
      }
      for (size_t i = 0; i + 1 < matched.size(); ++i) {
        const int a = matched[i], b = matched[i + 1];
        if (b - a - 1 > settings.maxGap || std::abs(d[a] - d[b]) < settings.minStep) continue;
        if (checked && d[a] > d[b]) {
          changed += cutNearSide(y, a, b, d, c, out, sc);
          continue;
        }
        const int best = strongestContour(c, std::max(0, a - settings.reach),
                                          std::min(w - 2, b - 1 + settings.reach));
        if (best < 0) continue;
        if (d[a] > d[b]) {
          // Near side on the left, unchecked: it ends at pixel `best`.
          for (int x = a + 1; x <= best && x < b; ++x) {
            out[x] = d[a];
            if (sc) sc[x] = fillScore;
            ++changed;
          }
          for (int x = best + 1; x <= a; ++x) {
            if (std::isfinite(out[x])) {
              out[x] = kNaN;
              if (sc) sc[x] = kNaN;
              ++changed;
            }
          }
        } else {
          // Near side on the right: it starts at pixel best + 1. The unmatched pixels before it
          // are mostly the ground this view sees and the other does not (left map: the -x side of
          // a nearer surface); they stay unmatched (filling them raised Cones bad-2 2.90 -> 3.33
          // %).
          for (int x = b; x <= best; ++x) {
            if (std::isfinite(out[x]) && fitsFarBetter(y, x, d[b], d[a])) {
              out[x] = kNaN;
              if (sc) sc[x] = kNaN;
              ++changed;
            }
          }
        }
      }
      if (checked) {
        // Open ends: a matched run followed by more than maxGap unmatched pixels (a roof next
        // to textureless ground or a shadow) is extended to the strongest contour within
        // `reach`. A pixel is taken when it matches at the run's disparity, or when its grey is
        // nearer the run's last pixel than the pixel beyond the contour: the last pixels of a
        // roof's +x edge mix roof and ground through the blur, and their neighbour in the right
        // view is another surface, so the photometric test alone stopped 1-2 px short.
        const float* grey = left.ptr<float>(y);
        for (size_t i = 0; i < matched.size(); ++i) {
          const int a = matched[i];
          const int next = i + 1 < matched.size() ? matched[i + 1] : w;
          if (next - a - 1 <= settings.maxGap) continue;
          const int best = strongestContour(c, a, std::min(w - 2, a + settings.reach));
          for (int x = a + 1; x <= best; ++x) {
            const bool looksNear = std::abs(grey[x] - grey[a]) < std::abs(grey[x] - grey[best + 1]);
            if (!looksNear && error(y, x, d[a]) > settings.checkSigmas) break;
            out[x] = d[a];
            if (sc) sc[x] = fillScore;
            ++changed;
          }
        }
      }
    }
    changedTotal += changed;
  });
  return changedTotal;
}

}  // namespace delineo::stereo::detail
