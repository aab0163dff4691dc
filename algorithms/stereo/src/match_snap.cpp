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

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// One row as the snapping works on it (see snapStepsToContours).
struct SnapRow {
  explicit SnapRow(int w) : source(static_cast<size_t>(w)) {}

  // Row `rowIndex` of `disparity` and `score` (empty: none), with its contrast.
  void start(int rowIndex, const cv::Mat& contrast, cv::Mat& disparity, cv::Mat& score) {
    y = rowIndex;
    d = source.data();
    std::copy_n(disparity.ptr<float>(y), source.size(), d);
    c = contrast.ptr<float>(y);
    out = disparity.ptr<float>(y);
    sc = score.empty() ? nullptr : score.ptr<float>(y);
  }
  // The matched pixels of `d`, in order.
  void findMatched() {
    matched.clear();
    for (int x = 0; x < static_cast<int>(source.size()); ++x) {
      if (std::isfinite(d[x])) matched.push_back(x);
    }
  }
  // Leaves [first, last] unmatched (in `d` too); returns the pixels changed.
  int clear(int first, int last) {
    for (int x = first; x <= last; ++x) {
      d[x] = kNaN;
      out[x] = kNaN;
      if (sc) sc[x] = kNaN;
    }
    return std::max(0, last - first + 1);
  }

  int y = 0;
  // The row's disparities as they came in (its decisions read them while it writes `out`; a row
  // reads and writes no other row's): a copy of the map's row, in `source`.
  float* d = nullptr;
  const float* c = nullptr;  // the left image's contrast between x and x + 1
  float* out = nullptr;      // the map's row
  float* sc = nullptr;       // the score's row (nullptr: no score map)
  std::vector<int> matched;  // the matched pixels of `d` (findMatched)
  std::vector<float> source;
};

// The snapping along the rows (see snapStepsToContours): what every row reads (the images, their
// contrast and noise sigma, the grey map of the matches) and the stages done on one row. A stage
// writes only the row it is given.
class AlongRowsSnapping {
 public:
  AlongRowsSnapping(const cv::Mat& left, const cv::Mat& right, const StepContrast& prepared,
                    const StepSnapSettings& settings, float fillScore, const cv::Mat& disparity);

  // Whether the right view checks the changes (cuts, open ends and carried runs need it).
  bool checked() const { return checked_; }
  // The stages, in order; each returns the pixels it changed.
  // Runs carried across a contour split there (their gaps are then snapped like the others).
  int splitCarriedRuns(SnapRow& row) const;
  // The steps: a checked near side on the left gives its cut's costs, the others are snapped.
  int snapSteps(const SnapRow& row, std::vector<NearSideCut>& cuts) const;
  // Open ends extended to their contour.
  int extendOpenEnds(const SnapRow& row) const;
  // A checked cut, once chosen (chooseCuts), applied to its row of the map and score.
  int applyCut(const NearSideCut& cut, float* out, float* sc) const;

 private:
  bool ownRunCarried(const SnapRow& row, int nearEnd, int x0, int x1) const;
  bool carriedPast(const SnapRow& row, int x0, int x1, int e) const;
  NearSideCut cutCosts(const SnapRow& row, int a, int b) const;
  int nearSideStart(const float* d, int a, float dNear) const;
  int hardEnd(int y, int a, int last, float dNear, float dFar) const;
  int cutUncheckedNearSideOnLeft(const SnapRow& row, int a, int b, int best) const;
  int cutNearSideOnRight(const SnapRow& row, int a, int b, int best) const;
  int extendOpenEnd(const SnapRow& row, int a, int next) const;
  int offsetContour(const SnapRow& row, int a, int next) const;
  int growOpenEnd(const SnapRow& row, int a, int next, int best, int& grown) const;

