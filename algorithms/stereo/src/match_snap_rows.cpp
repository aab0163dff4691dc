#include "match_snap_rows.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "radiometry.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
// Rows on each side of a cut whose mean grey the contrast compares (as the row-wise snapping's
// kStepSide: an outline is a step between two grey levels, a 1–2 px line is not).
constexpr int kStepSide = 2;
// px: disparities this close are the same surface's.
constexpr float kSameSurface = 1.5F;
// Fewest pixels a strip's error is read on.
constexpr int kMinStripPixels = 4;

// One pass over the columns (see snapStepsAcrossRows): what every column reads (the images, their
// grey map, the map as it was) and the steps that move one column's pixels (snapColumn).
class AcrossRowsPass {
 public:
  AcrossRowsPass(const cv::Mat& left, const cv::Mat& right, double sigma, double gain,
                 double offset, const RowStepSnapSettings& settings, float fillScore,
                 cv::Mat& disparity, cv::Mat& score)
      : left_(left),
        right_(right),
        sigma_(sigma),
        gain_(gain),
        offset_(offset),
        settings_(settings),
        fillScore_(fillScore),
        disparity_(disparity),
        score_(score),
        before_(disparity.clone()),
        w_(left.cols),
        h_(left.rows),
        minContrast_(static_cast<float>(settings.edgeSigmas * sigma)) {}

  // The column's steps, from the top: each one's outline, then its pixels moved onto it.
  // Returns the pixels changed.
  int snapColumn(int x) {
    int changed = 0;
    int a = -1;  // the last matched row above
    for (int y = 0; y < h_; ++y) {
      const float db = disparity_.at<float>(y, x);
      if (db != db) continue;
      if (a >= 0 && y - a - 1 <= settings_.maxGap &&
          std::abs(db - disparity_.at<float>(a, x)) >= settings_.minStep) {
        y = snapStep(x, a, y, changed);
      }
      a = disparity_.at<float>(y, x) == disparity_.at<float>(y, x) ? y : a;
    }
    return changed;
  }

 private:
  // The step between the matched rows a < b of column x: moves its pixels onto its outline
  // (adding them to `changed`) and returns the last row the column's scan has covered.
  int snapStep(int x, int a, int b, int& changed) {
    const float da = disparity_.at<float>(a, x);
    const float db = disparity_.at<float>(b, x);
    const int cut = outline(x, a, b);
    if (cut >= 0 && cut <= a) {
      // The upper side carried below the outline: rows cut .. b − 1 take the lower side's
      // disparity, from the gap upwards.
      for (int v = b - 1; v >= cut && moveIfExplained(x, v, db, changed); --v) {
      }
    } else if (cut > a && cut <= b && settings_.gapErrorSigmas > 0) {
      // The outline lies in the gap: each side's unmatched pixels up to it take the side's
      // disparity, from the side towards the outline, while each is explained there.
      for (int v = a + 1; v < cut && fillIfExplained(x, v, da, changed); ++v) {
      }
      for (int v = b - 1; v >= cut && fillIfExplained(x, v, db, changed); --v) {
      }
    } else if (cut > b) {
      // The lower side carried above it: rows a + 1 .. cut − 1, from the gap downwards.
      const int end = cut - 1;
      for (int v = a + 1; v <= end && moveIfExplained(x, v, da, changed); ++v) {
      }
      // The rows moved are the upper side's now: the scan goes on after them.
      return std::max(b, end);
    }
    return b;
  }

  // The outline of the step a < b in column x: the cut above the row of the strongest local
  // maximum of contrastAbove within [a − reach + 1, b + reach], at least minContrast; -1: none.
  int outline(int x, int a, int b) const {
    int cut = -1;
    float strongest = minContrast_;
    for (int c = std::max(1, a - settings_.reach + 1); c <= std::min(h_ - 1, b + settings_.reach);
         ++c) {
      // A local maximum only: the cut next to a stronger outline just outside the range reads
      // part of it (1000² / 128 d: the top of a plain roof, 7 rows above a box on it, moved the
      // roof's rows onto the box's disparity).
      const float contrast = contrastAbove(x, c);
      if (contrast >= strongest && contrast >= contrastAbove(x, c - 1) &&
          contrast >= contrastAbove(x, c + 1)) {
        strongest = contrast;
        cut = c;
      }
    }
    return cut;
  }

  // Pixel (y, x) of a carried run takes disparity `to` when that explains its strip clearly
  // better than its own; an unmatched one (the gap) stays unmatched and is passed over when `to`
  // explains it. False: the move stops.
  bool moveIfExplained(int x, int y, float to, int& changed) {
    float& d = disparity_.at<float>(y, x);
    const double atNew = stripError(y, x, to, to);
    if (!(atNew <= settings_.maxErrorSigmas)) return false;
    if (d != d) return true;
    if (!(atNew <= settings_.winRatio * stripError(y, x, d, to))) return false;
    d = to;
    score_.at<float>(y, x) = fillScore_;
    ++changed;
    return true;
  }

  // Unmatched pixel (v, x) of the gap takes its side's disparity `to` when that explains it.
  // False: the fill stops.
  bool fillIfExplained(int x, int v, float to, int& changed) {
    if (!(tripletError(v, x, to) <= settings_.gapErrorSigmas)) return false;
    disparity_.at<float>(v, x) = to;
    score_.at<float>(v, x) = fillScore_;
    ++changed;
    return true;
  }

