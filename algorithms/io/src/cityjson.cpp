#include "delineo/io/cityjson.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>
#include <ogr_srs_api.h>

#include "delineo/core/error.hpp"
#include "delineo/io/output_file.hpp"
#include "gdal_support.hpp"

namespace delineo::io {

using core::Error;
using core::ErrorCode;
using Json = nlohmann::ordered_json;

namespace {

constexpr double kMetreScale = 0.001;   // transform unit of x, y in metres and of z: 1 mm
constexpr double kDegreeScale = 1e-8;   // transform unit of x, y in degrees: about 1 mm
constexpr double kMaxRoofHeight = 1e4;  // m; a larger "roof height" is not one
constexpr double kMaxZOffset = 1e4;     // m; a larger elevation of the ground level is not one
constexpr double kMaxTerrainPoints = 1e7;  // grid points of the terrain; more is a mistaken step

using GridPoint = std::array<long long, 3>;  // a vertex in transform units
using GridRing = std::vector<std::array<long long, 2>>;

// What the output's x, y are, and how a left-image pixel gets there.
struct OutputFrame {
  GeoReference geo;
  double pixelSize = 1.0;
  cv::Point2d fromPixel(const cv::Point2d& pixel) const {
    if (geo.valid()) return geo.pixelToMap(pixel);
    return {pixel.x * pixelSize, -pixel.y * pixelSize};  // y up: the model is not mirrored
  }
};

struct CrsDescription {
  std::string referenceSystem;  // OGC URL of the EPSG code, empty when there is none
  bool geographic = false;      // x, y in degrees
};

CrsDescription describeCrs(const std::string& wkt) {
  CrsDescription crs;
  if (wkt.empty()) return crs;
  detail::ScopedGdalErrors quiet;
  const detail::SpatialReferencePtr srs(OSRNewSpatialReference(nullptr));
  if (OSRSetFromUserInput(srs.get(), wkt.c_str()) != OGRERR_NONE) return crs;
  crs.geographic = OSRIsGeographic(srs.get()) != 0;
  if (OSRGetAuthorityCode(srs.get(), nullptr) == nullptr) OSRAutoIdentifyEPSG(srs.get());
  const char* authority = OSRGetAuthorityName(srs.get(), nullptr);
  const char* code = OSRGetAuthorityCode(srs.get(), nullptr);
  if (authority != nullptr && code != nullptr && std::string(authority) == "EPSG") {
    crs.referenceSystem = std::string("https://www.opengis.net/def/crs/EPSG/0/") + code;
  }
  return crs;
}

using Rings = std::vector<std::vector<cv::Point2d>>;  // outline first, then the holes, in the output frame

// A part of a building's roof, in the output frame.
struct PartBlock {
  std::string name;  // "building 7 part 2", for messages
  std::string key;   // its City Object id
  Rings rings;
  double height = 0.0;  // m, its roof above the ground level
};

// One building to extrude, in the output frame.
struct Block {
  const core::Feature* feature = nullptr;
  std::string name;                       // "building 7", for messages
  std::string key;                        // its City Object id
  Rings rings;                            // outline first, then the holes
  double height = 0.0;                    // m, the roof above the ground level
  std::vector<PartBlock> parts;           // two or more: written as BuildingParts
  double base = 0.0;                      // m, its ground above the ground level
  double foot = 0.0;                      // m, the solid's bottom: the base, or lower to meet the terrain
  bool hasBase = false;                   // the base came from the feature (else 0)
};

std::string formatNumber(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

std::string buildingNumber(const core::Feature& feature, size_t index) {
  const auto it = feature.attributes.find("id");
  if (it != feature.attributes.end()) {
    if (const auto* id = std::get_if<long long>(&it->second)) return std::to_string(*id);
    if (const auto* text = std::get_if<std::string>(&it->second)) return *text;
  }
  return std::to_string(index + 1);
}

// A height attribute of the feature (m); nullopt when absent or NaN (the project's "unknown").
std::optional<double> heightOf(const core::Feature& feature, const std::string& attribute, const std::string& name) {
  const auto stored = feature.attributes.find(attribute);
  const bool unknown = stored != feature.attributes.end() && std::holds_alternative<double>(stored->second) &&
                       std::isnan(std::get<double>(stored->second));
  if (unknown) return std::nullopt;
  try {
    return core::numberProperty(feature, attribute, kMaxRoofHeight);
  } catch (const Error& e) {
    throw Error(ErrorCode::InvalidParameter, name + ": " + e.detail());
  }
}

Rings ringsInFrame(const core::Polygon& polygon, const OutputFrame& frame) {
  auto toFrame = [&](const core::Ring& ring) {
    std::vector<cv::Point2d> out;
    for (const auto& p : ring) out.push_back(frame.fromPixel(p));
    return out;
  };
  Rings rings{toFrame(polygon.outer)};
  for (const auto& hole : polygon.holes) rings.push_back(toFrame(hole));
  return rings;
}

// The parts of a building whose roof is above its base; the others listed in `leftOut`.
std::vector<PartBlock> partBlocksOf(const Block& block, const std::vector<CityJsonPart>& parts, const OutputFrame& frame,
                                    std::vector<std::string>& leftOut) {
  std::vector<PartBlock> out;
  for (size_t i = 0; i < parts.size(); ++i) {
    PartBlock part;
    part.name = block.name + " part " + std::to_string(i + 1);
    part.key = block.key + "-part-" + std::to_string(i + 1);
    if (!(std::abs(parts[i].height) <= kMaxRoofHeight)) {
      throw Error(ErrorCode::InvalidParameter, part.name + ": its roof height is not a number within +-1e4 m");
    }
    if (!(std::llround(parts[i].height / kMetreScale) > std::llround(block.base / kMetreScale))) {
      leftOut.push_back(part.name + ": roof height " + formatNumber(parts[i].height) + " m is not above its building's base");
      continue;
    }
    part.height = parts[i].height;
    part.rings = ringsInFrame(parts[i].polygon, frame);
    out.push_back(std::move(part));
  }
  return out;
}

// The block of a feature, or the reason it is left out.
std::optional<Block> blockOf(const core::Feature& feature, size_t index, const OutputFrame& frame,
                             const CityJsonOptions& options, std::string& leftOutBecause) {
  Block block;
  block.feature = &feature;
  block.name = "building " + buildingNumber(feature, index);
  block.key = "building-" + buildingNumber(feature, index);
  const std::optional<double> height = heightOf(feature, options.heightAttribute, block.name);
  const std::optional<double> base = heightOf(feature, options.baseAttribute, block.name);
  if (!height) {
    leftOutBecause = block.name + ": no roof height";
    return std::nullopt;
  }
  block.hasBase = base.has_value();
  block.base = base.value_or(0.0);
  block.foot = block.base;
  if (!(std::llround(*height / kMetreScale) > std::llround(block.base / kMetreScale))) {
    leftOutBecause = block.name + ": roof height " + formatNumber(*height) + " m is not above " +
                     (base ? "its ground height " + formatNumber(*base) + " m" : std::string("the ground"));
    return std::nullopt;
  }
  block.height = *height;
  block.rings = ringsInFrame(feature.polygon, frame);
  return block;
}

double signedArea(const GridRing& ring) {
  double twice = 0.0;
  for (size_t i = 0; i < ring.size(); ++i) {
    const auto& a = ring[i];
    const auto& b = ring[(i + 1) % ring.size()];
    twice += static_cast<double>(a[0]) * static_cast<double>(b[1]) - static_cast<double>(b[0]) * static_cast<double>(a[1]);
  }
  return 0.5 * twice;
}

// The transform's origin and units.
struct Grid {
  std::array<double, 3> scale{kMetreScale, kMetreScale, kMetreScale};
  std::array<double, 3> translate{0.0, 0.0, 0.0};
  long long unitsOf(double value, int axis) const { return std::llround((value - translate[axis]) / scale[axis]); }
};

// A ring on the grid: consecutive repeats dropped, counter-clockwise (seen from above) when
// `counterClockwise`, clockwise otherwise. Throws for a degenerate ring.
GridRing gridRing(const std::vector<cv::Point2d>& ring, const Grid& grid, bool counterClockwise,
                  const std::string& what) {
  GridRing out;
  for (const auto& p : ring) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      throw Error(ErrorCode::InvalidParameter, what + " has a vertex that is not a finite number");
    }
    const std::array<long long, 2> q{grid.unitsOf(p.x, 0), grid.unitsOf(p.y, 1)};
    if (out.empty() || out.back() != q) out.push_back(q);
  }
  while (out.size() > 1 && out.front() == out.back()) out.pop_back();
  const double area = out.size() >= 3 ? signedArea(out) : 0.0;
  if (area == 0.0) {
    throw Error(ErrorCode::InvalidParameter,
                what + " is degenerate (fewer than 3 distinct vertices at the file's precision, or zero area)");
  }
  if ((area > 0.0) != counterClockwise) std::reverse(out.begin(), out.end());
  return out;
}

// The file's vertices, each written once.
class VertexPool {
 public:
  int indexOf(const GridPoint& point) {
    const auto [it, added] = index_.emplace(point, static_cast<int>(vertices_.size()));
    if (added) vertices_.push_back(point);
    return it->second;
  }
  const std::vector<GridPoint>& vertices() const { return vertices_; }

