#pragma once
// Shared by the libFuzzer targets: GDAL's in-memory files and the one exception type a reader
// may throw. Anything else escaping a reader (or a crash, leak or sanitizer report) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include <cpl_vsi.h>

namespace delineo::fuzz {

// The fuzzer's bytes as a GDAL /vsimem/ file, removed when the object goes out of scope.
class MemoryFile {
 public:
  MemoryFile(std::string path, const uint8_t* data, size_t size) : path_(std::move(path)) {
    // GDAL reads the buffer in place (no copy, not owned): the fuzzer keeps it alive.
    VSIFCloseL(VSIFileFromMemBuffer(path_.c_str(), const_cast<GByte*>(data),
                                    static_cast<vsi_l_offset>(size), FALSE));
  }
  ~MemoryFile() { VSIUnlink(path_.c_str()); }
  MemoryFile(const MemoryFile&) = delete;
  MemoryFile& operator=(const MemoryFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace delineo::fuzz
