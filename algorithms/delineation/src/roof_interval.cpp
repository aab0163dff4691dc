#include "delineo/delineation/roof_interval.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"

namespace delineo::delineation {

using core::Error;
using core::ErrorCode;

void RoofIntervalParams::validate() const { core::checkDeclaredRanges(*this); }

namespace {

// The polygon's neighbourhood: its box grown by `margin` (clipped to the image), the polygon
// rasterised there, and each pixel's distance to the polygon's inside and outside.
struct Neighbourhood {
  cv::Rect roi;
  cv::Mat inside;        // CV_8U, 255 inside the polygon (holes excluded)
  cv::Mat depth;         // CV_32F, distance of an inside pixel to the nearest outside pixel
  cv::Mat outerDistance; // CV_32F, distance of a pixel to the polygon's outer ring's inside
};

Neighbourhood neighbourhood(const cv::Mat& disparity, const core::Polygon& polygon, double margin) {
  if (disparity.empty() || disparity.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput, "the disparity map must be single-band float32");
  }
  Neighbourhood n;
  if (polygon.outer.size() < 3) return n;
  const cv::Rect2d box = core::boundingBox(polygon.outer);
  const int m = static_cast<int>(std::ceil(margin)) + 2;
  const int x0 = static_cast<int>(std::floor(box.x)) - m, y0 = static_cast<int>(std::floor(box.y)) - m;
  const int x1 = static_cast<int>(std::ceil(box.x + box.width)) + m;
  const int y1 = static_cast<int>(std::ceil(box.y + box.height)) + m;
  n.roi = cv::Rect(x0, y0, x1 - x0, y1 - y0) & cv::Rect(0, 0, disparity.cols, disparity.rows);
  if (n.roi.empty()) return n;
  core::Polygon local = polygon;
  const cv::Point2d shift(n.roi.x, n.roi.y);
  for (auto& p : local.outer) p -= shift;
  for (auto& hole : local.holes) {
    for (auto& p : hole) p -= shift;
  }
  n.inside = core::rasterize(local, n.roi.size());
  // Pixels outside the image count as outside: pad by one pixel before the distance transform.
  cv::Mat padded;
  cv::copyMakeBorder(n.inside, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::distanceTransform(padded, n.depth, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  n.depth = n.depth(cv::Rect(1, 1, n.roi.width, n.roi.height)).clone();
  local.holes.clear();
  const cv::Mat outer = core::rasterize(local, n.roi.size());
  cv::distanceTransform(outer == 0, n.outerDistance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return n;
}

std::vector<float> samples(const cv::Mat& disparity, const cv::Rect& roi, const cv::Mat& mask) {
  std::vector<float> out;
  for (int y = 0; y < roi.height; ++y) {
    const float* d = disparity.ptr<float>(roi.y + y) + roi.x;
    const uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < roi.width; ++x) {
      if (m[x] != 0 && std::isfinite(d[x])) out.push_back(d[x]);
    }
  }
  return out;
}

// Histogram of `values` in bins of `width` starting at `origin`.
struct Histogram {
  double origin = 0.0, width = 1.0;
  std::vector<double> counts;
  double centre(size_t i) const { return origin + (static_cast<double>(i) + 0.5) * width; }
};

Histogram histogram(const std::vector<float>& values, double width) {
  Histogram h;
  h.width = width;
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  h.origin = std::floor(*lo / width) * width;
  h.counts.assign(static_cast<size_t>((*hi - h.origin) / width) + 1, 0.0);
  for (float v : values) {
    const size_t i = std::min(h.counts.size() - 1, static_cast<size_t>((v - h.origin) / width));
    h.counts[i] += 1.0;
  }
  return h;
}

std::vector<double> smoothed(const std::vector<double>& counts, double sigmaBins) {
  if (sigmaBins <= 0.0) return counts;
  const int r = static_cast<int>(std::ceil(3.0 * sigmaBins));
  std::vector<double> kernel(static_cast<size_t>(2 * r + 1));
  for (int k = -r; k <= r; ++k) kernel[static_cast<size_t>(k + r)] = std::exp(-0.5 * k * k / (sigmaBins * sigmaBins));
  std::vector<double> out(counts.size(), 0.0);
  const int n = static_cast<int>(counts.size());
  for (int i = 0; i < n; ++i) {
    for (int k = -r; k <= r; ++k) {
      const int j = i + k;
      if (j >= 0 && j < n) out[static_cast<size_t>(i)] += kernel[static_cast<size_t>(k + r)] * counts[static_cast<size_t>(j)];
    }
  }
  return out;
}

// Sum of the counts within `halfBins` bins of each bin.
std::vector<double> windowSums(const std::vector<double>& counts, int halfBins) {
  const int n = static_cast<int>(counts.size());
  std::vector<double> prefix(counts.size() + 1, 0.0);
  for (int i = 0; i < n; ++i) prefix[static_cast<size_t>(i + 1)] = prefix[static_cast<size_t>(i)] + counts[static_cast<size_t>(i)];
  std::vector<double> out(counts.size());
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - halfBins), b = std::min(n, i + halfBins + 1);
    out[static_cast<size_t>(i)] = prefix[static_cast<size_t>(b)] - prefix[static_cast<size_t>(a)];
  }
  return out;
}

double median(std::vector<float> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

double groundLevelOf(const std::vector<float>& band, const RoofIntervalParams& params) {
  if (band.empty()) return std::numeric_limits<double>::quiet_NaN();
  const Histogram h = histogram(band, params.binWidth);
  const int half = std::max(1, static_cast<int>(std::lround(params.groundWindow / params.binWidth)));
  const std::vector<double> mass = windowSums(h.counts, half);
  const double needed = params.groundShare * static_cast<double>(band.size());
  // The lowest level holding enough of the band, then up to the top of that mass's peak.
  size_t i = 0;
  while (i < mass.size() && mass[i] < needed) ++i;
  if (i == mass.size()) i = static_cast<size_t>(std::max_element(mass.begin(), mass.end()) - mass.begin());
  // Ground is not one level (terrain slope, kerbs, a car park lower than the lawn): the most
  // populated level within `groundSpan` above the lowest well-populated one.
  size_t best = i;
  for (size_t j = i; j < mass.size() && h.centre(j) <= h.centre(i) + params.groundSpan; ++j) {
    if (mass[j] > mass[best]) best = j;
  }
  const double level = h.centre(best);
  std::vector<float> near;
  for (float v : band) {
    if (std::abs(v - level) <= params.groundWindow) near.push_back(v);
  }
  return median(near);
}

// A band pixel: ROI coordinates and disparity.
struct GroundSample {
  float x, y, d;
};

std::vector<GroundSample> bandSamples(const cv::Mat& disparity, const cv::Rect& roi, const cv::Mat& mask) {
  std::vector<GroundSample> out;
  for (int y = 0; y < roi.height; ++y) {
    const float* d = disparity.ptr<float>(roi.y + y) + roi.x;
    const uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < roi.width; ++x) {
      if (m[x] != 0 && std::isfinite(d[x])) out.push_back({static_cast<float>(x), static_cast<float>(y), d[x]});
    }
  }
  return out;
}

// Plane d = a + b (x - cx) + c (y - cy) through `samples` by least squares; false when degenerate.
struct Plane {
  double a = 0.0, b = 0.0, c = 0.0, cx = 0.0, cy = 0.0;
  double at(double x, double y) const { return a + b * (x - cx) + c * (y - cy); }
};

bool fitPlane(const std::vector<GroundSample>& samples, const std::vector<char>& use, Plane& plane) {
  double n = 0.0, sx = 0.0, sy = 0.0;
  for (size_t i = 0; i < samples.size(); ++i) {
    if (use[i]) n += 1.0, sx += samples[i].x, sy += samples[i].y;
  }
  if (n < 3.0) return false;
  Plane p;
  p.cx = sx / n, p.cy = sy / n;
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0.0, 0.0, 0.0);
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!use[i]) continue;
    const cv::Vec3d row(1.0, samples[i].x - p.cx, samples[i].y - p.cy);
    normal += row * row.t();
    rhs += row * static_cast<double>(samples[i].d);
  }
  cv::Vec3d solution;
  if (!cv::solve(normal, rhs, solution, cv::DECOMP_CHOLESKY)) return false;
  p.a = solution[0], p.b = solution[1], p.c = solution[2];
  plane = p;
  return true;
}

