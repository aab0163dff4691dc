#pragma once
// Polygon I/O through OGR: GeoJSON (.geojson/.json) and GeoPackage (.gpkg), chosen by extension;
// Shapefiles (.shp) are read, not written. Other extensions are read with any OGR driver.
//
// Coordinates: polygons in memory are always in left-image pixel coordinates (core/geometry.hpp).
// On disk they are in pixel coordinates when no GeoReference is given (or it is invalid), and in
// the raster's CRS through its geotransform when one is given. Reading with a GeoReference that
// has a CRS, a layer in another CRS is first transformed into the raster's (a GeoJSON file
// without a "crs" member is WGS 84 longitude/latitude, RFC 7946); a layer without CRS, or with
// GeoPackage's "undefined" one, is taken to be in the raster's CRS, as is any layer when the
// GeoReference has no CRS.
#include <string>
#include <vector>

#include "delineo/core/geometry.hpp"
#include "delineo/io/raster.hpp"

namespace delineo::io {

// Reads every Polygon / MultiPolygon feature (a MultiPolygon gives one Feature per part).
// Throws FileNotFound, UnreadableFile (invalid JSON / not a vector file), UnsupportedInput
// (non-polygon geometry), and InvalidParameter-free core::Error(UnreadableFile) for an empty
// or degenerate polygon (fewer than 3 distinct vertices or zero area) or a vertex that cannot be
// transformed into the raster's CRS (pixel coordinates in a GeoJSON file without "crs", read
// over a georeferenced raster, are usually no valid latitude), naming the feature.
// InvalidParameter when `geo.crsWkt` is not a CRS.
std::vector<core::Feature> readFeatures(const std::string& path, const GeoReference& geo = {});

// Writes features with their attributes (long long → Integer64, double → Real,
// string → String). Overwrites an existing file. Throws WriteFailed, also for a .shp path: the
// DBF's 10-character field names would cut attribute names such as roof_height_m.
void writeFeatures(const std::string& path, const std::vector<core::Feature>& features,
                   const GeoReference& geo = {}, const std::string& layerName = "buildings");

}  // namespace delineo::io
