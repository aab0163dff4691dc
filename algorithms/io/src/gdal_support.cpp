#include "gdal_support.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <mutex>

#include <cpl_error.h>

namespace delineo::io::detail {

void ensureGdalRegistered() {
  static std::once_flag registered;
  std::call_once(registered, [] { GDALAllRegister(); });
}

ScopedGdalErrors::ScopedGdalErrors() {
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLErrorReset();
}

ScopedGdalErrors::~ScopedGdalErrors() { CPLPopErrorHandler(); }

bool ScopedGdalErrors::failed() const {
  const CPLErr type = CPLGetLastErrorType();
  return type == CE_Failure || type == CE_Fatal;
}

void ScopedGdalErrors::reset() { CPLErrorReset(); }

std::string ScopedGdalErrors::describe(const std::string& prefix) const {
  const char* message = CPLGetLastErrorMsg();
  if (message == nullptr || *message == '\0') return prefix;
  return prefix + " (GDAL: " + message + ")";
}

bool isVirtualPath(const std::string& path) { return path.rfind("/vsi", 0) == 0; }

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace delineo::io::detail
