#pragma once
// Internal GDAL helpers shared by raster and vector I/O (not part of the public API).
#include <memory>
#include <string>
#include <type_traits>

#include <gdal.h>
#include <ogr_srs_api.h>

namespace delineo::io::detail {

// Registers every GDAL/OGR driver exactly once, from any thread.
void ensureGdalRegistered();

// Silences GDAL's default stderr error printing for the current thread while alive and keeps the
// last error message so it can be put into a core::Error. GDAL's error state is per thread, so
// concurrent calls on separate datasets do not see each other's messages.
class ScopedGdalErrors {
 public:
  ScopedGdalErrors();
  ~ScopedGdalErrors();
  ScopedGdalErrors(const ScopedGdalErrors&) = delete;
  ScopedGdalErrors& operator=(const ScopedGdalErrors&) = delete;

  // True when GDAL reported a CE_Failure or CE_Fatal since construction (or the last reset()).
  bool failed() const;
  void reset();
  // "<prefix> (GDAL: <message>)" or just the prefix when GDAL said nothing.
  std::string describe(const std::string& prefix) const;
};

// True for GDAL virtual file system paths (/vsimem/, /vsizip/...), which do not exist on disk.
bool isVirtualPath(const std::string& path);

// Lower-case file extension with its dot (".tif"), empty when none.
std::string lowerExtension(const std::string& path);

// An OGR spatial reference, destroyed on scope exit.
struct SpatialReferenceDeleter {
  void operator()(OGRSpatialReferenceH srs) const { OSRDestroySpatialReference(srs); }
};
using SpatialReferencePtr = std::unique_ptr<std::remove_pointer_t<OGRSpatialReferenceH>, SpatialReferenceDeleter>;

// Closes a GDAL dataset handle on scope exit.
struct DatasetCloser {
  void operator()(void* dataset) const {
    if (dataset != nullptr) GDALClose(static_cast<GDALDatasetH>(dataset));
  }
};

}  // namespace delineo::io::detail
