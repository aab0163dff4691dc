#include "match_snap.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <tuple>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "match_snap_cut_lines.hpp"
#include "radiometry.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
// Longest segment a checked cut scores: the near side's reach, the gap and the far pixel.
constexpr int kMaxCutSpan = 64;
// Fewest pixels a near side's slope is fitted on.
constexpr int kMinSlopePixels = 4;

// Pixels on each side of x | x + 1 whose mean grey the contrast compares: a roof's outline is a
// step between two grey levels, a roof's parapet line or a texture stroke 1–2 px wide is not
// (with single pixels, a dark line 10 px inside a roof outweighed the outline: 11.7 σ against
// 5.7 σ on 1000², row 841).
constexpr int kStepSide = 2;

// |mean I(x+1 .. x+kStepSide) − mean I(x−kStepSide+1 .. x)| on each row (fewer pixels at the
// image's ends); nodata as 0. `filled`: no NaN. Not averaged over rows: that smeared slanted
// outlines (the line through the rows' cuts gives the continuity across rows).
cv::Mat rowContrast(const cv::Mat& filled) {
  const int w = filled.cols, h = filled.rows;
  cv::Mat step(h, w - 1, CV_32F);
  // Both sides' sums as written out for the general case below, so that the values are the
  // same; without the image's ends the loop has no branches and is vectorised.
  static_assert(kStepSide == 2);
  const auto edge = [w](const float* row, int x) {
    float before = 0, after = 0;
    int nBefore = 0, nAfter = 0;
    for (int k = 0; k < kStepSide; ++k) {
      if (x - k >= 0) {
        before += row[x - k];
        ++nBefore;
      }
      if (x + 1 + k < w) {
        after += row[x + 1 + k];
        ++nAfter;
      }
    }
    return std::abs(after / static_cast<float>(nAfter) - before / static_cast<float>(nBefore));
  };
  for (int y = 0; y < h; ++y) {
    const float* row = filled.ptr<float>(y);
    float* s = step.ptr<float>(y);
    s[0] = edge(row, 0);
    for (int x = 1; x + 2 < w; ++x) {
      const float before = (0.0F + row[x]) + row[x - 1];
      const float after = (0.0F + row[x + 1]) + row[x + 2];
      s[x] = std::abs(after / 2.0F - before / 2.0F);
    }
    for (int x = std::max(1, w - 2); x + 1 < w; ++x) s[x] = edge(row, x);
  }
  return step;
}

// NaN as 0, in one pass.
cv::Mat withoutNaN(const cv::Mat& m) {
  cv::Mat filled(m.size(), CV_32F);
  for (int y = 0; y < m.rows; ++y) {
    const float* in = m.ptr<float>(y);
    float* out = filled.ptr<float>(y);
    for (int x = 0; x < m.cols; ++x) out[x] = in[x] == in[x] ? in[x] : 0.0F;
  }
  return filled;
}
}  // namespace

StepContrast stepContrast(const cv::Mat& left, const cv::Mat& right, double leftNoise) {
  CV_Assert(left.type() == CV_32F && (right.empty() || right.size() == left.size()));
  StepContrast out;
  if (left.cols < 3 || left.rows < 1) return out;
  const cv::Mat filled = withoutNaN(left);
  out.contrast = rowContrast(filled);
  out.sigma = leftNoise >= 0 ? leftNoise : noiseSigma(filled);
  if (!right.empty()) out.rightContrast = rowContrast(withoutNaN(right));
  return out;
}

int snapStepsToContours(const cv::Mat& left, const cv::Mat& right, const StepSnapSettings& settings,
                        float fillScore, cv::Mat& disparity, cv::Mat& score) {
  return snapStepsToContours(left, right, stepContrast(left, right), settings, fillScore, disparity,
                             score);
}

