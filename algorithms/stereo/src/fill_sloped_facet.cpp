// The plane of a sloped facet: a flat region whose outline lines up at no constant disparity,
// fitted through its row ends and those of its counterpart in the right view.
#include "fill_internal.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

namespace delineo::stereo::detail {

std::vector<RowEnds> regionRowEnds(const cv::Mat& region, const cv::Rect& box, int minSpan) {
  std::vector<RowEnds> rows;
  for (int y = 0; y < box.height; ++y) {
    const uchar* m = region.ptr<uchar>(y);
    int first = -1, last = -1;
    for (int x = 0; x < box.width; ++x) {
      if (!m[x]) continue;
      if (first < 0) first = x;
      last = x;
    }
    if (first >= 0 && last - first >= minSpan) {
      rows.push_back({box.y + y, box.x + first, box.x + last});
    }
  }
  return rows;
}

namespace {

// The points within `within` px of the plane.
std::vector<cv::Point3d> pointsNear(const std::vector<cv::Point3d>& points, const FillPlane& plane,
                                    double within) {
  std::vector<cv::Point3d> near;
  for (const auto& p : points) {
    if (std::abs(plane.residual(p)) <= within) near.push_back(p);
  }
  return near;
}

// Least-squares plane d = c + a·x + b·y through points (x, y, d), coordinates centred for the
// conditioning; false when the points do not fix it (all on one row, ...).
bool fitPlane(const std::vector<cv::Point3d>& points, FillPlane& plane) {
  if (points.size() < 3) return false;
  double mx = 0, my = 0;
  for (const auto& p : points) {
    mx += p.x;
    my += p.y;
  }
  mx /= static_cast<double>(points.size());
  my /= static_cast<double>(points.size());
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0, 0, 0);
  for (const auto& p : points) {
    const cv::Vec3d row(1.0, p.x - mx, p.y - my);
    normal += row * row.t();
    rhs += row * p.z;
  }
  cv::Vec3d coeffs;
  if (!cv::solve(normal, rhs, coeffs, cv::DECOMP_CHOLESKY)) return false;
  plane.a = coeffs[1];
  plane.b = coeffs[2];
  plane.c = coeffs[0] - plane.a * mx - plane.b * my;
  return true;
}

// A flat region whose outline lines up at no constant disparity can be a sloped facet (a gable
// roof's plain side): its disparity changes along the outline. Its counterpart in the right view is
// a flat region of the same grey level, and the two flat masks stop the same 2 px inside the
// facet's first and last pixels (their 5x5 windows reach the contour), so the ends of a row
// correspond: the left region spans [l0, l1] on row y, its counterpart [r0, r1], and the facet's
// disparity is l0 − r0 at (l0 − 2, y) and l1 − r1 at (l1 + 2, y). (Measured at l0 and l1 instead,
// the slope of a 0.15 px/px facet came out 0.165.) A plane through those points, kept when most
// rows agree with it within a pixel (a facet partly hidden in the right view or merged there with a
// surface of the same grey gives rows that do not), fills the region. Of the right regions of about
// the region's grey level in its search band, the one with the most agreeing points is taken.
// A hip roof's facet has its row ends on two kinds of contours: on one side the hips it shares
// with the other facets (the same crease in both views: the ends agree), on the other its eave,
// beside which the right view sees the facade, where the right region's ends scatter by a few
// pixels (seed 5 600², the dark facet at x 130–185, y 334–361: 26 of 27 hip-side ends within
// 1 px of the plane, 10 of 27 eave-side ones; the region was left unmatched). `points` holds
// each row's two ends in turn (the region's first pixel, then its last): the plane is kept when
// the ends of one side agree with it on planeSideShare of the rows and those of the other side on
// planeEaveShare (they fix the slope across the rows).
bool oneSideAgrees(const std::vector<cv::Point3d>& points, const FillPlane& plane,
                   const RegionFillSettings& settings) {
  if (settings.planeSideShare > 1 || points.empty()) return false;
  size_t agree[2] = {0, 0};
  for (size_t k = 0; k < points.size(); ++k) {
    const cv::Point3d& p = points[k];
    if (std::abs(plane.residual(p)) <= settings.planeInlier) {
      ++agree[k % 2];
    }
  }
  const double rows = static_cast<double>(points.size() / 2);
  const double high = static_cast<double>(std::max(agree[0], agree[1]));
  const double low = static_cast<double>(std::min(agree[0], agree[1]));
  return high >= settings.planeSideShare * rows && low >= settings.planeEaveShare * rows;
}

// A facet merged in the left view with a surface of its grey beyond one of its ends (a hip
// roof's facet beside ground of its grey) has, on those rows, row ends far from its plane, which
// pull the least-squares fit off before the inliers are kept. When the plain fit is not kept, the
// worst planeTrimShare of the points are dropped and the plane fitted again, until every point
// left agrees with it within planeInlier (at least 2 · planeMinRows points left).
bool trimmedPlane(const std::vector<cv::Point3d>& points, const RegionFillSettings& settings,
                  FillPlane& plane) {
  if (settings.planeTrimShare <= 0) return false;
  std::vector<cv::Point3d> kept = points;
  while (static_cast<int>(kept.size()) >= 2 * settings.planeMinRows && fitPlane(kept, plane)) {
    std::vector<std::pair<double, size_t>> residuals;
    for (size_t k = 0; k < kept.size(); ++k) {
      const cv::Point3d& p = kept[k];
      residuals.emplace_back(std::abs(plane.residual(p)), k);
    }
    std::sort(residuals.rbegin(), residuals.rend());
    if (residuals.front().first <= settings.planeInlier) return true;
    const size_t drop = std::max<size_t>(
        1, static_cast<size_t>(settings.planeTrimShare * static_cast<double>(kept.size())));
    std::vector<uchar> dropped(kept.size(), 0);
    for (size_t k = 0; k < drop && k < residuals.size(); ++k) dropped[residuals[k].second] = 1;
    std::vector<cv::Point3d> next;
    for (size_t k = 0; k < kept.size(); ++k) {
      if (!dropped[k]) next.push_back(kept[k]);
    }
    kept = std::move(next);
  }
  return false;
}

// slopedFacetPlane in its steps: the counterparts of the region in the right view (counterparts),
// for each the plane through the row ends (fitCounterpart), kept when it passes (passes), with
// the rows it fills (filledRowSpans); then whether the constant, if any, wins over it
// (constantWins).
struct SlopedFacet {
  // One counterpart's row ends and plane.
  struct Fit {
    std::vector<cv::Point3d> points;   // each row's two ends in turn (first, then last)
    std::vector<cv::Vec2i> rightEnds;  // each row's (r0, r1), as its two points
    FillPlane plane;
    std::vector<cv::Point3d> inliers;  // the points within planeInlier px of the plane
    bool ok = false;                   // a plane was fitted
    bool bothSides = false;            // planeMinShare of the points are inliers
    bool trimmed = false;              // the plane of the trimmed fit (trimmedPlane)
  };

