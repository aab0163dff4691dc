// libFuzzer target: io::readFeatures on arbitrary bytes as a GeoJSON file (GDAL /vsimem/), read in
// pixels and over a georeferenced image in UTM 31N (the file's CRS brought into the image's).
// Expected outcomes: features, or core::Error. Seeds: corpus/geojson.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <cpl_conv.h>
#include <ogr_srs_api.h>

#include "delineo/core/error.hpp"
#include "delineo/io/vector.hpp"
#include "fuzz_support.hpp"

namespace {
// 0.5 m pixels of an image in UTM 31N (EPSG:32631) near Toulouse.
delineo::io::GeoReference utmImage() {
  delineo::io::GeoReference geo;
  geo.geoTransform = {370000.0, 0.5, 0.0, 4830000.0, 0.0, -0.5};
  geo.hasTransform = true;
  OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
  char* wkt = nullptr;
  if (OSRImportFromEPSG(srs, 32631) == OGRERR_NONE && OSRExportToWkt(srs, &wkt) == OGRERR_NONE) geo.crsWkt = wkt;
  CPLFree(wkt);
  OSRDestroySpatialReference(srs);
  return geo;
}

// What every caller relies on: polygons of at least 3 finite vertices.
void checkFeatures(const std::vector<delineo::core::Feature>& features) {
  for (const auto& feature : features) {
    if (feature.polygon.outer.size() < 3) __builtin_trap();
    for (const auto& p : feature.polygon.outer) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) __builtin_trap();
    }
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const delineo::io::GeoReference geo = utmImage();
  delineo::fuzz::MemoryFile file("/vsimem/fuzz_features.geojson", data, size);
  for (const delineo::io::GeoReference& over : {delineo::io::GeoReference{}, geo}) {
    try {
      checkFeatures(delineo::io::readFeatures(file.path(), over));
    } catch (const delineo::core::Error&) {
    }
  }
  return 0;
}
