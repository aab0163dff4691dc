#pragma once
// Boolean operations on sets of polygons (left-image pixels, holes kept) through OGR's GEOS:
// the tiling of a building's outline into its roof parts (project::roofParts). A set is a list of
// polygons that do not overlap; results come back as such a list, without the lines and points
// an operation may leave where two polygons only touch.
#include <optional>
#include <vector>

#include "delineo/core/geometry.hpp"

namespace delineo::io {

using PolygonSet = std::vector<core::Polygon>;

// The parts of `a` inside `b`, of `a` outside `b`, and of either. An invalid input polygon (a
// self-touching ring after rounding) is made valid first. Throws core::Error(ProcessingFailed)
// when GDAL is built without GEOS.
PolygonSet intersectionOf(const PolygonSet& a, const PolygonSet& b);
PolygonSet differenceOf(const PolygonSet& a, const PolygonSet& b);
PolygonSet unionOf(const PolygonSet& a, const PolygonSet& b);

// The pieces of `polygon` cut along the segment from `from` to `to` (an operator's cut across a
// building), largest first; empty when the segment does not cross it from side to side, so that
// fewer than two pieces would come out. The cut is a blade kSplitWidth px wide.
inline constexpr double kSplitWidth = 0.001;
PolygonSet splitAlong(const core::Polygon& polygon, cv::Point2d from, cv::Point2d to);

// `a` and `b` as one polygon: their union when they overlap or touch; when they lie apart by at
// most `maxGap` px (two outlines on either side of a shared wall), the vertices of each within
// `maxGap` of the other's border are first moved onto it. A hole of the union that is no
// courtyard of `a` or `b` (a pocket where they do not quite meet) is filled. nullopt when they
// stay apart or the union has a part of its own (they are farther apart somewhere).
std::optional<core::Polygon> mergedOutline(const core::Polygon& a, const core::Polygon& b, double maxGap);

// Length (px) of the border of `a` that runs along the border of `b` (within `tolerance` px).
double sharedBorderLength(const core::Polygon& a, const core::Polygon& b, double tolerance = 0.01);

// Length (px) of the rings of `polygon`, holes included.
double perimeter(const core::Polygon& polygon);

}  // namespace delineo::io