  std::pair<int, int> band(const RowEnds& r) const {
    return searchBand(r, dmin, dmax, right.labels.cols);
  }
  std::vector<std::pair<int, int>> counterparts() const;
  Fit fitCounterpart(int label, const std::optional<float>& constant) const;
  void readRowEnds(int label, Fit& fit) const;
  std::optional<cv::Point3d> subpixelEnd(const RowEnds& r, int label, int leftEnd, int rightEnd,
                                         int step) const;
  bool passes(const Fit& fit, size_t bestInliers) const;
  std::vector<cv::Vec2i> filledRowSpans(const Fit& fit) const;
  bool constantWins(float constant, const FillPlane& plane,
                    const std::vector<cv::Point3d>& points) const;

  const cv::Mat& region;
  const cv::Rect& box;
  const RightFlatRegions& right;
  double leftMean, gain, offset, sigma;
  int dmin, dmax;
  const RegionFillSettings& settings;
  const EdgeViews* edgeViews;  // (optional) the row ends read from the edges
  const std::vector<RowEnds> rows = regionRowEnds(region, box);
};

}  // namespace

bool slopedFacetPlane(const cv::Mat& region, const cv::Rect& box, const RightFlatRegions& right,
                      double leftMean, double gain, double offset, double sigma, int dmin, int dmax,
                      const RegionFillSettings& settings, const std::optional<float>& constant,
                      FillPlane& plane, bool* oneSided, std::vector<cv::Vec2i>* rowSpans,
                      const EdgeViews* edgeViews) {
  const SlopedFacet facet{region, box,  right, leftMean, gain,     offset,
                          sigma,  dmin, dmax,  settings, edgeViews};
  if (static_cast<int>(facet.rows.size()) < settings.planeMinRows) return false;
  size_t bestInliers = 0;
  std::vector<cv::Point3d> bestPoints;
  for (const auto& [count, label] : facet.counterparts()) {
    SlopedFacet::Fit fit = facet.fitCounterpart(label, constant);
    if (!facet.passes(fit, bestInliers)) continue;
    bestInliers = fit.inliers.size();
    plane = fit.plane;
    if (oneSided != nullptr) *oneSided = !fit.bothSides;
    if (rowSpans != nullptr) *rowSpans = facet.filledRowSpans(fit);
    bestPoints = std::move(fit.points);
  }
  if (bestInliers == 0) return false;
  return !(constant && facet.constantWins(*constant, plane, bestPoints));
}

