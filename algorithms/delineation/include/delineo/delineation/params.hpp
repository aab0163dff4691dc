#pragma once
// Parameters of the statistical active polygon (docs/delineation.md explains each choice).
#include "delineo/core/params.hpp"
#include "delineo/delineation/regularize.hpp"

namespace delineo::delineation {

struct DelineationParams {
  double occlusionPercent = 10.0;  // %, p: share of ROI pixels assumed unmatched (paper: 10)
  double edgeWeight = 5.0;         // λ of the edge terms (4) and (5) (paper: 5)
  double rigidity = 15.0;          // β of the angle prior (6) (paper: 15)
  int initialSpacing = 16;         // px between vertices when polygonising the init (paper: 16)
  int refinedSpacing = 8;          // px between vertices after the insertion step (paper: 8)
  int moveRadius = 2;              // px, half side of the square of candidate vertex positions
  int maxIterations = 400;         // sweeps (moves, edge moves, deletions) over all rounds
  int roiMargin = 24;              // px added around the initial polygon to make the ROI
  int costWindow = 5;              // px, side of the correlation window of Crit
  double costBrightness = 20.0;    // × noise sigma: Crit's mean grey term for flat windows (0 = NCC only)
  int groundTolerance = 3;         // px, half width of a ground interval estimated around the init or given as one value
  int groundSearch = 64;           // px searched below the roof interval when ground is unknown
  int ringWidth = 8;               // px, width of the band outside the init used to estimate ground without a map
  bool edgeMoves = true;           // also translate whole edges (two vertices at once)
  bool courtyards = true;          // look for inner courtyards after convergence (holes)
  bool notches = true;             // carve ground regions reaching the outline after convergence
  bool balanceIntervals = true;    // compare roof and ground costs over equally many disparities
  double minCourtyardArea = 120.0; // px², smallest courtyard tried
  double edgeContrast = 0.1;       // Crit units: ground-likeness inside that mutes an edge (0 = off)
  double minAngle = 20.0;          // degrees: sharpest vertex angle a change may create (0 = off)
  double minGap = 2.0;             // px: narrowest finger or slit a change may create (0 = off)
  int shortcutVertices = 16;       // most consecutive vertices one shortcut move removes (< 2 = off)
  double shortcutWidth = 4.0;      // px: widest (mean width) piece a shortcut may cut off
  double maxExcursion = 8.0;       // px: farthest a vertex may go outside the initial contour
  bool regionInit = true;          // start from the roof-like region inside the init when lower F
  double regionTolerance = 8.0;    // px: coarsest outline simplification of the region stage
  int costAggregation = 5;         // px, side of the box filter applied to c_roof and c_ground (1 = off)
  double costCap = 1.6;            // × NoMatchCost: c_roof and c_ground capped there for the terms (0 = off)
  double costCapFloor = 0.35;      // Crit units: the cap is never below this
  double intermediateMargin = 0.1; // Crit units: in-between match this much better: not roof (0 = off)
  int intermediateGuard = 1;       // disparities kept off each interval when looking between them
  double mapCost = 0.6;            // Crit units: where the matcher's map has a value, cost of the class it rules out (0 = off)
  RegularizationParams regularization;  // the outline's last stage (its keys start with regularize)
  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"occlusion", "Occlusion", "%",
                      "Percentage p of ROI pixels taken as unmatched; NoMatchCost is the (100-p)% "
                      "quantile of the best costs (paper: 10)",
                      0, 99},
      occlusionPercent);
    v(core::ParamInfo{"edge-weight", "Edge weight", "",
                      "Weight lambda of the left and right image edge terms (paper: 5)", 0, 1000},
      edgeWeight);
    v(core::ParamInfo{"rigidity", "Rigidity", "",
                      "Weight beta of the vertex angle prior R (paper: 15)", 0, 10000},
      rigidity);
    v(core::ParamInfo{"initial-spacing", "Initial spacing", "px",
                      "Vertex spacing when polygonising the initial contour (paper: 16)", 2, 256},
      initialSpacing);
    v(core::ParamInfo{"refined-spacing", "Refined spacing", "px",
                      "Vertex spacing after the insertion step (paper: 8)", 2, 256},
      refinedSpacing);
    v(core::ParamInfo{"move-radius", "Move radius", "px",
                      "Half side of the square of candidate positions of a vertex move", 1, 8},
      moveRadius);
    v(core::ParamInfo{"max-iterations", "Max iterations", "",
                      "Maximum number of optimisation sweeps", 1, 100000},
      maxIterations);
    v(core::ParamInfo{"roi-margin", "ROI margin", "px",
                      "Margin added around the initial polygon to make the region of interest", 0,
                      1000},
      roiMargin);
    v(core::ParamInfo{"cost-window", "Cost window", "px",
                      "Side of the correlation window of the per-pixel cost", 3, 31},
      costWindow);
    v(core::ParamInfo{"cost-brightness", "Cost brightness", "× noise",
                      "Windows with little texture (where NCC is noise) are also compared by mean "
                      "grey level after a global gain/offset match of the views; a difference of "
                      "this many noise sigmas costs 1 (0 = NCC only, as in the paper)",
                      0, 100},
      costBrightness);
    v(core::ParamInfo{"ground-tolerance", "Ground tolerance", "px",
                      "Half width of the ground disparity interval estimated around the init", 0,
                      32},
      groundTolerance);
    v(core::ParamInfo{"ground-search", "Ground search", "px",
                      "Disparities searched below the roof interval when ground is not given", 1,
                      1024},
      groundSearch);
    v(core::ParamInfo{"ring-width", "Ring width", "px",
                      "Width of the band outside the init where ground disparity is estimated when there is no disparity map", 2,
                      200},
      ringWidth);
    v(core::ParamInfo{"edge-moves", "Edge moves", "",
                      "Also try translating whole edges (two vertices together)"},
      edgeMoves);
    v(core::ParamInfo{"courtyards", "Courtyards", "",
                      "Search for inner courtyards (holes) after convergence"},
      courtyards);
    v(core::ParamInfo{"notches", "Notches", "",
                      "After convergence, carve ground-leaning regions inside the polygon that reach "
                      "(within 12 px) its outline, keeping the carved outline when its optimised "
                      "energy is lower"},
      notches);
    v(core::ParamInfo{"balance-intervals", "Balance intervals", "",
                      "Search the narrower of the roof and ground intervals over as many "
                      "disparities as the wider one (extended away from the other), so that "
                      "textureless pixels favour neither"},
      balanceIntervals);
    v(core::ParamInfo{"min-courtyard-area", "Min courtyard area", "px²",
                      "Smallest interior ground region tried as a courtyard", 16, 1e9},
      minCourtyardArea);
    v(core::ParamInfo{"edge-contrast", "Edge contrast gate", "",
                      "Edge gate: an edge sample counts fully when c_ground - c_roof averaged "
                      "over 5 px inside the contour is >= 0, not at all when it is <= -X (ground "
                      "inside: spikes, fingers), linearly between (Crit units; 0 = paper's terms)",
                      0, 1},
      edgeContrast);
    v(core::ParamInfo{"min-angle", "Min angle", "deg",
                      "Sharpest vertex angle an optimisation step may create (spike tips; 0 = off)",
                      0, 60},
      minAngle);
    v(core::ParamInfo{"min-gap", "Min gap", "px",
                      "Narrowest finger or slit (antiparallel edges) an optimisation step may "
                      "create (0 = off)",
                      0, 20},
      minGap);
    v(core::ParamInfo{"shortcut-vertices", "Shortcut vertices", "",
                      "Most consecutive vertices removed by one shortcut move, which cuts off a "
                      "spike, finger or slit in one step (0 or 1 = off)",
                      0, 256},
      shortcutVertices);
    v(core::ParamInfo{"shortcut-width", "Shortcut width", "px",
                      "Widest piece a shortcut may cut off, as its mean width 2 * area / path "
                      "length (thin spikes and fingers, not wings of the building)",
                      0.5, 100},
      shortcutWidth);
    v(core::ParamInfo{"max-excursion", "Max excursion", "px",
                      "Farthest a vertex may go outside the operator's initial contour (the "
                      "outline is rough, not wrong: neighbouring roofs and trees at roof height "
                      "stay out); at least roi-margin = no limit",
                      0, 10000},
      maxExcursion);
    v(core::ParamInfo{"region-init", "Region init", "",
                      "Start from the outline of the largest roof-like region (c_roof < c_ground) "
                      "inside the initial contour when its energy is lower (carves notches a "
                      "rough contour cannot reach)"},
      regionInit);
    v(core::ParamInfo{"region-tolerance", "Region tolerance", "px",
                      "Coarsest Douglas-Peucker tolerance of the region stage's outline: 2 px and "
                      "each doubling up to this are tried, the lowest energy is kept",
                      0.5, 64},
      regionTolerance);
    v(core::ParamInfo{"cost-aggregation", "Cost aggregation", "px",
                      "Side of the box filter applied to c_roof and c_ground before the area "
                      "terms (on a textureless roof each pixel's cost is noise, its mean is not; "
                      "1 = per pixel as in the paper)",
                      1, 31},
      costAggregation);
    v(core::ParamInfo{"cost-cap", "Cost cap", "× NoMatchCost",
                      "Cap c_roof and c_ground at this multiple of NoMatchCost in the area terms "
                      "(a pixel matching neither interval, a tree or a neighbour's wall, weighs the "
                      "same whichever side of the contour it lies on); "
                      "the edge gate, region stage and courtyard seeds keep the plain costs (0 = off)",
                      0, 10},
      costCap);
    v(core::ParamInfo{"cost-cap-floor", "Cost cap floor", "",
                      "Lowest value of the cost cap, in Crit units (0 = perfect match, 0.5 = no "
                      "correlation): on a clean pair NoMatchCost is near 0 and a multiple of it "
                      "alone would flatten every cost",
                      0, 1},
      costCapFloor);
    v(core::ParamInfo{"intermediate-margin", "Intermediate height margin", "",
                      "A pixel matching no roof disparity (c_roof above NoMatchCost) but a "
                      "disparity between the ground and roof intervals (below NoMatchCost, this "
                      "much better than both) shows something at another height, a crown or a "
                      "wall: it is kept out of the roof like an excluded pixel (0 = off)",
                      0, 1},
      intermediateMargin);
    v(core::ParamInfo{"intermediate-guard", "Intermediate height guard", "px",
                      "Disparities next to each interval left out of the in-between search (a "
                      "window straddling a roof edge matches just inside the gap)",
                      0, 16},
      intermediateGuard);
    v(core::ParamInfo{"map-cost", "Disparity map cost", "",
                      "Where the matcher's disparity map has a value, c_roof and c_ground come from "
                      "it: 0 for the class it shows, this for the other (0 = correlation costs only)",
                      0, 1},
      mapCost);
    regularization.visit(v);
  }
  void validate() const;
};

}  // namespace delineo::delineation
