#pragma once
// CityJSON 1.1 LoD1 block models of buildings (https://www.cityjson.org/specs/1.1.3/): each
// building's footprint extruded from the ground (z = 0) to its roof height, courtyards kept.
//
// One "Building" City Object per building, with one "Solid" geometry of "lod": "1": the ground
// surface, the roof surface, one wall per edge of the outline and of each hole, every surface
// oriented with its normal pointing out of the solid. Heights are metres above the ground the
// roof height was measured from; the blocks stand on z = 0 whatever the terrain.
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

struct CityJsonOptions {
  GeoReference geo;                 // pixel → map; the local frame is used when not valid
  double localPixelSize = 1.0;      // m per pixel of the local frame (the height model's gsd)
  std::string heightAttribute = "roof_height_m";  // the roof height, m above the ground
};

struct CityJsonSummary {
  int written = 0;                   // Building objects written
  std::vector<std::string> leftOut;  // one line per building left out: "building 3: no roof height"
};

// Writes `buildings` (footprints in left-image pixels, attributes copied to the City Objects)
// as a CityJSON file through a temporary file (output_file.hpp). A building without a roof
// height, or whose roof height is not above 0, is left out and listed in the summary. Throws
// core::Error(InvalidParameter) naming the building for a degenerate ring (fewer than 3 distinct
// vertices at 1 mm, zero area, or a non-finite vertex) or a roof height that is not a number,
// and WriteFailed naming the file.
CityJsonSummary writeCityJson(const std::string& path, const std::vector<core::Feature>& buildings,
                              const CityJsonOptions& options = {});

// True for the file names CityJSON is written to: "*.city.json" and "*.cityjson" (any case).
bool isCityJsonPath(const std::string& path);

}  // namespace delineo::io
