#include "delineo/delineation/delineate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/delineation/roof_interval.hpp"
#include "delineo/stereo/cost_service.hpp"

namespace delineo::delineation {

namespace {

using core::Error;
using core::ErrorCode;

std::string str(const DisparityInterval& d) {
  return std::to_string(d.min) + ":" + std::to_string(d.max);
}

void requireInterval(const DisparityInterval& d, const char* what) {
  if (d.min > d.max) {
    throw Error(ErrorCode::InvalidParameter,
                std::string(what) + " disparity interval " + str(d) + " is empty (min > max)");
  }
}

bool contains(const DisparityInterval& outer, const DisparityInterval& inner) {
  return outer.min <= inner.min && inner.max <= outer.max;
}

// Value at quantile q in [0, 1] of the finite values of a CV_32F image (optionally masked).
double quantile(const cv::Mat& values, double q, const cv::Mat& mask = {}) {
  std::vector<float> v;
  v.reserve(values.total());
  for (int y = 0; y < values.rows; ++y) {
    const float* p = values.ptr<float>(y);
    const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    for (int x = 0; x < values.cols; ++x) {
      if ((m == nullptr || m[x]) && std::isfinite(p[x])) v.push_back(p[x]);
    }
  }
  if (v.empty()) return std::nan("");
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

cv::Mat toFloat(const cv::Mat& image) {
  cv::Mat f;
  image.convertTo(f, CV_32F);
  return f;
}

// The initial contour in left-image coordinates, from the polygon or the mask.
core::Polygon initialPolygon(const DelineationRequest& request, cv::Size imageSize) {
  if (request.initMask.empty()) return request.init;
  if (request.initMask.size() != imageSize || request.initMask.type() != CV_8U) {
    throw Error(ErrorCode::MismatchedInputs,
                "the initial above-ground mask must be CV_8U of the left image's size");
  }
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(request.initMask != 0, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  if (contours.empty()) {
    throw Error(ErrorCode::InvalidParameter, "the initial above-ground mask is empty");
  }
  const auto largest = std::max_element(contours.begin(), contours.end(), [](const auto& a, const auto& b) {
    return cv::contourArea(a) < cv::contourArea(b);
  });
  std::vector<cv::Point> simplified;
  cv::approxPolyDP(*largest, simplified, 1.0, true);
  core::Polygon p;
  // Contour points are pixel centres of border pixels: their corners are half a pixel out.
  for (const auto& v : simplified) p.outer.emplace_back(v.x + 0.5, v.y + 0.5);
  return p;
}

// Normalised gradient: Sobel of a lightly smoothed image divided by the 99th percentile of the
// magnitude, so that the edge weight does not depend on the image's contrast.
void normalisedGradient(const cv::Mat& image, cv::Mat& gx, cv::Mat& gy) {
  cv::Mat f = toFloat(image);
  cv::patchNaNs(f, 0.0);
  cv::GaussianBlur(f, f, {0, 0}, 0.7);
  cv::Sobel(f, gx, CV_32F, 1, 0, 3, 1.0 / 8);
  cv::Sobel(f, gy, CV_32F, 0, 1, 3, 1.0 / 8);
}

void normaliseBy99(cv::Mat& gx, cv::Mat& gy) {
  cv::Mat mag;
  cv::magnitude(gx, gy, mag);
  const double scale = quantile(mag, 0.99);
  if (std::isfinite(scale) && scale > 1e-6) {
    gx /= scale;
    gy /= scale;
  }
}

// Region stage: inside the initial contour, the pixels whose roof interval matches better than
// the ground's on average over 9x9 pixels (opened 3x3, closed 7x7); the outline of the largest
// component, simplified at a few tolerances and polygonised. Carves the notches of concave
// buildings that a rough (box) contour cannot reach by local moves. Empty when there is no
// usable component.
std::vector<IntPolygon> regionStageCandidates(const EnergyImages& im, const cv::Mat& initMask,
                                              const DelineationParams& params) {
  // Aggregated over 9x9 pixels: on a textureless roof each pixel's difference is noise, but its
  // mean still leans to the roof (balanced intervals).
  cv::Mat difference = im.uncappedDifference.empty() ? cv::Mat(im.groundCost - im.roofCost) : im.uncappedDifference.clone();
  cv::blur(difference, difference, {9, 9}, {-1, -1}, cv::BORDER_REPLICATE);
  cv::Mat roofLike = (difference > 0) & initMask;
  cv::morphologyEx(roofLike, roofLike, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  cv::morphologyEx(roofLike, roofLike, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}));
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(roofLike, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  if (contours.empty()) return {};
  const auto largest = std::max_element(contours.begin(), contours.end(), [](const auto& a, const auto& b) {
    return cv::contourArea(a) < cv::contourArea(b);
  });
  if (cv::contourArea(*largest) < 0.1 * cv::countNonZero(initMask)) return {};
  std::vector<IntPolygon> candidates;
  // A fine tolerance keeps notches, a coarse one drops the noise of a textureless roof's
  // outline; the energy picks.
  std::vector<double> tolerances{std::min(2.0, params.regionTolerance)};
  while (tolerances.back() * 2 <= params.regionTolerance) tolerances.push_back(tolerances.back() * 2);
  for (const double tolerance : tolerances) {
    std::vector<cv::Point> simplified;
    cv::approxPolyDP(*largest, simplified, tolerance, true);
    if (simplified.size() < 3) continue;
    core::Ring ring;
    // Contour points are pixel centres of border pixels: their corners are half a pixel out.
    for (const auto& v : simplified) ring.emplace_back(v.x + 0.5, v.y + 0.5);
    IntPolygon p;
    p.outer = polygonise(ring, params.initialSpacing, im.roofCost.size());
    if (p.outer.size() < 3 || !isValidPolygon(p) || core::area(toPolygon(p)) < 4.0) continue;
    candidates.push_back(std::move(p));
  }
  return candidates;
}

// The matcher's validated map as the class evidence where it has a value: a disparity in the roof
// interval makes c_roof 0 and c_ground `map-cost`; one farther than `intermediate-guard` from it
// (ground, a neighbour at another height, a crown) the reverse. Unmatched pixels and those within
// the guard keep their correlation costs. Per pixel, before aggregation. The 5x5 correlation
// window cannot tell a roof with a repeated or smooth texture from a shift of it, nor a neighbour
// at another height from the roof; the matcher's adaptive windows, coarse-to-fine search and
// left-right check can. Returns the mask of the pixels the map puts above the roof interval
// (beyond the guard), where no courtyard starts.
cv::Mat applyMapCosts(const cv::Mat& disparity, const DisparityInterval& roof, const DelineationParams& params,
                      cv::Mat& roofCost, cv::Mat& groundCost) {
  const float r0 = static_cast<float>(roof.min) - 0.5f, r1 = static_cast<float>(roof.max) + 0.5f;
  const float guard = static_cast<float>(params.intermediateGuard);
  const float high = static_cast<float>(params.mapCost);
  cv::Mat aboveRoof = cv::Mat::zeros(disparity.size(), CV_8U);
  for (int y = 0; y < disparity.rows; ++y) {
    const float* d = disparity.ptr<float>(y);
    float* roofRow = roofCost.ptr<float>(y);
    float* groundRow = groundCost.ptr<float>(y);
    uchar* aboveRow = aboveRoof.ptr<uchar>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      if (!std::isfinite(d[x])) continue;
      if (d[x] >= r0 && d[x] <= r1) {
        roofRow[x] = 0.0f;
        groundRow[x] = high;
      } else if (d[x] < r0 - guard || d[x] > r1 + guard) {
        roofRow[x] = high;
        groundRow[x] = 0.0f;
        if (d[x] > r1 + guard) aboveRow[x] = 255;
      }
    }
  }
  return aboveRoof;
}

// The ground interval when the request gives none: with the matcher's map, the level of
// estimateGroundLevel() (the one the GUI's pick and histogram show); without it, or when the map
// has no ground around the init, the median best disparity of the cost volume in a ring
// `ring-width` px wide outside the init. ± `ground-tolerance`, kept off the roof interval.
// Returns the interval and the level.
std::pair<DisparityInterval, double> estimateGroundInterval(const stereo::CorrelationCostService& costs,
                                                            const DelineationRequest& request,
                                                            const core::Polygon& init, const cv::Mat& initMask,
                                                            float noMatchCost, const DelineationParams& params) {
  double level = std::numeric_limits<double>::quiet_NaN();
  if (!request.disparity.empty()) level = estimateGroundLevel(request.disparity, init);
  if (!std::isfinite(level)) {
    cv::Mat ring;
    cv::dilate(initMask, ring, cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                                          {2 * params.ringWidth + 1, 2 * params.ringWidth + 1}));
    ring &= ~initMask;
    ring &= (costs.bestCost() <= noMatchCost);
    cv::Mat bestDisparity;
    costs.bestDisparity().convertTo(bestDisparity, CV_32F);
    level = quantile(bestDisparity, 0.5, ring);
  }
  if (!std::isfinite(level)) {
    throw Error(ErrorCode::ProcessingFailed,
                "cannot estimate the ground disparity: no matched pixel around the initial polygon");
  }
  const int g = static_cast<int>(std::lround(level));
  DisparityInterval ground{g - params.groundTolerance, g + params.groundTolerance};
  // The ground interval must not overlap the roof's, or both costs would agree on the roof.
  if (g < request.roof.min) ground.max = std::min(ground.max, request.roof.min - 1);
  else if (g > request.roof.max) ground.min = std::max(ground.min, request.roof.max + 1);
  if (ground.min > ground.max) {
    throw Error(ErrorCode::ProcessingFailed, "the ground disparity estimated around the initial polygon (" +
                                                 std::to_string(g) + ") falls inside the roof interval " +
                                                 str(request.roof));
  }
  return {ground, g};
}

}  // namespace

std::pair<DisparityInterval, DisparityInterval> costIntervals(const DisparityInterval& roof,
                                                              const DisparityInterval& ground,
                                                              bool balance) {
  DisparityInterval r = roof, g = ground;
  if (!balance) return {r, g};
  const int roofWidth = r.max - r.min + 1, groundWidth = g.max - g.min + 1;
  const bool roofAbove = r.min + r.max >= g.min + g.max;
  if (roofWidth < groundWidth) {
    if (roofAbove) r.max += groundWidth - roofWidth;
    else r.min -= groundWidth - roofWidth;
  } else if (groundWidth < roofWidth) {
    if (roofAbove) g.min -= roofWidth - groundWidth;
    else g.max += roofWidth - groundWidth;
  }
  return {r, g};
}

// Refuses a building with nothing to work on: no image data under its initial polygon, or an
// exclusion mask covering all of it.
void requireDataUnder(const cv::Mat& left, const cv::Mat& right, const cv::Mat& excludeMask,
                      const core::Polygon& init) {
  const cv::Mat inside = core::rasterize(init, left.size());
  if (cv::countNonZero((left == left) & inside) == 0) {
    throw Error(ErrorCode::UnsupportedInput, "the left image has no data under the initial polygon");
  }
  // The right view of the building lies on the same rows, shifted by its disparity.
  const cv::Rect2d box = core::boundingBox(init.outer);
  const int row0 = std::clamp(static_cast<int>(std::floor(box.y)), 0, right.rows - 1);
  const int row1 = std::clamp(static_cast<int>(std::ceil(box.y + box.height)), row0 + 1, right.rows);
  const cv::Mat rows = right.rowRange(row0, row1);
  if (cv::countNonZero(rows == rows) == 0) {
    throw Error(ErrorCode::UnsupportedInput, "the right image has no data on the initial polygon's rows");
  }
  if (!excludeMask.empty() && cv::countNonZero(inside & (excludeMask == 0)) == 0) {
    throw Error(ErrorCode::InvalidParameter,
                "the exclusion mask covers the whole initial polygon: nothing is left to delineate");
  }
}

cv::Rect regionOfInterest(const cv::Mat& left, const cv::Mat& right,
                          const DelineationRequest& request, const DelineationParams& params) {
  params.validate();
  if (left.empty() || right.empty()) {
    throw Error(ErrorCode::MismatchedInputs, "delineation needs both images of the pair");
  }
  if (left.size() != right.size()) {
    throw Error(ErrorCode::MismatchedInputs,
                "left (" + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
                    ") and right (" + std::to_string(right.cols) + "x" +
                    std::to_string(right.rows) + ") images differ in size");
  }
  if (left.channels() != 1 || right.channels() != 1) {
    throw Error(ErrorCode::UnsupportedInput, "delineation needs single-band images");
  }
  requireInterval(request.roof, "roof");
  if (request.ground) {
    requireInterval(*request.ground, "ground");
    // x_right = x_left - d: a roof is nearer the cameras than its ground, its disparities larger.
    if (request.ground->max >= request.roof.min) {
      throw Error(ErrorCode::InvalidParameter,
                  "the ground disparity interval " + str(*request.ground) +
                      (request.ground->min > request.roof.max ? " lies above" : " overlaps") +
                      " the roof interval " + str(request.roof) +
                      ": a roof's disparities are larger than its ground's");
    }
  }
  if (request.searchRange) {
    requireInterval(*request.searchRange, "search");
    if (!contains(*request.searchRange, request.roof)) {
      throw Error(ErrorCode::InvalidParameter, "roof disparity interval " + str(request.roof) +
                                                   " lies outside the search range " +
                                                   str(*request.searchRange));
    }
    if (request.ground && !contains(*request.searchRange, *request.ground)) {
      throw Error(ErrorCode::InvalidParameter, "ground disparity interval " +
                                                   str(*request.ground) +
                                                   " lies outside the search range " +
                                                   str(*request.searchRange));
    }
  }
  if (!request.disparity.empty() && (request.disparity.size() != left.size() || request.disparity.type() != CV_32F)) {
    throw Error(ErrorCode::MismatchedInputs,
                "the disparity map must be single-band float of the left image's size (" +
                    std::to_string(left.cols) + "x" + std::to_string(left.rows) + "), not " +
                    std::to_string(request.disparity.cols) + "x" + std::to_string(request.disparity.rows));
  }
  if (!request.excludeMask.empty() &&
      (request.excludeMask.size() != left.size() || request.excludeMask.type() != CV_8U)) {
    throw Error(ErrorCode::MismatchedInputs,
                "the exclusion mask must be single-band 8-bit of the left image's size (" +
                    std::to_string(left.cols) + "x" + std::to_string(left.rows) + "), not " +
                    std::to_string(request.excludeMask.cols) + "x" +
                    std::to_string(request.excludeMask.rows));
  }
  const core::Polygon init = initialPolygon(request, left.size());
  if (init.outer.size() < 3 || core::area(init) < 4.0 || !core::isSimple(init.outer)) {
    throw Error(ErrorCode::InvalidParameter,
                "the initial polygon is degenerate (fewer than 3 distinct vertices, "
                "self-intersecting, or smaller than 4 px²)");
  }
  const cv::Rect2d box = core::boundingBox(init.outer);
  if (box.x < 0 || box.y < 0 || box.x + box.width > left.cols || box.y + box.height > left.rows) {
    throw Error(ErrorCode::InvalidParameter,
                "the initial polygon (bounding box " + std::to_string(box.x) + "," +
                    std::to_string(box.y) + " " + std::to_string(box.width) + "x" +
                    std::to_string(box.height) + ") is outside the image (" +
                    std::to_string(left.cols) + "x" + std::to_string(left.rows) + ")");
  }
  requireDataUnder(left, right, request.excludeMask, init);
  const int m = params.roiMargin;
  const cv::Rect grown(static_cast<int>(std::floor(box.x)) - m, static_cast<int>(std::floor(box.y)) - m,
                       static_cast<int>(std::ceil(box.x + box.width)) - static_cast<int>(std::floor(box.x)) + 2 * m,
                       static_cast<int>(std::ceil(box.y + box.height)) - static_cast<int>(std::floor(box.y)) + 2 * m);
  return grown & cv::Rect(0, 0, left.cols, left.rows);
}

namespace {

// The initial polygon in ROI coordinates, polygonised (out.init), and where a vertex may go
// (within `max-excursion` of it, when that is less than the ROI margin). Returns its mask.
cv::Mat initialInRoi(const core::Polygon& init, const DelineationParams& params, PreparedEnergy& out) {
  const cv::Rect roi = out.roi;
  const cv::Size size = roi.size();
  core::Ring local;
  for (const auto& v : init.outer) local.emplace_back(v.x - roi.x, v.y - roi.y);
  out.init.outer = polygonise(local, params.initialSpacing, size);
  const cv::Mat initMask = core::rasterize(toPolygon(out.init), size);
  if (params.maxExcursion < params.roiMargin) {
    cv::Mat distance;
    cv::distanceTransform(initMask == 0, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    out.images.allowed = distance <= params.maxExcursion;
  }
  return initMask;
}

// c_roof and c_ground: the lowest Crit over the roof interval and over the ground's (given, or
// estimated around the init), both as searched (balanceIntervals); then the matcher's map where
// it has a value (map-cost) and the box filter (cost-aggregation).
void areaCosts(const stereo::CorrelationCostService& costs, const DelineationRequest& request,
               const core::Polygon& init, const cv::Mat& initMask, const DelineationParams& params,
               PreparedEnergy& out) {
  EnergyImages& im = out.images;
  // Ground interval: given, or estimated around the init.
  if (request.ground) {
    out.ground = *request.ground;
    out.groundDisparity = 0.5 * (out.ground.min + out.ground.max);
  } else {
    std::tie(out.ground, out.groundDisparity) = estimateGroundInterval(costs, request, init, initMask, im.noMatchCost, params);
  }
  std::tie(out.roofSearched, out.groundSearched) =
      costIntervals(request.roof, out.ground, params.balanceIntervals);
  im.roofCost = costs.minCost(out.roofSearched.min, out.roofSearched.max);
  im.groundCost = costs.minCost(out.groundSearched.min, out.groundSearched.max);
  if (params.mapCost > 0 && !request.disparity.empty()) {
    im.aboveRoof = applyMapCosts(request.disparity(out.roi), request.roof, params, im.roofCost, im.groundCost);
  }
  if (params.costAggregation > 1) {
    const cv::Size k(params.costAggregation, params.costAggregation);
    cv::blur(im.roofCost, im.roofCost, k, {-1, -1}, cv::BORDER_REPLICATE);
    cv::blur(im.groundCost, im.groundCost, k, {-1, -1}, cv::BORDER_REPLICATE);
  }
}

// The pixels kept out of the roof (out.excluded): the request's exclusion mask and, with
// `intermediate-margin`, the pixels seen at a height between the roof's and the ground's; their
// costs made those of a non-roof pixel.
void excludeNonRoof(const stereo::CorrelationCostService& costs, const DelineationRequest& request,
                    const DelineationParams& params, PreparedEnergy& out) {
  EnergyImages& im = out.images;
  out.excluded = cv::Mat::zeros(out.roi.size(), CV_8U);
  if (!request.excludeMask.empty()) out.excluded = request.excludeMask(out.roi) != 0;
  if (params.intermediateMargin > 0) {
    // Something at another height than both the roof and the ground (a tree crown lower than
    // the roof, a wall, a neighbour's lower annex) matches a disparity between the intervals. A
    // roof pixel does not: where it matches no roof disparity (textureless, occluded) it matches
    // none well, so the in-between match must also be a good one. Without this such pixels are
    // neutral (cost cap) and the contour keeps the crowns it starts around.
    const bool roofAbove = out.roofSearched.min >= out.groundSearched.min;
    const DisparityInterval& below = roofAbove ? out.groundSearched : out.roofSearched;
    const DisparityInterval& above = roofAbove ? out.roofSearched : out.groundSearched;
    const int d0 = std::max(below.max + 1 + params.intermediateGuard, costs.dmin());
    const int d1 = std::min(above.min - 1 - params.intermediateGuard, costs.dmax());
    if (d0 <= d1) {
      // Per pixel, not aggregated like c_roof and c_ground: a crown's flank or a wall is a few
      // px wide and slopes through the gap, its neighbours match other in-between disparities
      // (aggregating it too measured 0.933 / 0.898 / 0.922 against 0.944 / 0.905 / 0.938 on
      // the held-out box runs, docs/delineation.md).
      const cv::Mat between = costs.minCost(d0, d1);
      const float margin = static_cast<float>(params.intermediateMargin);
      const cv::Mat elsewhere = (between < im.noMatchCost) & (im.roofCost > im.noMatchCost) &
                                (between + margin < cv::min(im.roofCost, im.groundCost));
      out.excluded |= elsewhere;
    }
  }
  if (cv::countNonZero(out.excluded) > 0) {
    // Known non-roof pixels: the worst Crit inside (capped below like every other cost), at
    // most NoMatchCost outside. Before the region stage, so that its roof-like region skips them.
    im.roofCost.setTo(1.0f, out.excluded);
    im.groundCost.setTo(im.noMatchCost, out.excluded & (im.groundCost > im.noMatchCost));
  }
}

// Roof disparity per pixel of `roi`: argmin of Crit within the roof interval, median-filtered.
cv::Mat roofDisparityPerPixel(const stereo::CorrelationCostService& costs, const DisparityInterval& roof,
                              cv::Rect roi) {
  const cv::Size size = roi.size();
  const int d0 = std::max(roof.min, costs.dmin()), d1 = std::min(roof.max, costs.dmax());
  cv::Mat roofDisparity(size, CV_32F, cv::Scalar(0.5f * (d0 + d1)));
  for (int y = 0; y < size.height; ++y) {
    float* rd = roofDisparity.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      float best = std::numeric_limits<float>::infinity();
      for (int d = d0; d <= d1; ++d) {
        const float c = costs.cost(roi.x + x, roi.y + y, d);
        if (c < best) {
          best = c;
          rd[x] = static_cast<float>(d);
        }
      }
    }
  }
  cv::medianBlur(roofDisparity, roofDisparity, 5);
  return roofDisparity;
}

// d_xy: the roof disparity at the nearest roof-like pixel of the initial region (inside the
// init, roof interval matching better than the ground's). The paper takes the nearest pixel
// of the initial contour; an operator's rough contour often lies on the ground, so its own
// disparity would be the ground's. Also sets out.roofDisparity, the median over those pixels
// (the roof interval's middle when there are none).
cv::Mat nearestRoofDisparity(const cv::Mat& roofDisparity, const cv::Mat& initMask, const DisparityInterval& roof,
                             PreparedEnergy& out) {
  const EnergyImages& im = out.images;
  const cv::Size size = roofDisparity.size();
  cv::Mat roofLike = initMask & (im.roofCost < im.groundCost);
  cv::Mat dxy(size, CV_32F);
  if (cv::countNonZero(roofLike) == 0) {
    dxy.setTo(0.5 * (roof.min + roof.max));
    out.roofDisparity = 0.5 * (roof.min + roof.max);
    return dxy;
  }
  cv::Mat seeds = ~roofLike, dist, labels;
  cv::distanceTransform(seeds, dist, labels, cv::DIST_L2, 3, cv::DIST_LABEL_PIXEL);
  std::vector<float> labelDisparity(static_cast<size_t>(size.area()) + 1, 0.f);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      if (roofLike.at<uchar>(y, x)) labelDisparity[labels.at<int>(y, x)] = roofDisparity.at<float>(y, x);
    }
  }
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) dxy.at<float>(y, x) = labelDisparity[labels.at<int>(y, x)];
  }
  out.roofDisparity = quantile(roofDisparity, 0.5, roofLike);
  return dxy;
}