  double meanResidual(int y, int x, float d, bool absolute, double none) const;
  double error(int y, int x, float d) const { return meanResidual(y, x, d, true, 1e30); }
  // Signed mean residual, in noise sigmas (0 where nothing is read).
  double signedResidual(int y, int x, float d) const { return meanResidual(y, x, d, false, 0.0); }
  int strongestContour(const float* c, int e0, int e1) const;
  bool offsetSplits(double after, int nAfter, double before, int nBefore) const;
  bool fitsFarBetter(int y, int x, float dNear, float dFar) const {
    return !checked_ || error(y, x, dFar) < error(y, x, dNear);
  }
  double rightContrastAt(int y, int e, float dNear) const;
  double nearSlope(int a, const float* d, double mid) const;

  const cv::Mat& left_;
  const cv::Mat& right_;
  const StepSnapSettings& settings_;
  const float fillScore_;
  const int w_, h_;
  const cv::Mat& contrast_;
  const cv::Mat& rightContrast_;
  const double sigma_;
  const float minContrast_;
  // Photometric check (when `right` is given): mean |left − mapped right| of the pixel and its
  // two vertical neighbours at disparity d, right view read with linear interpolation.
  const bool checked_;
  double gain_ = 1, offset_ = 0;
  int dlo_ = 0;  // the smallest disparity of the map (checked only): carried runs search from it
  // Brightness offset (noise sigmas) that tells two surfaces apart: above the sensor noise and
  // above the few grey levels by which two views of one surface differ (exposure, non-Lambertian
  // surfaces). The grey levels are the input's own (the snapping reads the original images): the
  // floor suits 8-bit data; for images scaled to [0, 1] it is never reached.
  const double offsetBound_;
  const bool useRight_;  // the right view's contrast counts in the checked cut
};

AlongRowsSnapping::AlongRowsSnapping(const cv::Mat& left, const cv::Mat& right,
                                     const StepContrast& prepared, const StepSnapSettings& settings,
                                     float fillScore, const cv::Mat& disparity)
    : left_(left),
      right_(right),
      settings_(settings),
      fillScore_(fillScore),
      w_(left.cols),
      h_(left.rows),
      contrast_(prepared.contrast),
      rightContrast_(prepared.rightContrast),
      sigma_(prepared.sigma),
      minContrast_(static_cast<float>(settings.edgeSigmas * prepared.sigma)),
      checked_(!right.empty() && settings.checkSigmas > 0),
      offsetBound_(std::max(settings.carriedOffset, settings.carriedOffsetGrey / prepared.sigma)),
      useRight_(checked_ && settings.rightContourWeight > 0 && !prepared.rightContrast.empty()) {
  if (useRight_) CV_Assert(rightContrast_.size() == contrast_.size());
  if (!checked_) return;
  const auto [mn, mx] = matchedRange(disparity, settings.threads);
  dlo_ = static_cast<int>(std::floor(mn));
  const int dhi = static_cast<int>(std::ceil(mx));
  // The grey map of the matched pixel pairs, the images' moments as the fallback: every check
  // below compares errors a few noise sigmas apart, and the images' moments can be several grey
  // levels off at a roof's grey (simulated seed 14 1000²: gain 1.040 and offset 1.17 against
  // the matches' 1.086 and -6.44, the simulator's 1.087 and -6.5), which a plain roof's pixels
  // then carry at their own disparity.
  std::tie(gain_, offset_) = radiometricMapOfMatches(
      left, right, disparity, [&] { return radiometricMap(left, right, dlo_, dhi); }, 1000,
      settings.threads);
}

// ---- runs carried across a contour ----

