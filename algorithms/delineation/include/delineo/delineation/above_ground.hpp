#pragma once
// The above-ground object under a clicked pixel: the connected region standing at least a height
// margin above the local ground, grown from the click by steps of at most a height (so that a
// neighbour of another height stays out) and joined by the thin parts touching it (parapets),
// its outline traced and simplified (docs/dem.md, "Ground level and
// above-ground objects"). The ground is estimateGroundLevel() (roof_interval.hpp), the estimate
// the roof interval proposal and the histogram's ground line use: first in a band around the
// click, then next to the region found, until the two agree; so the ground the operator sees on
// the histogram of a picked object is the ground that cut it out. No GUI interaction here.
#include <limits>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"
#include "delineo/delineation/roof_interval.hpp"

namespace delineo::delineation {

struct AboveGroundParams {
  double heightMargin = 2.5;       // m, an object's pixels stand at least this above the ground
  double searchRadius = 120.0;     // px, band around the click where the ground is first sought
  double maxSearchRadius = 2000.0; // px, the band doubles up to this while the click is not above it
  double maxStep = 0.75;           // m, largest height step between neighbouring pixels of one object
  int thinWidth = 9;               // px, above-ground parts this narrow touching the object join it
  double snapRadius = 4.0;         // px, a click on no data takes the nearest object pixel this near
  int opening = 3;                 // px, side of the square opening that cuts thin links (1: off)
  int smoothing = 7;               // px, side of the square closing then opening of the object's mask
  double simplification = 2.0;     // px, Douglas-Peucker tolerance of the outline
  int refinements = 3;             // times the ground is estimated again next to the object found

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"height-margin", "Height margin", "m",
                "An above-ground object stands at least this high above the local ground", 0.1, 1000},
      heightMargin);
    v(ParamInfo{"search-radius", "Ground search radius", "px",
                "Width of the band around the click where the ground is first sought", 4, 100000},
      searchRadius);
    v(ParamInfo{"max-search-radius", "Largest ground search radius", "px",
                "The band doubles up to this width while the click is not above its ground", 4, 100000},
      maxSearchRadius);
    v(ParamInfo{"max-step", "Largest step", "m",
                "Largest height step between neighbouring pixels of one object, so that a neighbour "
                "of another height is left out (0: any step)",
                0, 1000},
      maxStep);
    v(ParamInfo{"thin-width", "Thin part width", "px",
                "Above-ground parts narrower than this that touch the object join it, as parapets do "
                "(1: none)",
                1, 101},
      thinWidth);
    v(ParamInfo{"snap-radius", "Snap radius", "px",
                "A click on a pixel without height takes the nearest object pixel this near", 0, 100},
      snapRadius);
    v(ParamInfo{"opening", "Opening", "px",
                "Side of the square opening that cuts thin links between objects (1: none)", 1, 51},
      opening);
    v(ParamInfo{"smoothing", "Outline smoothing", "px",
                "Side of the square closing then opening that smooths the object before its outline is "
                "traced (1: none)",
                1, 51},
      smoothing);
    v(ParamInfo{"simplification", "Outline simplification", "px",
                "Largest distance between the traced outline and its simplified polygon", 0, 50},
      simplification);
    v(ParamInfo{"refinements", "Ground refinements", "",
                "Times the ground is estimated again next to the object found", 0, 20},
      refinements);
  }
  // Throws core::Error(InvalidParameter): a field outside its domain, an even opening or smoothing, a
  // largest search radius below the first.
  void validate() const;
};

enum class PickOutcome {
  Found,
  NoGround,        // no height in the band around the click
  NotAboveGround,  // the clicked pixel is no higher than the ground plus the margin
};

struct AboveGroundObject {
  PickOutcome outcome = PickOutcome::NotAboveGround;
  core::Polygon outline;  // left-image pixels (vertices at pixel centres of the region's border)
  cv::Mat mask;           // CV_8U, the map's size, 255 inside the object's outer border (empty unless Found)
  int pixels = 0;
  // px of disparity: estimateGroundLevel() next to `outline` when Found, else the level around
  // the click (NaN when there is none).
  double groundLevel = std::numeric_limits<double>::quiet_NaN();
  int refinements = 0;    // ground estimates after the first
};

// The above-ground object at `click` (left-image pixel coordinates) on `disparity` (CV_32F, px,
// NaN = no value; higher is higher). `metresPerPixel` (m of height per px of disparity, its
// absolute value is used) turns the height margin into disparity. `ground` are the ground
// estimate's parameters (the histogram's: the defaults). Throws core::Error: UnsupportedInput for
// an empty or non-float map, InvalidParameter for bad parameters, a zero scale or a click outside
// the map.
AboveGroundObject aboveGroundObjectAt(const cv::Mat& disparity, cv::Point2d click, double metresPerPixel,
                                      const AboveGroundParams& params = {},
                                      const RoofIntervalParams& ground = {});

// The outer outline of the non-zero pixels of `mask` (CV_8U) holding pixel `seed`, traced and
// simplified by `tolerance` px, vertices at pixel centres. Empty when `seed` is not set.
core::Polygon traceOutline(const cv::Mat& mask, cv::Point seed, double tolerance);

}  // namespace delineo::delineation
