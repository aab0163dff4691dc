#pragma once
// A simulated square scene as the matcher takes it: both views in float and its search range.
#include <opencv2/core.hpp>

#include "delineo/sim/scene.hpp"
#include "delineo/stereo/match.hpp"

namespace delineo::stereo::testing {

struct SceneViews {
  cv::Mat left, right;
  MatchParams params;  // the scene's range, 2 threads, the other defaults
};

inline SceneViews sceneViews(int size, int seed) {
  const sim::Scene scene = sim::simulateScene(sim::squareSceneParams(size, seed));
  SceneViews v;
  scene.left.convertTo(v.left, CV_32F);
  scene.right.convertTo(v.right, CV_32F);
  v.params.dmin = scene.disparityMin;
  v.params.dmax = scene.disparityMax;
  v.params.threads = 2;
  return v;
}

}  // namespace delineo::stereo::testing
