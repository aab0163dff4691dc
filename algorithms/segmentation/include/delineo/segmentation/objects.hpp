#pragma once
// Above-ground objects: the connected above-ground pieces of one class (building or vegetation)
// of a classification, building pieces split into their height levels (levels.hpp), each with its outline, area, heights above the DTM and, with a disparity
// map, its roof disparity interval and the ground disparity next to it (docs/dem.md, "Building vs
// vegetation, objects and proposals"). Left-image pixel coordinates. No GUI interaction here.
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"
#include "delineo/segmentation/classify.hpp"
#include "delineo/segmentation/levels.hpp"

namespace delineo::segmentation {

struct ObjectParams {
  double minArea = 10.0;        // m², smaller objects are dropped
  int smoothing = 3;            // px, side of the square closing then opening before tracing (1: off)
  double simplification = 1.0;  // px, Douglas-Peucker tolerance of the outline
  double roofPercentile = 2.0;  // %, the roof interval spans this percentile to its complement
  double coreShrink = 2.0;      // px, the roof interval is read this far inside the object

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"min-area", "Minimum area", "m²", "Objects smaller than this are dropped", 0, 1e9}, minArea);
    v(ParamInfo{"smoothing", "Outline smoothing", "px",
                "Side of the square closing then opening of an object before its outline is traced (1: none)", 1, 51},
      smoothing);
    v(ParamInfo{"simplification", "Outline simplification", "px",
                "Largest distance between the traced outline and its simplified polygon", 0, 50},
      simplification);
    v(ParamInfo{"roof-percentile", "Roof percentile", "%",
                "The roof disparity interval runs from this percentile of the object's disparities to its complement",
                0, 49},
      roofPercentile);
    v(ParamInfo{"core-shrink", "Core shrink", "px",
                "The roof disparity interval is read this far inside the object, away from its walls", 0, 100},
      coreShrink);
  }
  void validate() const;  // throws core::Error(InvalidParameter), also for an even smoothing
};

struct SceneObject {
  int id = 0;                          // 1-based, in scan order of the label image
  ClassLabel cls = kClassBuilding;
  core::Polygon outline;               // left-image pixels, holes for courtyards
  int pixels = 0;
  double areaM2 = 0.0;                 // pixels times gsd²
  double meanHeight = std::numeric_limits<double>::quiet_NaN();  // m above the DTM
  double maxHeight = std::numeric_limits<double>::quiet_NaN();
  // With a disparity map: the robust roof interval (px, inclusive integers) and the ground level
  // next to the outline (delineation::estimateGroundLevel, px, NaN when none).
  bool hasRoofInterval = false;
  int roofDisparityMin = 0, roofDisparityMax = 0;
  double groundDisparity = std::numeric_limits<double>::quiet_NaN();
};

struct ObjectSet {
  core::RunStatus status = core::RunStatus::Completed;
  std::vector<SceneObject> objects;
  cv::Mat index;  // CV_32S, the object id of each pixel, 0 for none (dropped objects included)
};

// The objects of `labels` (CV_8U ClassLabel). `ndsm`: CV_32F heights above the DTM (m, NaN no
// data). `disparity`: optional CV_32F map (px, NaN no value). `regions`: optional CV_32S region
// map (the ground segmentation's, -1 none); with it every building piece is split into its
// height levels by `split` (levels.hpp), each level an object. Throws core::Error:
// UnsupportedInput for empty or wrongly typed rasters, MismatchedInputs for sizes that differ,
// InvalidParameter for bad parameters or gsd. Polls `progress`; a cancel returns the objects
// found so far.
ObjectSet extractObjects(const cv::Mat& labels, const cv::Mat& ndsm, double gsd, const ObjectParams& params = {},
                         const cv::Mat& disparity = {}, core::Progress* progress = nullptr,
                         const cv::Mat& regions = {}, const LevelSplit& split = {});

// The outline of the non-zero pixels of `mask` (CV_8U, one connected piece expected; the largest
// is taken): outer ring and the holes of at least `minHolePixels`, traced a quarter pixel inside
// the pixels' borders and simplified by `simplification` px. Empty when the mask is empty.
core::Polygon traceMask(const cv::Mat& mask, double simplification, double minHolePixels);

// objects.geojson: one feature per object with id, class ("building"/"vegetation"), area_m2,
// mean_height_m, max_height_m and, when known, roof_disparity_min/max and ground_disparity.
std::vector<core::Feature> objectFeatures(const std::vector<SceneObject>& objects);

}  // namespace delineo::segmentation
