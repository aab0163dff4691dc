// libFuzzer target: io::readRaster on arbitrary bytes as a GeoTIFF file (GDAL /vsimem/), kept
// as read and as grey float. Only GDAL's GTiff driver is left registered, so the target fuzzes
// the reader and its TIFF path rather than every format GDAL knows. Expected outcomes: a raster
// of the declared size, or core::Error. Seeds: corpus/raster.
#include <cstddef>
#include <cstdint>
#include <string>

#include <cpl_conv.h>
#include <gdal.h>

#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // Register as the reader does, then drop every driver but GTiff (readRaster registers once).
  try {
    (void)delineo::io::readRaster("/vsimem/no-such-file.tif");
  } catch (const delineo::core::Error&) {
  }
  for (int i = GDALGetDriverCount() - 1; i >= 0; --i) {
    GDALDriverH driver = GDALGetDriver(i);
    if (std::string(GDALGetDriverShortName(driver)) != "GTiff") {
      GDALDeregisterDriver(driver);
      GDALDestroyDriver(driver);  // deregistering alone leaves it allocated (a leak report)
    }
  }
  CPLSetConfigOption("GDAL_DISABLE_READDIR_ON_OPEN", "EMPTY_DIR");  // no sidecar file lookups
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  delineo::fuzz::MemoryFile file("/vsimem/fuzz_raster.tif", data, size);
  for (const bool asGreyFloat : {false, true}) {
    delineo::io::ReadOptions options;
    // The size guard under test, below the fuzzer's 2 GiB memory limit: a few bytes may declare a
    // raster of nearly the default 4 GiB, which is a valid size to read but not to fuzz with.
    options.maxBytes = std::uint64_t{256} << 20;
    if (asGreyFloat) {
      options.type = delineo::io::PixelType::Float32;
      options.toGrey = true;
    }
    try {
      const auto raster = delineo::io::readRaster(file.path(), options);
      if (raster.data.empty()) __builtin_trap();
      if (asGreyFloat && raster.data.type() != CV_32FC1) __builtin_trap();
    } catch (const delineo::core::Error&) {
    }
  }
  return 0;
}
