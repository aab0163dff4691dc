#include "delineo/dem/enhance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/core/nan_mask.hpp"

namespace delineo::dem {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kRowsPerPoll = 32;  // rows between two cancel polls in the filters

using core::Error;
using core::ErrorCode;

// Median of the finite values of `values` under non-zero `mask` in the (2 half + 1)² window
// around (x, y); NaN when there is none. `buffer` is scratch space.
float maskedMedian(const cv::Mat& values, const cv::Mat& mask, int x, int y, int half,
                   std::vector<float>& buffer) {
  buffer.clear();
  const int y0 = std::max(0, y - half), y1 = std::min(values.rows - 1, y + half);
  const int x0 = std::max(0, x - half), x1 = std::min(values.cols - 1, x + half);
  for (int yy = y0; yy <= y1; ++yy) {
    const float* v = values.ptr<float>(yy);
    const uchar* m = mask.ptr<uchar>(yy);
    for (int xx = x0; xx <= x1; ++xx) {
      if (m[xx] != 0 && std::isfinite(v[xx])) buffer.push_back(v[xx]);
    }
  }
  if (buffer.empty()) return kNaN;
  const size_t mid = buffer.size() / 2;
  std::nth_element(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(mid), buffer.end());
  const float upper = buffer[mid];
  if (buffer.size() % 2 == 1) return upper;
  const float lower = *std::max_element(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5f * (lower + upper);
}

// For every pixel, the position of the nearest pixel where `sources` is non-zero (L2 distance
// transform with pixel labels); `distance` receives the distance in px. Positions are (-1, -1)
// when there is no source.
cv::Mat nearestSource(const cv::Mat& sources, cv::Mat& distance) {
  cv::Mat labels;
  const cv::Mat notSource = sources == 0;
  cv::distanceTransform(notSource, distance, labels, cv::DIST_L2, cv::DIST_MASK_5,
                        cv::DIST_LABEL_PIXEL);
  // A source pixel carries its own label: the table from label to position.
  std::vector<cv::Point> where(static_cast<size_t>(sources.total()) + 1, cv::Point(-1, -1));
  for (int y = 0; y < sources.rows; ++y) {
    for (int x = 0; x < sources.cols; ++x) {
      if (sources.at<uchar>(y, x) != 0) where[static_cast<size_t>(labels.at<int>(y, x))] = {x, y};
    }
  }
  cv::Mat nearest(sources.size(), CV_32SC2, cv::Scalar(-1, -1));
  if (cv::countNonZero(sources) == 0) return nearest;
  for (int y = 0; y < sources.rows; ++y) {
    for (int x = 0; x < sources.cols; ++x) {
      const cv::Point p = where[static_cast<size_t>(labels.at<int>(y, x))];
      nearest.at<cv::Vec2i>(y, x) = {p.x, p.y};
    }
  }
  return nearest;
}

// Pixels of the largest 8-connected component of a CV_8U mask.
int largestComponent(const cv::Mat& mask) {
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  int largest = 0;
  for (int i = 1; i < n; ++i) largest = std::max(largest, stats.at<int>(i, cv::CC_STAT_AREA));
  return largest;
}

void checkDem(const cv::Mat& dem) {
  if (dem.empty()) throw Error(ErrorCode::UnsupportedInput, "the DEM is empty");
  if (dem.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput,
                "the DEM must be one channel of float32 heights, got type " +
                    std::to_string(dem.type()));
  }
  int finite = 0;
  for (int y = 0; y < dem.rows; ++y) {
    const float* row = dem.ptr<float>(y);
    for (int x = 0; x < dem.cols; ++x) {
      if (std::isinf(row[x])) {
        throw Error(ErrorCode::UnsupportedInput, "the DEM holds an infinite height at pixel (" +
                                                     std::to_string(x) + ", " +
                                                     std::to_string(y) + ")");
      }
      finite += std::isfinite(row[x]) ? 1 : 0;
    }
  }
  if (finite == 0) throw Error(ErrorCode::UnsupportedInput, "the DEM holds no height (all no data)");
}

void checkRing(const core::Ring& ring, size_t index, const char* what) {
  if (ring.size() < 3) {
    throw Error(ErrorCode::InvalidParameter, "footprint " + std::to_string(index) + ": its " +
                                                 what + " has fewer than 3 vertices");
  }
  for (const auto& p : ring) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      throw Error(ErrorCode::InvalidParameter, "footprint " + std::to_string(index) + ": its " +
                                                   what + " has a non-finite coordinate");
    }
  }
}