// Runs carried across a contour (see match_snap.hpp). Only the strongest contour of the run's
// end is tried: trying each one gave the same outlines (±0.5 point) at a cost (Aloe, 219 d:
// 1.90 s against 1.71 s in all).
int AlongRowsSnapping::splitCarriedRuns(SnapRow& row) const {
  if (!checked_ || settings_.carriedRuns <= 0) return 0;
  const float* d = row.d;
  int changed = 0;
  const int m = settings_.carriedRuns;
  int previousEnd = -1;  // last pixel of the run before (-1: none)
  for (int x0 = 0; x0 < w_;) {
    if (!std::isfinite(d[x0])) {
      ++x0;
      continue;
    }
    int x1 = x0;  // the run is [x0, x1]
    while (x1 + 1 < w_ && std::isfinite(d[x1 + 1]) && std::abs(d[x1 + 1] - d[x1]) <= 1.0F) ++x1;
    const int nearEnd = previousEnd;
    previousEnd = x1;
    if (ownRunCarried(row, nearEnd, x0, x1)) {
      changed += row.clear(x0, x1);
      previousEnd = nearEnd;
      x0 = x1 + 1;
      continue;
    }
    const int e = strongestContour(row.c, std::max(x0 + m - 1, x1 - settings_.maxGap), x1 - m - 1);
    if (e >= 0 && carriedPast(row, x0, x1, e)) changed += row.clear(e + 1, x1);
    x0 = x1 + 1;
  }
  return changed;
}

// A short run [x0, x1] of its own just past a nearer run's end (`nearEnd`, -1: none), across a
// contour, offset in brightness from its counterpart at its own disparity while the nearer run's
// last pixels agree: the nearer surface's value carried onto ground the right view does not see
// (it maps onto the wall only that view shows), split off at the outline (no pixels of its own
// before the contour to compare with).
bool AlongRowsSnapping::ownRunCarried(const SnapRow& row, int nearEnd, int x0, int x1) const {
  const float* d = row.d;
  if (!(settings_.carriedOwnRuns > 0 && settings_.carriedOffset > 0 && nearEnd >= 0 &&
        x0 - nearEnd - 1 <= settings_.carriedOwnGap && x1 - x0 + 1 <= settings_.carriedOwnRuns &&
        x1 - x0 + 1 >= settings_.carriedOffsetPixels && d[nearEnd] > d[x0] &&
        strongestContour(row.c, std::max(0, nearEnd - 1), std::min(w_ - 2, x0)) >= 0)) {
    return false;
  }
  const int n = x1 - x0 + 1;
  double after = 0, nearRun = 0;
  int nNear = 0;
  for (int x = x0; x <= x1; ++x) after += signedResidual(row.y, x, d[x]);
  for (int x = nearEnd - 1;
       x >= 0 && nNear < n && std::isfinite(d[x]) && std::abs(d[x] - d[nearEnd]) <= 1.0F;
       --x, ++nNear) {
    nearRun += signedResidual(row.y, x, d[x]);
  }
  return offsetSplits(after, n, nearRun, nNear);
}

