#pragma once
// Loading of the hand-labelled real roofs (tests/bench/data/real_roofs.json) shared by the
// benchmarks that read them: rings from JSON, and the matcher's disparity map of a pair, computed
// once and cached as a GeoTIFF.
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/stereo/match.hpp"

namespace delineo::bench {

inline core::Polygon ringOf(const nlohmann::json& points) {
  core::Polygon p;
  for (const auto& v : points) p.outer.emplace_back(v.at(0).get<double>(), v.at(1).get<double>());
  return p;
}

inline cv::Mat disparityFor(const std::string& name, const std::string& left,
                            const std::string& right, int dmin, int dmax,
                            const std::filesystem::path& cache) {
  namespace fs = std::filesystem;
  const fs::path cached =
      cache / (name + "_" + std::to_string(dmin) + "_" + std::to_string(dmax) + ".tif");
  if (fs::exists(cached)) {
    io::ReadOptions options;
    options.type = io::PixelType::Float32;
    return io::readRaster(cached.string(), options).data;
  }
  stereo::MatchParams params;
  params.dmin = dmin;
  params.dmax = dmax;
  std::fprintf(stderr, "matching %s (%d..%d px)...\n", name.c_str(), dmin, dmax);
  const cv::Mat disparity =
      stereo::matchStereo(io::readGreyFloat(left), io::readGreyFloat(right), params).disparity;
  fs::create_directories(cache);
  io::writeFloatGeoTiff(cached.string(), disparity);
  return disparity;
}

}  // namespace delineo::bench