// Paints footprint `index` (label index + 1) into `labels` where no earlier footprint is, and
// returns the bounding box of the pixels it covers in the image.
cv::Rect paintFootprint(const core::Polygon& polygon, size_t index, cv::Mat& labels) {
  checkRing(polygon.outer, index, "outer ring");
  for (const auto& hole : polygon.holes) checkRing(hole, index, "hole");
  const cv::Rect2d box = core::boundingBox(polygon.outer);
  const cv::Rect image(0, 0, labels.cols, labels.rows);
  const cv::Rect roi = cv::Rect(static_cast<int>(std::floor(box.x)), static_cast<int>(std::floor(box.y)),
                                static_cast<int>(std::ceil(box.br().x) - std::floor(box.x)) + 1,
                                static_cast<int>(std::ceil(box.br().y) - std::floor(box.y)) + 1) &
                       image;
  cv::Mat mask;
  if (!roi.empty()) {
    core::Polygon shifted = polygon;
    const cv::Point2d offset(roi.x, roi.y);
    for (auto& p : shifted.outer) p -= offset;
    for (auto& hole : shifted.holes) {
      for (auto& p : hole) p -= offset;
    }
    mask = core::rasterize(shifted, roi.size());
  }
  if (mask.empty() || cv::countNonZero(mask) == 0) {
    throw Error(ErrorCode::MismatchedInputs, "footprint " + std::to_string(index) +
                                                 " covers no pixel of the " +
                                                 std::to_string(labels.cols) + "x" +
                                                 std::to_string(labels.rows) + " DEM");
  }
  cv::Mat target = labels(roi);
  target.setTo(static_cast<int>(index) + 1, mask & (target == 0));
  return cv::boundingRect(mask) + roi.tl();
}

// Median of the finite values of `values` under non-zero `mask`; NaN when there is none.
// `count` receives how many values there were.
double medianUnder(const cv::Mat& values, const cv::Mat& mask, int& count) {
  std::vector<float> v;
  for (int y = 0; y < values.rows; ++y) {
    const float* row = values.ptr<float>(y);
    const uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < values.cols; ++x) {
      if (m[x] != 0 && std::isfinite(row[x])) v.push_back(row[x]);
    }
  }
  count = static_cast<int>(v.size());
  if (v.empty()) return std::nan("");
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The parts of `mask` at least `size` px thick (a morphological opening by a size x size square).
cv::Mat thickParts(const cv::Mat& mask, int size) {
  cv::Mat opened;
  cv::morphologyEx(mask, opened, cv::MORPH_OPEN, cv::Mat::ones(size, size, CV_8U));
  return opened;
}

