#pragma once
// Automatic building proposals: the building objects of a classification as pending buildings,
// one initial polygon per building with the attributes `delineo-cli delineate --init` reads (id,
// roof_disparity_min/max, ground_disparity), so the active polygon can start from each
// (docs/dem.md, "Building vs vegetation, objects and proposals"). No GUI interaction here.
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"
#include "delineo/segmentation/classify.hpp"
#include "delineo/segmentation/objects.hpp"

namespace delineo::segmentation {

struct DetectParams {
  double minBuildingArea = 50.0;  // m², smaller building objects are not proposed
  double minHeight = 2.5;         // m, building objects whose mean height above the DTM is lower are not proposed
  double growth = 0.0;            // px, the proposed polygon is the object's outline grown by this
  int groundTolerance = 3;        // px, delineate's ground tolerance: a ground disparity is written only this far below the roof

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"min-building-area", "Minimum building area", "m²",
                "Building objects smaller than this are not proposed", 0, 1e9},
      minBuildingArea);
    v(ParamInfo{"min-height", "Minimum height", "m",
                "Building objects whose mean height above the terrain is lower are not proposed", 0, 1000},
      minHeight);
    v(ParamInfo{"growth", "Growth", "px", "The proposed polygon is the object's outline grown by this", 0, 100},
      growth);
    v(ParamInfo{"ground-tolerance", "Ground tolerance", "px",
                "The delineation's ground tolerance: a ground disparity is proposed only when its interval "
                "stays below the roof's",
                0, 50},
      groundTolerance);
  }
  void validate() const;  // throws core::Error(InvalidParameter)
};

// One feature per proposed building: the object's outline (grown by `growth`) with id (the
// object's), roof_disparity_min/max (integers, when the object has a roof interval),
// ground_disparity (an integer, when known and its interval of ±ground-tolerance lies below the
// roof interval; otherwise delineate estimates it from a ring), area_m2 and mean_height_m.
// Vegetation objects are never proposed.
std::vector<core::Feature> proposeBuildings(const std::vector<SceneObject>& objects, const DetectParams& params = {});

struct Detection {
  core::RunStatus status = core::RunStatus::Completed;
  Classification classification;
  ObjectSet objects;
  std::vector<core::Feature> proposals;
};

// The whole chain on one scene: classify(), extractObjects(), proposeBuildings(). Inputs as in
// classify() plus the optional disparity map (CV_32F px, NaN no value) that gives the proposals
// their intervals; with `regions`, building pieces are split into height levels by `split`.
// Throws like the three steps; a cancel returns status Canceled.
Detection detectBuildings(const cv::Mat& image, const cv::Mat& aboveGround, const cv::Mat& ndsm, double gsd,
                          const cv::Mat& disparity = {}, const cv::Mat& regions = {},
                          const ClassifyParams& classifyParams = {}, const ObjectParams& objectParams = {},
                          const DetectParams& detectParams = {}, core::Progress* progress = nullptr,
                          const LevelSplit& split = {});

}  // namespace delineo::segmentation
