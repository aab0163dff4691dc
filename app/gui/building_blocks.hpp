#pragma once
// The 3D view's blocks of the buildings: each from the ground next to it to its roof, one block
// per roof level (project::roofParts, as the CityJSON export writes them). Kept per building and
// made again only when its outline or roof height, the DEM or the project's parameters change: a
// roof's parts take 10-60 ms, and the view is refreshed after every edit.
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/project/project.hpp"
#include "delineo/widgets/terrain3d_view.hpp"

namespace delineo::gui {

class BuildingBlocks {
 public:
  // The blocks of the buildings that have an outline and a roof height and are not rejected,
  // on `dem` (m, the DEM shown).
  std::vector<widgets::BuildingOutline> of(const project::Project& project, const cv::Mat& dem);

 private:
  struct Entry {
    core::Polygon outline;
    double roofHeight = 0.0;
    std::vector<widgets::BuildingOutline> blocks;
  };
  std::vector<widgets::BuildingOutline> blocksOf(const project::Project& project, const project::Building& b,
                                                 const cv::Mat& dem) const;

  cv::Mat dem_;           // the DEM the entries were made on (shared, so its buffer stays the same)
  std::string settings_;  // the height model and parameters they were made with
  std::map<int, Entry> entries_;
};

}  // namespace delineo::gui
