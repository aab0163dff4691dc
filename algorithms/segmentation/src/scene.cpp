#include "delineo/segmentation/scene.hpp"

#include <string>

#include "delineo/core/error.hpp"

namespace delineo::segmentation {

void SceneParams::validate() const {
  ground.validate();
  classify.validate();
  objects.validate();
  detect.validate();
}

namespace {

// The height-level split of building objects reads the segmentation's and the proposals' thresholds.
LevelSplit levelSplitOf(const SceneParams& params) {
  LevelSplit split;
  split.minStep = params.ground.criticalHeight;
  split.stepBand = params.ground.stepBand;
  split.wallSlope = params.ground.wallSlope;
  split.minPartArea = params.detect.minBuildingArea;
  return split;
}

}  // namespace

SceneAnalysis analyseScene(const cv::Mat& dem, const cv::Mat& image, double gsd, const SceneParams& params,
                           const cv::Mat& disparity, core::Progress* progress) {
  params.validate();
  if (!image.empty() && !dem.empty() && image.size() != dem.size()) {
    throw core::Error(core::ErrorCode::MismatchedInputs,
                      "the image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                          " px and the DEM " + std::to_string(dem.cols) + "x" + std::to_string(dem.rows) +
                          ": both must be on the left image's grid");
  }
  if (!disparity.empty() && disparity.size() != dem.size()) {
    throw core::Error(core::ErrorCode::MismatchedInputs,
                      "the disparity map is " + std::to_string(disparity.cols) + "x" +
                          std::to_string(disparity.rows) + " px and the DEM " + std::to_string(dem.cols) + "x" +
                          std::to_string(dem.rows));
  }
  SceneAnalysis out;
  {  // 1. ground / above-ground, DTM, nDSM
    core::Progress::Range range(progress, 0.0, 0.6);
    range.setStage(core::StageId::SegmentingGround);
    out.ground = segmentGround(dem, gsd, params.ground, progress ? &range : nullptr);
  }
  if (out.ground.status == core::RunStatus::Canceled) {
    out.status = core::RunStatus::Canceled;
    return out;
  }
  {  // 2-4. building vs vegetation, objects, proposals
    core::Progress::Range range(progress, 0.6, 1.0);
    range.setStage(core::StageId::DetectingObjects);
    out.detection = detectBuildings(image, out.ground.aboveGround, out.ground.ndsm, gsd, disparity,
                                    out.ground.regions, params.classify, params.objects, params.detect,
                                    progress ? &range : nullptr, levelSplitOf(params));
  }
  out.status = out.detection.status;
  core::report(progress, 1.0);
  return out;
}

}  // namespace delineo::segmentation