// Gradients: left on the ROI (computed with a border so that the ROI edge is exact), right
// resampled at (x - d_xy, y).
void edgeImages(const cv::Mat& left, const cv::Mat& right, cv::Rect roi, const cv::Mat& dxy, EnergyImages& im) {
  const cv::Size size = roi.size();
  const cv::Rect full(0, 0, left.cols, left.rows);
  const cv::Rect leftBox = cv::Rect(roi.x - 3, roi.y - 3, roi.width + 6, roi.height + 6) & full;
  cv::Mat lgx, lgy;
  normalisedGradient(left(leftBox), lgx, lgy);
  const cv::Rect inBox(roi.x - leftBox.x, roi.y - leftBox.y, roi.width, roi.height);
  im.leftGradX = lgx(inBox).clone();
  im.leftGradY = lgy(inBox).clone();
  normaliseBy99(im.leftGradX, im.leftGradY);
  const cv::Rect rightBox = cv::Rect(0, roi.y - 3, right.cols, roi.height + 6) & full;
  cv::Mat rgx, rgy;
  normalisedGradient(right(rightBox), rgx, rgy);
  cv::Mat mapX(size, CV_32F), mapY(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      mapX.at<float>(y, x) = static_cast<float>(roi.x + x - rightBox.x) - dxy.at<float>(y, x);
      mapY.at<float>(y, x) = static_cast<float>(roi.y + y - rightBox.y);
    }
  }
  cv::remap(rgx, im.rightGradX, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
  cv::remap(rgy, im.rightGradY, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
  normaliseBy99(im.rightGradX, im.rightGradY);
}

// The region stage (`region-init`): an outline of the roof-like region inside the init replaces
// the operator's (out.init) when its energy is lower.
void regionStage(const cv::Mat& initMask, const DelineationParams& params, PreparedEnergy& out) {
  const EnergyImages& im = out.images;
  const EnergyWeights weights{params.edgeWeight, params.rigidity, params.edgeContrast,
                              params.minAngle, params.minGap};
  PolygonEnergy energy(im, weights);
  energy.setPolygon(out.init);
  const double operatorEnergy = energy.total();
  // The energy decides: the region outline (finest tolerance) replaces the operator's only
  // when it is lower; then the coarser outlines may replace it when lower still. (Letting a
  // coarse outline compete with the operator's directly replaced good operator contours by
  // simpler, lower-F but worse outlines on textureless roofs.)
  std::vector<IntPolygon> candidates = regionStageCandidates(im, initMask, params);
  if (candidates.empty()) return;
  energy.setPolygon(candidates.front());
  double lowest = energy.total();
  if (!(lowest < operatorEnergy)) return;
  size_t best = 0;
  for (size_t i = 1; i < candidates.size(); ++i) {
    energy.setPolygon(candidates[i]);
    if (energy.total() < lowest) {
      lowest = energy.total();
      best = i;
    }
  }
  out.init = std::move(candidates[best]);
  out.regionInit = true;
}

// `cost-cap`: a pixel that matches neither interval (a tree or a neighbour's wall left as
// ground, a wall taken as roof) costs no more than the occlusion band. After the region stage,
// which compares outlines on the plain costs.
void capCosts(const DelineationParams& params, EnergyImages& im) {
  im.uncappedDifference = im.groundCost - im.roofCost;
  // The floor keeps the cap meaningful on clean pairs, where NoMatchCost is near 0 and a
  // multiple of it would flatten every cost (no area evidence left against the edge terms).
  const float cap = static_cast<float>(std::max(params.costCap * im.noMatchCost, params.costCapFloor));
  im.roofCost = cv::min(im.roofCost, cap);
  im.groundCost = cv::min(im.groundCost, cap);
}

}  // namespace

