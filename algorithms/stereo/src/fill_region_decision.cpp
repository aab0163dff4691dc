// The decision on each flat region: the constant its outline lines up at, or a sloped facet's
// plane; the region grown back to its contour and the fill written.
#include "fill_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "ordering.hpp"

namespace delineo::stereo::detail {

namespace {

// Mean value of the matches within 1.5 px of `centre`.
float clusterMean(const std::vector<float>& values, float centre) {
  double sum = 0, n = 0;
  for (const float v : values) {
    if (std::abs(v - centre) <= 1.5F) {
      sum += v;
      n += 1;
    }
  }
  return static_cast<float>(n > 0 ? sum / n : centre);
}

// Median of the matches within `reach` px of `centre` (`centre` when there are none).
float medianNear(const std::vector<float>& values, float centre, float reach) {
  std::vector<float> within;
  for (const float v : values) {
    if (std::abs(v - centre) <= reach) within.push_back(v);
  }
  if (within.empty()) return centre;
  const auto middle = within.begin() + static_cast<std::ptrdiff_t>(within.size() / 2);
  std::nth_element(within.begin(), middle, within.end());
  return *middle;
}

// The value filled for the cluster around `centre`: the median of its matches (within 1.5 px),
// then, with `refocus` > 0, the median of those within `refocus` px of that median.
float clusterMedian(const std::vector<float>& values, float centre, double refocus) {
  const float median = medianNear(values, centre, 1.5F);
  return refocus > 0 ? medianNear(values, median, static_cast<float>(refocus)) : median;
}

// Where the ring error `errorAt` is lowest on a 0.05 px grid within `reach` px of `centre`.
template <class ErrorAt>
float ringMinimumNear(const ErrorAt& errorAt, float centre, double reach) {
  const int steps = static_cast<int>(std::floor(reach / 0.05 + 1e-9));
  float lowestAt = centre;
  double lowest = errorAt(centre);
  for (int k = -steps; k <= steps; ++k) {
    if (k == 0) continue;
    const float value = centre + 0.05f * static_cast<float>(k);
    const double e = errorAt(value);
    if (e < lowest) {
      lowest = e;
      lowestAt = value;
    }
  }
  return lowestAt;
}

float medianOfThree(float a, float b, float c) {
  return std::max(std::min(a, b), std::min(std::max(a, b), c));
}

// Centres (integer disparities) of the two largest clusters of ±1 px among `values`; the second
// is at least 3 px from the first and holds at least `minCount` values, else absent.
std::vector<int> twoLargestClusters(const std::vector<float>& values, int dmin, int dmax,
                                    int minCount) {
  const int bins = dmax - dmin + 1;
  std::vector<int> histogram(static_cast<size_t>(bins), 0);
  for (const float v : values) {
    const int k = std::clamp(static_cast<int>(std::lround(v)) - dmin, 0, bins - 1);
    ++histogram[static_cast<size_t>(k)];
  }
  auto clusterAt = [&](int k) {
    int c = 0;
    for (int j = std::max(0, k - 1); j <= std::min(bins - 1, k + 1); ++j) {
      c += histogram[static_cast<size_t>(j)];
    }
    return c;
  };
  int first = 0;
  for (int k = 1; k < bins; ++k) {
    if (clusterAt(k) > clusterAt(first)) first = k;
  }
  int second = -1;
  for (int k = 0; k < bins; ++k) {
    if (std::abs(k - first) > 2 && (second < 0 || clusterAt(k) > clusterAt(second))) second = k;
  }
  std::vector<int> centres{first + dmin};
  if (second >= 0 && clusterAt(second) >= minCount) centres.push_back(second + dmin);
  return centres;
}

// The cluster candidates of a region can be too close in outline error to pass the contrast
// test (a roof of nearly the ground's grey). Scanning every integer disparity of the range then
// confirms `best` when the scan's minimum is within `reach` px of it and at most `agreement` ×
// the lowest error found 3 px or more away: the outline lines up there and nowhere else.
// (`best` is a sub-pixel cluster mean and a large roof's ring error is flat within a pixel of
// its minimum: the integer minimum can lie 1.4 px away.)
template <typename ErrorAt>
bool scanConfirms(const ErrorAt& errorAt, int dmin, int dmax, float best, double agreement,
                  double reach) {
  std::vector<double> errors(static_cast<size_t>(dmax - dmin + 1));
  for (int d = dmin; d <= dmax; ++d)
    errors[static_cast<size_t>(d - dmin)] = errorAt(static_cast<float>(d));
  const auto lowest = std::min_element(errors.begin(), errors.end());
  const int found = dmin + static_cast<int>(lowest - errors.begin());
  if (std::abs(static_cast<double>(found) - best) > reach || *lowest >= 1e29) return false;
  double other = 1e30;
  for (int d = dmin; d <= dmax; ++d) {
    if (std::abs(d - found) > 2) other = std::min(other, errors[static_cast<size_t>(d - dmin)]);
  }
  return *lowest <= agreement * other;
}

// Whether the outline lines up clearly better somewhere else than at `best`: some integer
// disparity more than 2 px from it with a ring error below `ratio` × `bestError`.
// `errorAt(d, stopAbove)` may give up (any value ≥ stopAbove) once the error is sure to exceed it.
template <typename ErrorAt>
bool scanFindsBetterElsewhere(const ErrorAt& errorAt, int dmin, int dmax, float best,
                              double bestError, double ratio) {
  const double limit = ratio * bestError;
  for (int d = dmin; d <= dmax; ++d) {
    if (std::abs(d - best) > 2 && errorAt(static_cast<float>(d), limit) < limit) return true;
  }
  return false;
}

// The flat region stops 2 px short of its contour (its 5x5 windows reach across it): grow it
// back, 4-connected and at most `growReach` px, over the pixels that look like the region next to
// them (within growSigmas noise sigmas of the mean of the region pixels in their 7x7
// neighbourhood) and that match at the region's disparity on their own (|left − mapped right|
// within growPhotometric noise sigmas). The contour's mixed pixel fails the first test, the
// surface beyond it both: the fill then ends at the image contour.
void growToContour(const cv::Mat& left, const cv::Mat& right, const cv::Rect& box,
                   const cv::Mat& region, const FillPlane& plane, double gain, double offset,
                   double sigma, const RegionFillSettings& settings, cv::Mat& grown) {
  cv::Mat leftBox = left(box).clone();
  cv::patchNaNs(leftBox, 0.0);
  cv::Mat regionF, sum, count;
  region.convertTo(regionF, CV_32F, 1.0 / 255.0);
  cv::boxFilter(leftBox.mul(regionF), sum, CV_32F, {7, 7}, {-1, -1}, false);
  cv::boxFilter(regionF, count, CV_32F, {7, 7}, {-1, -1}, false);
  const auto like = [&](int x, int y) {
    const float a = left.at<float>(box.y + y, box.x + x);
    const int xr = box.x + x - static_cast<int>(std::lround(plane.at(box.x + x, box.y + y)));
    if (!std::isfinite(a) || xr < 0 || xr >= right.cols) return false;
    const float b = right.at<float>(box.y + y, xr);
    const float n = count.at<float>(y, x);
    if (!std::isfinite(b) || n < 1.0F) return false;
    return std::abs(a - sum.at<float>(y, x) / n) <= settings.growSigmas * sigma &&
           std::abs(a - (gain * b + offset)) <= settings.growPhotometric * sigma;
  };
  for (int step = 0; step < settings.growReach; ++step) {
    const cv::Mat before = grown.clone();
    for (int y = 0; y < box.height; ++y) {
      for (int x = 0; x < box.width; ++x) {
        if (before.at<uchar>(y, x)) continue;
        const bool touches = (x > 0 && before.at<uchar>(y, x - 1)) ||
                             (x + 1 < box.width && before.at<uchar>(y, x + 1)) ||
                             (y > 0 && before.at<uchar>(y - 1, x)) ||
                             (y + 1 < box.height && before.at<uchar>(y + 1, x));
        if (touches && like(x, y)) grown.at<uchar>(y, x) = 255;
      }
    }
  }
}

// The 2 px on both sides of a region's outline (CV_8U 0/255 mask in, same size out).
cv::Mat outlineRing(const cv::Mat& region) {
  cv::Mat outer, inner;
  cv::dilate(region, outer, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
  cv::erode(region, inner, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}), {-1, -1}, 1,
            cv::BORDER_CONSTANT, 0);
  return outer & ~inner;
}

// The matches left of `region` (in `box`) on its rows that `plane` filled in would hide in the
// right view by the ordering check's test (hides(), with its default settings: u − d(u) >
// x − plane(x) + 1 and d(u) at least 2 px below the plane, x the row's first region pixel).
// Looked for up to `reach` px left of the region.
long matchesHiddenBy(const FillPlane& plane, const cv::Mat& region, const cv::Rect& box,
                     const cv::Mat& disparity, int reach) {
  const OrderingSettings ordering;
  long hidden = 0;
  for (int y = 0; y < box.height; ++y) {
    const uchar* m = region.ptr<uchar>(y);
    const uchar* first = std::find_if(m, m + box.width, [](uchar v) { return v != 0; });
    if (first == m + box.width) continue;
    const int x = box.x + static_cast<int>(first - m), row = box.y + y;
    const double value = plane.at(x, row);
    const float* d = disparity.ptr<float>(row);
    for (int u = x - 1; u >= 0 && u >= x - reach; --u) {
      if (d[u] == d[u] && hides<double>(x - value, value, u - d[u], d[u], ordering)) ++hidden;
    }
  }
  return hidden;
}

// The decision on one flat region, in its steps: the region and the matches around it (at
// construction); the constant of its outline's matches (outlineConstant); the plane or constant
// it is filled with (fillPlane); the region grown to its contour (grownRegion) and the fill
// written (write).
struct RegionDecision : RegionFillShared {
  RegionDecision(const RegionFillShared& shared, int label, const cv::Rect& regionBox);