int snapStepsToContours(const cv::Mat& left, const cv::Mat& right, const StepContrast& prepared,
                        const StepSnapSettings& settings, float fillScore, cv::Mat& disparity,
                        cv::Mat& score) {
  CV_Assert(left.type() == CV_32F && disparity.type() == CV_32F && left.size() == disparity.size());
  CV_Assert(settings.cutReach >= 0 && settings.cutAhead >= 0 &&
            settings.cutReach + settings.maxGap + settings.cutAhead + 4 <= kMaxCutSpan);
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
  int dlo = 0;  // the smallest disparity of the map (checked only): carried runs search from it
  if (checked) {
    const auto [mn, mx] = matchedRange(disparity, settings.threads);
    dlo = static_cast<int>(std::floor(mn));
    const int dhi = static_cast<int>(std::ceil(mx));
    // The grey map of the matched pixel pairs, the images' moments as the fallback: every check
    // below compares errors a few noise sigmas apart, and the images' moments can be several grey
    // levels off at a roof's grey (simulated seed 14 1000²: gain 1.040 and offset 1.17 against
    // the matches' 1.086 and -6.44, the simulator's 1.087 and -6.5), which a plain roof's pixels
    // then carry at their own disparity.
    std::tie(gain, offset) = radiometricMapOfMatches(
        left, right, disparity, [&] { return radiometricMap(left, right, dlo, dhi); }, 1000,
        settings.threads);
  }
  // Mean of left − mapped right (its absolute value, or signed: a brightness offset) over the
  // pixel and its two vertical neighbours at disparity d, in noise sigmas; `none` where nothing
  // is read.
  const auto meanResidual = [&](int y, int x, float d, bool absolute, double none) {
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
      const double residual = a - (gain * b + offset);
      sum += absolute ? std::abs(residual) : residual;
      ++n;
    }
    return n > 0 ? sum / n / sigma : none;
  };
  const auto error = [&](int y, int x, float d) { return meanResidual(y, x, d, true, 1e30); };
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
  // Signed mean residual, in noise sigmas (0 where nothing is read).
  const auto signedResidual = [&](int y, int x, float d) {
    return meanResidual(y, x, d, false, 0.0);
  };
  // Brightness offset (noise sigmas) that tells two surfaces apart: above the sensor noise and
  // above the few grey levels by which two views of one surface differ (exposure, non-Lambertian
  // surfaces). The grey levels are the input's own (the snapping reads the original images): the
  // floor suits 8-bit data; for images scaled to [0, 1] it is never reached.
  const double offsetBound = std::max(settings.carriedOffset, settings.carriedOffsetGrey / sigma);
  // Two surfaces by brightness: the pixels past a contour are offset from their counterparts by
  // at least offsetBound on average while the run's pixels before it agree within half that
  // (sums of signed residuals and their counts).
  const auto offsetSplits = [offsetBound](double after, int nAfter, double before, int nBefore) {
    return nBefore > 0 && std::abs(after / nAfter) >= offsetBound &&
           std::abs(before / nBefore) <= offsetBound / 2;
  };
  const auto fitsFarBetter = [&](int y, int x, float dNear, float dFar) {
    return !checked || error(y, x, dFar) < error(y, x, dNear);
  };

  // Checked cut of a near side on the left (a roof's +x edge: both views see the ground there):
  // the near side's last pixel e over [s0 - 1, b] is the one of least total error, near pixels
  // scored at the near disparity (along its slope) up to e, far ones at the far disparity from
  // e + 2 (pixel e + 1 mixes both surfaces through the blur, and in the right view its roof part
  // is missing: it biased the cut towards the ground), minus contourWeight × the contrast between
  // e and e + 1. s0 goes back over the near side's pixels by up to cutReach (fattened roofs),
  // over holes of at most nearHoleGap unmatched pixels too (a roof's pixel matched alone before
  // its outline was kept by the cut and then removed as a speckle, the hole left open). Errors
  // are capped so that one outlier pixel does not decide. Pixels up to e take the near
  // disparity, the near pixels after it become unmatched; the far side is left alone.
  // The roof's edge is a contour in the right view too (roof against the wall that view sees),
  // at x − dNear: its contrast there, in the left view's grey levels and noise sigmas, capped so
  // that a strong texture line inside the roof does not outweigh the photometric evidence.
  const cv::Mat& rightContrast = prepared.rightContrast;
  const bool useRight = checked && settings.rightContourWeight > 0 && !rightContrast.empty();
  if (useRight) CV_Assert(rightContrast.size() == contrast.size());
  const auto rightContrastAt = [&](int y, int e, float dNear) -> double {
    if (!useRight) return 0.0;
    const int xr = static_cast<int>(std::lround(static_cast<float>(e) - dNear));
    if (xr < 0 || xr >= rightContrast.cols) return 0.0;
    return std::min(settings.rightContourCap, gain * rightContrast.at<float>(y, xr) / sigma);
  };
  // The slope along the row of the near side ending at a: the least-squares line through the
  // row's matched pixels of its last nearSlopePixels px above the mid-level `mid` (a matcher's
  // fronto-parallel windows give a sloped facet as steps, several runs), clamped to
  // ±maxNearSlope; 0 with fewer than kMinSlopePixels of them.
  const auto nearSlope = [&](int a, const float* d, double mid) {
    if (settings.nearSlopePixels <= 0) return 0.0;
    double su = 0, sv = 0, suu = 0, suv = 0;
    int count = 0;
    for (int x = std::max(0, a - settings.nearSlopePixels); x <= a; ++x) {
      if (!std::isfinite(d[x]) || d[x] <= mid) continue;
      const double u = x - a, v = d[x] - d[a];
      su += u;
      sv += v;
      suu += u * u;
      suv += u * v;
      ++count;
    }
    const double det = count * suu - su * su;
    if (count < kMinSlopePixels || det <= 0) return 0.0;
    return std::clamp((count * suv - su * sv) / det, -settings.maxNearSlope, settings.maxNearSlope);
  };
  const auto cutCosts = [&](int y, int a, int b, const float* d, const float* c) {
    NearSideCut cut;
    cut.y = y;
    cut.b = b;
    cut.dNear = d[a];
    cut.dFar = d[b];
    int s0 = a;
    const int reachStart = std::max(0, a - settings.cutReach);
    for (;;) {
      // The next near pixel back, over at most nearHoleGap unmatched ones.
      int x = s0 - 1;
      while (x >= reachStart && s0 - 1 - x < settings.nearHoleGap && !std::isfinite(d[x])) --x;
      if (x < reachStart || !std::isfinite(d[x]) || std::abs(d[x] - cut.dNear) > 1.0F) break;
      s0 = x;
    }
    // Far pixels are scored up to b + 2 whatever they hold: every cut then scores the same
    // number of pixels (n − 1), and the first far pixel may still turn out to be near.
    const int s1 = std::min(w - 1, b + 2 + settings.cutAhead);
    const int n = s1 - s0 + 1;
    cut.s0 = s0;
    cut.s1 = s1;
    // Prefix sums of the capped errors: near[k] over [s0, s0 + k), far likewise.
    double nearSum[kMaxCutSpan + 1], farSum[kMaxCutSpan + 1];
    nearSum[0] = farSum[0] = 0;
    // The near surface may slope along the row (a pitched roof's facet, sloping towards its
    // outline): its disparity follows the line fitted to its last pixels, through d[a]. (The hard
    // end below reads the level near disparity: along the slope, seed 3 600² lost 0.2 edge%.)
    cut.a = a;
    cut.slope = static_cast<float>(nearSlope(a, d, 0.5 * (cut.dNear + cut.dFar)));
    for (int k = 0; k < n; ++k) {
      nearSum[k + 1] =
          nearSum[k] + std::min(settings.errorCap, error(y, s0 + k, cut.nearAt(s0 + k)));
      farSum[k + 1] = farSum[k] + std::min(settings.errorCap, error(y, s0 + k, cut.dFar));
    }
    cut.eFirst = s0 - 1;
    cut.ownLast = std::min(b, s1 - 1);
    // The near side's value may explain the gap's pixels as well as the far side's does (a plain
    // roof beside plain ground of its grey): the photometric costs then tie, and a seam or a
    // texture line inside the roof took the cut (seed 3 600², rows 143-152: 4-9 px short). Where
    // the near disparity fails hard on two pixels that the far one explains (at the near
    // disparity the ground past a roof's +x edge falls on the wall only the right view shows),
    // after gap pixels it explains on average (within checkSigmas + carriedMargin, each capped at
    // errorCap: a thin seam errs by more), the near surface reaches that far: cuts before it
    // cost hardEndPenalty × errorCap more per pixel left out.
    int hardEnd = -1;
    if (settings.hardEndPenalty > 0) {
      const int last = std::min(b, s1 - 1);
      const auto failsHard = [&](int x) {
        return x + 1 <= last && error(y, x, cut.dNear) >= settings.errorCap &&
               error(y, x + 1, cut.dNear) >= settings.errorCap &&
               error(y, x, cut.dFar) <= settings.checkSigmas &&
               error(y, x + 1, cut.dFar) <= settings.checkSigmas;
      };
      double sum = 0;
      int counted = 0;
      for (int x = a + 1; x <= last; ++x) {
        // The near surface's last pixel: two before the failure (the one before it mixes both
        // surfaces through the blur and may fail on its own).
        int end = -1;
        if (failsHard(x)) {
          end = x - 2;
        } else if (error(y, x, cut.dNear) > settings.errorCap && failsHard(x + 1)) {
          end = x - 1;
        }
        if (end >= 0) {
          if (end > a && counted > 0 &&
              sum <= (settings.checkSigmas + settings.carriedMargin) * counted) {
            hardEnd = end;
          }
          break;
        }
        sum += std::min(settings.errorCap, error(y, x, cut.dNear));
        ++counted;
      }
    }
    const int eLast = std::min(b + settings.cutAhead, s1 - 1);
    cut.cost.clear();
    for (int e = cut.eFirst; e <= eLast; ++e) {
      const int nearEnd = e - s0 + 1;                 // near pixels: [0, nearEnd)
      const int farStart = std::min(n, nearEnd + 1);  // far pixels: [farStart, n)
      cut.cost.push_back(
          static_cast<float>(nearSum[nearEnd] + farSum[n] - farSum[farStart] -
                             settings.contourWeight * (e >= 0 ? c[e] / sigma : 0.0) -
                             settings.rightContourWeight * rightContrastAt(y, e, cut.dNear)));
      if (e < hardEnd) {
        cut.cost.back() +=
            static_cast<float>(settings.hardEndPenalty * settings.errorCap * (hardEnd - e));
      }
    }
    return cut;
  };
  // Pixels up to the chosen e take the near disparity, the near pixels after it become unmatched.
  const auto applyCut = [&](const NearSideCut& cut, float* out, float* sc) {
    const int e = cut.chosen;
    int changes = 0;
    for (int x = cut.s0; x <= std::max(std::min(cut.b, cut.s1 - 1), e); ++x) {
      const bool nearValued = std::isfinite(out[x]) && std::abs(out[x] - cut.dNear) <= 1.0F;
      if (x <= e && !nearValued) {
        out[x] = cut.nearAt(x);
        if (sc) sc[x] = fillScore;
        ++changes;
      } else if (x > e && nearValued) {
        out[x] = kNaN;
        if (sc) sc[x] = kNaN;
        ++changes;
      }
    }
    return changes;
  };

  // Runs carried across a contour (see match_snap.hpp). Only the strongest contour of the run's
  // end is tried: trying each one gave the same outlines (±0.5 point) at a cost (Aloe, 219 d:
  // 1.90 s against 1.71 s in all).
  const auto splitCarriedRuns = [&](int y, float* d, float* out, float* sc) {
    if (!checked || settings.carriedRuns <= 0) return 0;
    const float* c = contrast.ptr<float>(y);
    int changed = 0;
    const int m = settings.carriedRuns;
    int previousEnd = -1;  // last pixel of the run before (-1: none)
    // Leaves [first, last] unmatched; returns the pixels changed.
    const auto clearRun = [&](int first, int last) {
      for (int x = first; x <= last; ++x) {
        d[x] = kNaN;
        out[x] = kNaN;
        if (sc) sc[x] = kNaN;
      }
      return std::max(0, last - first + 1);
    };
    for (int x0 = 0; x0 < w;) {
      if (!std::isfinite(d[x0])) {
        ++x0;
        continue;
      }
      int x1 = x0;  // the run is [x0, x1]
      while (x1 + 1 < w && std::isfinite(d[x1 + 1]) && std::abs(d[x1 + 1] - d[x1]) <= 1.0F) ++x1;
      const int nearEnd = previousEnd;
      previousEnd = x1;
      // A short run of its own just past a nearer run's end, across a contour, offset in
      // brightness from its counterpart at its own disparity while the nearer run's last pixels
      // agree: the nearer surface's value carried onto ground the right view does not see (it
      // maps onto the wall only that view shows), split off at the outline (no pixels of its
      // own before the contour to compare with).
      if (settings.carriedOwnRuns > 0 && settings.carriedOffset > 0 && nearEnd >= 0 &&
          x0 - nearEnd - 1 <= settings.carriedOwnGap && x1 - x0 + 1 <= settings.carriedOwnRuns &&
          x1 - x0 + 1 >= settings.carriedOffsetPixels && d[nearEnd] > d[x0] &&
          strongestContour(c, std::max(0, nearEnd - 1), std::min(w - 2, x0)) >= 0) {
        const int n = x1 - x0 + 1;
        double after = 0, nearRun = 0;
        int nNear = 0;
        for (int x = x0; x <= x1; ++x) after += signedResidual(y, x, d[x]);
        for (int x = nearEnd - 1;
             x >= 0 && nNear < n && std::isfinite(d[x]) && std::abs(d[x] - d[nearEnd]) <= 1.0F;
             --x, ++nNear) {
          nearRun += signedResidual(y, x, d[x]);
        }
        if (offsetSplits(after, n, nearRun, nNear)) {
          changed += clearRun(x0, x1);
          previousEnd = nearEnd;
          x0 = x1 + 1;
          continue;
        }
      }
      // The stretch after a contour near the run's end is scored at the run's disparities and
      // at each integer disparity at least minStep farther: when one of those explains it
      // (within checkSigmas) better by carriedMargin sigmas, the run was carried across.
      const int e = strongestContour(c, std::max(x0 + m - 1, x1 - settings.maxGap), x1 - m - 1);
      if (e >= 0) {
        // Pixels e and e + 1 mix both surfaces through the blur: left out.
        const int n = x1 - e - 1;
        double atRun = 0;
        for (int x = e + 2; x <= x1; ++x) atRun += std::min(settings.errorCap, error(y, x, d[x]));
        const double bound = n * std::min(atRun / n - settings.carriedMargin, settings.checkSigmas);
        bool carried = false;
        for (int df = dlo; !carried && df <= static_cast<int>(std::floor(d[x1] - settings.minStep));
             ++df) {
          double sum = 0;
          for (int x = e + 2; x <= x1 && sum < bound; ++x) {
            sum += std::min(settings.errorCap, error(y, x, static_cast<float>(df)));
          }
          carried = sum < bound;
        }
        // Or the stretch's mean brightness differs from its counterpart's at the run's disparity
        // while the run's own pixels before the contour agree: two surfaces. A roof's value
        // carried onto ground that the right view does not see (hidden by the next building)
        // maps, at the roof's disparity, onto the wall only the right view shows; no disparity
        // explains that ground, and the wall's texture can correlate with it (NCC ignores the
        // offset), but its brightness does not. Texture and interpolation errors cancel in the
        // signed mean; an offset does not.
        if (!carried && settings.carriedOffset > 0 && n >= settings.carriedOffsetPixels) {
          double after = 0, before = 0;
          int nBefore = 0;
          for (int x = e + 2; x <= x1; ++x) after += signedResidual(y, x, d[x]);
          for (int x = std::max(x0, e - n); x < e; ++x, ++nBefore) {
            before += signedResidual(y, x, d[x]);
          }
          carried = offsetSplits(after, n, before, nBefore);
        }
        if (carried) changed += clearRun(e + 1, x1);
      }
      x0 = x1 + 1;
    }
    return changed;
  };

  // The checked cuts of each row, applied once every row's are known (continuity below).
  std::vector<std::vector<NearSideCut>> cutsByRow(static_cast<size_t>(h));
  // Rows are independent (each writes only its own): bands of rows on the workers.
  std::atomic<int> changedTotal{0};
  forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
    int changed = 0;
    std::vector<int> matched;
    // The row's disparities as they came in (its decisions read them while it writes its output;
    // a row reads and writes no other row's).
    std::vector<float> source(static_cast<size_t>(w));
    for (int y = rowStart; y < rowEnd; ++y) {
      float* d = source.data();
      std::copy_n(disparity.ptr<float>(y), w, d);
      const float* c = contrast.ptr<float>(y);
      float* out = disparity.ptr<float>(y);
      float* sc = score.empty() ? nullptr : score.ptr<float>(y);
      changed += splitCarriedRuns(y, d, out, sc);
      matched.clear();
      for (int x = 0; x < w; ++x) {
        if (std::isfinite(d[x])) matched.push_back(x);
      }
      for (size_t i = 0; i + 1 < matched.size(); ++i) {
        const int a = matched[i], b = matched[i + 1];
        if (b - a - 1 > settings.maxGap || std::abs(d[a] - d[b]) < settings.minStep) continue;
        if (checked && d[a] > d[b]) {
          cutsByRow[static_cast<size_t>(y)].push_back(cutCosts(y, a, b, d, c));
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
        // Up to openReach, a contour farther than that is taken when the brightness says the
        // run's surface ends there: at the run's disparity the two pixels past it (after the
        // mixed one) are offset from their counterpart by at least offsetBound, the pixels up to
        // it within half that on average, and no stronger contrast lies between the run's end
        // and it (a roof's texture inside its outline is a weaker step than the outline).
        const float* grey = left.ptr<float>(y);
        for (size_t i = 0; i < matched.size(); ++i) {
          const int a = matched[i];
          const int next = i + 1 < matched.size() ? matched[i + 1] : w;
          if (next - a - 1 <= settings.maxGap) continue;
          int best = strongestContour(c, a, std::min(w - 2, a + settings.reach));
          if (settings.openReach > 0 && settings.carriedOffset > 0) {
            double inside = 0;  // signed residuals of a + 1 .. e at the run's disparity
            float strongest = 0, bestContrast = 0;
            for (int e = a; e <= std::min({w - 4, a + settings.openReach, next - 4}); ++e) {
              if (e > a) inside += signedResidual(y, e, d[a]);
              const bool strongestSoFar = c[e] >= strongest;
              strongest = std::max(strongest, c[e]);
              if (!strongestSoFar || c[e] < minContrast || c[e] <= bestContrast) continue;
              if (e > a && std::abs(inside / (e - a)) > offsetBound / 2) continue;
              const double beyond =
                  (signedResidual(y, e + 2, d[a]) + signedResidual(y, e + 3, d[a])) / 2;
              if (std::abs(beyond) >= offsetBound) {
                bestContrast = c[e];
                best = std::max(best, e);
              }
            }
          }
          // The run grows over the gap's pixels its disparity explains better (by carriedMargin)
          // than the far side's after the gap (within errorCap: a thin seam's pixels err by a few
          // sigmas through interpolation): the run's surface goes on there (a plain roof strip
          // after a seam, next to plain dark ground). A contour within 2 px of the first pixel
          // that evidence fails on (it mixes both surfaces through the blur) is the surface's
          // edge when the pixels up to it match at the run's disparity on average.
          int grown = a;  // the pixels up to it were checked by the growth
          if (settings.openGrowth > 0 && next < w && d[next] <= d[a] - settings.minStep) {
            int g = a;
            while (g + 1 < std::min(next, a + 1 + settings.openGrowth)) {
              const double own = error(y, g + 1, d[a]);
              if (own > settings.errorCap ||
                  own + settings.carriedMargin > error(y, g + 1, d[next])) {
                break;
              }
              ++g;
            }
            const int e = g > a + 1 ? strongestContour(c, std::max(a, g - 2),
                                                       std::min({w - 3, g + 2, next - 2}))
                                    : -1;
            // The contrast of a step spreads over the pixels beside it: only its peak is the edge.
            if (e > best && c[e] >= c[e - 1] && c[e] >= c[e + 1]) {
              double own = 0;
              for (int x = a + 1; x <= e; ++x)
                own += std::min(settings.errorCap, error(y, x, d[a]));
              if (own <= settings.checkSigmas * (e - a)) {
                best = e;
                grown = std::min(g, e);
              }
            }
          }
          for (int x = a + 1; x <= best; ++x) {
            const bool looksNear = std::abs(grey[x] - grey[a]) < std::abs(grey[x] - grey[best + 1]);
            if (x > grown && !looksNear && error(y, x, d[a]) > settings.checkSigmas) break;
            out[x] = d[a];
            if (sc) sc[x] = fillScore;
            ++changed;
          }
        }
      }
    }
    changedTotal += changed;
  });
  if (checked) {
    chooseCuts(cutsByRow, settings);
    forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
      int changed = 0;
      for (int y = rowStart; y < rowEnd; ++y) {
        float* out = disparity.ptr<float>(y);
        float* sc = score.empty() ? nullptr : score.ptr<float>(y);
        for (const NearSideCut& cut : cutsByRow[static_cast<size_t>(y)]) {
          changed += applyCut(cut, out, sc);
        }
      }
      changedTotal += changed;
    });
  }
  return changedTotal;
}

}  // namespace delineo::stereo::detail
