#pragma once
// Pictures and raster dumps the benchmarks write for a look (PNG, or TIFF for float maps), and
// outlines dumped as JSON lines (BENCH_DUMP_OUTLINES) to compare other regularizers with.
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "delineo/core/geometry.hpp"

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

// An outline as JSON: its outer ring, then its holes, each a list of [x, y].
inline nlohmann::json ringsJson(const core::Polygon& p) {
  nlohmann::json out = nlohmann::json::array();
  auto add = [&](const core::Ring& ring) {
    nlohmann::json points = nlohmann::json::array();
    for (const auto& v : ring) points.push_back({v.x, v.y});
    out.push_back(points);
  };
  add(p.outer);
  for (const auto& h : p.holes) add(h);
  return out;
}

// Appends `line` to the file `path` as one line of JSON (silently nothing when it cannot be
// opened).
inline void appendJsonLine(const std::string& path, const nlohmann::json& line) {
  if (FILE* f = std::fopen(path.c_str(), "a")) {
    std::fprintf(f, "%s\n", line.dump().c_str());
    std::fclose(f);
  }
}

}  // namespace delineo::bench
