// A building's roof parts (declared in roof_parts.hpp): roof level regions traced, squared and
// made to tile the building's outline.
#include "delineo/project/roof_parts.hpp"

#include <algorithm>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/delineation/params.hpp"
#include "delineo/io/polygon_sets.hpp"

namespace delineo::project {

namespace {

using io::PolygonSet;

// A piece of the tiling and the level its region stands at.
struct Piece {
  core::Polygon polygon;
  int level = 0;
};

core::Polygon shifted(const core::Polygon& polygon, cv::Point2d by) {
  core::Polygon out = polygon;
  for (auto& p : out.outer) p += by;
  for (auto& hole : out.holes) {
    for (auto& p : hole) p += by;
  }
  return out;
}

// The outline's bounding box grown by `margin` px, within an image of `size`.
cv::Rect cropAround(const core::Polygon& outline, cv::Size size, int margin) {
  const cv::Rect2d box = core::boundingBox(outline.outer);
  const cv::Rect grown(cv::Point(static_cast<int>(std::floor(box.x)) - margin, static_cast<int>(std::floor(box.y)) - margin),
                       cv::Point(static_cast<int>(std::ceil(box.x + box.width)) + margin,
                                 static_cast<int>(std::ceil(box.y + box.height)) + margin));
  return grown & cv::Rect(cv::Point(0, 0), size);
}

// The polygons of a region's mask, on a grid of half pixels grown by one half pixel and traced
// through the centres of its border cells: the region's pixel border pushed out by a quarter pixel,
// so that neighbouring regions overlap by half a pixel instead of leaving a gap.
PolygonSet tracedPolygons(const cv::Mat& mask) {
  cv::Mat fine, grown;
  cv::resize(mask, fine, mask.size() * 2, 0, 0, cv::INTER_NEAREST);
  cv::dilate(fine, grown, cv::Mat::ones(3, 3, CV_8U));
  std::vector<std::vector<cv::Point>> contours;
  std::vector<cv::Vec4i> hierarchy;
  cv::findContours(grown, contours, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_SIMPLE);
  auto ringOf = [](const std::vector<cv::Point>& contour) {
    core::Ring ring;
    for (const auto& p : contour) ring.emplace_back(0.5 * (p.x + 0.5), 0.5 * (p.y + 0.5));
    return ring;
  };
  PolygonSet out;
  for (size_t i = 0; i < contours.size(); ++i) {
    if (hierarchy[i][3] >= 0 || contours[i].size() < 3) continue;
    core::Polygon polygon{ringOf(contours[i]), {}};
    for (int h = hierarchy[i][2]; h >= 0; h = hierarchy[static_cast<size_t>(h)][0]) {
      if (contours[static_cast<size_t>(h)].size() >= 3) polygon.holes.push_back(ringOf(contours[static_cast<size_t>(h)]));
    }
    if (core::area(polygon) > 0.0) out.push_back(std::move(polygon));
  }
  return out;
}

// `polygon` squared in the building's orientation: the first result the regularization's gate
// lets through at its tolerance, half and a quarter of it (as delineate() tries); else as traced.
core::Polygon squared(const core::Polygon& polygon, delineation::RegularizationParams squaring, double orientation) {
  const double tolerance = squaring.tolerance;
  for (const double share : {1.0, 0.5, 0.25}) {
    squaring.tolerance = std::max(tolerance * share, delineation::RegularizationParams::kMinTolerance);
    try {
      const auto outcome = delineation::regularizeOutline(polygon, squaring, {}, orientation);
      if (outcome.status != delineation::RegularizationStatus::KeptRaw) return outcome.polygon;
    } catch (const core::Error&) {
      break;  // not a polygon the regularization takes
    }
  }
  return polygon;
}

PolygonSet squared(const PolygonSet& polygons, const delineation::RegularizationParams& squaring, double orientation) {
  PolygonSet out;
  for (const auto& polygon : polygons) out.push_back(squared(polygon, squaring, orientation));
  return out;
}

// The regions cut out of the outline, the smallest first; the largest is what is left.
std::vector<Piece> tiledPieces(const core::Polygon& outline, const segmentation::RoofLevelRegions& regions,
                               const std::vector<PolygonSet>& shapes) {
  std::vector<int> order(shapes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return regions.regionPixels[static_cast<size_t>(a)] < regions.regionPixels[static_cast<size_t>(b)]; });
  std::vector<Piece> pieces;
  PolygonSet taken;
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    const int region = order[i];
    const PolygonSet part = io::differenceOf(io::intersectionOf(shapes[static_cast<size_t>(region)], {outline}), taken);
    for (const auto& polygon : part) pieces.push_back({polygon, regions.regionLevel[static_cast<size_t>(region)]});
    taken = io::unionOf(taken, part);
  }
  for (const auto& polygon : io::differenceOf({outline}, taken)) {
    pieces.push_back({polygon, regions.regionLevel[static_cast<size_t>(order.back())]});
  }
  return pieces;
}

// A piece too small (under `minArea` px²) or too thin (mean width 2 area / perimeter under
// `minWidth` px: a strip's width, half a square's side) to stand on its own.
bool isSliver(const core::Polygon& polygon, double minArea, double minWidth) {
  const double area = core::area(polygon);
  return area < minArea || 2.0 * area < minWidth * io::perimeter(polygon);
}