PreparedEnergy prepareEnergy(const stereo::CorrelationCostService& costs, const cv::Mat& left,
                             const cv::Mat& right, const DelineationRequest& request,
                             const DelineationParams& params) {
  PreparedEnergy out;
  out.roi = costs.roi();
  EnergyImages& im = out.images;
  const core::Polygon init = initialPolygon(request, left.size());
  const cv::Mat initMask = initialInRoi(init, params, out);
  const cv::Mat bestCost = costs.bestCost();
  im.noMatchCost = static_cast<float>(quantile(bestCost, 1.0 - params.occlusionPercent / 100.0));
  if (!std::isfinite(im.noMatchCost)) im.noMatchCost = 1.0f;
  areaCosts(costs, request, init, initMask, params, out);
  excludeNonRoof(costs, request, params, out);
  const cv::Mat dxy =
      nearestRoofDisparity(roofDisparityPerPixel(costs, request.roof, out.roi), initMask, request.roof, out);
  // Occlusion band: walls seen in the left image and ground hidden in the right one lie next to
  // the roof on the -x side when the roof is nearer (larger d, since x_right = x_left - d).
  im.occlusionSide = out.roofDisparity >= out.groundDisparity ? -1 : +1;
  cv::Mat width = cv::abs(dxy - out.groundDisparity);
  width.convertTo(im.occlusionWidth, CV_32S);  // rounds to nearest
  edgeImages(left, right, out.roi, dxy, im);
  if (params.regionInit) regionStage(initMask, params, out);
  if (params.costCap > 0) capCosts(params, im);
  return out;
}