// Right regions of the region's grey level met in the rows' search bands, by pixel count: the
// three largest.
std::vector<std::pair<int, int>> SlopedFacet::counterparts() const {
  std::vector<std::pair<int, int>> candidates;  // (count, label)
  std::vector<int> counts;
  for (const RowEnds& r : rows) {
    const int* l = right.labels.ptr<int>(r.y);
    const auto [x0, x1] = band(r);
    for (int x = x0; x <= x1; ++x) {
      if (l[x] == 0) continue;
      if (static_cast<size_t>(l[x]) >= counts.size()) {
        counts.resize(static_cast<size_t>(l[x]) + 1, 0);
      }
      ++counts[static_cast<size_t>(l[x])];
    }
  }
  for (size_t k = 1; k < counts.size(); ++k) {
    const double mapped = gain * right.meanGrey[k] + offset;
    if (counts[k] >= settings.planeMinRows &&
        std::abs(mapped - leftMean) <= settings.planeGreySigmas * sigma) {
      candidates.emplace_back(counts[k], static_cast<int>(k));
    }
  }
  std::sort(candidates.rbegin(), candidates.rend());
  if (candidates.size() > 3) candidates.resize(3);
  return candidates;
}

// The plane through the row ends of the region and of right region `label`.
SlopedFacet::Fit SlopedFacet::fitCounterpart(int label,
                                             const std::optional<float>& constant) const {
  Fit fit;
  readRowEnds(label, fit);
  const std::vector<cv::Point3d>& points = fit.points;
  // Fit, keep the points within planeInlier px, fit again (twice).
  fit.inliers = points;
  fit.ok = fitPlane(fit.inliers, fit.plane);
  for (int pass = 0; pass < 2 && fit.ok; ++pass) {
    fit.inliers = pointsNear(points, fit.plane, settings.planeInlier);
    fit.ok = fitPlane(fit.inliers, fit.plane);
  }
  fit.bothSides =
      fit.ok && static_cast<double>(fit.inliers.size()) >= settings.planeMinShare * points.size();
  // Failing that, when no constant lines the outline up, the trimmed fit (see trimmedPlane).
  if (fit.ok && !constant && !fit.bothSides && !oneSideAgrees(points, fit.plane, settings)) {
    FillPlane t;
    if (trimmedPlane(points, settings, t)) {
      fit.plane = t;
      fit.inliers = pointsNear(points, fit.plane, settings.planeInlier);
      fit.bothSides =
          static_cast<double>(fit.inliers.size()) >= settings.planeMinShare * points.size();
      fit.trimmed = true;
    }
  }
  return fit;
}

// The points of the rows whose ends in right region `label` lie inside their search band, and
// those ends.
void SlopedFacet::readRowEnds(int label, Fit& fit) const {
  for (const RowEnds& r : rows) {
    const auto [x0, x1] = band(r);
    const auto [r0, r1] = labelEndsInBand(right.labels, r, label, dmin, dmax);
    // Ends cut by the band are not the region's ends.
    if (r0 <= x0 || r1 >= x1) continue;
    // The ends' difference is the disparity at the facet's first and last pixels (both masks
    // stop kFlatReach px inside them; on a slanted facet those inner pixels are not the same
    // surface points in the two views).
    fit.points.push_back(subpixelEnd(r, label, r.l0, r0, -1)
                             .value_or(cv::Point3d(r.l0 - kFlatReach, r.y, r.l0 - r0)));
    fit.points.push_back(subpixelEnd(r, label, r.l1, r1, +1)
                             .value_or(cv::Point3d(r.l1 + kFlatReach, r.y, r.l1 - r1)));
    fit.rightEnds.emplace_back(r0, r1);
  }
}

// With `edgeViews`, an end whose edges are sharp in both views (see subpixelEdge) is the
// edges' difference at the left view's edge, when within 1.5 px of the whole-pixel one.
std::optional<cv::Point3d> SlopedFacet::subpixelEnd(const RowEnds& r, int label, int leftEnd,
                                                    int rightEnd, int step) const {
  if (edgeViews == nullptr) return std::nullopt;
  const auto inLeft = subpixelEdge(edgeViews->left.ptr<float>(r.y), edgeViews->left.cols, leftEnd,
                                   step, leftMean, sigma);
  const auto inRight =
      subpixelEdge(edgeViews->right.ptr<float>(r.y), edgeViews->right.cols, rightEnd, step,
                   right.meanGrey[static_cast<size_t>(label)], sigma / gain);
  if (!inLeft || !inRight || std::abs(*inLeft - *inRight - (leftEnd - rightEnd)) > 1.5) {
    return std::nullopt;
  }
  return cv::Point3d(*inLeft, r.y, *inLeft - *inRight);
}

