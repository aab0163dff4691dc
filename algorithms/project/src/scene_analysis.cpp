// The project's scene analysis (segmentation library): ground / above-ground, DTM, nDSM, classes,
// objects and building proposals with the project's parameter groups.
#include <string>

#include <opencv2/core.hpp>

#include "delineo/core/error.hpp"
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

}  // namespace delineo::project