namespace {

// The disparities the correlation costs are computed over: the full search range when known,
// else the roof and ground intervals' hull.
DisparityInterval costSearchInterval(const DelineationRequest& request, const DelineationParams& params) {
  if (request.searchRange) return *request.searchRange;
  if (request.ground) {
    const auto [r, g] = costIntervals(request.roof, *request.ground, params.balanceIntervals);
    return {std::min(r.min, g.min), std::max(r.max, g.max)};
  }
  // Ground assumed below the roof, with an interval of 2 * ground-tolerance + 1 disparities.
  const int below = request.roof.min - params.groundSearch;
  const auto [r, g] =
      costIntervals(request.roof, {below, below + 2 * params.groundTolerance}, params.balanceIntervals);
  return {std::min(r.min, g.min), std::max(r.max, request.roof.max)};
}

std::unique_ptr<stereo::CorrelationCostService> costsOver(const cv::Mat& left, const cv::Mat& right, cv::Rect roi,
                                                             const DelineationRequest& request,
                                                        const DelineationParams& params, core::Progress* progress) {
  const DisparityInterval search = costSearchInterval(request, params);
  stereo::CostParams costParams;
  costParams.window = params.costWindow;
  costParams.brightnessScale = params.costBrightness;
  return stereo::CorrelationCostService::compute(toFloat(left), toFloat(right), roi, search.min, search.max,
                                                 costParams, progress);
}

// An outline in left-image pixels as the energy's integer polygon in ROI coordinates (vertices
// rounded to pixel corners, clamped to the ROI, repeated vertices dropped).
IntPolygon toRoiPolygon(const core::Polygon& outline, cv::Rect roi) {
  auto convert = [&](const core::Ring& ring) {
    IntRing out;
    for (const auto& v : ring) {
      const cv::Point p(std::clamp(static_cast<int>(std::lround(v.x)) - roi.x, 0, roi.width),
                        std::clamp(static_cast<int>(std::lround(v.y)) - roi.y, 0, roi.height));
      if (out.empty() || out.back() != p) out.push_back(p);
    }
    while (out.size() > 1 && out.front() == out.back()) out.pop_back();
    return out;
  };
  IntPolygon out;
  out.outer = convert(outline.outer);
  for (const auto& hole : outline.holes) out.holes.push_back(convert(hole));
  return out;
}

double outlineLength(const core::Polygon& p) {
  auto ringLength = [](const core::Ring& r) {
    double s = 0;
    for (size_t i = 0; i < r.size(); ++i) s += cv::norm(r[(i + 1) % r.size()] - r[i]);
    return s;
  };
  double s = ringLength(p.outer);
  for (const auto& h : p.holes) s += ringLength(h);
  return s;
}

EnergyWeights weightsOf(const DelineationParams& params) {
  return {params.edgeWeight, params.rigidity, params.edgeContrast, params.minAngle, params.minGap};
}

// The energy gate of the regularization stage: a regularized outline whose F(C) (vertices on the
// pixel grid) exceeds the raw one's by more than the margin per px of the raw outline's length
// is refused, and the raw outline kept. Returns the terms of the outline kept.
EnergyTerms gateByEnergy(RegularizationOutcome& reg, const core::Polygon& raw, const EnergyTerms& rawTerms,
                         const PreparedEnergy& prepared, const DelineationParams& params) {
  if (reg.status != RegularizationStatus::Regularized) return rawTerms;
  const IntPolygon local = toRoiPolygon(reg.polygon, prepared.roi);
  if (!isValidPolygon(local)) {
    reg.status = RegularizationStatus::KeptRaw;
    reg.reason = "not a valid polygon on the pixel grid";
    reg.polygon = raw;
    reg.outputVertices = reg.inputVertices;
    return rawTerms;
  }
  const EnergyTerms terms = referenceEnergy(prepared.images, weightsOf(params), local);
  reg.energyChange = terms.total() - rawTerms.total();
  const double allowed = params.regularization.energyMargin * outlineLength(raw);
  if (reg.energyChange > allowed) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "energy +%.1f > %.1f allowed", reg.energyChange, allowed);
    reg.status = RegularizationStatus::KeptRaw;
    reg.reason = buf;
    reg.polygon = raw;
    reg.outputVertices = reg.inputVertices;
    return rawTerms;
  }
  return terms;
}

