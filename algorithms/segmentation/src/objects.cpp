#include "delineo/segmentation/objects.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/delineation/roof_interval.hpp"

namespace delineo::segmentation {

using core::Error;
using core::ErrorCode;

void ObjectParams::validate() const {
  core::checkDeclaredRanges(*this);
  if (smoothing % 2 == 0) throw Error(ErrorCode::InvalidParameter, "smoothing must be odd");
}

namespace {

core::Ring ringOf(const std::vector<cv::Point>& contour, double simplification, cv::Point2d offset) {
  std::vector<cv::Point> simplified;
  cv::approxPolyDP(contour, simplified, simplification * 2.0, true);
  if (simplified.size() < 3) simplified = contour;
  core::Ring ring;
  // Contour points are pixel indices of the doubled mask: pixel k covers [k/2, (k+1)/2).
  for (const cv::Point& p : simplified) ring.emplace_back(offset.x + (p.x + 0.5) / 2.0, offset.y + (p.y + 0.5) / 2.0);
  return ring;
}

// The p-th percentile (0..100) of `v` (not empty), by partial sort.
float percentile(std::vector<float>& v, double p) {
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(std::lround(p / 100.0 * (v.size() - 1))));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

void measureHeights(SceneObject& o, const cv::Mat& ndsm, const cv::Mat& mask) {
  double sum = 0, top = -1e300;
  long n = 0;
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      const float h = ndsm.at<float>(y, x);
      if (mask.at<uchar>(y, x) == 0 || !std::isfinite(h)) continue;
      sum += h, ++n, top = std::max(top, static_cast<double>(h));
    }
  }
  if (n > 0) o.meanHeight = sum / n, o.maxHeight = top;
}

