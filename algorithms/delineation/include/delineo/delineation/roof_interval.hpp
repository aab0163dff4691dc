#pragma once
// Roof disparity interval and ground level proposed from a disparity map and an operator's rough
// polygon (docs/delineation.md, "Roof interval and ground level proposal"). No GUI interaction
// here: the GUI's histogram and `delineo-cli run` call the same functions.
#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"

namespace delineo::delineation {

struct RoofIntervalParams {
  double binWidth = 0.5;        // px, histogram bin
  double smoothing = 0.5;       // px, sigma of the Gaussian that smooths the histograms
  double coreShrink = 8.0;      // px, the roof peak is read this far inside the polygon (at most a quarter of its size)
  double minRoofHeight = 3.0;   // px of disparity: a roof peak lies at least this above the ground level
  double entryReach = 10.0;     // px, roof-level regions reaching this far outside the polygon are a neighbour's (0: off)
  double peakFraction = 0.2;    // the interval spans the peak down to this share of its height
  int padding = 1;              // px added on each side of the interval
  double groundMargin = 120.0;  // px, width of the neighbourhood outside the polygon searched for ground
  double groundShare = 0.05;    // share of the neighbourhood's matched pixels a ground level must hold
  double groundWindow = 2.0;    // px, half width of the disparity window counted around a ground level
  double groundSpan = 8.0;      // px, the ground is the most populated level this far above the lowest one
  double groundReach = 40.0;    // px, the ground plane is read along the polygon where band ground lies this near (0: no plane)
  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"bin-width", "Bin width", "px", "Width of a bin of the disparity histograms", 0.05, 10},
      binWidth);
    v(core::ParamInfo{"smoothing", "Smoothing", "px", "Sigma of the Gaussian smoothing the histograms", 0, 10},
      smoothing);
    v(core::ParamInfo{"core-shrink", "Core shrink", "px",
                      "The roof peak is read this far inside the polygon, away from its border", 0, 200},
      coreShrink);
    v(core::ParamInfo{"min-roof-height", "Minimum roof height", "px",
                      "A roof peak lies at least this much disparity above the ground level", 0, 1000},
      minRoofHeight);
    v(core::ParamInfo{"entry-reach", "Entry reach", "px",
                      "Regions at a roof level that reach this far outside the polygon are a neighbour's roof (0: off)",
                      0, 1000},
      entryReach);
    v(core::ParamInfo{"peak-fraction", "Peak fraction", "",
                      "The interval covers the roof peak down to this share of its height", 0.01, 0.99},
      peakFraction);
    v(core::ParamInfo{"padding", "Padding", "px", "Disparities added on each side of the interval", 0, 50},
      padding);
    v(core::ParamInfo{"ground-margin", "Ground margin", "px",
                      "Width of the neighbourhood outside the polygon where the ground level is sought", 4, 100000},
      groundMargin);
    v(core::ParamInfo{"ground-share", "Ground share", "",
                      "Share of the neighbourhood's matched pixels a level needs to count as ground", 0.001, 1},
      groundShare);
    v(core::ParamInfo{"ground-window", "Ground window", "px",
                      "Half width of the disparity window counted around a candidate ground level", 0.25, 50},
      groundWindow);
    v(core::ParamInfo{"ground-span", "Ground span", "px",
                      "The ground is the most populated level up to this far above the lowest well-populated one", 0, 100},
      groundSpan);
    v(core::ParamInfo{"ground-reach", "Ground reach", "px",
                      "The ground plane is read along the polygon where ground was seen this near (0: the band's level)",
                      0, 100000},
      groundReach);
  }
  void validate() const;
};

struct RoofIntervalProposal {
  bool found = false;        // false: too few matched pixels inside the polygon
  int low = 0, high = 0;     // px, proposed roof interval (inclusive)
  double peak = 0.0;         // px, disparity of the roof's main peak
  double groundLevel = 0.0;  // px, NaN when the neighbourhood holds no matched pixel
  int roofSamples = 0;       // matched pixels of the polygon's core the peak was read from
  int groundSamples = 0;     // matched pixels of the neighbourhood
};

// Ground level (px) next to `polygon`, from the matched pixels of a band `groundMargin` px wide
// outside it: the lowest level holding at least `groundShare` of them (counted within
// `groundWindow`), then the most populated level up to `groundSpan` above it, refined as the
// median of the pixels within `groundWindow` of that level. A plane is then fitted to the band's
// pixels within `groundWindow` of that level (five refits to the pixels within `groundWindow` of
// the plane) and averaged along the polygon's outer ring where that ground lies within
// `groundReach` px: on a sloping ground, the level beside the building rather than the band's.
// NaN when the band holds no matched pixel. `disparity` is float32 in left-image geometry,
// NaN = no value.
double estimateGroundLevel(const cv::Mat& disparity, const core::Polygon& polygon,
                           const RoofIntervalParams& params = {});

// Roof interval: the most populated histogram peak of the polygon's core (the polygon shrunk by
// `coreShrink`) at least `minRoofHeight` above the ground level (unless that level lies above
// the core's own most populated level, i.e. is a neighbour's roof), widened to where the smoothed
// histogram falls under `peakFraction` of the peak, plus `padding`. Levels are compared without
// their pixels in regions that enter the polygon from outside (connected pixels at the level
// reaching `entryReach` px outside the polygon: a neighbour's roof crossing a rough outline),
// among the most populated level and the other peaks holding at least a fifth of its pixels;
// when none keeps that fifth (a polygon drawn inside its roof), the most populated level.
// Throws InvalidParameter for a wrong map type or bad parameters; `found` is false when the
// polygon holds < 10 matched pixels.
RoofIntervalProposal proposeRoofInterval(const cv::Mat& disparity, const core::Polygon& polygon,
                                         const RoofIntervalParams& params = {});

}  // namespace delineo::delineation
