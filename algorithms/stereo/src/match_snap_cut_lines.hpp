#pragma once
// The checked cuts of a step's near side taken on a line across rows (internal to
// delineo_stereo; see snapStepsToContours).
#include <vector>

#include "match_snap.hpp"

namespace delineo::stereo::detail {

// One checked cut of a near side on the left: the candidate last near pixels e in
// [eFirst, eFirst + cost.size()) with their costs, and the one chosen.
struct NearSideCut {
  int y = 0, a = 0, b = 0, s0 = 0, s1 = 0;
  float dNear = 0, dFar = 0;
  // The near surface's slope along the row (px of disparity per px) through its last pixel a.
  float slope = 0;
  int eFirst = 0;
  // The last candidate the row may take on its own evidence (later ones: line only).
  int ownLast = 0;
  std::vector<float> cost;
  int chosen = 0;
  int rowBest = 0;           // argmin of the row's own cost
  int prev = -1, next = -1;  // the same outline's cut in the rows above and below (index)
  // The near surface's disparity at x: dNear at a, along its slope on either side.
  float nearAt(int x) const { return dNear + slope * static_cast<float>(x - a); }
};

// The outline is a line across rows: each cut is linked to the cut of the same step (near and
// far disparities within linkDisparity, candidate ranges overlapping) in the rows above and
// below. The row's cut is then the point of the line through rows y ± lineRows of least total
// cost, each row's cost taken relative to its own best and capped at lineCap (a row that the
// line misses, at a corner or a notch, costs no more than that).
// Three passes over bands of rows on the workers (`threads`). A row's work writes only its own
// cuts, and the `next` links of the row above, which no other row sets; of the other rows it
// reads only fields that an earlier pass wrote, or that no pass changes: the result does not
// depend on the bands.
void chooseCuts(std::vector<std::vector<NearSideCut>>& rows, const StepSnapSettings& settings);

}  // namespace delineo::stereo::detail
