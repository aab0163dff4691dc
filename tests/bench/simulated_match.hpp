#pragma once
// The matcher on a simulated scene, shared by the benchmarks of the scene analysis: its
// disparity over the scene's full range, and its DEM through the scene's height model.
#include <opencv2/core.hpp>

#include "delineo/dem/heights.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/match.hpp"

namespace delineo::bench {

inline cv::Mat matchScene(const sim::Scene& scene) {
  cv::Mat left, right;
  scene.left.convertTo(left, CV_32F);
  scene.right.convertTo(right, CV_32F);
  stereo::MatchParams mp;
  mp.dmin = scene.disparityMin;
  mp.dmax = scene.disparityMax;
  return stereo::matchStereo(left, right, mp).disparity;
}

// Heights (m) from a disparity map of the scene by the scene's model.
inline cv::Mat sceneHeights(const sim::Scene& scene, const cv::Mat& disparity) {
  dem::HeightModel model;
  model.metresPerPixel = scene.metresPerDisparity;
  model.groundDisparity = scene.groundDisparity;
  return dem::heightsFromDisparity(disparity, model);
}

}  // namespace delineo::bench
