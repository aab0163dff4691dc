// The project's scene analysis (segmentation library): ground / above-ground, DTM, nDSM, classes,
// objects and building proposals with the project's parameter groups, and proposals turned into
// pending buildings.
#include <algorithm>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "delineo/core/error.hpp"
#include "delineo/delineation/feature_request.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/segmentation/scene.hpp"

namespace delineo::project {

using core::Error;
using core::ErrorCode;

namespace {
segmentation::SceneParams sceneParameters(const Project& project) {
  segmentation::SceneParams params;
  params.ground = parameters<segmentation::GroundParams>(project, kSegmentGroup);
  params.classify = parameters<segmentation::ClassifyParams>(project, kClassifyGroup);
  params.objects = parameters<segmentation::ObjectParams>(project, kObjectsGroup);
  params.detect = parameters<segmentation::DetectParams>(project, kDetectGroup);
  return params;
}
}  // namespace

SceneAnalysisOutcome analyseScene(const Project& project, const cv::Mat& heights, const cv::Mat& image,
                                  const cv::Mat& disparity, core::Progress* progress) {
  if (heights.empty()) {
    throw Error(ErrorCode::InvalidParameter,
                "the scene analysis needs heights: a DEM, or the disparity and the height model");
  }
  if (!(project.height.gsd > 0.0)) {
    throw Error(ErrorCode::InvalidParameter, "the scene analysis needs the ground sample distance (height model's gsd > 0)");
  }
  const segmentation::SceneAnalysis analysis =
      segmentation::analyseScene(heights, image, project.height.gsd, sceneParameters(project), disparity, progress);
  SceneAnalysisOutcome out;
  out.status = analysis.status;
  if (analysis.status == core::RunStatus::Canceled) return out;
  out.dtm = analysis.ground.dtm;
  out.ndsm = analysis.ground.ndsm;
  out.classes = analysis.classes();
  out.objectIndex = analysis.detection.objects.index;
  out.objects = segmentation::objectFeatures(analysis.detection.objects.objects);
  out.proposals = analysis.detection.proposals;
  out.regions = analysis.ground.regionCount;
  out.rounds = analysis.ground.iterations;
  out.converged = analysis.ground.converged;
  return out;
}

namespace {
core::Polygon shifted(core::Polygon polygon, cv::Point2d by) {
  for (auto& p : polygon.outer) p += by;
  for (auto& hole : polygon.holes) {
    for (auto& p : hole) p += by;
  }
  return polygon;
}

// Share of `polygon`'s pixels that lie inside `other`, both rasterized on their common box.
double coveredShare(const core::Polygon& polygon, const core::Polygon& other) {
  if (polygon.outer.size() < 3 || other.outer.size() < 3) return 0.0;
  const cv::Rect2d a = core::boundingBox(polygon.outer), b = core::boundingBox(other.outer);
  if ((a & b).area() <= 0.0) return 0.0;
  const cv::Rect box = cv::Rect(a | b) + cv::Size(2, 2);
  const cv::Point2d by(-box.x, -box.y);
  const cv::Mat ma = core::rasterize(shifted(polygon, by), box.size());
  const cv::Mat mb = core::rasterize(shifted(other, by), box.size());
  const int inside = cv::countNonZero(ma);
  return inside > 0 ? static_cast<double>(cv::countNonZero(ma & mb)) / inside : 0.0;
}

// The proposal's roof interval (detect's roof_disparity_min/max), read as every feature's is;
// none when it carries none. A malformed one is left out too, with the reason in `problem`: the
// operator then sets the interval, as for a drawn building.
std::optional<DisparityInterval> roofInterval(const core::Feature& proposal, std::string& problem) {
  try {
    const auto roof = delineation::readFeatureIntervals(proposal).roof;
    if (!roof) return std::nullopt;
    return DisparityInterval{roof->min, roof->max};
  } catch (const core::Error& e) {
    problem = "roof interval not read: " + e.detail();
    return std::nullopt;
  }
}
}  // namespace

std::vector<int> addProposedBuildings(Project& project, const std::vector<core::Feature>& proposals,
                                      const std::string& origin, std::vector<std::string>* problems) {
  std::vector<int> added;
  for (const core::Feature& proposal : proposals) {
    if (proposal.polygon.outer.size() < 3) continue;
    // A building the operator already has (any status) is not proposed twice.
    const bool known = std::any_of(project.buildings.begin(), project.buildings.end(), [&](const Building& b) {
      return coveredShare(proposal.polygon, b.currentPolygon()) > kProposalOverlap ||
             coveredShare(b.currentPolygon(), proposal.polygon) > kProposalOverlap;
    });
    if (known) continue;
    Building b;
    b.id = project.nextBuildingId();
    b.initial = proposal.polygon;
    std::string problem;
    b.roofInterval = roofInterval(proposal, problem);
    std::string detail = origin.empty() ? std::string("building proposal") : origin + ": building proposal";
    if (!problem.empty()) {
      detail += ", " + problem;
      if (problems != nullptr) problems->push_back("building " + std::to_string(b.id) + ": " + problem);
    }
    b.addHistory("detected", detail);
    project.buildings.push_back(b);
    added.push_back(b.id);
  }
  return added;
}

}  // namespace delineo::project