// The piece sharing most border with piece `index` (of another level when `otherLevel`), or -1.
int neighbourOf(const std::vector<Piece>& pieces, size_t index, bool otherLevel) {
  int best = -1;
  double bestLength = 0.0;
  for (size_t j = 0; j < pieces.size(); ++j) {
    if (j == index || (otherLevel && pieces[j].level == pieces[index].level)) continue;
    const double length = io::sharedBorderLength(pieces[index].polygon, pieces[j].polygon);
    if (length > bestLength) best = static_cast<int>(j), bestLength = length;
  }
  return best;
}

// Piece `from` joins piece `into` (whose level the union keeps).
void joinPieces(std::vector<Piece>& pieces, size_t from, size_t into) {
  const int level = pieces[into].level;
  const PolygonSet joined = io::unionOf({pieces[into].polygon}, {pieces[from].polygon});
  pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(std::max(from, into)));
  pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(std::min(from, into)));
  for (const auto& polygon : joined) pieces.push_back({polygon, level});
}

// Slivers join the piece they share most border with, the smallest first; then pieces of one
// level that touch along a border become one.
void absorbSlivers(std::vector<Piece>& pieces, double minArea, double minWidth) {
  for (size_t guard = 0; guard < 4 * pieces.size() + 8; ++guard) {
    int smallest = -1, into = -1;
    for (size_t i = 0; i < pieces.size(); ++i) {
      if (!isSliver(pieces[i].polygon, minArea, minWidth)) continue;
      if (smallest >= 0 && core::area(pieces[i].polygon) >= core::area(pieces[static_cast<size_t>(smallest)].polygon)) continue;
      const int neighbour = neighbourOf(pieces, i, false);
      if (neighbour >= 0) smallest = static_cast<int>(i), into = neighbour;
    }
    if (smallest < 0) break;
    joinPieces(pieces, static_cast<size_t>(smallest), static_cast<size_t>(into));
  }
  for (size_t i = 0; i < pieces.size(); ++i) {
    for (size_t j = i + 1; j < pieces.size(); ++j) {
      if (pieces[i].level != pieces[j].level || io::sharedBorderLength(pieces[i].polygon, pieces[j].polygon) <= 0.0) continue;
      joinPieces(pieces, j, i);
      i = static_cast<size_t>(-1);  // the list changed: start again
      break;
    }
  }
}

// The median of the finite heights (crop) whose pixel centre lies inside `polygon` (crop pixels).
double medianHeightInside(const cv::Mat& heights, const core::Polygon& polygon) {
  const cv::Mat inside = core::rasterize(polygon, heights.size());
  std::vector<float> values;
  for (int y = 0; y < heights.rows; ++y) {
    for (int x = 0; x < heights.cols; ++x) {
      const float h = heights.at<float>(y, x);
      if (inside.at<uchar>(y, x) != 0 && std::isfinite(h)) values.push_back(h);
    }
  }
  if (values.empty()) return std::nan("");
  auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The pieces of the regions on the crop (crop pixels), before their heights.
std::vector<Piece> piecesOfRegions(const segmentation::RoofLevelRegions& regions, const core::Polygon& outline,
                                   const delineation::RegularizationParams& squaring) {
  const double orientation = delineation::dominantOrientation(outline, {}, 0.0);
  std::vector<PolygonSet> shapes;
  for (size_t r = 0; r < regions.regionLevel.size(); ++r) {
    shapes.push_back(squared(tracedPolygons(regions.labels == static_cast<int>(r)), squaring, orientation));
  }
  return tiledPieces(outline, regions, shapes);
}

}  // namespace

std::vector<RoofPart> partitionRoof(const cv::Mat& heights, const core::Polygon& outline, double gsd,
                                    const segmentation::RoofLevelParams& params,
                                    const delineation::RegularizationParams& squaring) {
  params.validate();
  const std::vector<RoofPart> whole{{outline, std::nan("")}};
  if (!params.on() || heights.empty() || outline.outer.size() < 3) return whole;
  const cv::Rect crop = cropAround(outline, heights.size(), static_cast<int>(std::ceil(squaring.tolerance)) + 3);
  if (crop.area() == 0) return whole;
  const core::Polygon local = shifted(outline, -cv::Point2d(crop.tl()));
  const cv::Mat cropHeights = heights(crop);
  const segmentation::RoofLevelRegions regions =
      segmentation::roofLevelRegions(cropHeights, core::rasterize(local, crop.size()), gsd, params);
  if (regions.regionLevel.size() < 2) return {{outline, medianHeightInside(cropHeights, local)}};
  std::vector<Piece> pieces = piecesOfRegions(regions, local, squaring);
  absorbSlivers(pieces, params.minArea / (gsd * gsd), 0.5 * params.cleanWidth / gsd);
  if (pieces.size() < 2) return {{outline, medianHeightInside(cropHeights, local)}};
  std::vector<RoofPart> parts;
  for (const Piece& piece : pieces) {
    const double median = medianHeightInside(cropHeights, piece.polygon);
    parts.push_back({shifted(piece.polygon, cv::Point2d(crop.tl())),
                     std::isfinite(median) ? median : regions.levels[static_cast<size_t>(piece.level)]});
  }
  return parts;
}

std::vector<RoofPart> roofParts(const Project& project, const cv::Mat& heights, const core::Polygon& outline) {
  const auto params = parameters<segmentation::RoofLevelParams>(project, kRoofLevelsGroup);
  const auto delineation = parameters<delineation::DelineationParams>(project, "delineation");
  if (!(project.height.gsd > 0.0)) return {{outline, std::nan("")}};
  return partitionRoof(heights, outline, project.height.gsd, params, delineation.regularization);
}

}  // namespace delineo::project