// Whether the run [x0, x1] was carried across the contour at e: the stretch after it is scored
// at the run's disparities and at each integer disparity at least minStep farther; when one of
// those explains it (within checkSigmas) better by carriedMargin sigmas, the run was carried
// across.
bool AlongRowsSnapping::carriedPast(const SnapRow& row, int x0, int x1, int e) const {
  const float* d = row.d;
  const int y = row.y;
  // Pixels e and e + 1 mix both surfaces through the blur: left out.
  const int n = x1 - e - 1;
  double atRun = 0;
  for (int x = e + 2; x <= x1; ++x) atRun += std::min(settings_.errorCap, error(y, x, d[x]));
  const double bound = n * std::min(atRun / n - settings_.carriedMargin, settings_.checkSigmas);
  bool carried = false;
  for (int df = dlo_; !carried && df <= static_cast<int>(std::floor(d[x1] - settings_.minStep));
       ++df) {
    double sum = 0;
    for (int x = e + 2; x <= x1 && sum < bound; ++x) {
      sum += std::min(settings_.errorCap, error(y, x, static_cast<float>(df)));
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
  if (!carried && settings_.carriedOffset > 0 && n >= settings_.carriedOffsetPixels) {
    double after = 0, before = 0;
    int nBefore = 0;
    for (int x = e + 2; x <= x1; ++x) after += signedResidual(y, x, d[x]);
    for (int x = std::max(x0, e - n); x < e; ++x, ++nBefore) {
      before += signedResidual(y, x, d[x]);
    }
    carried = offsetSplits(after, n, before, nBefore);
  }
  return carried;
}

// ---- the steps: matched pixels a < b, at most maxGap unmatched between them ----

// Each step of the row: a checked near side on the left gives its cut's costs (`cuts`, applied
// once every row's are known); the others are snapped here. Returns the pixels changed.
int AlongRowsSnapping::snapSteps(const SnapRow& row, std::vector<NearSideCut>& cuts) const {
  const float* d = row.d;
  int changed = 0;
  for (size_t i = 0; i + 1 < row.matched.size(); ++i) {
    const int a = row.matched[i], b = row.matched[i + 1];
    if (b - a - 1 > settings_.maxGap || std::abs(d[a] - d[b]) < settings_.minStep) continue;
    if (checked_ && d[a] > d[b]) {
      cuts.push_back(cutCosts(row, a, b));
      continue;
    }
    const int best = strongestContour(row.c, std::max(0, a - settings_.reach),
                                      std::min(w_ - 2, b - 1 + settings_.reach));
    if (best < 0) continue;
    changed += d[a] > d[b] ? cutUncheckedNearSideOnLeft(row, a, b, best)
                           : cutNearSideOnRight(row, a, b, best);
  }
  return changed;
}

// Checked cut of a near side on the left (a roof's +x edge: both views see the ground there):
// the near side's last pixel e over [s0 - 1, b] is the one of least total error, near pixels
// scored at the near disparity (along its slope) up to e, far ones at the far disparity from
// e + 2 (pixel e + 1 mixes both surfaces through the blur, and in the right view its roof part
// is missing: it biased the cut towards the ground), minus contourWeight × the contrast between
// e and e + 1. s0 goes back over the near side's pixels by up to cutReach (fattened roofs),
// over holes of at most nearHoleGap unmatched pixels too (a roof's pixel matched alone before
// its outline would otherwise stay an island, removed as a speckle, and leave a hole). Errors
// are capped so that one outlier pixel does not decide. Pixels up to e take the near
// disparity, the near pixels after it become unmatched; the far side is left alone.
NearSideCut AlongRowsSnapping::cutCosts(const SnapRow& row, int a, int b) const {
  const int y = row.y;
  const float* d = row.d;
  const float* c = row.c;
  NearSideCut cut;
  cut.y = y;
  cut.b = b;
  cut.dNear = d[a];
  cut.dFar = d[b];
  const int s0 = nearSideStart(d, a, cut.dNear);
  // Far pixels are scored up to b + 2 whatever they hold: every cut then scores the same
  // number of pixels (n − 1), and the first far pixel may still turn out to be near.
  const int s1 = std::min(w_ - 1, b + 2 + settings_.cutAhead);
  const int n = s1 - s0 + 1;
  cut.s0 = s0;
  cut.s1 = s1;
  // Prefix sums of the capped errors: near[k] over [s0, s0 + k), far likewise.
  double nearSum[kMaxCutSpan + 1], farSum[kMaxCutSpan + 1];
  nearSum[0] = farSum[0] = 0;
  // The near surface may slope along the row (a pitched roof's facet, sloping towards its
  // outline): its disparity follows the line fitted to its last pixels, through d[a]. (hardEnd
  // reads the level near disparity: along the slope, seed 3 600² lost 0.2 edge%.)
  cut.a = a;
  cut.slope = static_cast<float>(nearSlope(a, d, 0.5 * (cut.dNear + cut.dFar)));
  for (int k = 0; k < n; ++k) {
    nearSum[k + 1] =
        nearSum[k] + std::min(settings_.errorCap, error(y, s0 + k, cut.nearAt(s0 + k)));
    farSum[k + 1] = farSum[k] + std::min(settings_.errorCap, error(y, s0 + k, cut.dFar));
  }
  cut.eFirst = s0 - 1;
  cut.ownLast = std::min(b, s1 - 1);
  const int hard = hardEnd(y, a, std::min(b, s1 - 1), cut.dNear, cut.dFar);
  const int eLast = std::min(b + settings_.cutAhead, s1 - 1);
  cut.cost.clear();
  for (int e = cut.eFirst; e <= eLast; ++e) {
    const int nearEnd = e - s0 + 1;                 // near pixels: [0, nearEnd)
    const int farStart = std::min(n, nearEnd + 1);  // far pixels: [farStart, n)
    cut.cost.push_back(
        static_cast<float>(nearSum[nearEnd] + farSum[n] - farSum[farStart] -
                           settings_.contourWeight * (e >= 0 ? c[e] / sigma_ : 0.0) -
                           settings_.rightContourWeight * rightContrastAt(y, e, cut.dNear)));
    if (e < hard) {
      cut.cost.back() +=
          static_cast<float>(settings_.hardEndPenalty * settings_.errorCap * (hard - e));
    }
  }
  return cut;
}

// The first pixel s0 of the near side ending at a that a cut may go back to: over its own
// pixels (within 1 px of dNear) by up to cutReach, and over holes of at most nearHoleGap
// unmatched pixels between them.
int AlongRowsSnapping::nearSideStart(const float* d, int a, float dNear) const {
  int s0 = a;
  const int reachStart = std::max(0, a - settings_.cutReach);
  for (;;) {
    // The next near pixel back, over at most nearHoleGap unmatched ones.
    int x = s0 - 1;
    while (x >= reachStart && s0 - 1 - x < settings_.nearHoleGap && !std::isfinite(d[x])) --x;
    if (x < reachStart || !std::isfinite(d[x]) || std::abs(d[x] - dNear) > 1.0F) break;
    s0 = x;
  }
  return s0;
}

// The near side's value may explain the gap's pixels as well as the far side's does (a plain
// roof beside plain ground of its grey): the photometric costs then tie, and a seam or a
// texture line inside the roof took the cut (seed 3 600², rows 143-152: 4-9 px short). Where
// the near disparity fails hard on two pixels that the far one explains (at the near
// disparity the ground past a roof's +x edge falls on the wall only the right view shows),
// after gap pixels it explains on average (within checkSigmas + carriedMargin, each capped at
// errorCap: a thin seam errs by more), the near surface reaches that far: cuts before it
// cost hardEndPenalty × errorCap more per pixel left out.
// Returns that last pixel of the near surface (after a, up to `last`), or -1.
int AlongRowsSnapping::hardEnd(int y, int a, int last, float dNear, float dFar) const {
  if (settings_.hardEndPenalty <= 0) return -1;
  const auto failsHard = [&](int x) {
    return x + 1 <= last && error(y, x, dNear) >= settings_.errorCap &&
           error(y, x + 1, dNear) >= settings_.errorCap &&
           error(y, x, dFar) <= settings_.checkSigmas &&
           error(y, x + 1, dFar) <= settings_.checkSigmas;
  };
  double sum = 0;
  int counted = 0;
  for (int x = a + 1; x <= last; ++x) {
    // The near surface's last pixel: two before the failure (the one before it mixes both
    // surfaces through the blur and may fail on its own).
    int end = -1;
    if (failsHard(x)) {
      end = x - 2;
    } else if (error(y, x, dNear) > settings_.errorCap && failsHard(x + 1)) {
      end = x - 1;
    }
    if (end >= 0) {
      const bool explained =
          counted > 0 && sum <= (settings_.checkSigmas + settings_.carriedMargin) * counted;
      return end > a && explained ? end : -1;
    }
    sum += std::min(settings_.errorCap, error(y, x, dNear));
    ++counted;
  }
  return -1;
}

// Near side on the left, unchecked: it ends at pixel `best`.
int AlongRowsSnapping::cutUncheckedNearSideOnLeft(const SnapRow& row, int a, int b,
                                                  int best) const {
  int changed = 0;
  for (int x = a + 1; x <= best && x < b; ++x) {
    row.out[x] = row.d[a];
    if (row.sc) row.sc[x] = fillScore_;
    ++changed;
  }
  for (int x = best + 1; x <= a; ++x) {
    if (std::isfinite(row.out[x])) {
      row.out[x] = kNaN;
      if (row.sc) row.sc[x] = kNaN;
      ++changed;
    }
  }
  return changed;
}

// Near side on the right: it starts at pixel best + 1. The unmatched pixels before it are mostly
// the ground this view sees and the other does not (left map: the -x side of a nearer surface);
// they stay unmatched (filling them raised Cones bad-2 2.90 -> 3.33 %).
int AlongRowsSnapping::cutNearSideOnRight(const SnapRow& row, int a, int b, int best) const {
  int changed = 0;
  for (int x = b; x <= best; ++x) {
    if (std::isfinite(row.out[x]) && fitsFarBetter(row.y, x, row.d[b], row.d[a])) {
      row.out[x] = kNaN;
      if (row.sc) row.sc[x] = kNaN;
      ++changed;
    }
  }
  return changed;
}

// Pixels up to the chosen e take the near disparity, the near pixels after it become unmatched.
int AlongRowsSnapping::applyCut(const NearSideCut& cut, float* out, float* sc) const {
  const int e = cut.chosen;
  int changes = 0;
  for (int x = cut.s0; x <= std::max(std::min(cut.b, cut.s1 - 1), e); ++x) {
    const bool nearValued = std::isfinite(out[x]) && std::abs(out[x] - cut.dNear) <= 1.0F;
    if (x <= e && !nearValued) {
      out[x] = cut.nearAt(x);
      if (sc) sc[x] = fillScore_;
      ++changes;
    } else if (x > e && nearValued) {
      out[x] = kNaN;
      if (sc) sc[x] = kNaN;
      ++changes;
    }
  }
  return changes;
}

// ---- open ends (checked only) ----

// Open ends: a matched run followed by more than maxGap unmatched pixels (a roof next
// to textureless ground or a shadow) is extended to the strongest contour within
// `reach`. A pixel is taken when it matches at the run's disparity, or when its grey is
// nearer the run's last pixel than the pixel beyond the contour: the last pixels of a
// roof's +x edge mix roof and ground through the blur, and their neighbour in the right
// view is another surface, so the photometric test alone stopped 1-2 px short.
int AlongRowsSnapping::extendOpenEnds(const SnapRow& row) const {
  if (!checked_) return 0;
  int changed = 0;
  for (size_t i = 0; i < row.matched.size(); ++i) {
    const int a = row.matched[i];
    const int next = i + 1 < row.matched.size() ? row.matched[i + 1] : w_;
    if (next - a - 1 <= settings_.maxGap) continue;
    changed += extendOpenEnd(row, a, next);
  }
  return changed;
}

// The run ending at a, whose next matched pixel is `next` (w: none): its contour, then its
// pixels up to it. Returns the pixels changed.
int AlongRowsSnapping::extendOpenEnd(const SnapRow& row, int a, int next) const {
  const float* d = row.d;
  const float* grey = left_.ptr<float>(row.y);
  int best = strongestContour(row.c, a, std::min(w_ - 2, a + settings_.reach));
  if (settings_.openReach > 0 && settings_.carriedOffset > 0) {
    best = std::max(best, offsetContour(row, a, next));
  }
  int grown = a;  // the pixels up to it were checked by the growth
  best = growOpenEnd(row, a, next, best, grown);
  int changed = 0;
  for (int x = a + 1; x <= best; ++x) {
    const bool looksNear = std::abs(grey[x] - grey[a]) < std::abs(grey[x] - grey[best + 1]);
    if (x > grown && !looksNear && error(row.y, x, d[a]) > settings_.checkSigmas) break;
    row.out[x] = d[a];
    if (row.sc) row.sc[x] = fillScore_;
    ++changed;
  }
  return changed;
}

// Up to openReach, a contour farther than that is taken when the brightness says the
// run's surface ends there: at the run's disparity the two pixels past it (after the
// mixed one) are offset from their counterpart by at least offsetBound, the pixels up to
// it within half that on average, and no stronger contrast lies between the run's end
// and it (a roof's texture inside its outline is a weaker step than the outline).
// Returns the farthest such contour, or -1.
int AlongRowsSnapping::offsetContour(const SnapRow& row, int a, int next) const {
  const float* c = row.c;
  const float da = row.d[a];
  int best = -1;
  double inside = 0;  // signed residuals of a + 1 .. e at the run's disparity
  float strongest = 0, bestContrast = 0;
  for (int e = a; e <= std::min({w_ - 4, a + settings_.openReach, next - 4}); ++e) {
    if (e > a) inside += signedResidual(row.y, e, da);
    const bool strongestSoFar = c[e] >= strongest;
    strongest = std::max(strongest, c[e]);
    if (!strongestSoFar || c[e] < minContrast_ || c[e] <= bestContrast) continue;
    if (e > a && std::abs(inside / (e - a)) > offsetBound_ / 2) continue;
    const double beyond = (signedResidual(row.y, e + 2, da) + signedResidual(row.y, e + 3, da)) / 2;
    if (std::abs(beyond) >= offsetBound_) {
      bestContrast = c[e];
      best = std::max(best, e);
    }
  }
  return best;
}

// The run grows over the gap's pixels its disparity explains better (by carriedMargin)
// than the far side's after the gap (within errorCap: a thin seam's pixels err by a few
// sigmas through interpolation): the run's surface goes on there (a plain roof strip
// after a seam, next to plain dark ground). A contour within 2 px of the first pixel
// that evidence fails on (it mixes both surfaces through the blur) is the surface's
// edge when the pixels up to it match at the run's disparity on average.
// Returns that edge when it lies past `best` (`grown`: the pixels up to it the growth checked),
// `best` otherwise.
int AlongRowsSnapping::growOpenEnd(const SnapRow& row, int a, int next, int best,
                                   int& grown) const {
  const float* d = row.d;
  const float* c = row.c;
  const int y = row.y;
  if (!(settings_.openGrowth > 0 && next < w_ && d[next] <= d[a] - settings_.minStep)) {
    return best;
  }
  int g = a;
  while (g + 1 < std::min(next, a + 1 + settings_.openGrowth)) {
    const double own = error(y, g + 1, d[a]);
    if (own > settings_.errorCap || own + settings_.carriedMargin > error(y, g + 1, d[next])) {
      break;
    }
    ++g;
  }
  const int e =
      g > a + 1 ? strongestContour(c, std::max(a, g - 2), std::min({w_ - 3, g + 2, next - 2})) : -1;
  // The contrast of a step spreads over the pixels beside it: only its peak is the edge.
  if (e > best && c[e] >= c[e - 1] && c[e] >= c[e + 1]) {
    double own = 0;
    for (int x = a + 1; x <= e; ++x) own += std::min(settings_.errorCap, error(y, x, d[a]));
    if (own <= settings_.checkSigmas * (e - a)) {
      grown = std::min(g, e);
      return e;
    }
  }
  return best;
}

// ---- what the stages measure ----

// Mean of left − mapped right (its absolute value, or signed: a brightness offset) over the
// pixel and its two vertical neighbours at disparity d, in noise sigmas; `none` where nothing
// is read.
double AlongRowsSnapping::meanResidual(int y, int x, float d, bool absolute, double none) const {
  double sum = 0;
  int n = 0;
  for (int v = std::max(0, y - 1); v <= std::min(h_ - 1, y + 1); ++v) {
    const float xr = static_cast<float>(x) - d;
    const int x0 = static_cast<int>(std::floor(xr));
    if (x0 < 0 || x0 + 1 >= w_) continue;
    const float t = xr - static_cast<float>(x0);
    const float* r = right_.ptr<float>(v);
    const float a = left_.at<float>(v, x);
    const float b = (1 - t) * r[x0] + t * r[x0 + 1];
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    const double residual = a - (gain_ * b + offset_);
    sum += absolute ? std::abs(residual) : residual;
    ++n;
  }
  return n > 0 ? sum / n / sigma_ : none;
}

// Contour position e (between pixels e and e + 1) of the strongest contrast in [e0, e1] of a
// row's contrast `c`, when it is at least minContrast; -1 otherwise.
int AlongRowsSnapping::strongestContour(const float* c, int e0, int e1) const {
  int best = -1;
  float bestContrast = minContrast_;
  for (int e = e0; e <= e1; ++e) {
    if (c[e] >= bestContrast) {
      bestContrast = c[e];
      best = e;
    }
  }
  return best;
}

// Two surfaces by brightness: the pixels past a contour are offset from their counterparts by
// at least offsetBound on average while the run's pixels before it agree within half that
// (sums of signed residuals and their counts).
bool AlongRowsSnapping::offsetSplits(double after, int nAfter, double before, int nBefore) const {
  return nBefore > 0 && std::abs(after / nAfter) >= offsetBound_ &&
         std::abs(before / nBefore) <= offsetBound_ / 2;
}

// The roof's edge is a contour in the right view too (roof against the wall that view sees),
// at x − dNear: its contrast there, in the left view's grey levels and noise sigmas, capped so
// that a strong texture line inside the roof does not outweigh the photometric evidence.
double AlongRowsSnapping::rightContrastAt(int y, int e, float dNear) const {
  if (!useRight_) return 0.0;
  const int xr = static_cast<int>(std::lround(static_cast<float>(e) - dNear));
  if (xr < 0 || xr >= rightContrast_.cols) return 0.0;
  return std::min(settings_.rightContourCap, gain_ * rightContrast_.at<float>(y, xr) / sigma_);
}

// The slope along the row of the near side ending at a: the least-squares line through the
// row's matched pixels of its last nearSlopePixels px above the mid-level `mid` (a matcher's
// fronto-parallel windows give a sloped facet as steps, several runs), clamped to
// ±maxNearSlope; 0 with fewer than kMinSlopePixels of them.
double AlongRowsSnapping::nearSlope(int a, const float* d, double mid) const {
  if (settings_.nearSlopePixels <= 0) return 0.0;
  double su = 0, sv = 0, suu = 0, suv = 0;
  int count = 0;
  for (int x = std::max(0, a - settings_.nearSlopePixels); x <= a; ++x) {
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
  return std::clamp((count * suv - su * sv) / det, -settings_.maxNearSlope, settings_.maxNearSlope);
}
}  // namespace

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
  const AlongRowsSnapping snapping(left, right, prepared, settings, fillScore, disparity);
  // The checked cuts of each row, applied once every row's are known (continuity across rows).
  std::vector<std::vector<NearSideCut>> cutsByRow(static_cast<size_t>(h));
  // Rows are independent (each writes only its own): bands of rows on the workers.
  std::atomic<int> changedTotal{0};
  forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
    int changed = 0;
    SnapRow row(w);
    for (int y = rowStart; y < rowEnd; ++y) {
      row.start(y, prepared.contrast, disparity, score);
      changed += snapping.splitCarriedRuns(row);
      row.findMatched();
      changed += snapping.snapSteps(row, cutsByRow[static_cast<size_t>(y)]);
      changed += snapping.extendOpenEnds(row);
    }
    changedTotal += changed;
  });
  if (snapping.checked()) {
    // Each checked cut on the line through its step's rows, then applied.
    chooseCuts(cutsByRow, settings);
    forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
      int changed = 0;
      for (int y = rowStart; y < rowEnd; ++y) {
        float* out = disparity.ptr<float>(y);
        float* sc = score.empty() ? nullptr : score.ptr<float>(y);
        for (const NearSideCut& cut : cutsByRow[static_cast<size_t>(y)]) {
          changed += snapping.applyCut(cut, out, sc);
        }
      }
      changedTotal += changed;
    });
  }
  return changedTotal;
}

}  // namespace delineo::stereo::detail
