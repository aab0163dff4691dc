#pragma once
// A building's roof parts: its outline split into one part per roof level (docs/dem.md, "Roof
// levels"), each with its own height: the CityJSON export's BuildingParts and the 3D view's blocks.
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/delineation/regularize.hpp"
#include "delineo/project/project.hpp"
#include "delineo/segmentation/roof_levels.hpp"

namespace delineo::project {

// The project file's group of segmentation::RoofLevelParams.
inline constexpr const char* kRoofLevelsGroup = "roof-levels";

struct RoofPart {
  core::Polygon polygon;        // left-image pixels
  double height = std::nan(""); // m, the median of the heights inside it (its level without any)
};

// The parts of `outline` on `heights` (CV_32F m on the left image's grid, NaN = none), `gsd` m per
// px: the regions of segmentation::roofLevelRegions() traced (each grown by a quarter pixel, so
// that neighbours overlap instead of leaving a gap), squared by delineation::regularizeOutline() with
// `squaring` in the building outline's orientation (kept as traced when its gate refuses), then
// made to tile the outline: the smaller regions are cut out first, each clipped to the outline and
// minus those before it, and the largest region is the outline minus all of them. A piece left
// smaller than `min-area` or thinner than half `clean-width` (a sliver between two squared borders)
// joins the part it shares most border with. The parts therefore cover the outline exactly,
// without overlaps, and neighbours share their border. One part, the outline itself, when the
// roof has one level, without heights, or when `params` is off.
std::vector<RoofPart> partitionRoof(const cv::Mat& heights, const core::Polygon& outline, double gsd,
                                    const segmentation::RoofLevelParams& params,
                                    const delineation::RegularizationParams& squaring);

// partitionRoof() with the project's "roof-levels" group, its gsd and the regularization of its
// "delineation" group: the parts the export writes and the 3D view draws. Empty `heights`: one part.
std::vector<RoofPart> roofParts(const Project& project, const cv::Mat& heights, const core::Polygon& outline);

}  // namespace delineo::project
