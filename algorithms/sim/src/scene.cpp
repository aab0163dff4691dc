#include "delineo/sim/scene.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include <opencv2/core/utility.hpp>

#include "layout.hpp"
#include "noise.hpp"
#include "render.hpp"

namespace delineo::sim {

void SceneParams::validate() const {
  core::checkDeclaredRanges(*this);
  if (supersampling % 2 == 0) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "supersampling = " + std::to_string(supersampling) +
                          " must be odd (the centre sample carries the ground truth)");
  }
  if (2.0 * margin >= std::min(width, height)) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "margin = " + std::to_string(margin) + " px leaves no room in a " +
                          std::to_string(width) + "x" + std::to_string(height) + " image");
  }
}

namespace {

core::Feature footprintFeature(const detail::Building& b, const SceneParams& p) {
  // The roof outline at eave height as the left view sees it: a pure shift along the rows.
  const detail::ViewGeometry left = detail::leftView(p);
  const double shift = left.project(0.0, b.eaveZ);
  auto project = [&](const core::Ring& ring) {
    core::Ring out = ring;
    for (auto& q : out) q.x += shift;
    return out;
  };
  auto disparityOf = [&](double z) { return z / p.metresPerDisparity + p.groundDisparity; };
  core::Feature f;
  f.polygon.outer = project(b.footprint.outer);
  for (const auto& h : b.footprint.holes) f.polygon.holes.push_back(project(h));
  f.attributes["id"] = static_cast<long long>(b.id);
  f.attributes["roof_disparity_min"] = disparityOf(b.eaveZ);
  f.attributes["roof_disparity_max"] = disparityOf(b.ridgeZ);
  f.attributes["superstructure_disparity_max"] = disparityOf(b.topZ);
  f.attributes["ground_disparity"] = disparityOf(b.baseZ);
  f.attributes["height_m"] = b.eaveZ - b.baseZ;
  f.attributes["ridge_height_m"] = b.ridgeZ - b.baseZ;
  f.attributes["roof_type"] = std::string(detail::toString(b.roof));
  f.attributes["shape"] = std::string(detail::toString(b.shape));
  f.attributes["orientation_deg"] = b.angle * 180.0 / 3.14159265358979323846;
  return f;
}

}  // namespace

SceneParams squareSceneParams(int size, int seed) {
  SceneParams sp;
  sp.seed = seed;
  sp.width = size;
  sp.height = size;
  sp.buildings = std::max(1, size * size / 40000);
  sp.trees = std::max(1, size * size / 30000);
  return sp;
}

namespace {

// Radiance of both views in grey levels, before gain, offset and noise.
struct Radiance {
  cv::Mat left, right;
};

// Renders every row, rows in parallel: the radiance of both views and the scene's ground truth
// (disparity of both views, DEM, labels, occlusion). False when canceled.
bool renderRows(const SceneParams& params, const detail::Layout& layout, Scene& scene,
                Radiance& radiance, core::Progress* progress) {
  const detail::RowRenderer renderer(params, layout);
  const int w = params.width, h = params.height;
  radiance.left.create(h, w, CV_32F);
  radiance.right.create(h, w, CV_32F);
  scene.disparity.create(h, w, CV_32F);
  scene.disparityRight.create(h, w, CV_32F);
  scene.dem.create(h, w, CV_32F);
  scene.labels.create(h, w, CV_8U);
  scene.occlusion.create(h, w, CV_8U);
  std::atomic<int> rowsDone{0};
  std::atomic<bool> stop{false};
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& range) {
    for (int y = range.start; y < range.end; ++y) {
      if (stop.load()) return;
      if (core::isCanceled(progress)) {
        stop.store(true);
        return;
      }
      detail::RowOutput out;
      out.left = radiance.left.ptr<float>(y);
      out.right = radiance.right.ptr<float>(y);
      out.disparity = scene.disparity.ptr<float>(y);
      out.disparityRight = scene.disparityRight.ptr<float>(y);
      out.dem = scene.dem.ptr<float>(y);
      out.labels = scene.labels.ptr<std::uint8_t>(y);
      out.occlusion = scene.occlusion.ptr<std::uint8_t>(y);
      renderer.renderRow(y, out);
      const int done = ++rowsDone;
      if (done % 8 == 0 || done == h) core::report(progress, 0.05 + 0.9 * done / h);
    }
  });
  return !(stop.load() || core::isCanceled(progress));
}

