#pragma once
// The whole scene analysis of seed 002 in named stages (docs/dem.md): ground / above-ground
// segmentation with its DTM and nDSM (ground.hpp), building vs vegetation, objects and building
// proposals (detect.hpp). `delineo-cli segment`, `delineo-cli detect`, `run --detect` and the
// GUI's "Detect buildings" call this one function.
#include <opencv2/core.hpp>

#include "delineo/core/progress.hpp"
#include "delineo/segmentation/detect.hpp"
#include "delineo/segmentation/ground.hpp"

namespace delineo::segmentation {

// Every parameter of the chain, by group (the project's groups "segment", "classify", "objects"
// and "detect"; the CLI's flags).
struct SceneParams {
  GroundParams ground;
  ClassifyParams classify;
  ObjectParams objects;
  DetectParams detect;
  // Throws core::Error(InvalidParameter) naming the parameter.
  void validate() const;
};

struct SceneAnalysis {
  core::RunStatus status = core::RunStatus::Completed;  // Canceled: the rest may be empty
  GroundResult ground;   // regions, above-ground mask, DTM, nDSM
  Detection detection;   // classes, objects, proposals
  // CV_8U ClassLabel per pixel: 0 ground or no data, 1 building, 2 vegetation (labels.tif).
  const cv::Mat& classes() const { return detection.classification.labels; }
};

// Stages: 1. ground / above-ground and DTM on `dem` (segmentGround); 2. building vs vegetation on
// the above-ground regions of `image`; 3. objects (building pieces split where their regions
// stand critical-height apart, levels.hpp; outline, area, heights, intervals read from
// `disparity` when given); 4. building proposals. `dem`: CV_32F heights in metres (NaN = no
// data) on the left image's grid; `image`: the left image, CV_8U grey or BGR, same size;
// `gsd`: metres per pixel. Throws core::Error: InvalidParameter (parameters, gsd),
// UnsupportedInput (types), MismatchedInputs (sizes). Polls cancel in every stage.
SceneAnalysis analyseScene(const cv::Mat& dem, const cv::Mat& image, double gsd, const SceneParams& params,
                           const cv::Mat& disparity = {}, core::Progress* progress = nullptr);

}  // namespace delineo::segmentation
