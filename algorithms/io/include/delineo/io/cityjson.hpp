#pragma once
// CityJSON 1.1 LoD1 block models of buildings (https://www.cityjson.org/specs/1.1.3/): each
// building's footprint extruded from its ground height (its base; z = 0 when it has none) to its
// roof height, courtyards kept, and optionally the terrain as a TIN.
//
// One "Building" City Object per building, with one "Solid" geometry of "lod": "1": the ground
// surface, the roof surface, one wall per edge of the outline and of each hole, every surface
// oriented with its normal pointing out of the solid. Heights are metres above the ground level
// the roof height was measured from; `zOffset` (the elevation of that level above a vertical
// datum) is added to every z, not to the attributes.
//
// A building with roof parts (several roof levels) is a "Building" without geometry whose
// "children" are its "BuildingPart"s, each naming it in its "parents": one Solid per part, from
// the building's base (and foot) to the part's roof height, attributes roof_height_m and
// measuredHeight. The parts tile the outline; their shared walls are written once per part.
//
// The terrain: one "TINRelief" City Object, a "CompositeSurface" of "lod": "1" whose surfaces are
// triangles: a regular grid of the DTM every `step` px (vertices at pixel centres), two
// triangles per cell whose four corners have a height, each facing up. With a terrain, a block
// whose outline crosses terrain lower than its base reaches down to the lowest such point, so
// that no wall floats above the terrain; its base (and measuredHeight) stay as given.
//
// x and y: the map coordinates of the GeoReference when it is valid (metadata.referenceSystem
// names its EPSG code when the CRS has one); otherwise a local frame in metres, x = column ×
// pixel size, y = −row × pixel size (y up, so the model is not mirrored), said in the metadata's
// title. Vertices are integers through "transform" (1 mm, or 1e-8 degree in a geographic CRS),
// each written once.
#include <string>
#include <vector>

#include "delineo/core/geometry.hpp"
#include "delineo/io/raster.hpp"

namespace delineo::io {

// The terrain's heights and grid.
struct CityJsonTerrain {
  cv::Mat heights;  // CV_32F, m above the ground level, on the left image's grid, NaN = none; empty: no terrain
  int step = 1;     // px between neighbouring vertices of the grid
};

struct CityJsonOptions {
  GeoReference geo;                 // pixel → map; the local frame is used when not valid
  double localPixelSize = 1.0;      // m per pixel of the local frame (the height model's gsd)
  std::string heightAttribute = "roof_height_m";  // the roof height, m above the ground level
  std::string baseAttribute = "ground_height_m";  // the block's base, m; absent: base at 0
  double zOffset = 0.0;             // m added to every z (the ground level's elevation), within ±1e4
  CityJsonTerrain terrain;
};

// A part of a building's roof: its polygon (left-image pixels) and roof height, m.
struct CityJsonPart {
  core::Polygon polygon;
  double height = 0.0;
};

// A building and its parts: none (or one) for one block.
struct CityJsonBuilding {
  core::Feature feature;
  std::vector<CityJsonPart> parts;
};

struct CityJsonSummary {
  int written = 0;                   // Building objects written
  int parts = 0;                     // BuildingPart objects written
  std::vector<std::string> leftOut;  // one line per building left out: "building 3: no roof height"
  int terrainVertices = 0;           // of the TINRelief (0 without terrain)
  int terrainTriangles = 0;
};

// Writes `buildings` (footprints in left-image pixels, attributes copied to the City Objects,
// "measuredHeight" = roof height − base) as a CityJSON file through a temporary file
// (output_file.hpp). A building without a roof height, or whose roof is not above its base, is
// left out and listed in the summary. Throws core::Error(InvalidParameter) naming the building
// for a degenerate ring (fewer than 3 distinct vertices at 1 mm, zero area, or a non-finite
// vertex) or a roof or base height that is not a number, for a terrain step below 1 or of more
// than 10⁷ grid points, and WriteFailed naming the file.
CityJsonSummary writeCityJson(const std::string& path, const std::vector<core::Feature>& buildings,
                              const CityJsonOptions& options = {});
// The same with roof parts: a building with two parts or more is written as its BuildingParts. A
// part whose roof is not above the building's base is left out (listed in the summary); a part's
// degenerate polygon or non-finite height throws like a building's.
CityJsonSummary writeCityJson(const std::string& path, const std::vector<CityJsonBuilding>& buildings,
                              const CityJsonOptions& options = {});

// True for the file names CityJSON is written to: "*.city.json" and "*.cityjson" (any case).
bool isCityJsonPath(const std::string& path);

}  // namespace delineo::io
