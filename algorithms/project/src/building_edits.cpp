#include "delineo/project/building_edits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "delineo/io/polygon_sets.hpp"
#include "delineo/project/pipeline.hpp"
#include "history_detail.hpp"

namespace delineo::project {

using detail::withOrigin;

namespace {
// The building on `polygon` as an operator's edit leaves it: its outline when it had one (status
// Corrected, energy unknown, roof height read on `disparity`), else its initial polygon (Pending).
void reshape(const Project& project, Building& b, const core::Polygon& polygon, const cv::Mat& disparity) {
  const bool outlined = b.hasOutline();
  b.initial = polygon;
  b.outline = outlined ? polygon : core::Polygon{};
  b.status = outlined ? BuildingStatus::Corrected : BuildingStatus::Pending;
  b.energy = std::nan("");
  b.energyTerms.reset();
  b.roofHeight = outlined && !disparity.empty() ? roofHeight(project, disparity, polygon) : std::nan("");
}

std::string segmentText(cv::Point2d from, cv::Point2d to) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.1f, %.1f)-(%.1f, %.1f)", from.x, from.y, to.x, to.y);
  return text;
}

std::string joinedSourceIds(const std::string& a, const std::string& b) {
  if (a.empty() || a == b) return b;
  if (b.empty()) return a;
  return a + ";" + b;
}
}  // namespace

BuildingEdit splitBuilding(Project& project, int id, cv::Point2d from, cv::Point2d to, const cv::Mat& disparity,
                           const std::string& origin) {
  Building* building = project.find(id);
  if (building == nullptr) return {{}, EditRefusal::NoSuchBuilding, "no building " + std::to_string(id)};
  io::PolygonSet pieces = io::splitAlong(building->currentPolygon(), from, to);
  pieces.erase(std::remove_if(pieces.begin(), pieces.end(),
                              [](const core::Polygon& p) { return core::area(p) < kMinPieceArea; }),
               pieces.end());
  if (pieces.size() < 2) {
    return {{}, EditRefusal::NotCutInTwo, "the line does not cut the building in two: draw it across, from outside to outside"};
  }
  const Building original = *building;
  BuildingEdit edit;
  for (size_t i = 0; i < pieces.size(); ++i) {
    Building piece = original;
    if (i > 0) {
      piece.id = project.nextBuildingId();
      piece.history.clear();
    }
    reshape(project, piece, pieces[i], disparity);
    // The pieces are apart because they differ: each gets the roof interval its own disparities propose.
    if (const auto own = suggestRoofInterval(disparity, pieces[i])) piece.roofInterval = own;
    piece.addHistory("split", withOrigin(origin, "building " + std::to_string(id) + " cut along " +
                                                     segmentText(from, to) + " into " +
                                                     std::to_string(pieces.size()) + " pieces"));
    if (i == 0) *project.find(id) = piece;
    else project.buildings.push_back(piece);
    edit.ids.push_back(piece.id);
  }
  return edit;
}

BuildingEdit mergeBuildings(Project& project, int id, int other, const cv::Mat& disparity, const std::string& origin) {
  if (id == other) return {{}, EditRefusal::SameBuilding, "a building cannot be merged with itself"};
  Building* a = project.find(id);
  const Building* b = project.find(other);
  if (a == nullptr || b == nullptr) {
    return {{}, EditRefusal::NoSuchBuilding, "no building " + std::to_string(a == nullptr ? id : other)};
  }
  const auto merged = io::mergedOutline(a->currentPolygon(), b->currentPolygon(), kMergeGap);
  if (!merged) {
    return {{}, EditRefusal::TooFarApart,
            "buildings " + std::to_string(id) + " and " + std::to_string(other) + " are more than " +
                std::to_string(static_cast<int>(kMergeGap)) + " px apart"};
  }
  const bool outlined = a->hasOutline() || b->hasOutline();
  if (outlined && !a->hasOutline()) a->outline = a->initial;  // reshape() keeps the outlined state
  if (a->roofInterval && b->roofInterval) {
    a->roofInterval = DisparityInterval{std::min(a->roofInterval->low, b->roofInterval->low),
                                        std::max(a->roofInterval->high, b->roofInterval->high)};
  } else if (!a->roofInterval) {
    a->roofInterval = b->roofInterval;
  }
  a->sourceId = joinedSourceIds(a->sourceId, b->sourceId);
  reshape(project, *a, *merged, disparity);
  a->addHistory("merged", withOrigin(origin, "with building " + std::to_string(other)));
  project.buildings.erase(std::find_if(project.buildings.begin(), project.buildings.end(),
                                       [&](const Building& x) { return x.id == other; }));
  return {{id}, EditRefusal::None, {}};
}

}  // namespace delineo::project
