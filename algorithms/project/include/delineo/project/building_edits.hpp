#pragma once
// Edits of the buildings themselves rather than of one outline: one building cut in two along a
// line (a proposal or a map polygon that covers two buildings), two buildings merged into one (a
// building that detection or a map split in two). The GUI's Split and Merge actions.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/project/project.hpp"

namespace delineo::project {

// Largest gap (px) between two outlines that mergeBuildings() closes (the two sides of a wall).
inline constexpr double kMergeGap = 3.0;
// Least area (px²) of a piece a split keeps.
inline constexpr double kMinPieceArea = 4.0;

// Why a split or a merge changed nothing (the GUI words it in the interface's language).
enum class EditRefusal { None, NoSuchBuilding, NotCutInTwo, SameBuilding, TooFarApart };

// What a split or a merge did: the buildings it changed or made, or why it did nothing.
struct BuildingEdit {
  std::vector<int> ids;  // the buildings after the edit (a split: the first keeps the id); empty: refused
  EditRefusal why = EditRefusal::None;
  std::string refusal;   // why nothing changed, in English
  bool done() const { return !ids.empty(); }
};

// Cuts building `id` along the segment from `from` to `to` (left-image pixels), which must cross
// its polygon (outline, else initial polygon) from side to side. The largest piece keeps the id,
// the others become new buildings with the same method and source id. Each piece's roof interval
// is the one its own disparities propose (suggestRoofInterval() on `disparity`; the building's
// when there is no map or no proposal). A building with an outline gives Corrected pieces (the
// piece as outline and initial polygon, roof height read on `disparity`, energy unknown); a
// Pending one gives Pending pieces. Each gets a "split" history entry (`origin` first).
BuildingEdit splitBuilding(Project& project, int id, cv::Point2d from, cv::Point2d to, const cv::Mat& disparity = {},
                           const std::string& origin = {});

// Merges building `other` into building `id`: one polygon (their union, a gap of up to kMergeGap
// px between them closed), the roof interval spanning both, the source ids of both. The result
// is Corrected when either had an outline (roof height read on `disparity` when given), else
// Pending; `other` is removed. Refused when they lie farther apart or are the same building.
BuildingEdit mergeBuildings(Project& project, int id, int other, const cv::Mat& disparity = {},
                            const std::string& origin = {});

}  // namespace delineo::project
