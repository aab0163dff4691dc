#include "delineo/delineation/above_ground.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"

namespace delineo::delineation {

using core::Error;
using core::ErrorCode;

void AboveGroundParams::validate() const {
  core::checkDeclaredRanges(*this);
  if (opening % 2 == 0) throw Error(ErrorCode::InvalidParameter, "opening must be odd");
  if (smoothing % 2 == 0) throw Error(ErrorCode::InvalidParameter, "smoothing must be odd");
  if (maxSearchRadius < searchRadius) {
    throw Error(ErrorCode::InvalidParameter, "max-search-radius must not be below search-radius");
  }
}

namespace {

// Pixels standing more than `threshold` (px of disparity) high, opened to cut thin links.
cv::Mat aboveMask(const cv::Mat& disparity, double threshold, int opening) {
  cv::Mat above = disparity > threshold;  // NaN compares false: no data is not above
  if (opening > 1) {
    cv::morphologyEx(above, above, cv::MORPH_OPEN,
                     cv::getStructuringElement(cv::MORPH_RECT, {opening, opening}));
  }
  return above;
}

// The set pixel of `mask` nearest to `click` within `radius` px; (-1, -1) when there is none.
cv::Point nearestSet(const cv::Mat& mask, cv::Point click, double radius) {
  if (mask.at<uchar>(click) != 0) return click;
  const int r = static_cast<int>(std::floor(radius));
  cv::Point best(-1, -1);
  double bestDistance = radius * radius;
  for (int y = std::max(0, click.y - r); y <= std::min(mask.rows - 1, click.y + r); ++y) {
    for (int x = std::max(0, click.x - r); x <= std::min(mask.cols - 1, click.x + r); ++x) {
      const double d = (x - click.x) * (x - click.x) + (y - click.y) * (y - click.y);
      if (mask.at<uchar>(y, x) != 0 && d <= bestDistance) bestDistance = d, best = {x, y};
    }
  }
  return best;
}

// The 4-connected component of `mask` holding `seed`, as 255 in a CV_8U of the mask's size.
cv::Mat componentAt(const cv::Mat& mask, cv::Point seed) {
  cv::Mat filled = cv::Mat::zeros(mask.rows + 2, mask.cols + 2, CV_8U);
  cv::floodFill(mask, filled, seed, 255, nullptr, 0, 0, 4 | cv::FLOODFILL_MASK_ONLY | (255 << 8));
  return filled(cv::Rect(1, 1, mask.cols, mask.rows)).clone();
}

// The pixels of `above` reachable from `seed` by 4-connected steps of at most `maxStep` px of
// disparity (0: any step), as 255 in a CV_8U of the map's size: an object stops where a
// neighbour of another height begins.
cv::Mat growObject(const cv::Mat& above, const cv::Mat& disparity, cv::Point seed, double maxStep) {
  if (maxStep <= 0.0) return componentAt(above, seed);
  cv::Mat region = cv::Mat::zeros(above.size(), CV_8U);
  std::vector<cv::Point> stack{seed};
  region.at<uchar>(seed) = 255;
  const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  while (!stack.empty()) {
    const cv::Point p = stack.back();
    stack.pop_back();
    const float here = disparity.at<float>(p);
    for (const cv::Point& s : steps) {
      const cv::Point q = p + s;
      if (q.x < 0 || q.y < 0 || q.x >= above.cols || q.y >= above.rows) continue;
      if (region.at<uchar>(q) != 0 || above.at<uchar>(q) == 0) continue;
      if (std::abs(disparity.at<float>(q) - here) > maxStep) continue;
      region.at<uchar>(q) = 255;
      stack.push_back(q);
    }
  }
  return region;
}

// Labels (CV_32S, 1..count-1) of the parts of `mask` whose 4-connected neighbours differ by at
// most `maxStep` px (0: any step); returns the count including the background label 0.
int stepComponents(const cv::Mat& mask, const cv::Mat& disparity, double maxStep, cv::Mat& labels) {
  labels = cv::Mat::zeros(mask.size(), CV_32S);
  const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  std::vector<cv::Point> stack;
  int next = 1;
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uchar>(y, x) == 0 || labels.at<int>(y, x) != 0) continue;
      labels.at<int>(y, x) = next;
      stack.assign(1, cv::Point(x, y));
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        for (const cv::Point& s : steps) {
          const cv::Point q = p + s;
          if (q.x < 0 || q.y < 0 || q.x >= mask.cols || q.y >= mask.rows) continue;
          if (mask.at<uchar>(q) == 0 || labels.at<int>(q) != 0) continue;
          if (maxStep > 0.0 && std::abs(disparity.at<float>(q) - disparity.at<float>(p)) > maxStep) continue;
          labels.at<int>(q) = next;
          stack.push_back(q);
        }
      }
      ++next;
    }
  }
  return next;
}

