#include "building_blocks.hpp"

#include <cmath>

#include "delineo/core/error.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/roof_parts.hpp"

namespace delineo::gui {

namespace {
bool sameRing(const core::Ring& a, const core::Ring& b) { return a == b; }

bool samePolygon(const core::Polygon& a, const core::Polygon& b) {
  if (!sameRing(a.outer, b.outer) || a.holes.size() != b.holes.size()) return false;
  for (size_t i = 0; i < a.holes.size(); ++i) {
    if (!sameRing(a.holes[i], b.holes[i])) return false;
  }
  return true;
}

// What the blocks depend on besides the outline, the roof height and the DEM.
std::string settingsOf(const project::Project& project) {
  const project::HeightModel& h = project.height;
  return std::to_string(h.groundDisparity) + " " + std::to_string(h.metresPerPixel) + " " + std::to_string(h.gsd) +
         " " + project.parameters.dump();
}

// The roof parts of a building with several roof levels, or none (one level, roof levels off, or
// a parameter out of its domain: the block is then drawn whole, the form says what is wrong).
std::vector<project::RoofPart> roofPartsOrNone(const project::Project& project, const cv::Mat& dem,
                                               const core::Polygon& outline) {
  try {
    std::vector<project::RoofPart> parts = project::roofParts(project, dem, outline);
    if (parts.size() >= 2) return parts;
  } catch (const core::Error&) {
  }
  return {};
}
}  // namespace

std::vector<widgets::BuildingOutline> BuildingBlocks::blocksOf(const project::Project& project,
                                                               const project::Building& b, const cv::Mat& dem) const {
  // The ground next to the building, as the histogram's ground line reads it.
  const double base = project::groundHeightNextTo(project, dem, b.outline).value_or(0.0);
  const std::vector<project::RoofPart> parts = roofPartsOrNone(project, dem, b.outline);
  if (parts.empty()) return {{b.outline, base, b.roofHeight}};
  std::vector<widgets::BuildingOutline> blocks;
  for (const auto& part : parts) blocks.push_back({part.polygon, base, part.height});
  return blocks;
}

std::vector<widgets::BuildingOutline> BuildingBlocks::of(const project::Project& project, const cv::Mat& dem) {
  const std::string settings = settingsOf(project);
  if (dem.data != dem_.data || dem.size() != dem_.size() || settings != settings_) {
    entries_.clear();
    dem_ = dem;
    settings_ = settings;
  }
  std::map<int, Entry> current;
  std::vector<widgets::BuildingOutline> all;
  for (const project::Building& b : project.buildings) {
    if (!b.hasOutline() || b.status == project::BuildingStatus::Rejected || !std::isfinite(b.roofHeight)) continue;
    auto cached = entries_.find(b.id);
    const bool fresh = cached != entries_.end() && cached->second.roofHeight == b.roofHeight &&
                       samePolygon(cached->second.outline, b.outline);
    Entry entry = fresh ? std::move(cached->second) : Entry{b.outline, b.roofHeight, blocksOf(project, b, dem)};
    all.insert(all.end(), entry.blocks.begin(), entry.blocks.end());
    current.emplace(b.id, std::move(entry));
  }
  entries_ = std::move(current);
  return all;
}

}  // namespace delineo::gui