// Radiometry: the left view keeps the radiance, the right one gets gain and offset; both get
// independent Gaussian noise, then 8-bit rounding.
void makeViews(const SceneParams& params, const Radiance& radiance, Scene& scene) {
  const int w = params.width, h = params.height;
  scene.left.create(h, w, CV_8U);
  scene.right.create(h, w, CV_8U);
  const std::uint64_t noiseSeed = detail::mix64(static_cast<std::uint64_t>(params.seed) ^ 0x6e6f697365ULL);
  for (int y = 0; y < h; ++y) {
    const float* rl = radiance.left.ptr<float>(y);
    const float* rr = radiance.right.ptr<float>(y);
    std::uint8_t* l = scene.left.ptr<std::uint8_t>(y);
    std::uint8_t* r = scene.right.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      double vl = rl[x], vr = params.rightGain * rr[x] + params.rightOffset;
      if (params.noise > 0.0) {
        vl += params.noise * detail::hashedNormal(noiseSeed, 0, x, y);
        vr += params.noise * detail::hashedNormal(noiseSeed, 1, x, y);
      }
      l[x] = cv::saturate_cast<std::uint8_t>(vl);
      r[x] = cv::saturate_cast<std::uint8_t>(vr);
    }
  }
}

// The true disparity's range in whole px, widened by a margin (the ground's disparity when no
// pixel has one).
void setDisparityRange(const SceneParams& params, Scene& scene) {
  const int w = params.width, h = params.height;
  double dMin = std::numeric_limits<double>::max(), dMax = -dMin;
  for (int y = 0; y < h; ++y) {
    const float* d = scene.disparity.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      if (!std::isfinite(d[x])) continue;
      dMin = std::min(dMin, static_cast<double>(d[x]));
      dMax = std::max(dMax, static_cast<double>(d[x]));
    }
  }
  if (dMin > dMax) dMin = dMax = params.groundDisparity;
  const int rangeMargin = 2;
  scene.disparityMin = static_cast<int>(std::floor(dMin)) - rangeMargin;
  scene.disparityMax = static_cast<int>(std::ceil(dMax)) + rangeMargin;
}

}  // namespace

Scene simulateScene(const SceneParams& params, core::Progress* progress) {
  params.validate();
  Scene scene;
  scene.gsd = params.gsd;
  scene.metresPerDisparity = params.metresPerDisparity;
  scene.groundDisparity = params.groundDisparity;
  scene.seed = params.seed;

  core::setStage(progress, core::StageId::SimulatingLayout);
  const detail::Layout layout = detail::makeLayout(params);
  scene.buildingsPlaced = static_cast<int>(layout.buildings.size());
  scene.treesPlaced = static_cast<int>(layout.trees.size());
  core::report(progress, 0.05);
  if (core::isCanceled(progress)) {
    scene.status = core::RunStatus::Canceled;
    return scene;
  }

  core::setStage(progress, core::StageId::SimulatingRendering);
  Radiance radiance;
  if (!renderRows(params, layout, scene, radiance, progress)) {
    Scene canceled;
    canceled.status = core::RunStatus::Canceled;
    return canceled;
  }

  core::setStage(progress, core::StageId::SimulatingRadiometry);
  makeViews(params, radiance, scene);
  setDisparityRange(params, scene);
  for (const auto& b : layout.buildings) scene.footprints.push_back(footprintFeature(b, params));
  core::report(progress, 1.0);
  return scene;
}

}  // namespace delineo::sim
