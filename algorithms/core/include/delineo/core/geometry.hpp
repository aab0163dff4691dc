#pragma once
// Geometry shared by every domain. Coordinates are left-image (epipolar) pixels unless a type
// says otherwise: x to the right, y down, pixel (i, j) covers [i, i+1) x [j, j+1), so the centre
// of pixel (i, j) is (i + 0.5, j + 0.5).
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <opencv2/core.hpp>

namespace delineo::core {

using Ring = std::vector<cv::Point2d>;  // closed implicitly: last vertex connects to the first

struct Polygon {
  Ring outer;               // counter-clockwise or clockwise; helpers normalise when needed
  std::vector<Ring> holes;  // inner courtyards
};

using AttributeValue = std::variant<std::monostate, long long, double, std::string>;

struct Feature {
  Polygon polygon;
  std::map<std::string, AttributeValue> attributes;
};

// A numeric property of `feature`: nullopt when absent or null; else a finite number of magnitude
// at most `limit` (a string holding one whole is read too). Anything else throws
// core::Error(InvalidParameter) naming the property.
std::optional<double> numberProperty(const Feature& feature, const std::string& key, double limit);

// Signed area (shoelace): positive for counter-clockwise in a y-up frame, i.e. clockwise on
// screen with y down.
double signedArea(const Ring& ring);
double area(const Polygon& polygon);  // outer minus holes, always >= 0
cv::Rect2d boundingBox(const Ring& ring);
// True when segments p1-p2 and p3-p4 share at least one point (crossing, touching at an end
// point, or overlapping collinearly).
bool segmentsIntersect(const cv::Point2d& p1, const cv::Point2d& p2, const cv::Point2d& p3,
                       const cv::Point2d& p4);
// True when no two non-adjacent edges of the ring intersect and it has >= 3 vertices.
bool isSimple(const Ring& ring);
// Rasterises a polygon (with holes) into a CV_8U mask of the given size: 255 where the pixel
// centre is inside.
cv::Mat rasterize(const Polygon& polygon, cv::Size size);

// Editing an outline without changing its angles (the vertex editor's "keep the angles" drag,
// e.g. on a regularized outline). Both return the changed ring; every edge keeps its direction,
// so right angles stay right.
// Moves vertex `index` to `to`; its two neighbours slide along the edges beyond them. Throws
// Error(InvalidParameter) for fewer than 4 vertices or an index out of range.
Ring moveCornerKeepingAngles(const Ring& ring, int index, cv::Point2d to);
// Moves edge `index` (vertex index to index + 1) by `offset` px along its normal (positive: to
// the left of its direction in image coordinates, x right and y down); its end vertices slide
// along the neighbouring edges. Throws like moveCornerKeepingAngles (at least 3 vertices).
Ring moveEdgeKeepingAngles(const Ring& ring, int index, double offset);

}  // namespace delineo::core
