#pragma once
// What `segment` and `detect` share: the DEM, the left image and the ground sample distance
// read from their flags, and the scene analysis run with the commands' parameters
// (segmentation::analyseScene, docs/dem.md). Defined in segment.cpp.
#include <string>

#include <opencv2/core.hpp>

#include "cli_support.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/segmentation/scene.hpp"

namespace delineo::cli {

// Adds --dem, --image, --gsd, --scene, --disparity (required when `needsDisparity`) and --quiet.
void addSceneInputs(Options& opts, bool needsDisparity);

struct SceneInputs {
  io::Raster dem;     // CV_32F heights, NaN = no data
  cv::Mat image;      // CV_8U grey or BGR, the DEM's size
  cv::Mat disparity;  // CV_32F px, or empty
  double gsd = 0.0;   // m per pixel
};
// Reads the inputs named by the flags. Throws UsageError (neither or both of --gsd and --scene)
// and core::Error naming the file (unreadable, several bands, sizes that differ).
SceneInputs readSceneInputs(const Options& opts);

// Reads the inputs (readSceneInputs) and runs analyseScene() on them, with the command's progress
// ("reading", then the chain's stages, "writing" when it returns); input errors name the DEM.
// Throws Canceled on a cancel.
struct SceneRun {
  SceneInputs inputs;
  segmentation::SceneAnalysis analysis;
};
SceneRun runSceneAnalysis(const Options& opts, const segmentation::SceneParams& params);

}  // namespace delineo::cli