// Whether a counterpart's plane is kept over the best one so far (`bestInliers` inliers): agreed
// with on both sides or on one (oneSideAgrees), on enough rows, not too steep, with more
// inliers, and within the search range over the whole region.
bool SlopedFacet::passes(const Fit& fit, size_t bestInliers) const {
  const FillPlane& fitted = fit.plane;
  if (!fit.ok || !(fit.bothSides || oneSideAgrees(fit.points, fitted, settings)) ||
      static_cast<int>(fit.inliers.size()) < 2 * settings.planeMinRows ||
      std::abs(fitted.a) > settings.planeMaxSlope || std::abs(fitted.b) > settings.planeMaxSlope ||
      fit.inliers.size() <= bestInliers) {
    return false;
  }
  // The whole region must lie inside the range (a plane's extremes on a row are its ends).
  return std::all_of(rows.begin(), rows.end(), [&](const RowEnds& r) {
    const double d0 = fitted.at(r.l0, r.y), d1 = fitted.at(r.l1, r.y);
    return std::min(d0, d1) >= dmin && std::max(d0, d1) <= dmax;
  });
}

// The span of each row of `box` the plane fills: [first, last] columns over `box`, (1, 0) for
// none.
std::vector<cv::Vec2i> SlopedFacet::filledRowSpans(const Fit& fit) const {
  const FillPlane& fitted = fit.plane;
  const std::vector<cv::Point3d>& points = fit.points;
  // A plane not kept on both sides' ends (one side's, or a trimmed fit) fills only the rows
  // one of whose ends agrees with it (a row whose ends both disagree is another surface of
  // the facet's grey joined to it), and a row whose left region runs past the counterpart's
  // end (that end beyond the plane by more than planeInlier) only where the counterpart
  // maps: x − d(x) within [r0, r1] widened by kFlatReach, x = (xr + c + b·y) / (1 − a).
  // The sub-pixel ends agree within planeInlier more often, on a facet and on a surface of
  // its grey joined to it alike: their plane is limited row by row too.
  const bool limited = fit.trimmed || !fit.bothSides || edgeViews != nullptr;
  std::vector<cv::Vec2i> rowSpans(static_cast<size_t>(box.height),
                                  limited ? cv::Vec2i(1, 0) : cv::Vec2i(0, box.width - 1));
  for (size_t k = 0; limited && k + 1 < points.size(); k += 2) {
    const cv::Point3d& first = points[k];
    const cv::Point3d& last = points[k + 1];
    const int y = static_cast<int>(first.y);
    const double firstResidual = fitted.residual(first);
    const double lastResidual = fitted.residual(last);
    if (std::abs(firstResidual) > settings.planeInlier &&
        std::abs(lastResidual) > settings.planeInlier) {
      continue;
    }
    const double denominator = 1.0 - fitted.a;
    cv::Vec2i& span = rowSpans[static_cast<size_t>(y - box.y)];
    span = cv::Vec2i(0, box.width - 1);
    if (firstResidual < -settings.planeInlier) {
      const double x =
          (fit.rightEnds[k / 2][0] - kFlatReach + fitted.c + fitted.b * y) / denominator;
      span[0] = std::max(span[0], static_cast<int>(std::ceil(x)) - box.x);
    }
    if (lastResidual > settings.planeInlier) {
      const double x =
          (fit.rightEnds[k / 2][1] + kFlatReach + fitted.c + fitted.b * y) / denominator;
      span[1] = std::min(span[1], static_cast<int>(std::floor(x)) - box.x);
    }
  }
  return rowSpans;
}

// Whether `constant` wins over the plane through `points`: a constant that explains the row ends
// as well keeps the region (a flat roof's plane has a slope of noise); one outside the plane's
// range over the region says the counterpart is another surface of the same grey.
bool SlopedFacet::constantWins(float constant, const FillPlane& plane,
                               const std::vector<cv::Point3d>& points) const {
  const auto [lowest, highest] = planeRange(plane, rows);
  if (constant < lowest - settings.planeInlier || constant > highest + settings.planeInlier) {
    return true;
  }
  const auto agree = std::count_if(points.begin(), points.end(), [&](const cv::Point3d& p) {
    return std::abs(p.z - constant) <= settings.planeInlier;
  });
  return static_cast<double>(agree) >= settings.planeMinShare * points.size();
}

}  // namespace delineo::stereo::detail