// The regularization stage: the outline regularized at the parameter's tolerance, then at half
// and a quarter of it, until a result passes the outline gates and `energyGate` (which refuses a
// result by setting KeptRaw). A looser tolerance merges more, but on a ragged outline it can cut
// across a notch that a gate refuses where a tighter one passes. None passing, the first try's
// outcome: the raw outline, with the reason the whole tolerance failed.
template <class EnergyGate>
RegularizationOutcome regularizeWithinTolerance(const core::Polygon& raw, const RegularizationParams& params,
                                                const cv::Mat& left, EnergyGate&& energyGate) {
  RegularizationParams tried = params;
  std::optional<RegularizationOutcome> first;
  for (int k = 0; k < 3 && tried.tolerance >= RegularizationParams::kMinTolerance; ++k, tried.tolerance /= 2) {
    RegularizationOutcome outcome = regularizeOutline(raw, tried, left);
    if (outcome.status == RegularizationStatus::Regularized) energyGate(outcome);
    if (outcome.status != RegularizationStatus::KeptRaw) return outcome;  // regularized, or off
    if (!first) first = std::move(outcome);
  }
  return *first;
}

// An outline's energy on the costs delineate() would use for `request`, with those costs;
// nullopt when canceled. Throws InvalidParameter when the outline, on the pixel grid of its
// region of interest, is not a valid polygon.
struct OutlineOnCosts {
  PreparedEnergy prepared;
  EnergyTerms terms;
};
std::optional<OutlineOnCosts> energyOnCosts(const cv::Mat& left, const cv::Mat& right, const DelineationRequest& request,
                                            const DelineationParams& params, const core::Polygon& outline,
                                            core::Progress* progress) {
  const cv::Rect roi = regionOfInterest(left, right, request, params);
  const auto costs = costsOver(left, right, roi, request, params, progress);
  if (!costs || core::isCanceled(progress)) return std::nullopt;
  const IntPolygon polygon = toRoiPolygon(outline, roi);
  if (!isValidPolygon(polygon)) {
    throw Error(ErrorCode::InvalidParameter,
                "the outline is not a valid polygon on the pixel grid of its region of interest "
                "(a ring with fewer than 3 distinct corners, crossing itself or another ring)");
  }
  OutlineOnCosts out{prepareEnergy(*costs, left, right, request, params), {}};
  out.terms = referenceEnergy(out.prepared.images, weightsOf(params), polygon);
  return out;
}

}  // namespace