// Checks footprint `label` against the DEM and corrects its pixels in `labels` where the two
// disagree over more than params.outlineTolerance px: ground inside the outline (a strip of
// ground, a courtyard the outline left out) leaves the footprint; roof outside it (a roof part
// the outline missed, within params.outlineReach px) joins it. Thinner disagreements (the
// matcher's fattening of a roof, an outline a pixel or two off) follow the outline. Roof and
// ground are told apart by the midpoint between the roof's median height and the median height
// of the ground around the footprint; a footprint whose roof does not stand clear of its ground
// is left as it is. Paints its free roof pixels into `roofAround` (for the outer band) and
// returns the bounding box of the footprint's pixels afterwards.
// The 8-connected components of `mask` (CV_8U) that have a pixel in `seeds`, as a mask.
cv::Mat componentsTouching(const cv::Mat& mask, const cv::Mat& seeds) {
  cv::Mat components;
  const int n = cv::connectedComponents(mask, components, 8, CV_32S);
  std::vector<uchar> touches(static_cast<size_t>(n), 0);
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      const int c = components.at<int>(y, x);
      if (c > 0 && seeds.at<uchar>(y, x) != 0) touches[static_cast<size_t>(c)] = 1;
    }
  }
  cv::Mat out(mask.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      if (touches[static_cast<size_t>(components.at<int>(y, x))] != 0) out.at<uchar>(y, x) = 255;
    }
  }
  return out;
}

cv::Rect reconcileFootprint(const cv::Mat& dem, cv::Mat& labels, int label, cv::Rect box,
                            const EnhanceParams& params, FootprintEnhancement& info,
                            cv::Mat& roofAround) {
  const int groundReach = 2 * params.wallBand + params.groundWindow;
  const int grow = std::max(params.outlineReach, params.wallBand + groundReach) + 2;
  const cv::Rect roi = (box - cv::Point(grow, grow) + cv::Size(2 * grow, 2 * grow)) &
                       cv::Rect(0, 0, dem.cols, dem.rows);
  cv::Mat own = labels(roi);
  const cv::Mat heights = dem(roi);
  const cv::Mat inside = own == label, free = own == 0;
  cv::Mat depth, away;
  cv::distanceTransform(inside, depth, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::distanceTransform(~inside, away, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  int roofCount = 0, groundCount = 0;
  cv::Mat core = inside & (depth > params.wallBand);
  if (cv::countNonZero(core) == 0) core = inside;
  info.roofHeight = medianUnder(heights, core, roofCount);
  const cv::Mat ring = free & (away > params.wallBand) & (away <= params.wallBand + groundReach);
  info.groundHeight = medianUnder(heights, ring, groundCount);
  const double step = info.roofHeight - info.groundHeight;
  constexpr int kMinSamples = 8;
  if (params.outlineTolerance == 0 || roofCount < kMinSamples || groundCount < kMinSamples ||
      !(step > 0)) {
    return box;
  }
  // Heights below the midpoint are ground; within half a step of the roof's, roof.
  const double mid = info.roofHeight - 0.5 * step, top = info.roofHeight + 0.5 * step;
  const cv::Mat finite = core::numberMask(heights);
  const cv::Mat groundLike = finite & (heights < mid);
  const cv::Mat roofLike = finite & (heights >= mid) & (heights < top);
  const int size = params.outlineTolerance + 1;
  cv::Mat around = roofAround(roi);
  around.setTo(255, free & roofLike);

  // Ground inside: thick parts anywhere, and any ground in the wall band that reaches the ground
  // outside (the matcher fattens roofs outwards, so ground seen inside the outline is ground).
  cv::Mat removed = thickParts(inside & groundLike, size);
  removed |= inside & componentsTouching(groundLike & (free | (inside & (depth <= params.wallBand))), free);
  // Roof outside the outline joins when its thick part touches the footprint.
  cv::Mat near;
  cv::dilate(inside & ~removed, near, cv::Mat::ones(3, 3, CV_8U));
  const cv::Mat joined = componentsTouching(thickParts(free & roofLike & (away <= params.outlineReach), size), near);
  info.removedPixels += cv::countNonZero(removed);
  info.addedPixels += cv::countNonZero(joined & ~removed);
  own.setTo(0, removed);
  own.setTo(label, joined & ~removed);
  const cv::Mat after = own == label;
  if (cv::countNonZero(after) == 0) return box;  // never happens: the roof core is roof-like
  return cv::boundingRect(after) + roi.tl();
}

// Median filter of the DEM over the pixels of `mask` (ROI coordinates), written into `out` at
// those pixels. False when canceled.
bool filterOver(const cv::Mat& dem, const cv::Mat& mask, int window, cv::Mat& out,
                core::Progress* progress) {
  std::vector<float> buffer;
  buffer.reserve(static_cast<size_t>(window * window));
  for (int y = 0; y < mask.rows; ++y) {
    if (y % kRowsPerPoll == 0 && core::isCanceled(progress)) return false;
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uchar>(y, x) != 0) {
        out.at<float>(y, x) = maskedMedian(dem, mask, x, y, window / 2, buffer);
      }
    }
  }
  return true;
}

