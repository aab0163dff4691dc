// libFuzzer target: io::readFeatures on arbitrary bytes as a GeoJSON file (GDAL /vsimem/).
// Expected outcomes: features, or core::Error. Seeds: corpus/geojson.
#include <cstddef>
#include <cstdint>

#include "delineo/core/error.hpp"
#include "delineo/io/vector.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  delineo::fuzz::MemoryFile file("/vsimem/fuzz_features.geojson", data, size);
  try {
    const auto features = delineo::io::readFeatures(file.path());
    for (const auto& feature : features) {
      // What every caller relies on: a polygon with at least 3 vertices.
      if (feature.polygon.outer.size() < 3) __builtin_trap();
    }
  } catch (const delineo::core::Error&) {
  }
  return 0;
}