OutlineEnergy evaluateOutline(const cv::Mat& left, const cv::Mat& right, const DelineationRequest& request,
                              const DelineationParams& params, const core::Polygon& outline,
                              core::Progress* progress) {
  OutlineEnergy result;
  const auto evaluated = energyOnCosts(left, right, request, params, outline, progress);
  if (!evaluated) {
    result.status = core::RunStatus::Canceled;
    return result;
  }
  result.terms = evaluated->terms;
  return result;
}

RegularizationOutcome regularizeBuildingOutline(const cv::Mat& left, const cv::Mat& right,
                                                const DelineationRequest& request, const DelineationParams& params,
                                                const core::Polygon& outline, core::Progress* progress) {
  // The costs only once a result needs the energy gate.
  std::optional<OutlineOnCosts> raw;
  auto energyGate = [&](RegularizationOutcome& outcome) {
    if (!raw) raw = energyOnCosts(left, right, request, params, outline, progress);
    if (!raw) {  // canceled
      outcome.status = RegularizationStatus::Off;
      outcome.polygon = outline;
      outcome.outputVertices = outcome.inputVertices;
      return;
    }
    gateByEnergy(outcome, outline, raw->terms, raw->prepared, params);
  };
  return regularizeWithinTolerance(outline, params.regularization, left, energyGate);
}