 private:
  std::map<GridPoint, int> index_;
  std::vector<GridPoint> vertices_;
};

// The z of a block's foot and top in transform units, the ground level's elevation added.
struct BlockLevels {
  long long bottom = 0, top = 0;
};

// One surface of the solid: `rings` at height `z` (transform units), in their order or reversed.
Json horizontalSurface(const std::vector<GridRing>& rings, long long z, bool reversed, VertexPool& pool) {
  Json surface = Json::array();
  for (const auto& ring : rings) {
    Json indices = Json::array();
    for (size_t i = 0; i < ring.size(); ++i) {
      const auto& p = reversed ? ring[ring.size() - 1 - i] : ring[i];
      indices.push_back(pool.indexOf({p[0], p[1], z}));
    }
    surface.push_back(std::move(indices));
  }
  return surface;
}

// The solid's one shell. The outline is counter-clockwise and the holes clockwise seen from
// above, so the material is on the left of every edge: the roof (as is) faces up, the ground
// (reversed) faces down, and the wall a0 b0 b1 a1 under edge a → b faces to the edge's right,
// out of the material.
Json shellOf(const std::vector<GridRing>& rings, BlockLevels z, VertexPool& pool, Json& semanticValues) {
  const long long bottom = z.bottom, top = z.top;
  Json shell = Json::array();
  shell.push_back(horizontalSurface(rings, bottom, true, pool));
  semanticValues.push_back(0);
  shell.push_back(horizontalSurface(rings, top, false, pool));
  semanticValues.push_back(1);
  for (const auto& ring : rings) {
    for (size_t i = 0; i < ring.size(); ++i) {
      const auto& a = ring[i];
      const auto& b = ring[(i + 1) % ring.size()];
      Json corners = Json::array();
      for (const GridPoint& corner : {GridPoint{a[0], a[1], bottom}, GridPoint{b[0], b[1], bottom}, GridPoint{b[0], b[1], top},
                                      GridPoint{a[0], a[1], top}}) {
        corners.push_back(pool.indexOf(corner));
      }
      Json wall = Json::array();
      wall.push_back(std::move(corners));
      shell.push_back(std::move(wall));
      semanticValues.push_back(2);
    }
  }
  return shell;
}

// The LoD1 solid of `frameRings` (outline first) from `foot` to `height` (m); `name` for messages.
Json solidOf(const Rings& frameRings, const std::string& name, double foot, double height, const Grid& grid,
             double zOffset, VertexPool& pool) {
  std::vector<GridRing> rings;
  for (size_t r = 0; r < frameRings.size(); ++r) {
    const std::string what = name + (r == 0 ? "'s outline" : "'s hole " + std::to_string(r));
    rings.push_back(gridRing(frameRings[r], grid, r == 0, what));
  }
  Json values = Json::array();
  const BlockLevels levels{grid.unitsOf(foot + zOffset, 2), grid.unitsOf(height + zOffset, 2)};
  Json shell = shellOf(rings, levels, pool, values);
  Json surfaces = Json::array();
  for (const char* type : {"GroundSurface", "RoofSurface", "WallSurface"}) surfaces.push_back({{"type", type}});
  Json solid;
  solid["type"] = "Solid";
  solid["lod"] = "1";
  solid["boundaries"] = Json::array();
  solid["boundaries"].push_back(std::move(shell));
  solid["semantics"]["surfaces"] = std::move(surfaces);
  solid["semantics"]["values"] = Json::array();
  solid["semantics"]["values"].push_back(std::move(values));
  return solid;
}

Json attributesOf(const Block& block) {
  Json attributes = Json::object();
  for (const auto& [name, value] : block.feature->attributes) {
    if (const auto* integer = std::get_if<long long>(&value)) {
      attributes[name] = *integer;
    } else if (const auto* real = std::get_if<double>(&value)) {
      attributes[name] = std::isfinite(*real) ? Json(*real) : Json(nullptr);
    } else if (const auto* text = std::get_if<std::string>(&value)) {
      attributes[name] = *text;
    } else {
      attributes[name] = nullptr;
    }
  }
  attributes["measuredHeight"] = block.height - block.base;  // CityGML's name: ground to the highest point
  return attributes;
}

// The terrain's grid points: rows and columns 0, step, 2 step, ... of the DTM, at pixel centres.
struct TerrainGrid {
  const CityJsonTerrain& terrain;
  int rows() const { return terrain.heights.empty() ? 0 : (terrain.heights.rows - 1) / terrain.step + 1; }
  int cols() const { return terrain.heights.empty() ? 0 : (terrain.heights.cols - 1) / terrain.step + 1; }
  cv::Point2d pixel(int col, int row) const { return {col * terrain.step + 0.5, row * terrain.step + 0.5}; }
  float height(int col, int row) const { return terrain.heights.at<float>(row * terrain.step, col * terrain.step); }
  // The grid's four corners in left-image pixels (for the extent of a rotated frame).
  std::array<cv::Point2d, 4> corners() const {
    return {pixel(0, 0), pixel(cols() - 1, 0), pixel(0, rows() - 1), pixel(cols() - 1, rows() - 1)};
  }
  // The TIN's height at a left-image pixel position (clamped into the grid), interpolated in the
  // cell's triangle as terrainTriangles() splits it; none when a corner of the cell has no height.
  std::optional<double> surfaceAt(cv::Point2d p) const {
    if (rows() < 2 || cols() < 2) return std::nullopt;
    const double u = std::clamp((p.x - 0.5) / terrain.step, 0.0, cols() - 1.0);
    const double v = std::clamp((p.y - 0.5) / terrain.step, 0.0, rows() - 1.0);
    const int col = std::min(static_cast<int>(u), cols() - 2), row = std::min(static_cast<int>(v), rows() - 2);
    const double du = u - col, dv = v - row;
    const double z00 = height(col, row), z10 = height(col + 1, row), z11 = height(col + 1, row + 1),
                 z01 = height(col, row + 1);
    if (!std::isfinite(z00) || !std::isfinite(z10) || !std::isfinite(z11) || !std::isfinite(z01)) return std::nullopt;
    return du >= dv ? z00 + du * (z10 - z00) + dv * (z11 - z10) : z00 + dv * (z01 - z00) + du * (z11 - z01);
  }
};

// The terrain's lowest height along the rings of `polygon` (left-image pixels), sampled at least
// every pixel; none when no sample has a height.
std::optional<double> lowestTerrainAlong(const TerrainGrid& terrain, const core::Polygon& polygon) {
  std::optional<double> lowest;
  auto visit = [&](const core::Ring& ring) {
    for (size_t i = 0; i < ring.size(); ++i) {
      const cv::Point2d a = ring[i], b = ring[(i + 1) % ring.size()];
      const int samples = std::max(1, static_cast<int>(std::ceil(cv::norm(b - a))));
      for (int k = 0; k < samples; ++k) {
        const std::optional<double> z = terrain.surfaceAt(a + (b - a) * (static_cast<double>(k) / samples));
        if (z && (!lowest || *z < *lowest)) lowest = z;
      }
    }
  };
  visit(polygon.outer);
  for (const auto& hole : polygon.holes) visit(hole);
  return lowest;
}

// With a terrain, each block's solid reaches down to the terrain's lowest point along its
// outline when that is below its base, so that no wall floats above the terrain.
void reachDownToTerrain(std::vector<Block>& blocks, const TerrainGrid& terrain) {
  for (Block& block : blocks) {
    const std::optional<double> lowest = lowestTerrainAlong(terrain, block.feature->polygon);
    if (lowest) block.foot = std::min(block.base, *lowest);
  }
}

void checkTerrain(const CityJsonTerrain& terrain) {
  if (terrain.heights.empty()) return;
  if (terrain.heights.type() != CV_32FC1) throw Error(ErrorCode::InvalidParameter, "the terrain's heights must be one float32 band");
  if (terrain.step < 1) throw Error(ErrorCode::InvalidParameter, "the terrain step must be at least 1 px");
  const TerrainGrid grid{terrain};
  const double points = static_cast<double>(grid.rows()) * static_cast<double>(grid.cols());
  if (points > kMaxTerrainPoints) {
    throw Error(ErrorCode::InvalidParameter, "a terrain step of " + std::to_string(terrain.step) + " px gives " +
                                                 formatNumber(points) + " grid points (at most 1e7): take a larger step");
  }
}

// The transform's origin: the lower corner of the blocks and the terrain, on whole units of the frame.
Grid gridFor(const std::vector<Block>& blocks, const TerrainGrid& terrain, const OutputFrame& frame, bool geographic) {
  Grid grid;
  if (geographic) grid.scale[0] = grid.scale[1] = kDegreeScale;
  double minX = INFINITY, minY = INFINITY;
  std::vector<cv::Point2d> points;
  for (const auto& block : blocks) points.insert(points.end(), block.rings.front().begin(), block.rings.front().end());
  if (terrain.rows() > 0) {
    for (const auto& corner : terrain.corners()) points.push_back(frame.fromPixel(corner));
  }
  for (const auto& p : points) {
    if (std::isfinite(p.x)) minX = std::min(minX, p.x);
    if (std::isfinite(p.y)) minY = std::min(minY, p.y);
  }
  if (std::isfinite(minX)) grid.translate[0] = std::floor(minX);
  if (std::isfinite(minY)) grid.translate[1] = std::floor(minY);
  return grid;
}

// What the file holds and what its z are.
struct ContentDescription {
  bool bases = false;   // some block stands on its own ground height
  double zOffset = 0.0;
  int terrainStep = 0;  // px, 0 without terrain
};

std::string titleFor(const OutputFrame& frame, const CrsDescription& crs, const ContentDescription& content) {
  std::string title = "Buildings as LoD1 blocks (Delineo)";
  title += content.bases ? ", each from the ground next to it to its roof"
                         : ", each from the ground level to its roof (no ground heights: bases at the ground level)";
  title += "; z in metres above the height model's ground level";
  if (content.zOffset != 0.0) title += " + " + formatNumber(content.zOffset) + " m, the ground level's elevation";
  if (content.terrainStep > 0) {
    title += "; terrain: TIN of the DTM, one vertex every " + std::to_string(content.terrainStep) +
             " px; a block's walls reach down to the terrain where it is lower than the block's ground";
  }
  if (!frame.geo.valid()) {
    const std::string size = formatNumber(frame.pixelSize);
    return title + "; local frame in metres, not georeferenced: x = column × " + size + ", y = −row × " + size +
           " of the left image";
  }
  if (crs.referenceSystem.empty()) return title + "; x, y in the left image's map coordinates (CRS without an EPSG code)";
  return title;
}

Json metadataFor(const OutputFrame& frame, const CrsDescription& crs, const ContentDescription& content,
                 const Grid& grid, const VertexPool& pool) {
  Json metadata;
  metadata["title"] = titleFor(frame, crs, content);
  if (!crs.referenceSystem.empty()) metadata["referenceSystem"] = crs.referenceSystem;
  if (pool.vertices().empty()) return metadata;
  GridPoint low = pool.vertices().front(), high = low;
  for (const auto& v : pool.vertices()) {
    for (int axis = 0; axis < 3; ++axis) {
      low[axis] = std::min(low[axis], v[axis]);
      high[axis] = std::max(high[axis], v[axis]);
    }
  }
  Json extent = Json::array();
  for (const auto* corner : {&low, &high}) {
    for (int axis = 0; axis < 3; ++axis) {
      extent.push_back(grid.translate[axis] + grid.scale[axis] * static_cast<double>((*corner)[axis]));
    }
  }
  metadata["geographicalExtent"] = extent;
  return metadata;
}

Json cityObjectOf(const Block& block, const Grid& grid, double zOffset, VertexPool& pool) {
  Json object;
  object["type"] = "Building";
  object["attributes"] = attributesOf(block);
  if (!block.parts.empty()) {
    object["children"] = Json::array();
    for (const auto& part : block.parts) object["children"].push_back(part.key);
    return object;
  }
  object["geometry"] = Json::array();
  object["geometry"].push_back(solidOf(block.rings, block.name, block.foot, block.height, grid, zOffset, pool));
  return object;
}

// A BuildingPart of `block`: its solid from the building's foot, its roof height and measuredHeight.
Json partObjectOf(const Block& block, const PartBlock& part, const Grid& grid, double zOffset, VertexPool& pool) {
  Json object;
  object["type"] = "BuildingPart";
  object["attributes"] = {{"roof_height_m", part.height}, {"measuredHeight", part.height - block.base}};
  object["parents"] = Json::array({block.key});
  object["geometry"] = Json::array();
  object["geometry"].push_back(solidOf(part.rings, part.name, block.foot, part.height, grid, zOffset, pool));
  return object;
}

// The grid point's vertex; nullopt where the DTM has no height.
std::optional<GridPoint> terrainVertex(const TerrainGrid& terrain, int col, int row, const OutputFrame& frame,
                                       const Grid& grid, double zOffset) {
  const float height = terrain.height(col, row);
  if (!std::isfinite(height)) return std::nullopt;
  const cv::Point2d p = frame.fromPixel(terrain.pixel(col, row));
  return GridPoint{grid.unitsOf(p.x, 0), grid.unitsOf(p.y, 1), grid.unitsOf(height + zOffset, 2)};
}

// Twice the area of triangle a b c seen from above: positive when counter-clockwise (facing up).
double twiceAreaFromAbove(const GridPoint& a, const GridPoint& b, const GridPoint& c) {
  return static_cast<double>(b[0] - a[0]) * static_cast<double>(c[1] - a[1]) -
         static_cast<double>(c[0] - a[0]) * static_cast<double>(b[1] - a[1]);
}

// The terrain's triangles, each facing up: two per grid cell whose four corners have a height.
Json terrainTriangles(const TerrainGrid& terrain, const OutputFrame& frame, const Grid& grid, double zOffset,
                      VertexPool& pool, CityJsonSummary& summary) {
  const int cols = terrain.cols(), rows = terrain.rows();
  std::vector<std::optional<GridPoint>> vertices;
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) vertices.push_back(terrainVertex(terrain, col, row, frame, grid, zOffset));
  }
  std::vector<bool> used(vertices.size(), false);
  Json surfaces = Json::array();
  for (int row = 0; row + 1 < rows; ++row) {
    for (int col = 0; col + 1 < cols; ++col) {
      const std::array<size_t, 4> cell{static_cast<size_t>(row * cols + col), static_cast<size_t>(row * cols + col + 1),
                                       static_cast<size_t>((row + 1) * cols + col + 1), static_cast<size_t>((row + 1) * cols + col)};
      if (!std::all_of(cell.begin(), cell.end(), [&](size_t i) { return vertices[i].has_value(); })) continue;
      for (const std::array<size_t, 3>& t : {std::array<size_t, 3>{cell[0], cell[1], cell[2]}, std::array<size_t, 3>{cell[0], cell[2], cell[3]}}) {
        const double area = twiceAreaFromAbove(*vertices[t[0]], *vertices[t[1]], *vertices[t[2]]);
        if (area == 0.0) continue;
        const std::array<size_t, 3> up = area > 0.0 ? t : std::array<size_t, 3>{t[0], t[2], t[1]};
        Json ring = Json::array();
        for (size_t i : up) {
          ring.push_back(pool.indexOf(*vertices[i]));
          used[i] = true;
        }
        Json triangle = Json::array();
        triangle.push_back(std::move(ring));
        surfaces.push_back(std::move(triangle));
      }
    }
  }
  summary.terrainTriangles = static_cast<int>(surfaces.size());
  summary.terrainVertices = static_cast<int>(std::count(used.begin(), used.end(), true));
  return surfaces;
}