// Roof interval from the disparities of the object's core (the object shrunk by `coreShrink`,
// the whole object when the core holds fewer than 20 values), and the ground next to it.
void measureDisparity(SceneObject& o, const cv::Mat& disparity, const cv::Mat& mask, const ObjectParams& p) {
  cv::Mat core = mask;
  if (p.coreShrink > 0) {
    cv::Mat depth;
    cv::Mat padded;
    cv::copyMakeBorder(mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
    cv::distanceTransform(padded, depth, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    core = depth(cv::Rect(1, 1, mask.cols, mask.rows)) > p.coreShrink;
  }
  std::vector<float> values;
  for (const cv::Mat* m : {static_cast<const cv::Mat*>(&core), &mask}) {
    values.clear();
    for (int y = 0; y < m->rows; ++y) {
      for (int x = 0; x < m->cols; ++x) {
        const float d = disparity.at<float>(y, x);
        if (m->at<uchar>(y, x) != 0 && std::isfinite(d)) values.push_back(d);
      }
    }
    if (values.size() >= 20) break;
  }
  if (values.size() < 3) return;
  o.hasRoofInterval = true;
  o.roofDisparityMin = static_cast<int>(std::floor(percentile(values, p.roofPercentile)));
  o.roofDisparityMax = static_cast<int>(std::ceil(percentile(values, 100.0 - p.roofPercentile)));
}

}  // namespace

core::Polygon traceMask(const cv::Mat& mask, double simplification, double minHolePixels) {
  core::Polygon polygon;
  if (mask.empty() || cv::countNonZero(mask) == 0) return polygon;
  // Doubled so that the contour runs a quarter pixel inside the border instead of through the
  // border pixels' centres; one pixel of padding so that a piece touching the edge closes.
  cv::Mat big;
  cv::resize(mask != 0, big, {}, 2, 2, cv::INTER_NEAREST);
  cv::copyMakeBorder(big, big, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  std::vector<std::vector<cv::Point>> contours;
  std::vector<cv::Vec4i> hierarchy;
  cv::findContours(big, contours, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_SIMPLE);
  int outer = -1;
  double best = -1;
  for (int i = 0; i < static_cast<int>(contours.size()); ++i) {
    if (hierarchy[static_cast<size_t>(i)][3] >= 0) continue;  // a hole
    const double a = cv::contourArea(contours[static_cast<size_t>(i)]);
    if (a > best) best = a, outer = i;
  }
  const cv::Point2d offset(-0.5, -0.5);  // undo the padding (one doubled pixel = half a pixel)
  polygon.outer = ringOf(contours[static_cast<size_t>(outer)], simplification, offset);
  for (int h = hierarchy[static_cast<size_t>(outer)][2]; h >= 0; h = hierarchy[static_cast<size_t>(h)][0]) {
    const auto& hole = contours[static_cast<size_t>(h)];
    if (cv::contourArea(hole) / 4.0 < minHolePixels) continue;
    core::Ring ring = ringOf(hole, simplification, offset);
    if (ring.size() >= 3) polygon.holes.push_back(std::move(ring));
  }
  return polygon;
}

namespace {

// The object of the non-zero pixels of `mask` (the crop `box` of the scene), or false when it is
// under `minArea` or smoothed away.
bool makeObject(SceneObject& o, const cv::Mat& mask, const cv::Rect& box, const cv::Mat& ndsm, const cv::Mat& disparity,
                double gsd, const ObjectParams& params) {
  const double pixelArea = gsd * gsd;
  o.pixels = cv::countNonZero(mask);
  o.areaM2 = o.pixels * pixelArea;
  if (o.areaM2 < params.minArea) return false;
  measureHeights(o, ndsm(box), mask);
  // Outline of the piece smoothed in a padded crop (closing then opening).
  const int pad = params.smoothing + 1;
  cv::Mat crop;
  cv::copyMakeBorder(mask, crop, pad, pad, pad, pad, cv::BORDER_CONSTANT, 0);
  if (params.smoothing > 1) {
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {params.smoothing, params.smoothing});
    cv::morphologyEx(crop, crop, cv::MORPH_CLOSE, kernel);
    cv::morphologyEx(crop, crop, cv::MORPH_OPEN, kernel);
  }
  o.outline = traceMask(crop, params.simplification, params.minArea / pixelArea);
  if (o.outline.outer.size() < 3) return false;  // smoothed away
  const cv::Point2d shift(box.x - pad, box.y - pad);
  for (auto& v : o.outline.outer) v += shift;
  for (auto& hole : o.outline.holes) {
    for (auto& v : hole) v += shift;
  }
  if (!disparity.empty()) {
    measureDisparity(o, disparity(box), mask, params);
    o.groundDisparity = delineation::estimateGroundLevel(disparity, o.outline);
  }
  return true;
}

}  // namespace

ObjectSet extractObjects(const cv::Mat& labels, const cv::Mat& ndsm, double gsd, const ObjectParams& params,
                         const cv::Mat& disparity, core::Progress* progress, const cv::Mat& regions,
                         const LevelSplit& split) {
  params.validate();
  if (labels.empty() || labels.type() != CV_8UC1) {
    throw Error(ErrorCode::UnsupportedInput, "the class labels must be one band of 8 bits");
  }
  if (ndsm.empty() || ndsm.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput, "the heights above the DTM (nDSM) must be one band of float32");
  }
  if (!disparity.empty() && disparity.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput, "the disparity map must be one band of float32");
  }
  if (!regions.empty() && regions.type() != CV_32SC1) {
    throw Error(ErrorCode::UnsupportedInput, "the region map must be one band of 32-bit integers");
  }
  if (ndsm.size() != labels.size() || (!disparity.empty() && disparity.size() != labels.size()) ||
      (!regions.empty() && regions.size() != labels.size())) {
    throw Error(ErrorCode::MismatchedInputs,
                "the class labels, the nDSM, the disparity map and the region map must have one size");
  }
  if (!std::isfinite(gsd) || gsd <= 0.0) {
    throw Error(ErrorCode::InvalidParameter, "the ground sampling distance must be a positive number of metres");
  }
  ObjectSet out;
  out.index = cv::Mat::zeros(labels.size(), CV_32S);
  int nextId = 1;
  for (const ClassLabel cls : {kClassBuilding, kClassVegetation}) {
    const double done = cls == kClassBuilding ? 0.0 : 0.5;
    cv::Mat pieces, stats, centroids;
    const int n = cv::connectedComponentsWithStats(labels == cls, pieces, stats, centroids, 8, CV_32S);
    for (int c = 1; c < n; ++c) {
      if (core::isCanceled(progress)) {
        out.status = core::RunStatus::Canceled;
        return out;
      }
      const cv::Rect box(stats.at<int>(c, cv::CC_STAT_LEFT), stats.at<int>(c, cv::CC_STAT_TOP),
                         stats.at<int>(c, cv::CC_STAT_WIDTH), stats.at<int>(c, cv::CC_STAT_HEIGHT));
      const cv::Mat piece = pieces(box) == c;
      // Buildings: one part per height level (levels.hpp); vegetation and no region map: the piece.
      int partCount = 1;
      const cv::Mat parts = cls == kClassBuilding && !regions.empty()
                                ? splitLevels(piece, regions(box), ndsm(box), gsd, split, partCount)
                                : cv::Mat();
      for (int part = 1; part <= partCount; ++part) {
        const cv::Mat mask = partCount == 1 ? piece : cv::Mat(parts == part);
        SceneObject o;
        o.id = nextId++;
        o.cls = cls;
        out.index(box).setTo(o.id, mask);
        if (makeObject(o, mask, box, ndsm, disparity, gsd, params)) out.objects.push_back(std::move(o));
      }
      core::report(progress, done + 0.5 * c / n);
    }
  }
  return out;
}

std::vector<core::Feature> objectFeatures(const std::vector<SceneObject>& objects) {
  std::vector<core::Feature> features;
  for (const SceneObject& o : objects) {
    core::Feature f;
    f.polygon = o.outline;
    f.attributes["id"] = static_cast<long long>(o.id);
    f.attributes["class"] = std::string(o.cls == kClassBuilding ? "building" : "vegetation");
    f.attributes["area_m2"] = o.areaM2;
    if (std::isfinite(o.meanHeight)) f.attributes["mean_height_m"] = o.meanHeight;
    if (std::isfinite(o.maxHeight)) f.attributes["max_height_m"] = o.maxHeight;
    if (o.hasRoofInterval) {
      f.attributes["roof_disparity_min"] = static_cast<long long>(o.roofDisparityMin);
      f.attributes["roof_disparity_max"] = static_cast<long long>(o.roofDisparityMax);
    }
    if (std::isfinite(o.groundDisparity)) f.attributes["ground_disparity"] = o.groundDisparity;
    features.push_back(std::move(f));
  }
  return features;
}

}  // namespace delineo::segmentation