// The ground next to the polygon: a plane fitted to the band's pixels near the ground level
// (refitted to the pixels near the plane, so that a sloping ground is followed beyond the
// level's window), averaged along the polygon's outer ring where band ground lies within
// `groundReach` (elsewhere the plane would be extrapolated, e.g. along a side lined by other
// roofs). Falls back to `level` when there is too little ground to fit.
double groundNextTo(const Neighbourhood& n, const std::vector<GroundSample>& band, double level,
                    const RoofIntervalParams& params) {
  if (params.groundReach <= 0.0 || !std::isfinite(level)) return level;
  std::vector<char> near(band.size());
  for (size_t i = 0; i < band.size(); ++i) near[i] = std::abs(band[i].d - level) <= params.groundWindow;
  Plane plane;
  constexpr int kRefits = 5;  // more refits let the window creep up onto cars and low vegetation
  for (int k = 0; k < kRefits; ++k) {
    if (!fitPlane(band, near, plane)) return level;
    for (size_t i = 0; i < band.size(); ++i) {
      near[i] = std::abs(band[i].d - plane.at(band[i].x, band[i].y)) <= params.groundWindow;
    }
  }
  cv::Mat ground(n.roi.size(), CV_8U, cv::Scalar(255));  // 0 on the plane's ground pixels
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (size_t i = 0; i < band.size(); ++i) {
    if (!near[i]) continue;
    ground.at<uchar>(static_cast<int>(band[i].y), static_cast<int>(band[i].x)) = 0;
    lo = std::min(lo, band[i].d), hi = std::max(hi, band[i].d);
  }
  if (!(lo <= hi)) return level;
  cv::Mat reach;
  cv::distanceTransform(ground, reach, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  constexpr float kRing = 4.0f;  // px, width of the outer ring the plane is read on
  double sum = 0.0;
  int count = 0;
  for (int y = 0; y < n.roi.height; ++y) {
    const float* o = n.outerDistance.ptr<float>(y);
    const float* r = reach.ptr<float>(y);
    for (int x = 0; x < n.roi.width; ++x) {
      if (o[x] > 0.0f && o[x] <= kRing && r[x] <= params.groundReach) sum += plane.at(x, y), ++count;
    }
  }
  if (count == 0) return level;
  // Never beyond the disparities the plane was fitted to.
  return std::clamp(sum / count, static_cast<double>(lo), static_cast<double>(hi));
}

double groundLevelAround(const cv::Mat& disparity, const Neighbourhood& n, const RoofIntervalParams& params,
                         int* samplesCount) {
  const cv::Mat bandMask = (n.outerDistance > 1.0f) & (n.outerDistance <= static_cast<float>(params.groundMargin));
  const std::vector<GroundSample> band = bandSamples(disparity, n.roi, bandMask);
  if (samplesCount) *samplesCount = static_cast<int>(band.size());
  std::vector<float> values(band.size());
  for (size_t i = 0; i < band.size(); ++i) values[i] = band[i].d;
  return groundNextTo(n, band, groundLevelOf(values, params), params);
}

// The regions at `level`: 8-connected pixels within `halfWindow` of it, over the polygon and a
// band `reach` + 1 px around it; for each, whether it reaches `reach` px outside the polygon
// (courtyards, holes, are not outside) and whether it touches a non-zero pixel of `touch` (CV_8U
// over the neighbourhood, may be empty).
struct LevelRegions {
  cv::Mat atLevel, labels;
  std::vector<char> reachesOut, touches;
};

LevelRegions levelRegions(const cv::Mat& disparity, const Neighbourhood& n, double level, double halfWindow,
                          double reach, const cv::Mat& touch = {}) {
  LevelRegions r;
  cv::inRange(disparity(n.roi), level - halfWindow, level + halfWindow, r.atLevel);  // NaN is out of range
  r.atLevel &= n.outerDistance <= static_cast<float>(reach + 1.0);
  const int count = cv::connectedComponents(r.atLevel, r.labels, 8, CV_32S);
  r.reachesOut.assign(static_cast<size_t>(count), 0);
  r.touches.assign(static_cast<size_t>(count), 0);
  for (int y = 0; y < r.atLevel.rows; ++y) {
    const uchar* a = r.atLevel.ptr<uchar>(y);
    const uchar* t = touch.empty() ? nullptr : touch.ptr<uchar>(y);
    const float* o = n.outerDistance.ptr<float>(y);
    const int* l = r.labels.ptr<int>(y);
    for (int x = 0; x < r.atLevel.cols; ++x) {
      if (a[x] == 0) continue;
      if (o[x] >= static_cast<float>(reach)) r.reachesOut[static_cast<size_t>(l[x])] = 1;
      if (t != nullptr && t[x] != 0) r.touches[static_cast<size_t>(l[x])] = 1;
    }
  }
  return r;
}

// How many of the core's pixels lie in the regions for which `keep(region index)` holds.
template <class Keep>
int corePixelsOf(const LevelRegions& r, const cv::Mat& core, Keep keep) {
  int pixels = 0;
  for (int y = 0; y < r.atLevel.rows; ++y) {
    const uchar* a = r.atLevel.ptr<uchar>(y);
    const uchar* c = core.ptr<uchar>(y);
    const int* l = r.labels.ptr<int>(y);
    for (int x = 0; x < r.atLevel.cols; ++x) {
      if (a[x] != 0 && c[x] != 0 && keep(static_cast<size_t>(l[x]))) ++pixels;
    }
  }
  return pixels;
}

// How many of the core's pixels within `halfWindow` of `level` belong to regions that enter the
// polygon from outside, as a neighbour's roof crossing a rough outline does (they reach `reach`
// px outside the polygon).
int enteringCount(const cv::Mat& disparity, const Neighbourhood& n, const cv::Mat& core, double level,
                  double halfWindow, double reach) {
  const LevelRegions r = levelRegions(disparity, n, level, halfWindow, reach);
  return corePixelsOf(r, core, [&r](size_t k) { return r.reachesOut[k] != 0; });
}

// The roof level (bin): the most populated level above the floor, its pixels in regions that
// enter the polygon from outside not counted. Candidates are the most populated level and the
// other peaks of the mass holding at least a fifth of its mass; when every candidate keeps less
// than that fifth (a polygon drawn inside its roof), the most populated level.
size_t roofLevel(const cv::Mat& disparity, const Neighbourhood& n, const cv::Mat& core, const Histogram& h,
                 const std::vector<double>& mass, double floorLevel, int windowBins,
                 const RoofIntervalParams& params) {
  size_t first = mass.size();
  for (size_t i = 0; i < mass.size(); ++i) {
    if (h.centre(i) >= floorLevel && (first == mass.size() || mass[i] > mass[first])) first = i;
  }
  if (first == mass.size() || mass[first] <= 0.0) {
    return static_cast<size_t>(std::max_element(mass.begin(), mass.end()) - mass.begin());
  }
  if (params.entryReach <= 0.0) return first;
  const double bar = 0.2 * mass[first];
  const auto near = [windowBins](size_t a, size_t b) {
    return std::abs(static_cast<long>(a) - static_cast<long>(b)) <= windowBins;
  };
  std::vector<size_t> candidates = {first};  // then the other peaks, most populated first
  for (size_t i = 0; i < mass.size(); ++i) {
    const bool isMax = (i == 0 || mass[i] >= mass[i - 1]) && (i + 1 == mass.size() || mass[i] >= mass[i + 1]);
    if (isMax && !near(i, first) && h.centre(i) >= floorLevel && mass[i] >= bar) candidates.push_back(i);
  }
  std::stable_sort(candidates.begin() + 1, candidates.end(), [&](size_t a, size_t b) { return mass[a] > mass[b]; });
  const double halfWindow = (windowBins + 0.5) * h.width;  // the pixels counted in a level's mass
  constexpr size_t kMaxChecks = 6;  // entry counts at most (each labels the polygon's neighbourhood)
  std::vector<size_t> checked;
  size_t best = first;
  double bestKept = -1.0;
  for (size_t i : candidates) {
    if (mass[i] <= bestKept || checked.size() == kMaxChecks) break;
    // A peak next to a checked one (a plateau of the mass) lies in the same regions.
    if (std::any_of(checked.begin(), checked.end(), [&](size_t c) { return near(i, c); })) continue;
    checked.push_back(i);
    const double kept = mass[i] - enteringCount(disparity, n, core, h.centre(i), halfWindow, params.entryReach);
    if (kept > bestKept) best = i, bestKept = kept;
  }
  return bestKept >= bar ? best : first;
}

// How many of the core's pixels within `halfWindow` of `level` lie in regions that stay inside
// the polygon (none reaches `reach` px outside it) and touch the roof: pixels within [low, high]
// lie 2 px or less from them.
int attachedCount(const cv::Mat& disparity, const Neighbourhood& n, const cv::Mat& core, double level,
                  double halfWindow, double reach, int low, int high) {
  cv::Mat roofLevel;
  cv::inRange(disparity(n.roi), low, high, roofLevel);
  cv::dilate(roofLevel, roofLevel, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
  const LevelRegions r = levelRegions(disparity, n, level, halfWindow, reach, roofLevel);
  return corePixelsOf(r, core, [&r](size_t k) { return r.reachesOut[k] == 0 && r.touches[k] != 0; });
}

// The lowest disparity of a lower roof of the building, as the recessed roof inside a raised ring:
// the most populated level of the core's pixels between the floor and `low` (above the ground:
// not a courtyard or the street), when its regions that stay inside the polygon and touch the
// roof [low, high] (attachedCount: not a neighbour crossing a rough outline, nor a separate
// structure beside the building) hold at least a tenth of the core's matched pixels; that level
// down to `peakFraction` of its smoothed peak. NaN when there is none.
double lowerRoofLow(const cv::Mat& disparity, const Neighbourhood& n, const cv::Mat& core, const std::vector<float>& roof,
                    int low, int high, double floorLevel, const RoofIntervalParams& params) {
  if (!std::isfinite(floorLevel)) return std::numeric_limits<double>::quiet_NaN();
  std::vector<float> lower;
  for (float d : roof) {
    if (d >= floorLevel && d < static_cast<float>(low)) lower.push_back(d);
  }
  if (lower.size() < 10 || 10 * lower.size() < roof.size()) return std::numeric_limits<double>::quiet_NaN();
  const Histogram h = histogram(lower, params.binWidth);
  const int windowBins = std::max(1, static_cast<int>(std::lround(1.0 / params.binWidth)));
  const std::vector<double> mass = windowSums(h.counts, windowBins);
  const size_t mode = static_cast<size_t>(std::max_element(mass.begin(), mass.end()) - mass.begin());
  const double halfWindow = (windowBins + 0.5) * h.width;
  const int attached = attachedCount(disparity, n, core, h.centre(mode), halfWindow, params.entryReach, low, high);
  if (10 * static_cast<size_t>(attached) < roof.size()) return std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> smooth = smoothed(h.counts, params.smoothing / params.binWidth);
  size_t lo = mode;
  while (lo > 0 && smooth[lo - 1] >= params.peakFraction * smooth[mode]) --lo;
  return h.centre(lo) - 0.5 * h.width;
}

}  // namespace

double estimateGroundLevel(const cv::Mat& disparity, const core::Polygon& polygon, const RoofIntervalParams& params) {
  params.validate();
  const Neighbourhood n = neighbourhood(disparity, polygon, params.groundMargin);
  if (n.inside.empty()) return std::numeric_limits<double>::quiet_NaN();
  return groundLevelAround(disparity, n, params, nullptr);
}

RoofIntervalProposal proposeRoofInterval(const cv::Mat& disparity, const core::Polygon& polygon,
                                         const RoofIntervalParams& params) {
  params.validate();
  RoofIntervalProposal out;
  const Neighbourhood n = neighbourhood(disparity, polygon, params.groundMargin);
  if (n.inside.empty()) return out;
  out.groundLevel = groundLevelAround(disparity, n, params, &out.groundSamples);

  // The polygon's core: away from its border, where a rough outline holds ground, walls and
  // parapets. A small polygon keeps at least half of its inradius.
  const cv::Rect2d box = core::boundingBox(polygon.outer);
  const double shrink = std::min(params.coreShrink, 0.25 * std::min(box.width, box.height));
  cv::Mat core = n.depth > static_cast<float>(shrink);
  std::vector<float> roof = samples(disparity, n.roi, core);
  if (roof.size() < 10) core = n.inside, roof = samples(disparity, n.roi, core);
  out.roofSamples = static_cast<int>(roof.size());
  if (roof.size() < 10) return out;

  const Histogram h = histogram(roof, params.binWidth);
  const std::vector<double> smooth = smoothed(h.counts, params.smoothing / params.binWidth);
  const std::vector<double> mass = windowSums(h.counts, std::max(1, static_cast<int>(std::lround(1.0 / params.binWidth))));
  // A ground level above the core's most populated level is a neighbour's roof (the band saw no
  // ground): then it does not bound the roof peak.
  const size_t mode = static_cast<size_t>(std::max_element(mass.begin(), mass.end()) - mass.begin());
  const double floorLevel = std::isfinite(out.groundLevel) && out.groundLevel < h.centre(mode) + params.minRoofHeight
                                ? out.groundLevel + params.minRoofHeight
                                : -std::numeric_limits<double>::infinity();
  // The most populated level above the ground (mass within ±1 px), then its highest bin.
  const int reach = std::max(1, static_cast<int>(std::lround(1.0 / params.binWidth)));
  const size_t best = roofLevel(disparity, n, core, h, mass, floorLevel, reach, params);
  size_t peak = best;
  for (size_t i = best > static_cast<size_t>(reach) ? best - static_cast<size_t>(reach) : 0;
       i <= std::min(h.counts.size() - 1, best + static_cast<size_t>(reach)); ++i) {
    if (smooth[i] > smooth[peak]) peak = i;
  }
  out.peak = h.centre(peak);

  // The peak's spread: down to `peakFraction` of its height on each side.
  const double threshold = params.peakFraction * smooth[peak];
  size_t lo = peak, hi = peak;
  while (lo > 0 && smooth[lo - 1] >= threshold && h.centre(lo - 1) >= floorLevel) --lo;
  while (hi + 1 < smooth.size() && smooth[hi + 1] >= threshold) ++hi;
  out.low = static_cast<int>(std::floor(h.centre(lo) - 0.5 * h.width)) - params.padding;
  out.high = static_cast<int>(std::ceil(h.centre(hi) + 0.5 * h.width)) + params.padding;
  const double lowerLow = lowerRoofLow(disparity, n, core, roof, out.low, out.high, floorLevel, params);
  if (std::isfinite(lowerLow)) out.low = static_cast<int>(std::floor(lowerLow)) - params.padding;
  if (std::isfinite(floorLevel)) {
    // Never down to the ground itself, or the roof and ground costs would agree there.
    out.low = std::max(out.low, static_cast<int>(std::floor(out.groundLevel)) + 1);
    out.low = std::min(out.low, static_cast<int>(std::floor(out.peak)));
  }
  out.found = true;
  return out;
}

}  // namespace delineo::delineation