  std::optional<float> outlineConstant();
  std::optional<FillPlane> fillPlane(const std::optional<float>& constant);
  cv::Mat grownRegion(const FillPlane& plane) const;
  int write(const FillPlane& plane, const cv::Mat& grown) const;

  // The constant's parts.
  double ringErrorUnder(const std::pair<double, double>& map, const FillPlane& plane,
                        double stopAboveSum) const;
  double planeRingError(const FillPlane& plane, double stopAboveSum = 1e300) const;
  double ringError(float value) const;
  std::optional<float> edgeConstantNear(double reference, bool decide = false) const;
  struct Ranking {
    float best = 0;
    double bestError = 1e30, otherError = 1e30;
  };
  Ranking rankCandidates(const std::vector<int>& centres) const;
  void takeCoreWhenClearer(const std::vector<int>& centres, Ranking& ranked);
  std::optional<float> decidedByEdges(float best);
  std::optional<float> decideConstant();
  float constantNear(float best) const;
  // The plane's parts.
  std::optional<FillPlane> planeOrConstant(const std::optional<float>& constant);
  bool slopedFacet(const std::optional<float>& constant, FillPlane& plane);
  bool hidesTooMuch(const FillPlane& p) const;
  void keepRowSpans(const std::vector<cv::Vec2i>& rowSpans);
  void lineUpOffset(FillPlane& plane) const;
  // The fill's part.
  bool fillExplainsAsWell(int x, int y, float own, double value) const;

