#include "delineo/segmentation/detect.hpp"

#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"

namespace delineo::segmentation {

void DetectParams::validate() const { core::checkDeclaredRanges(*this); }

namespace {

// The outline grown by `growth` px: rasterised in its box, every pixel within `growth` of it
// added (Euclidean), traced again.
core::Polygon grown(const core::Polygon& outline, double growth) {
  if (growth <= 0) return outline;
  const int pad = static_cast<int>(std::ceil(growth)) + 2;
  const cv::Rect2d box = core::boundingBox(outline.outer);
  const cv::Point2d origin(std::floor(box.x) - pad, std::floor(box.y) - pad);
  core::Polygon local = outline;
  for (auto& v : local.outer) v -= origin;
  for (auto& hole : local.holes) {
    for (auto& v : hole) v -= origin;
  }
  const cv::Size size(static_cast<int>(std::ceil(box.width)) + 2 * pad + 2,
                      static_cast<int>(std::ceil(box.height)) + 2 * pad + 2);
  const cv::Mat mask = core::rasterize(local, size);
  cv::Mat distance;  // to the nearest pixel inside the outline
  cv::distanceTransform(mask == 0, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  core::Polygon out = traceMask(distance <= growth, 1.0, 1.0);
  for (auto& v : out.outer) v += origin;
  for (auto& hole : out.holes) {
    for (auto& v : hole) v += origin;
  }
  return out;
}

}  // namespace

std::vector<core::Feature> proposeBuildings(const std::vector<SceneObject>& objects, const DetectParams& params) {
  params.validate();
  std::vector<core::Feature> proposals;
  for (const SceneObject& o : objects) {
    if (o.cls != kClassBuilding || o.areaM2 < params.minBuildingArea) continue;
    if (!(o.meanHeight >= params.minHeight)) continue;  // NaN (no height) is not proposed either
    core::Feature f;
    f.polygon = grown(o.outline, params.growth);
    if (f.polygon.outer.size() < 3) continue;
    f.attributes["id"] = static_cast<long long>(o.id);
    if (o.hasRoofInterval) {
      f.attributes["roof_disparity_min"] = static_cast<long long>(o.roofDisparityMin);
      f.attributes["roof_disparity_max"] = static_cast<long long>(o.roofDisparityMax);
      if (std::isfinite(o.groundDisparity)) {
        const long long g = std::llround(o.groundDisparity);
        if (g + params.groundTolerance < o.roofDisparityMin) f.attributes["ground_disparity"] = g;
      }
    }
    f.attributes["area_m2"] = o.areaM2;
    f.attributes["mean_height_m"] = o.meanHeight;
    proposals.push_back(std::move(f));
  }
  return proposals;
}

Detection detectBuildings(const cv::Mat& image, const cv::Mat& aboveGround, const cv::Mat& ndsm, double gsd,
                          const cv::Mat& disparity, const cv::Mat& regions, const ClassifyParams& classifyParams,
                          const ObjectParams& objectParams, const DetectParams& detectParams,
                          core::Progress* progress, const LevelSplit& split) {
  classifyParams.validate();
  objectParams.validate();
  detectParams.validate();
  Detection out;
  {
    core::Progress::Range range(progress, 0.0, 0.7);
    out.classification = classify(image, aboveGround, ndsm, gsd, classifyParams, regions, progress ? &range : nullptr);
  }
  if (out.classification.status == core::RunStatus::Canceled) {
    out.status = core::RunStatus::Canceled;
    return out;
  }
  {
    core::Progress::Range range(progress, 0.7, 1.0);
    out.objects = extractObjects(out.classification.labels, ndsm, gsd, objectParams, disparity,
                                 progress ? &range : nullptr, regions, split);
  }
  if (out.objects.status == core::RunStatus::Canceled) {
    out.status = core::RunStatus::Canceled;
    return out;
  }
  out.proposals = proposeBuildings(out.objects.objects, detectParams);
  return out;
}

}  // namespace delineo::segmentation
