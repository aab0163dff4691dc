// Box-fitting: the stages chained for one building (an operator's init) or for every building
// segment of the image.
#include "delineo/boxfit/box_fitting.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "delineo/boxfit/stages.hpp"
#include "delineo/core/error.hpp"
#include "delineo/core/nan_mask.hpp"

namespace delineo::boxfit {

namespace {

using core::Error;
using core::ErrorCode;

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string metres(double v) {
  std::ostringstream s;
  s.precision(2);
  s << std::fixed << v << " m";
  return s.str();
}

void checkInputs(const cv::Mat& heights, const cv::Mat& image, const BoxFitRequest& request) {
  if (heights.empty()) throw Error(ErrorCode::InvalidParameter, "the DEM is empty");
  if (image.empty()) throw Error(ErrorCode::InvalidParameter, "the image is empty");
  if (heights.channels() != 1) {
    throw Error(ErrorCode::UnsupportedInput, "the DEM must have one band, it has " + std::to_string(heights.channels()));
  }
  if (image.channels() != 1) {
    throw Error(ErrorCode::UnsupportedInput, "the image must be grey (one channel), it has " + std::to_string(image.channels()));
  }
  if (heights.size() != image.size()) {
    throw Error(ErrorCode::MismatchedInputs, "the DEM is " + std::to_string(heights.cols) + "x" + std::to_string(heights.rows) +
                                                 " px but the image " + std::to_string(image.cols) + "x" +
                                                 std::to_string(image.rows) + ": the DEM must be on the image's pixel grid");
  }
  const auto& ring = request.init.outer;
  if (ring.empty()) return;
  if (ring.size() < 3) throw Error(ErrorCode::InvalidParameter, "the initial polygon needs at least 3 vertices");
  for (const auto& p : ring) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) throw Error(ErrorCode::InvalidParameter, "the initial polygon has a non-finite vertex");
  }
  if (std::abs(core::signedArea(ring)) < 1.0) throw Error(ErrorCode::InvalidParameter, "the initial polygon has no area");
  const cv::Rect2d box = core::boundingBox(ring);
  const cv::Rect2d image2d(0, 0, image.cols, image.rows);
  if ((box & image2d).area() <= 0) {
    std::ostringstream s;
    s << "the initial polygon (" << box.x << ", " << box.y << ", " << box.width << " x " << box.height
      << ") lies outside the " << image.cols << "x" << image.rows << " image";
    throw Error(ErrorCode::InvalidParameter, s.str());
  }
}

cv::Rect grown(const cv::Rect& r, int margin, cv::Size size) {
  return cv::Rect(r.x - margin, r.y - margin, r.width + 2 * margin, r.height + 2 * margin) & cv::Rect(0, 0, size.width, size.height);
}

// Heights above the local ground over `roi`, computed on `roi` widened by half the ground window
// (the opening needs the ground around the building). `window` is the opening's side (px, odd).
// Empty when no height is finite there.
cv::Mat aboveGround(const cv::Mat& heights, const cv::Rect& roi, int window, double* groundMedian) {
  const cv::Rect context = grown(roi, window / 2, heights.size());
  const cv::Mat filled = fillHeightGaps(heights(context));
  // The gap filling leaves NaN only where the whole context is NaN.
  if (cv::countNonZero(core::numberMask(filled)) == 0) return {};
  const cv::Mat ground = localGround(filled, window);
  const cv::Rect local(roi.tl() - context.tl(), roi.size());
  cv::Mat above = filled(local) - ground(local);
  if (groundMedian) {
    const cv::Mat around = ground(local).clone();
    std::vector<float> g(around.begin<float>(), around.end<float>());
    std::nth_element(g.begin(), g.begin() + static_cast<std::ptrdiff_t>(g.size() / 2), g.end());
    *groundMedian = g[g.size() / 2];
  }
  return above;
}