  const int r;         // the region's label
  const cv::Rect box;  // its bounding box grown by 4 px, within the image
  cv::Mat region;      // over `box`: the region (its core when that lines up clearly better)
  cv::Mat ring;        // its outline ring
  // The matches within 3 px of the region, and those of them on it or beside it on its rows.
  std::vector<float> matches, matchesBeside;
  float lowestMatch = std::numeric_limits<float>::infinity();
  float highestMatch = -std::numeric_limits<float>::infinity();
  bool inOwnLight = false;         // ring errors in the region's own light (outlineConstant)
  double constantError = 0;        // the constant's error on the (final) ring
  double candidateError = 1e30;    // the best candidate's, filled or not
  bool failedPhotometric = false;  // the best candidate's ring error was above the limit
};

RegionDecision::RegionDecision(const RegionFillShared& shared, int label, const cv::Rect& regionBox)
    : RegionFillShared(shared), r(label), box(regionBox) {
  region = labels(box) == r;
  cv::Mat near, beside;
  cv::dilate(region, near, cv::getStructuringElement(cv::MORPH_RECT, {7, 7}));
  cv::dilate(region, beside, cv::getStructuringElement(cv::MORPH_RECT, {7, 1}));
  ring = outlineRing(region);
  for (int y = 0; y < box.height; ++y) {
    const uchar* n = near.ptr<uchar>(y);
    const uchar* b = beside.ptr<uchar>(y);
    const float* d = disparity.ptr<float>(box.y + y) + box.x;
    for (int x = 0; x < box.width; ++x) {
      if (n[x] && std::isfinite(d[x])) {
        matches.push_back(d[x]);
        lowestMatch = std::min(lowestMatch, d[x]);
        highestMatch = std::max(highestMatch, d[x]);
        if (b[x]) matchesBeside.push_back(d[x]);
      }
    }
  }
}

// Mean |left − mapped right| over the ring at the plane's disparity, mapped by `map` (gain,
// offset). 1e30 as soon as the sum exceeds `stopAboveSum` (a bound on the mean times the
// ring's size: the mean is sure to exceed the bound; the scans of the whole range mostly meet
// such errors). In the region's own light when `inOwnLight` (see outlineConstant).
double RegionDecision::ringErrorUnder(const std::pair<double, double>& map, const FillPlane& plane,
                                      double stopAboveSum) const {
  if (inOwnLight) return ringErrorInOwnLight(left, right, ring, box, plane, map);
  double sum = 0, n = 0;
  const bool complete = visitRingResiduals(
      left, right, ring, box, plane, map,
      [&](double residual) {
        sum += std::abs(residual);
        n += 1;
      },
      [&] { return sum > stopAboveSum; });
  return complete && n > 0 ? sum / n : 1e30;
}

double RegionDecision::planeRingError(const FillPlane& plane, double stopAboveSum) const {
  return ringErrorUnder(imagesMap, plane, stopAboveSum);
}

// A constant's error on the current ring.
double RegionDecision::ringError(float value) const {
  return planeRingError(FillPlane{value, 0, 0});
}

// The constant its edges in both views give a plain region, when edgeMinSamples or more row
// ends give one within edgeReach of `reference` (see RegionFillSettings::edgeMinSamples).
// `decide`: only when the edges alone can decide (see RegionFillSettings::edgeDecideShare):
// most row ends read agree, on both sides of the region.
std::optional<float> RegionDecision::edgeConstantNear(double reference, bool decide) const {
  if (settings.edgeMinSamples <= 0 || (decide && settings.edgeDecideShare <= 0)) {
    return std::nullopt;
  }
  const EdgeReading edges =
      edgeDisparity(left, right, region, box, rightFlatRegionsOf(), matchedGain, matchedOffset,
                    sigma, dmin, dmax, static_cast<float>(reference), settings.edgeReach);
  if (edges.samples < settings.edgeMinSamples ||
      std::abs(edges.value - reference) > settings.edgeReach) {
    return std::nullopt;
  }
  if (decide && (edges.samples < settings.edgeDecideShare * edges.read ||
                 edges.fromLeftEnds < settings.edgeDecidePerSide ||
                 edges.samples - edges.fromLeftEnds < settings.edgeDecidePerSide)) {
    return std::nullopt;
  }
  return static_cast<float>(edges.value);
}

// The cluster candidates ranked by their error on the current ring.
RegionDecision::Ranking RegionDecision::rankCandidates(const std::vector<int>& centres) const {
  Ranking k;
  for (const int centre : centres) {
    const float value = clusterMean(matches, static_cast<float>(centre));
    const double e = ringError(value);
    if (e < k.bestError) {
      k.otherError = k.bestError;
      k.bestError = e;
      k.best = value;
    } else {
      k.otherError = std::min(k.otherError, e);
    }
  }
  return k;
}

// Thin flat parts joined to the region (a facade's plain bands between its window rows,
// joined to the roof above) put their own outline, which does not line up at the roof's
// disparity, into the ring. When the region's core (without them) lines up clearly better,
// the core is the region.
void RegionDecision::takeCoreWhenClearer(const std::vector<int>& centres, Ranking& ranked) {
  const int area = stats.at<int>(r, cv::CC_STAT_AREA);
  const cv::Mat core = flatCores(box) & region;
  const int coreArea = cv::countNonZero(core);
  if (coreArea < area && coreArea >= settings.coreMinShare * area) {
    const cv::Mat wholeRing = ring;
    ring = outlineRing(core);
    const Ranking onCore = rankCandidates(centres);
    if (onCore.bestError < settings.coreErrorRatio * ranked.bestError) {
      region = core;
      ranked = onCore;
    } else {
      ring = wholeRing;
    }
  }
}

// Where the ring alone cannot establish the candidate, the region's own edges in both
// views may still tell its disparity (see RegionFillSettings::edgeDecideShare), when the
// outline lines up there within the photometric limit. Sim seed 35 600²: a plain
// diamond-shaped roof at 31.47 px, 3 711 px, unmatched but 257 of them, whose ring lines
// up about as well elsewhere (plain surroundings: the scan below does not confirm the
// candidate); 65 of its 76 row ends read agree (16 at left ends), at 31.40: 3 578 of its
// pixels within 0.3 px, edge 84.4 → 94.4 %. Sim seed 29 1000²: a plain roof at 21.91 whose
// candidate, the matches' cluster mean 21.46, misses the limit (ring error 11.27 against
// 10.88; its edges give 21.82, 10.15): edge 86.8 → 89.7 %. A facet sloping along the rows
// agrees on one side only (sim seeds 10 1000², 12 and 34 600²: all of 31-78 agreeing ends on
// one side; filled level, bad-1 +0.2-0.5 point).
std::optional<float> RegionDecision::decidedByEdges(float best) {
  const auto edges = edgeConstantNear(best, true);
  if (!edges) return std::nullopt;
  const double error = ringError(*edges);
  if (!(error <= settings.photometric * sigma)) return std::nullopt;
  constantError = error;
  return edges;
}

// The constant disparity of the outline's matches, when the outline lines up there.
std::optional<float> RegionDecision::decideConstant() {
  if (static_cast<int>(matches.size()) < settings.minMatched) return std::nullopt;
  const std::vector<int> centres = twoLargestClusters(matches, dmin, dmax, settings.minMatched / 2);
  Ranking ranked = rankCandidates(centres);
  if (!flatCores.empty() && ranked.bestError < 1e29) takeCoreWhenClearer(centres, ranked);
  const auto [best, bestError, otherError] = ranked;
  candidateError = bestError;
  if (bestError > settings.photometric * sigma) {
    failedPhotometric = true;
    return decidedByEdges(best);
  }
  // The scan compares errors within a few tenths of each other across the range, so it reads
  // the right view through the matches' grey map: the images' moments can be off by several
  // grey levels on a dark roof, the same at every disparity, which flattens the scan (seed
  // 14 1000²: gain 1.040 and offset 1.17 against the matches' 1.086 and -6.44, the
  // simulator's 1.087 and -6.5; a 7 077 px dark roof's minimum was 0.936 × the lowest 3 px
  // or more away, 0.860 through the matches' map, with 0.93 needed).
  const auto scanError = [&](float value) {
    return ringErrorUnder(matchesMap, FillPlane{value, 0, 0}, 1e300);
  };
  if (bestError > settings.contrast * otherError &&
      !(settings.scanAgreement > 0 &&
        scanConfirms(scanError, dmin, dmax, best, settings.scanAgreement, settings.scanReach))) {
    return decidedByEdges(best);
  }
  const double ringPixels = cv::countNonZero(ring);
  const auto vetoError = [&](float value, double stopAbove) {
    return planeRingError(FillPlane{value, 0, 0}, stopAbove * ringPixels);
  };
  if (settings.scanVeto > 0 &&
      scanFindsBetterElsewhere(vetoError, dmin, dmax, best, bestError, settings.scanVeto)) {
    return std::nullopt;
  }
  const float value = constantNear(best);
  constantError = ringError(value);
  return value;
}

// The value filled in for the candidate `best`.
// The candidates are ranked by their clusters' means; the value filled in is the chosen
// cluster's median, refocused (see refocusReach). The matches next to a plain roof's
// outline are skewed: some windows along it match 1-1.7 px too far (seed 5's plain roof,
// filled +0.57 px off with the mean, +0.39 with the median; see docs/stereo.md, step 10).
// It is taken from the matches on the region's rows when there are enough:
// above and below it, along an outline parallel to the epipolar lines, the windows hold
// no step across the lines to fix them, and those matches ran 0.8-1.8 px high on seed 5's
// plain roof (filled 0.54 px high once the wide intervals' uniqueness test had rejected
// most of the good matches beside it).
float RegionDecision::constantNear(float best) const {
  const std::vector<float>& valueFrom =
      static_cast<int>(matchesBeside.size()) >= settings.minMatched ? matchesBeside : matches;
  float value = clusterMedian(valueFrom, best, settings.refocusReach);
  if (settings.ringArbiterReach > 0) {
    const auto errorAt = [&](float at) { return ringError(at); };
    value = medianOfThree(value, best, ringMinimumNear(errorAt, best, settings.ringArbiterReach));
  }
  // The region's edges in both views, when enough of them are sharp, over the three
  // estimates of the matches and the ring (see RegionFillSettings::edgeMinSamples).
  if (const auto edges = edgeConstantNear(best)) value = *edges;
  return value;
}

// The constant of the outline's matches (decideConstant). A shaded region whose outline lines up
// nowhere through the images' grey map is decided again in its own light (see
// RegionFillSettings::shadowOwnLight); its constantError is then an error in its own light,
// which a plane (measured through the map) does not beat.
std::optional<float> RegionDecision::outlineConstant() {
  if (const auto found = decideConstant()) return found;
  if (!settings.shadowOwnLight || !failedPhotometric ||
      !(cv::mean(left(box), region)[0] < leftMedian)) {
    return std::nullopt;
  }
  inOwnLight = true;
  const auto found = decideConstant();
  inOwnLight = false;
  if (!found) return std::nullopt;
  const auto agreeing = std::count_if(matchesBeside.begin(), matchesBeside.end(),
                                      [&](float d) { return std::abs(d - *found) <= 1.5f; });
  if (agreeing < settings.ownLightAgreement * static_cast<double>(matchesBeside.size())) {
    return std::nullopt;
  }
  return found;
}

// What the region is filled with: the plane of a sloped facet or the constant (see
// planeOrConstant); none when neither passed.
std::optional<FillPlane> RegionDecision::fillPlane(const std::optional<float>& constant) {
  if (settings.planeMinRows > 0) return planeOrConstant(constant);
  if (!constant) return std::nullopt;
  FillPlane plane;
  plane.c = *constant;
  return plane;
}

// A plane's counterpart is found by grey level anywhere in the range: a plain rooftop box
// (23 px on a roof at 20, 2000²) took a copy of itself 126 px away, whose outline lines up
// as well. Filled there, it would hide in the right view the roof's matches left of it on
// its rows, 14 times its area; a real facet hides at most about its own area (the
// ground it hides beside a roof is mostly unmatched already).
bool RegionDecision::hidesTooMuch(const FillPlane& p) const {
  return settings.planeHiddenRatio > 0 &&
         matchesHiddenBy(p, region, box, disparity, dmax - dmin) >
             settings.planeHiddenRatio * cv::countNonZero(region);
}

// The plane of the region as a sloped facet (slopedFacetPlane), in `plane`, the region then cut
// to the row spans it was fitted on; false when none passed.
bool RegionDecision::slopedFacet(const std::optional<float>& constant, FillPlane& plane) {
  const RightFlatRegions& rightFlat = rightFlatRegionsOf();
  const double leftMean = cv::mean(left(box), region)[0];
  bool oneSided = false;
  std::vector<cv::Vec2i> rowSpans;
  // Where no constant passed, the plane through the row ends' sub-pixel edges first (see
  // RegionFillSettings::planeEdgeEnds), kept when it passes the tests below that do not
  // involve a constant; else the plane through the whole-pixel ends.
  bool sloped = false;
  if (settings.planeEdgeEnds && !constant) {
    const EdgeViews views{left, right};
    FillPlane edgePlane;
    bool edgeOneSided = false;
    std::vector<cv::Vec2i> edgeRowSpans;
    sloped = slopedFacetPlane(region, box, rightFlat, leftMean, matchedGain, matchedOffset, sigma,
                              dmin, dmax, settings, constant, edgePlane, &edgeOneSided,
                              &edgeRowSpans, &views) &&
             !hidesTooMuch(edgePlane) &&
             (settings.planeCandidateRatio <= 0 ||
              planeRingError(edgePlane) < settings.planeCandidateRatio * candidateError);
    if (sloped) {
      plane = edgePlane;
      oneSided = edgeOneSided;
      rowSpans = std::move(edgeRowSpans);
    }
  }
  if (!sloped) {
    sloped = slopedFacetPlane(region, box, rightFlat, leftMean, matchedGain, matchedOffset, sigma,
                              dmin, dmax, settings, constant, plane, &oneSided, &rowSpans) &&
             !hidesTooMuch(plane);
  }
  if (sloped) keepRowSpans(rowSpans);
  if (sloped && oneSided) lineUpOffset(plane);
  return sloped;
}

// The region cut to the row spans (over `box`) its plane was fitted on.
void RegionDecision::keepRowSpans(const std::vector<cv::Vec2i>& rowSpans) {
  for (int y = 0; y < box.height; ++y) {
    uchar* m = region.ptr<uchar>(y);
    const cv::Vec2i span = rowSpans[static_cast<size_t>(y)];
    for (int x = 0; x < box.width; ++x) {
      if (x < span[0] || x > span[1]) m[x] = 0;
    }
  }
}

// A plane fixed mostly by one side's row ends carries their bias (the facet above: +1 px,
// the ring error's minimum at c − 1): its offset is set where the outline lines up best,
// within planeInlier of the fit.
void RegionDecision::lineUpOffset(FillPlane& plane) const {
  const FillPlane fitted = plane;
  double lowest = planeRingError(plane);
  for (double shift = -settings.planeInlier; shift <= settings.planeInlier + 1e-9; shift += 0.25) {
    const FillPlane shifted{fitted.c + shift, fitted.a, fitted.b};
    const double e = planeRingError(shifted);
    if (e < lowest) {
      lowest = e;
      plane = shifted;
    }
  }
}

// The sloped facet's plane (slopedFacet) where it passes the tests below, else the constant;
// none when neither passed.
std::optional<FillPlane> RegionDecision::planeOrConstant(const std::optional<float>& constant) {
  FillPlane plane;
  const bool sloped = slopedFacet(constant, plane);
  // Over a constant the outline lines up at, the plane must line it up clearly better: a
  // nearly level plane through a flat roof's row ends can edge out the constant by noise
  // (seed 3 1000²: 4.3475 against 4.3573 once the constant is refocused; seed 18 600²: a
  // plane rising 0.8 px over the roof, 4.951 against 5.142, filled it 0.6 px high; on 24
  // simulated scenes, the planes sloping 0.1 px per px or more that beat their constant did
  // so by 5.5 % or more).
  // Nor does a plane that changes by less than planeMinSpan over the region's extent (its
  // bounding box): such a plane is a flat roof's row ends fitted with a slope of noise,
  // and can still line the ring up better than the constant (sim seed 14 1000²: a roof at
  // 38.1 took a plane spanning 1.4 px, ring error 3.16 against the constant's 4.98, filled
  // 0.3-1.6 px low; bad-1 0.86 -> 0.62 % without it). 1.5 px: between that plane and the
  // 0.03 px per column facet of the tests (2.0 px over its flat region), which a constant
  // would miss by up to 1 px. (At 2.0 and 2.5 px, the sim's roof RMS gains one scene more,
  // seed 15 600², and that facet is lost.)
  const double span = std::abs(plane.a) * stats.at<int>(r, cv::CC_STAT_WIDTH) +
                      std::abs(plane.b) * stats.at<int>(r, cv::CC_STAT_HEIGHT);
  // Nor, over a constant, a plane that rises above all the matches around the region or
  // sinks below them: the constant says the region lies among them. A plain rooftop box and
  // its shadow on the roof, of the same grey, form one region whose counterpart in the right
  // view a dark wall splits; the row ends gave a plane rising 0.47 px per column, up to 12 px
  // above the roof and 7.6 px above the highest match around (51.4-59.0), over the constant
  // 57.95 (sim seed 24 1000²: roof RMS 0.330 -> 0.215 px once refused). Where no constant
  // passed, the matches around may all be the ground, and a roof's facets rise above them
  // (test_match_fill.cpp's plain facets on textured ground: this rule left them unfilled).
  const auto outsideMatches = [&] {
    const auto [lowest, highest] = planeRange(plane, regionRowEnds(region, box, 0));
    return highest > highestMatch + settings.planeInlier ||
           lowest < lowestMatch - settings.planeInlier;
  };
  if (!sloped || (constant && span < settings.planeMinSpan) ||
      (constant && settings.planeWithinMatches && outsideMatches()) ||
      (constant && !(planeRingError(plane) < settings.planeMargin * constantError)) ||
      (!constant && settings.planeCandidateRatio > 0 &&
       !(planeRingError(plane) < settings.planeCandidateRatio * candidateError))) {
    if (!constant) return std::nullopt;
    plane = FillPlane{*constant, 0, 0};
  } else if (!constant && span < settings.planeMinSpan) {
    // Taken where no constant passed, a plane that changes by less than planeMinSpan over the
    // region is a flat roof's row ends fitted with a slope of noise, as above (sim seed 39
    // 600²: a C-shaped plain roof at 26.74 whose matches around are mostly the ground's,
    // given a plane of 0.8 px span, 27.22 at its centroid): the region takes the constant
    // its edges give around the plane's value at its centroid (26.83 there; see
    // edgeMinSamples), else that value.
    const double centreValue = plane.at(centroids.at<double>(r, 0), centroids.at<double>(r, 1));
    const auto edges = edgeConstantNear(centreValue);
    plane = FillPlane{edges ? *edges : static_cast<float>(centreValue), 0, 0};
  } else if (!constant) {
    // Any other plane taken where no constant passed must line the outline up clearly better
    // (planeMargin) than the constant the region's edges give around its centroid value, as
    // a plane must over a constant that passed: a plain roof nearly level, whose row ends
    // were fitted with a slope (sim seed 24 600²: a roof at 53.45 given a plane rising 2.7
    // px over it, 52.65 at its centroid, ring error 14.67 against 14.57 for its edges'
    // 53.33).
    const double centreValue = plane.at(centroids.at<double>(r, 0), centroids.at<double>(r, 1));
    if (const auto edges = edgeConstantNear(centreValue)) {
      const FillPlane level{*edges, 0, 0};
      if (!(planeRingError(plane) < settings.planeMargin * planeRingError(level))) {
        plane = level;
      }
    }
  }
  return plane;
}

// The region grown to its contour (see RegionFillSettings::growReach).
cv::Mat RegionDecision::grownRegion(const FillPlane& plane) const {
  cv::Mat grown = region.clone();
  if (settings.growReach > 0) {
    growToContour(left, right, box, region, plane, gain, offset, sigma, settings, grown);
  }
  return grown;
}

// Whether the fill's value explains the inRegionWindow² window at (x, y) (image
// coordinates) about as well as the pixel's own disparity `own`: mean |left − mapped right|,
// both at whole disparities, at most inRegionRatio × the own one. False where the window
// leaves either view or meets nodata.
bool RegionDecision::fillExplainsAsWell(int x, int y, float own, double value) const {
  const int w = settings.inRegionWindow / 2;
  const int atOwn = static_cast<int>(std::lround(own));
  const int atFill = static_cast<int>(std::lround(value));
  const int lowest = std::min(atOwn, atFill), highest = std::max(atOwn, atFill);
  if (x - w < 0 || y - w < 0 || x + w >= left.cols || y + w >= left.rows || x - w - highest < 0 ||
      x + w - lowest >= right.cols) {
    return false;
  }
  double errorAtFill = 0, errorAtOwn = 0;
  for (int v = y - w; v <= y + w; ++v) {
    const float* a = left.ptr<float>(v);
    const float* b = right.ptr<float>(v);
    for (int u = x - w; u <= x + w; ++u) {
      errorAtFill += std::abs(a[u] - (gain * b[u - atFill] + offset));
      errorAtOwn += std::abs(a[u] - (gain * b[u - atOwn] + offset));
    }
  }
  // (NaN, from nodata, fails the comparison.)
  return errorAtFill <= settings.inRegionRatio * errorAtOwn;
}

// Writes the fill's disparities (and scores) over the grown region; the pixels written.
int RegionDecision::write(const FillPlane& plane, const cv::Mat& grown) const {
  int filled = 0;
  for (int y = 0; y < box.height; ++y) {
    const uchar* m = grown.ptr<uchar>(y);
    const uchar* inRegion = region.ptr<uchar>(y);
    const float* a = left.ptr<float>(box.y + y) + box.x;
    float* d = disparity.ptr<float>(box.y + y) + box.x;
    float* s = score.ptr<float>(box.y + y) + box.x;
    const float* b = right.ptr<float>(box.y + y);
    for (int x = 0; x < box.width; ++x) {
      if (!m[x]) continue;
      const double value = plane.at(box.x + x, box.y + y);
      // (A plane may leave the range a little beyond the region's row ends.)
      if (value < dmin || value > dmax) continue;
      const int xr = box.x + x - static_cast<int>(std::lround(value));
      if (xr < 0 || xr >= right.cols || !std::isfinite(b[xr])) continue;
      if (std::isfinite(d[x])) {
        // A region pixel matched far off the fill: a window that reached another surface's
        // texture (see inRegionReplaceOff).
        if (inRegion[x]) {
          if (settings.inRegionReplaceOff <= 0 ||
              std::abs(d[x] - value) < settings.inRegionReplaceOff ||
              !fillExplainsAsWell(box.x + x, box.y + y, d[x], value)) {
            continue;
          }
          d[x] = static_cast<float>(value);
          s[x] = fillScore;
          ++filled;
          continue;
        }
        // A grown pixel matched elsewhere (the far side's disparity carried over the outline
        // by a window that reached across it) is taken when the region's disparity explains
        // its grey level better than its own.
        if (std::abs(d[x] - value) < 2.0) continue;
        const int xo = box.x + x - static_cast<int>(std::lround(d[x]));
        if (xo < 0 || xo >= right.cols || !std::isfinite(b[xo])) continue;
        if (!(std::abs(a[x] - (gain * b[xo] + offset)) >
              std::abs(a[x] - (gain * b[xr] + offset)))) {
          continue;
        }
      }
      d[x] = static_cast<float>(value);
      s[x] = fillScore;
      ++filled;
    }
  }
  return filled;
}

}  // namespace

std::optional<FilledRegion> decideAndFillRegion(const RegionFillShared& shared, int label,
                                                const cv::Rect& box, int& filled) {
  RegionDecision decision(shared, label, box);
  const std::optional<float> constant = decision.outlineConstant();
  const std::optional<FillPlane> plane = decision.fillPlane(constant);
  if (!plane) return std::nullopt;
  const cv::Mat grown = decision.grownRegion(*plane);
  filled = decision.write(*plane, grown);
  return FilledRegion{box, grown, *plane};
}

}  // namespace delineo::stereo::detail
