#pragma once
// Distances and overlaps between two building outlines (core::Polygon, holes allowed).
// All lengths are in the polygons' coordinate unit (left-image pixels in memory), all areas in
// that unit squared. Definitions and rules: docs/metrics.md.
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"

namespace delineo::eval {

// Areas of two outlines and of their intersection.
struct OverlapAreas {
  double a = 0.0;
  double b = 0.0;
  double intersection = 0.0;
  bool exact = true;  // false when the rasterised fallback was used
};

// For simple polygons (every ring simple, holes inside the outer ring) the areas are exact, with
// no rasterisation: the boundary of a ∩ b is made of the pieces of ∂a inside b and the pieces of
// ∂b inside a; with every ring oriented interior-on-the-left, the shoelace integral over those
// pieces is the area (Green's theorem). Boundary pieces shared by both outlines count once when
// the interiors lie on the same side, not at all otherwise.
// A self-intersecting ring has no such orientation: the polygons are then read under the
// even-odd rule (as core::rasterize does) and all three areas are measured on a common raster
// of up to 16 samples per unit and at most 2048 samples across the pair (exact = false).
OverlapAreas overlapAreas(const core::Polygon& a, const core::Polygon& b);

// overlapAreas(a, b).intersection.
double intersectionArea(const core::Polygon& a, const core::Polygon& b);

// Intersection over union of the areas, in [0, 1]; 0 when both areas are zero.
double intersectionOverUnion(const core::Polygon& a, const core::Polygon& b);

// Shape error p1 of Sirmaçek, d'Angelo & Reinartz (after Rüther et al. 2002), in percent:
// 100 · Σ|B_pred − B_truth| / Σ B_truth over binary masks, i.e. the area of the symmetric
// difference over the area of the truth. Computed exactly from the polygons (the limit of the
// mask formula at infinite resolution). 0 for a perfect outline; can exceed 100.
// Returns NaN when the truth has zero area.
double shapeErrorP1(const core::Polygon& predicted, const core::Polygon& truth);

// Distance from a point to the boundary of a polygon (outer ring and holes).
double distanceToBoundary(const cv::Point2d& point, const core::Polygon& polygon);

// PoLiS distance (Avbelj, Müller & Bamler 2015): 1/(2q) Σ_{vertices a of A} d(a, ∂B) +
// 1/(2r) Σ_{vertices b of B} d(b, ∂A), q and r the vertex counts (holes included).
double polisDistance(const core::Polygon& a, const core::Polygon& b);

// Symmetric Hausdorff distance between the boundaries ∂a and ∂b. Each edge is sampled every
// `step` (and at its ends) and each sample's exact distance to the other boundary is taken, so
// the result is at most step/2 below the exact value and never above it.
double hausdorffDistance(const core::Polygon& a, const core::Polygon& b, double step);

// Corners of a polygon: the vertices (of all rings) where the outline turns by at least
// `minTurnDegrees`; repeated vertices are ignored.
std::vector<cv::Point2d> polygonCorners(const core::Polygon& polygon, double minTurnDegrees);

struct CornerMatching {
  double rms = 0.0;          // sqrt(mean of squared distances between matched corners); NaN if none
  int matched = 0;           // number of matched pairs
  int truthCorners = 0;
  int predictedCorners = 0;
};

// Matches corners by mutual nearest neighbour: a truth corner t and a predicted corner p are
// paired when p is the nearest predicted corner to t, t is the nearest truth corner to p, and
// |t − p| <= radius. Each corner is in at most one pair.
CornerMatching matchCorners(const std::vector<cv::Point2d>& predicted,
                            const std::vector<cv::Point2d>& truth, double radius);

}  // namespace delineo::eval