// The stages for one building in `roi`: `above` and `initMask` are ROI-sized. Returns false with
// `why` set when no building came out.
bool fitOne(const cv::Mat& above, const cv::Mat& initMask, double roofHeight, const cv::Mat& image, const cv::Rect& roi,
            cv::Size imageSize, const BoxFitParams& params, core::Progress* progress, BoxFitBuilding& out, std::string& why,
            core::RunStatus& status) {
  BoxFitDiagnostics& d = out.diagnostics;
  out.roi = roi;
  d.roofHeight = roofHeight;
  d.aboveGround = above;
  d.threshold = std::max(params.minHeight, params.thresholdFraction * roofHeight);
  core::setStage(progress, core::StageId::BoxFitSegment);
  auto t0 = std::chrono::steady_clock::now();
  d.segment = buildingSegment(above, initMask, roofHeight, params);
  d.segmentArea = cv::countNonZero(d.segment);
  d.segmentMs = msSince(t0);
  if (d.segmentArea == 0) {
    why = "no building segment of at least " + std::to_string(params.minArea) + " px between " + metres(d.threshold) +
          " and " + metres((1.0 + params.roofBand) * roofHeight + params.minHeight) + " above the ground";
    return false;
  }
  t0 = std::chrono::steady_clock::now();
  const cv::Mat edges = boxEdges(image(roi), params);
  const SkeletonSeeds seeds = skeletonSeeds(d.segment, params);
  d.skeletonPixels = cv::countNonZero(seeds.skeleton);
  d.junctions = seeds.junctions;
  for (const auto& s : seeds.seeds) d.seeds.emplace_back(s.point.x + 0.5 + roi.x, s.point.y + 0.5 + roi.y);
  d.seedsMs = msSince(t0);
  core::setStage(progress, core::StageId::BoxFitBoxes);
  t0 = std::chrono::steady_clock::now();
  const cv::Vec4b border(roi.x == 0, roi.y == 0, roi.br().x == imageSize.width, roi.br().y == imageSize.height);
  core::Progress::Range boxProgress(progress, 0.1, 0.8);
  BoxFitting fitting = fitSeedBoxes(d.segment, edges, seeds.seeds, params, border, progress ? &boxProgress : nullptr);
  // A second round of boxes for what the first left uncovered.
  const std::vector<Seed> extra = fitting.status == core::RunStatus::Completed
                                      ? uncoveredSeeds(d.segment, fitting.boxes, params)
                                      : std::vector<Seed>{};
  if (!extra.empty()) {
    core::Progress::Range extraProgress(progress, 0.8, 0.9);
    BoxFitting more = fitSeedBoxes(d.segment, edges, extra, params, border, progress ? &extraProgress : nullptr);
    fitting.status = more.status;
    fitting.anglesEvaluated += more.anglesEvaluated;
    fitting.boxes.insert(fitting.boxes.end(), more.boxes.begin(), more.boxes.end());
    for (const auto& s : extra) d.seeds.emplace_back(s.point.x + 0.5 + roi.x, s.point.y + 0.5 + roi.y);
  }
  d.boxesMs = msSince(t0);
  d.seedsFitted = static_cast<int>(fitting.boxes.size());
  d.seedsSkipped = fitting.seedsSkipped;
  d.anglesEvaluated = fitting.anglesEvaluated;
  d.mainOrientationDeg = fitting.mainOrientationDeg;
  d.boxesAtMainOrientation = fitting.boxesAtMainOrientation;
  if (fitting.status == core::RunStatus::Canceled) {
    status = core::RunStatus::Canceled;
    why = "canceled";
    return false;
  }
  core::setStage(progress, core::StageId::BoxFitOutline);
  t0 = std::chrono::steady_clock::now();
  core::Polygon outline = mergeBoxes(fitting.boxes, roi.size(), params, d.segment, &d.mergedArea);
  d.outlineMs = msSince(t0);
  if (outline.outer.size() < 3) {
    why = "no box could be grown from the " + std::to_string(seeds.seeds.size()) + " seeds";
    return false;
  }
  const cv::Point2d offset(roi.x, roi.y);
  for (auto& v : outline.outer) v += offset;
  for (auto& h : outline.holes) {
    for (auto& v : h) v += offset;
  }
  out.outline = std::move(outline);
  double weighted = 0, area = 0;
  for (auto& b : fitting.boxes) {
    b.centre += offset;
    b.seed += offset;
    weighted += b.energy * b.area();
    area += b.area();
  }
  out.energy = area > 0 ? weighted / area : 0.0;
  out.boxes = std::move(fitting.boxes);
  d.vertices = static_cast<int>(out.outline.outer.size());
  for (const auto& h : out.outline.holes) d.vertices += static_cast<int>(h.size());
  core::report(progress, 1.0);
  return true;
}

// The building's boxes reduced to those its outline is made of (after the whole-image check,
// which reads every box's energy).
void keepEssentialBoxes(BoxFitBuilding& building) {
  const cv::Point2d offset(building.roi.x, building.roi.y);
  for (auto& b : building.boxes) b.centre -= offset;
  building.boxes = essentialBoxes(building.boxes, building.roi.size());
  for (auto& b : building.boxes) b.centre += offset;
}

}  // namespace