DelineationResult delineate(const cv::Mat& left, const cv::Mat& right,
                            const DelineationRequest& request, const DelineationParams& params,
                            const IterationObserver& observer, core::Progress* progress) {
  DelineationResult result;
  result.roi = regionOfInterest(left, right, request, params);
  result.roof = request.roof;
  core::setStage(progress, core::StageId::CorrelationCosts);
  core::Progress::Range costProgress(progress, 0.0, 0.3);
  const auto costs = costsOver(left, right, result.roi, request, params, progress ? &costProgress : nullptr);
  result.polygon = initialPolygon(request, left.size());
  if (!costs || core::isCanceled(progress)) {
    result.status = core::RunStatus::Canceled;
    result.vertexCount = static_cast<int>(result.polygon.outer.size());
    return result;
  }
  const PreparedEnergy prepared = prepareEnergy(*costs, left, right, request, params);
  result.ground = prepared.ground;
  result.noMatchCost = prepared.images.noMatchCost;
  core::setStage(progress, core::StageId::ActivePolygon);
  core::Progress::Range optimiseProgress(progress, 0.3, 1.0);
  const cv::Point offset = result.roi.tl();
  IterationObserver forward;
  if (observer) {
    forward = [&](const IterationReport& report) {
      IterationReport shifted = report;
      for (size_t r = 0; r < shifted.polygon.ringCount(); ++r) {
        for (auto& v : shifted.polygon.ring(r)) v += offset;
      }
      observer(shifted);
    };
  }
  const ActivePolygonResult r = optimiseActivePolygon(
      prepared.images, prepared.init, params, forward, progress ? &optimiseProgress : nullptr);
  result.polygon = toPolygon(r.polygon, cv::Point2d(offset));
  result.rawPolygon = result.polygon;
  result.terms = r.terms;
  result.iterations = r.iterations;
  result.status = r.status;
  result.regularization.polygon = result.polygon;
  if (r.status == core::RunStatus::Completed) {
    EnergyTerms regularizedTerms = r.terms;
    result.regularization = regularizeWithinTolerance(
        result.rawPolygon, params.regularization, left, [&](RegularizationOutcome& outcome) {
          regularizedTerms = gateByEnergy(outcome, result.rawPolygon, r.terms, prepared, params);
        });
    result.terms = result.regularization.status == RegularizationStatus::Regularized ? regularizedTerms : r.terms;
    result.polygon = result.regularization.polygon;
  }
  result.vertexCount = static_cast<int>(result.polygon.outer.size());
  for (const auto& h : result.polygon.holes) result.vertexCount += static_cast<int>(h.size());
  if (progress && r.status == core::RunStatus::Completed) progress->report(1.0);
  return result;
}

}  // namespace delineo::delineation
