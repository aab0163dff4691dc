#pragma once
// Polygon I/O through OGR: GeoJSON (.geojson/.json) and GeoPackage (.gpkg), chosen by extension.
//
// Coordinates: polygons in memory are always in left-image pixel coordinates (core/geometry.hpp).
// On disk they are in pixel coordinates when no GeoReference is given (or it is invalid), and in
// the raster's CRS through its geotransform when one is given.
#include <string>
#include <vector>

#include "delineo/core/geometry.hpp"
#include "delineo/io/raster.hpp"

namespace delineo::io {

// Reads every Polygon / MultiPolygon feature (a MultiPolygon gives one Feature per part).
// Throws FileNotFound, UnreadableFile (invalid JSON / not a vector file), UnsupportedInput
// (non-polygon geometry), and InvalidParameter-free core::Error(UnreadableFile) for an empty
// or degenerate polygon (fewer than 3 distinct vertices or zero area), naming the feature.
std::vector<core::Feature> readFeatures(const std::string& path, const GeoReference& geo = {});

// Writes features with their attributes (long long → Integer64, double → Real,
// string → String). Overwrites an existing file. Throws WriteFailed.
void writeFeatures(const std::string& path, const std::vector<core::Feature>& features,
                   const GeoReference& geo = {}, const std::string& layerName = "buildings");

}  // namespace delineo::io
