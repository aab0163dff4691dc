#pragma once
// Pictures and raster dumps the benchmarks write for a look (PNG, or TIFF for float maps).
#include <filesystem>
#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace delineo::bench {

// Writes `image` to `path`, creating its folder; throws naming the file when it cannot be
// written, so that no picture a benchmark announces is silently missing.
inline void writeImage(const std::string& path, const cv::Mat& image) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  bool written = false;
  try {
    written = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path + ": cannot be written (" + e.what() + ")");
  }
  if (!written) throw std::runtime_error(path + ": cannot be written");
}

}  // namespace delineo::bench