// `region` with the parts of `above` around it (split like the object, by steps) that hold no
// `width` x `width` square and touch it: parapets and wall tops stand higher than a roof by more
// than a step, yet belong to it.
cv::Mat withThinParts(const cv::Mat& region, const cv::Mat& above, const cv::Mat& disparity, double maxStep,
                      int width) {
  if (width <= 1) return region;
  cv::Mat labels;
  const int count = stepComponents(above & ~region, disparity, maxStep, labels);
  // A part is wide when a square lies inside it: the square's labels are all its own.
  cv::Mat asFloat, lowest, highest;
  labels.convertTo(asFloat, CV_32F);
  const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, {width, width});
  cv::erode(asFloat, lowest, square);
  cv::dilate(asFloat, highest, square);
  cv::Mat touching;
  cv::dilate(region, touching, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  std::vector<char> wide(static_cast<size_t>(count), 0), touches(static_cast<size_t>(count), 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const float* lo = lowest.ptr<float>(y);
    const float* hi = highest.ptr<float>(y);
    const uchar* t = touching.ptr<uchar>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (l[x] == 0) continue;
      if (lo[x] == hi[x]) wide[static_cast<size_t>(l[x])] = 1;
      if (t[x] != 0) touches[static_cast<size_t>(l[x])] = 1;
    }
  }
  cv::Mat out = region.clone();
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    uchar* o = out.ptr<uchar>(y);
    for (int x = 0; x < labels.cols; ++x) {
      const auto k = static_cast<size_t>(l[x]);
      if (l[x] > 0 && touches[k] && !wide[k]) o[x] = 255;
    }
  }
  return out;
}

// The object: grown from the seed, with its thin parts, smoothed (a closing then an opening by a
// `smoothing` px square: the matcher's ragged edges and no-data notches), its holes filled.
cv::Mat objectAt(const cv::Mat& above, const cv::Mat& disparity, cv::Point seed, const AboveGroundParams& params,
                 double maxStep) {
  cv::Mat region =
      withThinParts(growObject(above, disparity, seed, maxStep), above, disparity, maxStep, params.thinWidth);
  if (params.smoothing > 1) {
    const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, {params.smoothing, params.smoothing});
    cv::Mat smoothed;
    cv::morphologyEx(region, smoothed, cv::MORPH_CLOSE, square);
    cv::morphologyEx(smoothed, smoothed, cv::MORPH_OPEN, square);
    if (smoothed.at<uchar>(seed) != 0) region = smoothed;  // a small object may vanish: keep it raw
  }
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(region.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  cv::Mat filled = cv::Mat::zeros(region.size(), CV_8U);
  for (size_t i = 0; i < contours.size(); ++i) {
    if (cv::pointPolygonTest(contours[i], seed, false) >= 0) {
      cv::drawContours(filled, contours, static_cast<int>(i), cv::Scalar(255), cv::FILLED);
    }
  }
  return filled;
}

// The ground level in a band of `radius` px around the click (a one-pixel polygon).
double groundAroundClick(const cv::Mat& disparity, cv::Point click, double radius, RoofIntervalParams ground) {
  ground.groundMargin = radius;
  core::Polygon pixel;
  const double x = click.x, y = click.y;
  pixel.outer = {{x, y}, {x + 1, y}, {x + 1, y + 1}, {x, y + 1}};
  return estimateGroundLevel(disparity, pixel, ground);
}

}  // namespace

