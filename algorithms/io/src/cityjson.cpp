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

// One building to extrude, in the output frame.
struct Block {
  const core::Feature* feature = nullptr;
  std::string name;                       // "building 7", for messages
  std::string key;                        // its City Object id
  std::vector<std::vector<cv::Point2d>> rings;  // outline first, then the holes
  double height = 0.0;                    // m above the ground
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

// The block of a feature, or the reason it is left out.
std::optional<Block> blockOf(const core::Feature& feature, size_t index, const OutputFrame& frame,
                             const std::string& heightAttribute, std::string& leftOutBecause) {
  Block block;
  block.feature = &feature;
  block.name = "building " + buildingNumber(feature, index);
  block.key = "building-" + buildingNumber(feature, index);
  std::optional<double> height;
  const auto stored = feature.attributes.find(heightAttribute);
  const bool unknown = stored != feature.attributes.end() && std::holds_alternative<double>(stored->second) &&
                       std::isnan(std::get<double>(stored->second));  // NaN: the project's "unknown"
  try {
    if (!unknown) height = core::numberProperty(feature, heightAttribute, kMaxRoofHeight);
  } catch (const Error& e) {
    throw Error(ErrorCode::InvalidParameter, block.name + ": " + e.detail());
  }
  if (!height) {
    leftOutBecause = block.name + ": no roof height";
    return std::nullopt;
  }
  if (!(std::llround(*height / kMetreScale) > 0)) {
    leftOutBecause = block.name + ": roof height " + formatNumber(*height) + " m is not above the ground";
    return std::nullopt;
  }
  block.height = *height;
  auto toFrame = [&](const core::Ring& ring) {
    std::vector<cv::Point2d> out;
    for (const auto& p : ring) out.push_back(frame.fromPixel(p));
    return out;
  };
  block.rings.push_back(toFrame(feature.polygon.outer));
  for (const auto& hole : feature.polygon.holes) block.rings.push_back(toFrame(hole));
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
Json shellOf(const std::vector<GridRing>& rings, long long top, VertexPool& pool, Json& semanticValues) {
  Json shell = Json::array();
  shell.push_back(horizontalSurface(rings, 0, true, pool));
  semanticValues.push_back(0);
  shell.push_back(horizontalSurface(rings, top, false, pool));
  semanticValues.push_back(1);
  for (const auto& ring : rings) {
    for (size_t i = 0; i < ring.size(); ++i) {
      const auto& a = ring[i];
      const auto& b = ring[(i + 1) % ring.size()];
      Json corners = Json::array();
      for (const GridPoint& corner : {GridPoint{a[0], a[1], 0}, GridPoint{b[0], b[1], 0}, GridPoint{b[0], b[1], top},
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

Json solidOf(const Block& block, const Grid& grid, VertexPool& pool) {
  std::vector<GridRing> rings;
  for (size_t r = 0; r < block.rings.size(); ++r) {
    const std::string what = block.name + (r == 0 ? "'s outline" : "'s hole " + std::to_string(r));
    rings.push_back(gridRing(block.rings[r], grid, r == 0, what));
  }
  Json values = Json::array();
  Json shell = shellOf(rings, grid.unitsOf(block.height, 2), pool, values);
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
  attributes["measuredHeight"] = block.height;  // CityGML's name: ground to the highest point
  return attributes;
}

// The transform's origin: the lower corner of the blocks, on whole units of the frame.
Grid gridFor(const std::vector<Block>& blocks, bool geographic) {
  Grid grid;
  if (geographic) grid.scale[0] = grid.scale[1] = kDegreeScale;
  double minX = INFINITY, minY = INFINITY;
  for (const auto& block : blocks) {
    for (const auto& p : block.rings.front()) {
      if (std::isfinite(p.x)) minX = std::min(minX, p.x);
      if (std::isfinite(p.y)) minY = std::min(minY, p.y);
    }
  }
  if (std::isfinite(minX)) grid.translate[0] = std::floor(minX);
  if (std::isfinite(minY)) grid.translate[1] = std::floor(minY);
  return grid;
}

std::string titleFor(const OutputFrame& frame, const CrsDescription& crs) {
  std::string title = "Buildings as LoD1 blocks (Delineo): heights in metres above the ground, base at z = 0";
  if (!frame.geo.valid()) {
    const std::string size = formatNumber(frame.pixelSize);
    return title + "; local frame in metres, not georeferenced: x = column × " + size + ", y = −row × " + size +
           " of the left image";
  }
  if (crs.referenceSystem.empty()) return title + "; x, y in the left image's map coordinates (CRS without an EPSG code)";
  return title;
}

Json metadataFor(const OutputFrame& frame, const CrsDescription& crs, const Grid& grid, const VertexPool& pool) {
  Json metadata;
  metadata["title"] = titleFor(frame, crs);
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

Json cityObjectOf(const Block& block, const Grid& grid, VertexPool& pool) {
  Json object;
  object["type"] = "Building";
  object["attributes"] = attributesOf(block);
  object["geometry"] = Json::array();
  object["geometry"].push_back(solidOf(block, grid, pool));
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

CityJsonSummary writeCityJson(const std::string& path, const std::vector<core::Feature>& buildings,
                              const CityJsonOptions& options) {
  const OutputFrame frame{options.geo, options.localPixelSize};
  if (!frame.geo.valid() && !(std::isfinite(frame.pixelSize) && frame.pixelSize > 0.0)) {
    throw Error(ErrorCode::InvalidParameter, "the local frame's pixel size must be a positive number of metres", path);
  }
  const CrsDescription crs = frame.geo.valid() ? describeCrs(frame.geo.crsWkt) : CrsDescription{};
  CityJsonSummary summary;
  std::vector<Block> blocks;
  // The problems of a building are the file's: its path goes into the error.
  auto naming = [&](const Error& e) { return Error(e.code(), e.detail(), path); };
  for (size_t i = 0; i < buildings.size(); ++i) {
    std::string leftOutBecause;
    try {
      if (auto block = blockOf(buildings[i], i, frame, options.heightAttribute, leftOutBecause)) {
        blocks.push_back(std::move(*block));
      } else {
        summary.leftOut.push_back(leftOutBecause);
      }
    } catch (const Error& e) {
      throw naming(e);
    }
  }
  const Grid grid = gridFor(blocks, crs.geographic);
  VertexPool pool;
  Json cityObjects = Json::object();
  for (const auto& block : blocks) {
    if (cityObjects.contains(block.key)) {
      throw Error(ErrorCode::InvalidParameter, "two buildings have the id of " + block.name, path);
    }
    try {
      cityObjects[block.key] = cityObjectOf(block, grid, pool);
    } catch (const Error& e) {
      throw naming(e);
    }
  }
  Json document;
  document["type"] = "CityJSON";
  document["version"] = "1.1";
  document["transform"] = {{"scale", grid.scale}, {"translate", grid.translate}};
  document["metadata"] = metadataFor(frame, crs, grid, pool);
  document["CityObjects"] = std::move(cityObjects);
  document["vertices"] = pool.vertices();
  writeTextFile(path, document.dump() + "\n");
  summary.written = static_cast<int>(blocks.size());
  return summary;
}

}  // namespace delineo::io
