#include "delineo/project/pipeline.hpp"
#include "delineo/project/roof_parts.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <opencv2/imgproc.hpp>

#include "delineo/boxfit/params.hpp"
#include "delineo/core/error.hpp"
#include "delineo/delineation/above_ground.hpp"
#include "delineo/delineation/params.hpp"
#include "delineo/delineation/roof_interval.hpp"
#include "delineo/dem/enhance.hpp"
#include "delineo/segmentation/roof_levels.hpp"
#include "delineo/segmentation/scene.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/disparity_range.hpp"
#include "delineo/stereo/match.hpp"

namespace delineo::project {

namespace fs = std::filesystem;
using core::Error;
using core::ErrorCode;

namespace {
template <class Params>
void validateGroup(const Project& project, const std::string& group) {
  try {
    (void)parameters<Params>(project, group);
  } catch (const Error& e) {
    throw Error(ErrorCode::InvalidParameter, "parameters." + group + ": " + e.detail());
  }
}
}  // namespace

void validateParameters(const Project& project) {
  validateGroup<stereo::RangeEstimateParams>(project, "range");
  validateGroup<stereo::MatchParams>(project, "matching");
  validateGroup<delineation::DelineationParams>(project, "delineation");
  validateGroup<boxfit::BoxFitParams>(project, "boxfit");
  validateGroup<dem::EnhanceParams>(project, "enhance");
  validateGroup<segmentation::GroundParams>(project, kSegmentGroup);
  validateGroup<segmentation::ClassifyParams>(project, kClassifyGroup);
  validateGroup<segmentation::ObjectParams>(project, kObjectsGroup);
  validateGroup<segmentation::DetectParams>(project, kDetectGroup);
  validateGroup<segmentation::RoofLevelParams>(project, kRoofLevelsGroup);
}

StereoPair readStereoPair(const Project& project) {
  if (project.left.empty() || project.right.empty()) {
    throw Error(ErrorCode::InvalidParameter, "the project names no left or right image");
  }
  StereoPair pair;
  pair.left = io::readGreyFloat(project.left, &pair.geo);
  pair.right = io::readGreyFloat(project.right);
  if (pair.left.size() != pair.right.size()) {
    throw Error(ErrorCode::MismatchedInputs,
                "left image is " + std::to_string(pair.left.cols) + "x" +
                    std::to_string(pair.left.rows) + " but right image " + project.right + " is " +
                    std::to_string(pair.right.cols) + "x" + std::to_string(pair.right.rows) +
                    "; an epipolar pair must have the same size",
                project.left);
  }
  if (!project.exclude.empty()) pair.exclude = io::readMask(project.exclude, pair.left.size());
  return pair;
}

cv::Mat readDisparity(const Project& project, cv::Size size) {
  if (project.disparity.empty()) return {};
  io::ReadOptions options;
  options.type = io::PixelType::Float32;
  options.toGrey = true;
  io::Raster raster = io::readRaster(project.disparity, options);
  if (raster.data.size() != size) {
    throw Error(ErrorCode::MismatchedInputs, "the disparity raster does not have the size of the left image",
                project.disparity);
  }
  return raster.data;
}

RangeOutcome estimateDisparityRange(const Project& project, const StereoPair& pair, core::Progress* progress) {
  const auto params = parameters<stereo::RangeEstimateParams>(project, "range");
  const stereo::RangeEstimate estimate = stereo::estimateDisparityRange(pair.left, pair.right, params, progress);
  RangeOutcome outcome;
  outcome.status = estimate.status;
  outcome.range = DisparityInterval{estimate.dmin, estimate.dmax};
  outcome.matches = estimate.matches;
  return outcome;
}

MatchingOutcome computeDisparity(const Project& project, const cv::Mat& left, const cv::Mat& right,
                                 core::Progress* progress) {
  if (!project.disparityRange) {
    throw Error(ErrorCode::InvalidParameter, "the project has no disparity range: estimate or give it first");
  }
  auto params = parameters<stereo::MatchParams>(project, "matching");
  params.dmin = project.disparityRange->low;
  params.dmax = project.disparityRange->high;
  params.validate();
  stereo::MatchResult result = stereo::matchStereo(left, right, params, progress);
  MatchingOutcome outcome;
  outcome.status = result.status;
  if (result.status == core::RunStatus::Completed) outcome.disparity = result.disparity;
  return outcome;
}

namespace {
std::vector<float> finiteValuesInside(const cv::Mat& values, const core::Polygon& polygon) {
  std::vector<float> out;
  if (values.empty() || polygon.outer.size() < 3) return out;
  const cv::Mat mask = core::rasterize(polygon, values.size());
  for (int y = 0; y < values.rows; ++y) {
    const float* v = values.ptr<float>(y);
    const uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < values.cols; ++x) {
      if (m[x] != 0 && std::isfinite(v[x])) out.push_back(v[x]);
    }
  }
  return out;
}

float percentile(std::vector<float>& values, double q) {
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(q * static_cast<double>(values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}
}  // namespace

std::optional<DisparityInterval> suggestRoofInterval(const cv::Mat& disparity, const core::Polygon& polygon) {
  if (disparity.empty()) return std::nullopt;
  const delineation::RoofIntervalProposal p = delineation::proposeRoofInterval(disparity, polygon);
  if (!p.found) return std::nullopt;
  return DisparityInterval{p.low, p.high};
}

std::optional<double> suggestGroundLevel(const cv::Mat& disparity, const core::Polygon& polygon) {
  if (disparity.empty()) return std::nullopt;
  const double level = delineation::estimateGroundLevel(disparity, polygon);
  if (!std::isfinite(level)) return std::nullopt;
  return level;
}

std::optional<double> suggestSceneGroundLevel(const cv::Mat& disparity) {
  if (disparity.empty()) return std::nullopt;
  // The same estimate with a band that covers the whole map, around its centre pixel.
  delineation::RoofIntervalParams params;
  params.groundMargin = std::max(disparity.cols, disparity.rows);
  const double cx = disparity.cols / 2, cy = disparity.rows / 2;
  core::Polygon centre;
  centre.outer = {{cx, cy}, {cx + 1, cy}, {cx + 1, cy + 1}, {cx, cy + 1}};
  const double level = delineation::estimateGroundLevel(disparity, centre, params);
  if (!std::isfinite(level)) return std::nullopt;
  return level;
}

dem::HeightModel demHeightModel(const HeightModel& model) {
  if (!model.known()) throw Error(ErrorCode::InvalidParameter, "the project has no height model");
  dem::HeightModel out;
  out.metresPerPixel = model.metresPerPixel;
  out.groundDisparity = model.groundDisparity;
  return out;
}

cv::Mat heightsFromDisparity(const Project& project, const cv::Mat& disparity) {
  if (disparity.empty() || !project.height.known()) return {};
  return dem::heightsFromDisparity(disparity, demHeightModel(project.height));
}

namespace {
// A DEM in metres brought to disparity by the project's height model (1 m per px without one).
cv::Mat demAsDisparity(const Project& project, const cv::Mat& dem) {
  return project.height.known() ? dem::disparityFromHeights(dem, demHeightModel(project.height)) : dem;
}
double metresPerPixelOf(const Project& project) { return project.height.known() ? project.height.metresPerPixel : 1.0; }
}  // namespace

ObjectPick pickAboveGroundObject(const Project& project, const cv::Mat& disparity, const cv::Mat& dem,
                                 cv::Point2d click) {
  ObjectPick pick;
  cv::Mat map;
  if (!disparity.empty() && project.height.known()) {
    map = disparity;
  } else if (!dem.empty()) {
    map = demAsDisparity(project, dem);
  } else {
    return pick;  // NoHeights
  }
  const auto params = parameters<delineation::AboveGroundParams>(project, "pick");
  const delineation::AboveGroundObject object =
      delineation::aboveGroundObjectAt(map, click, metresPerPixelOf(project), params);
  switch (object.outcome) {
    case delineation::PickOutcome::Found: pick.outcome = ObjectPick::Outcome::Found; break;
    case delineation::PickOutcome::NoGround: pick.outcome = ObjectPick::Outcome::NoGround; break;
    case delineation::PickOutcome::NotAboveGround: pick.outcome = ObjectPick::Outcome::NotAboveGround; break;
  }
  pick.outline = object.outline;
  pick.groundLevel = object.groundLevel;
  if (project.height.known() && std::isfinite(object.groundLevel)) {
    pick.groundHeight = project.height.heightAt(object.groundLevel);
  }
  return pick;
}

std::optional<double> groundHeightNextTo(const Project& project, const cv::Mat& dem, const core::Polygon& polygon) {
  if (dem.empty()) return std::nullopt;
  const auto level = suggestGroundLevel(demAsDisparity(project, dem), polygon);
  if (!level) return std::nullopt;
  return project.height.known() ? project.height.heightAt(*level) : *level;
}

double roofHeight(const Project& project, const cv::Mat& disparity, const core::Polygon& polygon) {
  if (!project.height.known()) return std::nan("");
  std::vector<float> values = finiteValuesInside(disparity, polygon);
  if (values.empty()) return std::nan("");
  return project.height.heightAt(percentile(values, 0.5));
}

std::string ensureSampleProject(const std::string& directory, core::Progress* progress) {
  const fs::path dir = fs::absolute(directory).lexically_normal();
  const fs::path projectPath = dir / "sample.delineo.json";
  std::error_code ec;
  if (fs::exists(projectPath, ec) && fs::exists(dir / "left.tif", ec) && fs::exists(dir / "right.tif", ec)) {
    return projectPath.string();
  }
  // Without the sample's project file, same-named files in the folder are someone else's.
  for (const char* name : {"left.tif", "right.tif", "dem.tif", "labels.tif"}) {
    if (fs::exists(dir / name, ec)) {
      throw Error(ErrorCode::UnusableOutput,
                  std::string("the folder already holds ") + name +
                      " but not the sample project: it is not replaced; choose an empty or new folder",
                  directory);
    }
  }
  sim::SceneParams params;
  params.seed = 2024;
  params.width = 512;
  params.height = 384;
  params.buildings = 7;
  params.trees = 8;
  const sim::Scene scene = sim::simulateScene(params, progress);
  if (scene.status == core::RunStatus::Canceled) {
    throw Error(ErrorCode::ProcessingFailed, "creating the sample scene was canceled");
  }
  fs::create_directories(dir, ec);
  io::writeGeoTiff((dir / "left.tif").string(), scene.left);
  io::writeGeoTiff((dir / "right.tif").string(), scene.right);
  io::writeFloatGeoTiff((dir / "dem.tif").string(), scene.dem);
  io::writeGeoTiff((dir / "labels.tif").string(), scene.labels);
  Project p;
  p.name = "Sample scene (simulated, seed " + std::to_string(params.seed) + ")";
  p.left = (dir / "left.tif").string();
  p.right = (dir / "right.tif").string();
  p.dem = (dir / "dem.tif").string();
  p.labels = (dir / "labels.tif").string();
  p.outputDir = "output";
  p.disparityRange = DisparityInterval{scene.disparityMin, scene.disparityMax};
  p.height = {scene.groundDisparity, scene.metresPerDisparity, scene.gsd};
  saveProject(p, projectPath.string());
  return projectPath.string();
}

}  // namespace delineo::project