  // Mean |left − mapped right| over the pixels x − halfWidth .. x + halfWidth of row y at
  // disparity d, in noise sigmas (right view read with linear interpolation), without the other
  // pixels whose disparity was within kSameSurface of `other` (NaN: none left out). +inf when
  // fewer than `fewest` are read.
  double rowError(int y, int x, float d, int halfWidth, float other, int fewest) const {
    const float* a = left_.ptr<float>(y);
    const float* r = right_.ptr<float>(y);
    const float* was = before_.ptr<float>(y);
    double sum = 0;
    int n = 0;
    for (int u = std::max(0, x - halfWidth); u <= std::min(w_ - 1, x + halfWidth); ++u) {
      if (u != x && std::abs(was[u] - other) < kSameSurface) continue;
      const float xr = static_cast<float>(u) - d;
      const int x0 = static_cast<int>(std::floor(xr));
      if (x0 < 0 || x0 + 1 >= w_) continue;
      const float t = xr - static_cast<float>(x0);
      const float b = (1 - t) * r[x0] + t * r[x0 + 1];
      if (!std::isfinite(a[u]) || !std::isfinite(b)) continue;
      sum += std::abs(a[u] - (gain_ * b + offset_));
      ++n;
    }
    return n >= fewest ? sum / n / sigma_ : std::numeric_limits<double>::infinity();
  }
  // The error over the row strip of (y, x) (stripHalf each side), without the strip's other pixels
  // whose disparity was within kSameSurface of `other`: where the outline crosses the row (a
  // slanted one, a narrow part of a roof, a carried run's end) those pixels would vote for `other`
  // on their own surface's behalf (a 6 px roof wing moved onto the ground without this; on the
  // battery, edge % 0.3–0.4 point lower on 4 runs). At least kMinStripPixels read.
  double stripError(int y, int x, float d, float other) const {
    return rowError(y, x, d, settings_.stripHalf, other, kMinStripPixels);
  }
  // The error of (y, x) and its two row neighbours: a gap's pixel next to the outline, whose row
  // strip would cross a slanted outline. At least 2 read.
  double tripletError(int y, int x, float d) const {
    return rowError(y, x, d, 1, std::numeric_limits<float>::quiet_NaN(), 2);
  }
  // |mean I(c .. c + kStepSide − 1) − mean I(c − kStepSide .. c − 1)| in column x: the contrast
  // of the cut above row c; -1 where a side leaves the image or meets nodata.
  float contrastAbove(int x, int c) const {
    if (c - kStepSide < 0 || c + kStepSide > h_) return -1;
    float above = 0, below = 0;
    for (int k = 0; k < kStepSide; ++k) {
      above += left_.at<float>(c - 1 - k, x);
      below += left_.at<float>(c + k, x);
    }
    if (!std::isfinite(above) || !std::isfinite(below)) return -1;
    return std::abs(below - above) / static_cast<float>(kStepSide);
  }

  const cv::Mat& left_;
  const cv::Mat& right_;
  const double sigma_, gain_, offset_;  // the left image's noise sigma, the views' grey map
  const RowStepSnapSettings& settings_;
  const float fillScore_;
  cv::Mat& disparity_;
  cv::Mat& score_;
  // The map as it was: the strips leave out the pixels that held the new disparity before any
  // move (and the columns are moved on several workers).
  const cv::Mat before_;
  const int w_, h_;
  const float minContrast_;
};

// One pass over the columns (see snapStepsAcrossRows), bands of columns on the workers (each
// column is moved on its own). Returns the pixels changed.
int snapPass(const cv::Mat& left, const cv::Mat& right, double sigma, double gain, double offset,
             const RowStepSnapSettings& settings, float fillScore, cv::Mat& disparity,
             cv::Mat& score) {
  AcrossRowsPass pass(left, right, sigma, gain, offset, settings, fillScore, disparity, score);
  std::vector<int> changedPerColumn(static_cast<size_t>(left.cols), 0);
  forRowBands(left.cols, settings.threads, [&](int colStart, int colEnd) {
    for (int x = colStart; x < colEnd; ++x) {
      changedPerColumn[static_cast<size_t>(x)] = pass.snapColumn(x);
    }
  });
  int total = 0;
  for (const int c : changedPerColumn) total += c;
  return total;
}
}  // namespace

int snapStepsAcrossRows(const cv::Mat& left, const cv::Mat& right, double sigma,
                        const RowStepSnapSettings& settings, float fillScore, cv::Mat& disparity,
                        cv::Mat& score) {
  CV_Assert(left.type() == CV_32F && right.type() == CV_32F && disparity.type() == CV_32F &&
            score.type() == CV_32F && left.size() == right.size() &&
            left.size() == disparity.size() && left.size() == score.size());
  if (left.rows < 2 * kStepSide + 1 || left.cols < 1 || !(sigma > 0)) return 0;
  // The grey map of the matched pairs; the images' moments at the map's disparities when too few
  // are matched (the moments can be several grey levels off at a roof's grey: simulated seed 9
  // 1000², a roof's top rows that carried the ground's value stayed so).
  const auto [lowest, highest] = matchedRange(disparity, settings.threads);
  const auto [gain, offset] = radiometricMapOfMatches(
      left, right, disparity,
      [&, lowest = lowest, highest = highest] {
        return radiometricMap(left, right, static_cast<int>(std::floor(lowest)),
                              static_cast<int>(std::ceil(highest)));
      },
      1000, settings.threads);
  int total = 0;
  for (int pass = 0; pass < settings.maxPasses; ++pass) {
    const int moved =
        snapPass(left, right, sigma, gain, offset, settings, fillScore, disparity, score);
    if (moved == 0) break;
    total += moved;
  }
  return total;
}

}  // namespace delineo::stereo::detail