Json terrainObjectOf(Json triangles, int step) {
  Json surface;
  surface["type"] = "CompositeSurface";
  surface["lod"] = "1";
  surface["boundaries"] = std::move(triangles);
  Json object;
  object["type"] = "TINRelief";
  object["attributes"] = {{"grid_step_px", step}};
  object["geometry"] = Json::array();
  object["geometry"].push_back(std::move(surface));
  return object;
}

}  // namespace

bool isCityJsonPath(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  auto endsWith = [&](const std::string& suffix) {
    return name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return endsWith(".city.json") || endsWith(".cityjson");
}

namespace {
// The checks of the options that do not depend on the buildings; a problem names `path`.
void checkOptions(const CityJsonOptions& options, const OutputFrame& frame, const std::string& path) {
  if (!frame.geo.valid() && !(std::isfinite(frame.pixelSize) && frame.pixelSize > 0.0)) {
    throw Error(ErrorCode::InvalidParameter, "the local frame's pixel size must be a positive number of metres", path);
  }
  if (!(std::abs(options.zOffset) <= kMaxZOffset)) {
    throw Error(ErrorCode::InvalidParameter, "the ground level's elevation must be a number within +-1e4 m", path);
  }
  try {
    checkTerrain(options.terrain);
  } catch (const Error& e) {
    throw Error(e.code(), e.detail(), path);
  }
}

// The blocks of the buildings, in their order; those left out listed in the summary.
std::vector<Block> blocksOf(const std::vector<CityJsonBuilding>& buildings, const OutputFrame& frame,
                            const CityJsonOptions& options, CityJsonSummary& summary) {
  std::vector<Block> blocks;
  for (size_t i = 0; i < buildings.size(); ++i) {
    std::string leftOutBecause;
    if (auto block = blockOf(buildings[i].feature, i, frame, options, leftOutBecause)) {
      std::vector<std::string> partsLeftOut;
      std::vector<PartBlock> parts = partBlocksOf(*block, buildings[i].parts, frame, partsLeftOut);
      if (parts.size() >= 2) {  // else one block, as without parts
        block->parts = std::move(parts);
        summary.leftOut.insert(summary.leftOut.end(), partsLeftOut.begin(), partsLeftOut.end());
      }
      blocks.push_back(std::move(*block));
    } else {
      summary.leftOut.push_back(leftOutBecause);
    }
  }
  return blocks;
}
}  // namespace

CityJsonSummary writeCityJson(const std::string& path, const std::vector<core::Feature>& buildings,
                              const CityJsonOptions& options) {
  std::vector<CityJsonBuilding> blocks;
  for (const auto& feature : buildings) blocks.push_back({feature, {}});
  return writeCityJson(path, blocks, options);
}

CityJsonSummary writeCityJson(const std::string& path, const std::vector<CityJsonBuilding>& buildings,
                              const CityJsonOptions& options) {
  const OutputFrame frame{options.geo, options.localPixelSize};
  checkOptions(options, frame, path);
  const CrsDescription crs = frame.geo.valid() ? describeCrs(frame.geo.crsWkt) : CrsDescription{};
  CityJsonSummary summary;
  // The problems of a building are the file's: its path goes into the error.
  auto naming = [&](const Error& e) { return Error(e.code(), e.detail(), path); };
  std::vector<Block> blocks;
  try {
    blocks = blocksOf(buildings, frame, options, summary);
  } catch (const Error& e) {
    throw naming(e);
  }
  const TerrainGrid terrain{options.terrain};
  reachDownToTerrain(blocks, terrain);
  const Grid grid = gridFor(blocks, terrain, frame, crs.geographic);
  VertexPool pool;
  Json cityObjects = Json::object();
  for (const auto& block : blocks) {
    if (cityObjects.contains(block.key)) {
      throw Error(ErrorCode::InvalidParameter, "two buildings have the id of " + block.name, path);
    }
    try {
      cityObjects[block.key] = cityObjectOf(block, grid, options.zOffset, pool);
      for (const auto& part : block.parts) {
        cityObjects[part.key] = partObjectOf(block, part, grid, options.zOffset, pool);
        ++summary.parts;
      }
    } catch (const Error& e) {
      throw naming(e);
    }
  }
  ContentDescription content;
  content.bases = std::any_of(blocks.begin(), blocks.end(), [](const Block& b) { return b.hasBase; });
  content.zOffset = options.zOffset;
  if (terrain.rows() > 0) {
    Json triangles = terrainTriangles(terrain, frame, grid, options.zOffset, pool, summary);
    if (!triangles.empty()) {
      cityObjects["terrain"] = terrainObjectOf(std::move(triangles), options.terrain.step);
      content.terrainStep = options.terrain.step;
    }
  }
  Json document;
  document["type"] = "CityJSON";
  document["version"] = "1.1";
  document["transform"] = {{"scale", grid.scale}, {"translate", grid.translate}};
  document["metadata"] = metadataFor(frame, crs, content, grid, pool);
  document["CityObjects"] = std::move(cityObjects);
  document["vertices"] = pool.vertices();
  writeTextFile(path, document.dump() + "\n");
  summary.written = static_cast<int>(blocks.size());
  return summary;
}

}  // namespace delineo::io
