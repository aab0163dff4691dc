#pragma once
// Raised planar surfaces of a disparity map replaced by their fitted plane (internal to
// delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct RoofPlaneSettings {
  float link = 0.5F;            // px, 4-neighbours of one surface differ by at most this
  int minPixels = 300;          // px, smaller surfaces are left as they are
  double maxResidual = 0.4;     // px, RMS of the plane's inliers (the matches' own noise ~0.2-0.3)
  double minInlierShare = 0.8;  // share of the surface within the inlier band of its plane
  double trimFactor = 2.5;      // inlier band: |residual| <= max(trimFactor RMS, trimFloor)
  double trimFloor = 0.3;       // px
  double minLowerShare = 0.5;   // share of the matched pixels around the surface that lie ...
  float lowerBy = 1.5F;         // ... this many px or more below its plane (a raised surface)
  int ringRadius = 2;           // px, "around": within this Chebyshev distance, outside it
  int gapReach = 8;  // px: the ring lies beyond the unmatched pixels and those at the surface's
                     //   level along its outline, across this many of them at most
  float absorbWithin = 1.5F;  // px: a roof's other pixels this near its plane take it too
  int threads = 1;            // workers over bands of rows (same result for any number)
};

struct RoofPlaneCounts {
  int planes = 0;     // surfaces replaced by their plane
  long pixels = 0;    // pixels set to their surface's plane (its inliers)
  long absorbed = 0;  // other pixels on or around a roof set to its plane
};

// Surfaces are the 4-connected components of matched pixels whose neighbours differ by at most
// `link` px. A surface of `minPixels` or more is fitted with a plane by least squares, trimmed
// three times to the pixels within the inlier band; when its inliers' RMS is <= `maxResidual`,
// they are `minInlierShare` of it or more, and it is raised above what surrounds it, its inliers
// take the plane's value. Raised: of the matched pixels within `ringRadius` px outside its outer
// outline (holes filled), once past the unmatched pixels and those at its level (within `lowerBy`
// of the plane: its own rim, cut from the surface by jumps) for up to `gapReach` px, half or
// more lie `lowerBy` px or more below the plane, that ring holding √count pixels or more: a roof,
// not the ground, a courtyard or a slope of terrain. (On real roofs, 5 cm aerial tiles of Toulouse,
// the big flat roofs had 85-87 % of their pixels in the band and an unmatched or rim border all
// around: see docs/stereo.md.) A roof's matches are noisy at the scale of the correlation window
// (blotches of ±0.5 px on weakly textured roofs); averaging over the window (the surface smoothing)
// cannot remove that, a plane over the whole roof does. Then the other matched pixels on such a
// roof or around it (within `ringRadius` of its outer outline, and across its rim) whose disparity
// lies within `absorbWithin` of the plane take it too (the same 1.5 px that tells the roof from
// what lies below it): the roof's outliers and the pixels a jump cut from it. Only those of small
// pieces, though: pixels of surfaces under `minPixels`, and the roof's own pixels beyond its inlier
// band in 8-connected blobs under `minPixels`; a larger one is a structure on the roof (a box, a
// parapet) and keeps its values. A hip roof's facets join without a step and form one surface that
// no plane fits: it is left as it is, as is anything not planar within the matches' noise.
RoofPlaneCounts fitRoofPlanes(cv::Mat& disparity, const RoofPlaneSettings& settings);

}  // namespace delineo::stereo::detail