// Roof filtering and vertical walls for one footprint inside `roi`. False when canceled.
bool enhanceFootprint(const cv::Mat& dem, const cv::Mat& labels, int label, cv::Rect roi,
                      const cv::Mat& gradient, double threshold, const EnhanceParams& params,
                      cv::Mat& out, FootprintEnhancement& info, core::Progress* progress) {
  const cv::Mat inside = labels(roi) == label;
  const cv::Mat heights = dem(roi);
  info.pixels = cv::countNonZero(inside);
  // Distance of each inside pixel to the nearest pixel outside the footprint: the outline's
  // first pixels are at 1. The ROI reaches past the footprint except at the image border, which
  // is not an outline.
  cv::Mat depth;
  cv::distanceTransform(inside, depth, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  double deepest = 0;
  cv::minMaxLoc(depth, nullptr, &deepest);
  // The band is narrowed on footprints too narrow to keep a core beyond it.
  info.band = std::min(params.wallBand, std::max(0, static_cast<int>(std::ceil(deepest)) - 1));
  const cv::Mat roofCore = depth > info.band;

  // Roof object test (the paper's rule): a gradient above the Otsu threshold on the roof, away
  // from the walls' own gradients (band + the gradient filter's reach).
  const int reach = static_cast<int>(std::ceil(3.0 * params.gradientSigma));
  cv::Mat tested = depth > info.band + reach;
  if (cv::countNonZero(tested) == 0) tested = roofCore;
  const cv::Mat strong = (gradient(roi) > threshold) & tested;  // false on NaN
  info.objectPixels = largestComponent(strong);
  info.window = info.objectPixels >= params.minObjectPixels ? params.smallWindow : params.largeWindow;

  cv::Mat roof(roi.size(), CV_32F, cv::Scalar(kNaN));
  if (!filterOver(heights, roofCore, info.window, roof, progress)) return false;
  const cv::Mat valid = roofCore & core::numberMask(roof);
  if (cv::countNonZero(valid) == 0) {
    info.window = 0;  // no height anywhere on the roof: left as it is
    return true;
  }
  // Band pixels and roof pixels still without height take the filtered roof's nearest height.
  cv::Mat distance;
  const cv::Mat nearest = nearestSource(valid, distance);
  cv::Mat target = out(roi);
  for (int y = 0; y < roi.height; ++y) {
    for (int x = 0; x < roi.width; ++x) {
      if (inside.at<uchar>(y, x) == 0) continue;
      const cv::Vec2i p = nearest.at<cv::Vec2i>(y, x);
      const float value = roof.at<float>(p[1], p[0]);
      if (!std::isfinite(heights.at<float>(y, x))) ++info.filledPixels;
      target.at<float>(y, x) = value;
    }
  }
  return true;
}

// The outer band: pixels outside every footprint within `band` px of one take the median ground
// height around the nearest ground pixel beyond the band. False when canceled.
bool flattenOuterBand(const cv::Mat& dem, const cv::Mat& labels, const cv::Mat& roofAround,
                      const EnhanceParams& params, cv::Mat& out, core::Progress* progress) {
  if (params.wallBand == 0) return true;
  const cv::Mat outside = labels == 0;
  cv::Mat away;
  cv::distanceTransform(outside, away, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  // Roof (as told by reconcileFootprint, empty when the check is off) more than 1 px from any
  // other pixel outside the footprints is roof an outline missed by a pixel or two, not the
  // matcher's one-pixel fattening: it keeps its height.
  cv::Mat fromOther;
  cv::distanceTransform(roofAround | ~outside, fromOther, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const cv::Mat missedRoof = roofAround & (fromOther > 1.5);
  const cv::Mat band = outside & (away <= params.wallBand) & ~missedRoof;
  const cv::Mat beyond = outside & (away > params.wallBand);
  const cv::Mat ground = beyond & core::numberMask(dem);
  cv::Mat distance, open;
  const cv::Mat nearest = nearestSource(ground, distance);
  // A band pixel farther than `reach` from anything beyond the band (a small courtyard, a dense
  // block) keeps its height rather than borrow a far one. No data beyond the band counts as
  // open ground: next to a wall it is mostly ground hidden in the other view.
  cv::distanceTransform(~beyond, open, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const double reach = 2.0 * params.wallBand + params.groundWindow;
  std::vector<float> buffer;
  for (int y = 0; y < dem.rows; ++y) {
    if (y % kRowsPerPoll == 0 && core::isCanceled(progress)) return false;
    for (int x = 0; x < dem.cols; ++x) {
      if (band.at<uchar>(y, x) == 0 || open.at<float>(y, x) > reach) continue;
      const cv::Vec2i p = nearest.at<cv::Vec2i>(y, x);
      if (p[0] < 0) continue;
      out.at<float>(y, x) = maskedMedian(dem, ground, p[0], p[1], params.groundWindow / 2, buffer);
    }
  }
  return true;
}

}  // namespace

void EnhanceParams::validate() const {
  core::checkDeclaredRanges(*this);
  for (const auto& [key, value] : {std::pair{"small-window", smallWindow},
                                   std::pair{"large-window", largeWindow},
                                   std::pair{"ground-window", groundWindow}}) {
    if (value % 2 == 0) {
      throw Error(ErrorCode::InvalidParameter,
                  std::string(key) + " = " + std::to_string(value) + " must be odd");
    }
  }
  if (smallWindow > largeWindow) {
    throw Error(ErrorCode::InvalidParameter, "small-window = " + std::to_string(smallWindow) +
                                                 " exceeds large-window = " +
                                                 std::to_string(largeWindow));
  }
}

cv::Mat gradientMagnitude(const cv::Mat& dem, double sigma) {
  const int r = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  cv::Mat kx(2 * r + 1, 2 * r + 1, CV_32F);
  double norm = 0;
  for (int v = -r; v <= r; ++v) {
    for (int u = -r; u <= r; ++u) {
      const double g = std::exp(-(u * u + v * v) / (2.0 * sigma * sigma));
      kx.at<float>(v + r, u + r) = static_cast<float>(u * g);
      norm += u * u * g;
    }
  }
  kx /= norm;  // a plane of slope s gives s
  const cv::Mat ky = kx.t();
  const cv::Mat missing = core::nanMask(dem);
  cv::Mat filled = dem.clone();
  filled.setTo(0.0f, missing);
  cv::Mat dx, dy, magnitude;
  cv::filter2D(filled, dx, CV_32F, kx, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  cv::filter2D(filled, dy, CV_32F, ky, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  cv::magnitude(dx, dy, magnitude);
  cv::Mat reached;
  cv::dilate(missing, reached, cv::Mat::ones(2 * r + 1, 2 * r + 1, CV_8U));
  magnitude.setTo(kNaN, reached);
  return magnitude;
}

double otsuThreshold(const cv::Mat& values) {
  std::vector<float> finite;
  finite.reserve(values.total());
  for (int y = 0; y < values.rows; ++y) {
    const float* row = values.ptr<float>(y);
    for (int x = 0; x < values.cols; ++x) {
      if (std::isfinite(row[x])) finite.push_back(row[x]);
    }
  }
  if (finite.size() < 2) return 0.0;
  const auto top = finite.begin() + static_cast<std::ptrdiff_t>(0.999 * (finite.size() - 1));
  std::nth_element(finite.begin(), top, finite.end());
  const double hi = *top;
  const double lo = *std::min_element(finite.begin(), finite.end());
  if (!(hi > lo)) return 0.0;
  constexpr int kBins = 256;
  const double width = (hi - lo) / kBins;
  std::vector<double> histogram(kBins, 0.0);
  for (float v : finite) {
    histogram[static_cast<size_t>(std::clamp(static_cast<int>((v - lo) / width), 0, kBins - 1))] += 1;
  }
  double total = 0, totalSum = 0;
  for (int i = 0; i < kBins; ++i) {
    total += histogram[i];
    totalSum += i * histogram[i];
  }
  // Between-class variance w0 w1 (m0 - m1)², maximised over the split after bin k.
  double w0 = 0, sum0 = 0, best = -1;
  int bestBin = 0;
  for (int k = 0; k < kBins - 1; ++k) {
    w0 += histogram[k];
    sum0 += k * histogram[k];
    const double w1 = total - w0;
    if (w0 == 0 || w1 == 0) continue;
    const double m0 = sum0 / w0, m1 = (totalSum - sum0) / w1;
    const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best) {
      best = between;
      bestBin = k;
    }
  }
  return lo + (bestBin + 1) * width;
}

EnhanceResult enhanceDem(const cv::Mat& dem, const std::vector<core::Polygon>& footprints,
                         const EnhanceParams& params, core::Progress* progress) {
  params.validate();
  checkDem(dem);
  cv::Mat labels(dem.size(), CV_32S, cv::Scalar(0));
  std::vector<cv::Rect> boxes;
  boxes.reserve(footprints.size());
  for (size_t i = 0; i < footprints.size(); ++i) {
    boxes.push_back(paintFootprint(footprints[i], i, labels));
  }

  EnhanceResult result;
  result.footprints.resize(footprints.size());
  cv::Mat roofAround = cv::Mat::zeros(dem.size(), CV_8U);
  for (size_t i = 0; i < footprints.size(); ++i) {
    boxes[i] = reconcileFootprint(dem, labels, static_cast<int>(i) + 1, boxes[i], params,
                                  result.footprints[i], roofAround);
  }
  auto canceled = [&] {
    result.status = core::RunStatus::Canceled;
    result.dem = dem;
    return result;
  };
  const cv::Mat gradient = gradientMagnitude(dem, params.gradientSigma);
  result.gradientThreshold = otsuThreshold(gradient);
  core::report(progress, 0.1);

  result.dem = dem.clone();
  // Each footprint's ROI reaches past its outline far enough for the distance to the outline.
  const int margin = 2;
  const cv::Rect image(0, 0, dem.cols, dem.rows);
  for (size_t i = 0; i < footprints.size(); ++i) {
    if (core::isCanceled(progress)) return canceled();
    const cv::Rect roi = (boxes[i] - cv::Point(margin, margin) + cv::Size(2 * margin, 2 * margin)) & image;
    core::Progress::Range part(progress, 0.1 + 0.8 * static_cast<double>(i) / footprints.size(),
                               0.1 + 0.8 * static_cast<double>(i + 1) / footprints.size());
    if (!enhanceFootprint(dem, labels, static_cast<int>(i) + 1, roi, gradient,
                          result.gradientThreshold, params, result.dem, result.footprints[i],
                          &part)) {
      return canceled();
    }
    part.report(1.0);
  }
  core::Progress::Range ground(progress, 0.9, 1.0);
  if (!flattenOuterBand(dem, labels, roofAround, params, result.dem, &ground)) return canceled();
  core::report(progress, 1.0);
  return result;
}

}  // namespace delineo::dem