namespace {
// The building inside the operator's initial polygon (`request.init`).
BoxFitResult fitFromInit(const cv::Mat& heights32, const cv::Mat& image, const BoxFitRequest& request,
                         const BoxFitParams& params, core::Progress* progress) {
  BoxFitResult result;
  const cv::Size size = image.size();
  const cv::Rect2d box = core::boundingBox(request.init.outer);
  const cv::Rect tight(cv::Point(static_cast<int>(std::floor(box.x)), static_cast<int>(std::floor(box.y))),
                       cv::Point(static_cast<int>(std::ceil(box.x + box.width)), static_cast<int>(std::ceil(box.y + box.height))));
  const cv::Rect roi = grown(tight, params.roiMargin, size);
  double groundMedian = 0;
  // An opening narrower than the building would take its roof for the ground: the window is
  // at least twice the initial polygon's longer side.
  const int window = std::max(params.groundWindow, (2 * std::max(tight.width, tight.height)) | 1);
  const cv::Mat above = aboveGround(heights32, roi, window, &groundMedian);
  if (above.empty()) {
    result.message = "no finite height in the DEM around the initial polygon";
    return result;
  }
  core::Polygon local = request.init;
  local.holes.clear();
  for (auto& v : local.outer) v -= cv::Point2d(roi.x, roi.y);
  const cv::Mat initMask = core::rasterize(local, roi.size());
  double roof = request.roofHeight ? *request.roofHeight : roofLevel(above, initMask, params.minHeight);
  if (!std::isfinite(roof) || roof < params.minHeight) {
    result.message = "nothing inside the initial polygon stands " + metres(params.minHeight) + " above the ground";
    return result;
  }
  BoxFitBuilding building;
  building.diagnostics.groundHeight = groundMedian;
  std::string why;
  if (fitOne(above, initMask, roof, image, roi, size, params, progress, building, why, result.status)) {
    keepEssentialBoxes(building);
    result.buildings.push_back(std::move(building));
  } else {
    result.message = why;
  }
  return result;
}

// Every region of the image higher than min-height, each fitted like an operator's init; without
// an operator's word that a building is there, a region none of whose boxes follows straight edges
// (a tree crown, a heap) is not one.
BoxFitResult fitWholeImage(const cv::Mat& heights32, const cv::Mat& image, const BoxFitParams& params,
                           core::Progress* progress) {
  BoxFitResult result;
  const cv::Size size = image.size();
  core::setStage(progress, core::StageId::BoxFitSegment);
  double groundMedian = 0;
  const cv::Mat above = aboveGround(heights32, cv::Rect(0, 0, size.width, size.height), params.groundWindow, &groundMedian);
  if (above.empty()) {
    result.message = "the DEM has no finite height";
    return result;
  }
  const std::vector<cv::Mat> regions = candidateRegions(above, params);
  if (regions.empty()) {
    result.message = "no region of at least " + std::to_string(params.minArea) + " px stands " + metres(params.minHeight) +
                     " above the ground";
    return result;
  }
  for (size_t i = 0; i < regions.size() && result.status != core::RunStatus::Canceled; ++i) {
    if (core::isCanceled(progress)) {
      result.status = core::RunStatus::Canceled;
      break;
    }
    core::Progress::Range range(progress, double(i) / regions.size(), double(i + 1) / regions.size());
    const cv::Rect roi = grown(cv::boundingRect(regions[i]), params.roiMargin, size);
    const cv::Mat initMask = regions[i](roi);
    const double roof = roofLevel(above(roi), initMask, params.minHeight);
    if (!std::isfinite(roof)) continue;
    BoxFitBuilding building;
    building.diagnostics.groundHeight = groundMedian;
    std::string why;
    if (!fitOne(above(roi), initMask, roof, image, roi, size, params, progress ? &range : nullptr, building, why,
                result.status)) {
      continue;
    }
    const bool straight = std::any_of(building.boxes.begin(), building.boxes.end(),
                                      [&](const Box& b) { return b.energy <= params.maxEnergy; });
    if (straight) {
      keepEssentialBoxes(building);
      result.buildings.push_back(std::move(building));
    }
  }
  if (result.buildings.empty() && result.status == core::RunStatus::Completed) {
    result.message = std::to_string(regions.size()) + " raised region(s) but no building fitted";
  }
  return result;
}
}  // namespace

BoxFitResult fitBoxes(const cv::Mat& heights, const cv::Mat& image, const BoxFitRequest& request,
                      const BoxFitParams& params, core::Progress* progress) {
  params.validate();
  checkInputs(heights, image, request);
  cv::Mat heights32;
  heights.convertTo(heights32, CV_32F);
  if (!request.init.outer.empty()) return fitFromInit(heights32, image, request, params, progress);
  return fitWholeImage(heights32, image, params, progress);
}

cv::Mat heightsFromDisparity(const cv::Mat& disparity, double groundDisparity, double metresPerPixel) {
  cv::Mat d;
  disparity.convertTo(d, CV_32F);
  return (d - groundDisparity) * metresPerPixel;
}

}  // namespace delineo::boxfit
