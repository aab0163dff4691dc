#pragma once
// Roof levels of one building (docs/dem.md, "Roof levels"): a roof with several levels (a lower
// inner roof inside a raised ring, an annex, a tower on a lower roof) split into regions, one per
// level, on the heights inside the building's footprint. The regions become the building's parts
// (project::roofParts: polygons, squared, tiling the outline; CityJSON BuildingParts).
//
// 1. Levels: modes of the histogram of the footprint's heights (bins of a tenth of `min-step`,
//    smoothed over a quarter of it), the most populated first; a mode is a level when it lies at
//    least `min-step` from every level kept and the histogram dips below half the lower of the two
//    peaks between them. A level holding fewer than `min-area` of pixels (those within half
//    `min-step` of it) is dropped, the smallest first.
// 2. Each pixel within half `min-step` of its nearest level takes it; the others (no height, a
//    wall between levels, a chimney above the roof) take the level of the nearest pixel that has one.
// 3. Cleaning: each level's pixels are opened with a disk `clean-width` across; the pixels it
//    frees go to the nearest other level.
// 4. Regions: the 4-connected pieces of each level; one smaller than `min-area` joins the region it
//    shares most border with, the smallest first.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"

namespace delineo::segmentation {

struct RoofLevelParams {
  std::string mode = "on";   // on | off: off keeps one block per building
  double minStep = 1.5;      // m, least height between two roof levels
  double minArea = 10.0;     // m², a smaller level or region joins its neighbour
  double cleanWidth = 1.0;   // m, a level's strips narrower than this go to the levels around them

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"roof-levels", "Roof levels", "",
                "A roof with several levels becomes one block per level (CityJSON BuildingParts, the 3D view), "
                "or one block per building",
                0, 0, "on|off"},
      mode);
    v(ParamInfo{"roof-level-step", "Roof level step", "m", "Least height between two roof levels", 0.1, 100},
      minStep);
    v(ParamInfo{"roof-level-min-area", "Roof level minimum area", "m²",
                "A roof level or part smaller than this joins its neighbour", 0, 1e6},
      minArea);
    v(ParamInfo{"roof-level-clean-width", "Roof level clean width", "m",
                "Strips of a level narrower than this go to the levels around them", 0, 100},
      cleanWidth);
  }
  void validate() const { core::checkDeclaredRanges(*this); }
  bool on() const { return mode == "on"; }
};

// The roof levels (m, ascending) of `heights` (finite values), step 1 above; `pixelArea` in m².
// At least one level when there are heights, none without.
std::vector<double> roofLevels(const std::vector<float>& heights, double pixelArea, const RoofLevelParams& params);

struct RoofLevelRegions {
  // CV_32S, the region of each pixel: inside the footprint, and outside it the region of the
  // nearest footprint pixel (so that a region's polygon reaches past the outline where it meets it).
  cv::Mat labels;
  std::vector<double> levels;      // m, ascending (roofLevels())
  std::vector<int> regionLevel;    // index into `levels` of each region
  std::vector<int> regionPixels;   // pixels of each region inside the footprint
};

// Steps 1-4 on `heights` (CV_32F m, NaN = none) inside `footprint` (CV_8U, non-zero inside, same
// size), `gsd` m per px. One region covering everything when the footprint has one level or no
// heights; no region for an empty footprint. Throws core::Error(InvalidParameter) for bad
// parameters, a gsd that is not positive or mismatched inputs.
RoofLevelRegions roofLevelRegions(const cv::Mat& heights, const cv::Mat& footprint, double gsd,
                                  const RoofLevelParams& params);

}  // namespace delineo::segmentation