core::Polygon traceOutline(const cv::Mat& mask, cv::Point seed, double tolerance) {
  core::Polygon polygon;
  if (mask.empty() || !cv::Rect(0, 0, mask.cols, mask.rows).contains(seed) || mask.at<uchar>(seed) == 0) {
    return polygon;
  }
  const cv::Mat region = componentAt(mask, seed);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(region, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  if (contours.empty()) return polygon;
  std::vector<cv::Point> simplified;
  cv::approxPolyDP(contours.front(), simplified, tolerance, true);
  // A region of one pixel row or column traces to fewer than three vertices: its box instead.
  if (simplified.size() < 3) {
    const cv::Rect box = cv::boundingRect(contours.front());
    const double x0 = box.x, y0 = box.y, x1 = box.x + box.width, y1 = box.y + box.height;
    polygon.outer = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    return polygon;
  }
  for (const cv::Point& p : simplified) polygon.outer.emplace_back(p.x + 0.5, p.y + 0.5);
  return polygon;
}

AboveGroundObject aboveGroundObjectAt(const cv::Mat& disparity, cv::Point2d click, double metresPerPixel,
                                      const AboveGroundParams& params, const RoofIntervalParams& ground) {
  params.validate();
  ground.validate();
  if (disparity.empty() || disparity.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput, "the disparity map must be one band of float32");
  }
  if (!std::isfinite(metresPerPixel) || metresPerPixel == 0.0) {
    throw Error(ErrorCode::InvalidParameter, "the metres per pixel of disparity must be finite and non-zero");
  }
  const cv::Point pixel(static_cast<int>(std::floor(click.x)), static_cast<int>(std::floor(click.y)));
  if (!std::isfinite(click.x) || !std::isfinite(click.y) || !cv::Rect(0, 0, disparity.cols, disparity.rows).contains(pixel)) {
    throw Error(ErrorCode::InvalidParameter, "the clicked point (" + std::to_string(click.x) + ", " +
                                                 std::to_string(click.y) + ") is outside the map");
  }
  const double margin = params.heightMargin / std::abs(metresPerPixel);
  AboveGroundObject object;
  // The ground around the click; a click far inside a large roof sees little ground in the band:
  // widen it until the click stands above the level found.
  cv::Mat above;
  cv::Point seed(-1, -1);
  for (double radius = params.searchRadius;; radius = std::min(2.0 * radius, params.maxSearchRadius)) {
    object.groundLevel = groundAroundClick(disparity, pixel, radius, ground);
    if (std::isfinite(object.groundLevel)) {
      above = aboveMask(disparity, object.groundLevel + margin, params.opening);
      seed = nearestSet(above, pixel, params.snapRadius);
      if (seed.x >= 0) break;
    }
    if (radius >= params.maxSearchRadius) break;
  }
  if (!std::isfinite(object.groundLevel)) {
    object.outcome = PickOutcome::NoGround;
    return object;
  }
  if (seed.x < 0) {
    object.outcome = PickOutcome::NotAboveGround;
    return object;
  }
  // Then the ground next to the object, as the histogram reads it, until the object stops changing.
  const double maxStep = params.maxStep / std::abs(metresPerPixel);
  cv::Mat region = objectAt(above, disparity, seed, params, maxStep);
  core::Polygon outline = traceOutline(region, seed, params.simplification);
  double level = estimateGroundLevel(disparity, outline, ground);
  for (int i = 0; i < params.refinements && std::isfinite(level); ++i) {
    if (std::abs(level - object.groundLevel) < 0.1 * margin) break;
    const cv::Mat next = aboveMask(disparity, level + margin, params.opening);
    const cv::Point nextSeed = nearestSet(next, pixel, params.snapRadius);
    if (nextSeed.x < 0) break;  // the click is not above that ground: keep the object found
    ++object.refinements;
    object.groundLevel = level;
    seed = nextSeed;
    region = objectAt(next, disparity, seed, params, maxStep);
    outline = traceOutline(region, seed, params.simplification);
    level = estimateGroundLevel(disparity, outline, ground);
  }
  object.outcome = PickOutcome::Found;
  object.outline = outline;
  object.mask = region;
  object.pixels = cv::countNonZero(object.mask);
  object.groundLevel = level;  // the histogram's ground line for this outline
  return object;
}

}  // namespace delineo::delineation
