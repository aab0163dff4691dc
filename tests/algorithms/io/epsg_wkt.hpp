#pragma once
// Test helper for the io library: the WKT of an EPSG coordinate reference system, as a
// georeferenced raster carries it (GeoReference::crsWkt).
#include <string>

#include <cpl_conv.h>
#include <ogr_srs_api.h>

namespace delineo::io::testing {

inline std::string wktOfEpsg(int epsg) {
  OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
  std::string text;
  char* wkt = nullptr;
  if (OSRImportFromEPSG(srs, epsg) == OGRERR_NONE && OSRExportToWkt(srs, &wkt) == OGRERR_NONE) text = wkt;
  CPLFree(wkt);
  OSRDestroySpatialReference(srs);
  return text;
}

}  // namespace delineo::io::testing
