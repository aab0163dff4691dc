#pragma once
// Loading of the hand-labelled real roofs (tests/bench/data/real_roofs.json) shared by the
// benchmarks that read them: their options (--data, --labels, --cache) and clean skip without the
// data folder, rings from JSON, the roofs' sets, the operator's rectangle around a roof, and each
// pair's images and matcher's disparity map, loaded once, the map cached as a GeoTIFF.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/stereo/match.hpp"
#include "shared_data.hpp"

namespace delineo::bench {

inline std::filesystem::path defaultDisparityCache() {
  return std::filesystem::temp_directory_path() / "delineo_bench_disparity";
}

// The options every bench on the labelled real roofs takes: --data DIR (the data folder),
// --labels FILE (real_roofs.json) and --cache DIR (the matcher's maps).
struct RealRoofsOptions {
  std::string dataRoot = defaultDataRoot();
  std::string labels = DELINEO_BENCH_DATA_DIR "/real_roofs.json";
  std::string cache = defaultDisparityCache().string();

  // True, with i moved onto the value, when argv[i] is one of these options and has a value.
  bool take(int argc, char** argv, int& i) {
    if (i + 1 >= argc) return false;
    const std::string option = argv[i];
    std::string* value = option == "--data"     ? &dataRoot
                         : option == "--labels" ? &labels
                         : option == "--cache"  ? &cache
                                                : nullptr;
    if (value == nullptr) return false;
    *value = argv[++i];
    return true;
  }
};

// True, after a "skipped" line, when the data folder is missing: the bench then exits 0 (its
// ctest smoke run is given a folder that does not exist).
inline bool skippedWithoutData(const std::string& dataRoot) {
  if (std::filesystem::is_directory(dataRoot)) return false;
  std::printf("skipped: no data folder %s\n", dataRoot.c_str());
  return true;
}

// True, after a "skipped" line, when no labelled roof could be run (every pair's images absent).
inline bool skippedWithoutRoofs(int runs, const std::string& dataRoot) {
  if (runs > 0) return false;
  std::printf("skipped: no labelled roof found under %s\n", dataRoot.c_str());
  return true;
}

inline nlohmann::json readLabels(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The set of a labelled roof: "held-out" when marked "heldOut" (not used to choose the methods or
// their defaults, see data/README.md), else "tuning".
inline std::string roofSet(const nlohmann::json& roof) {
  return roof.value("heldOut", false) ? "held-out" : "tuning";
}

// The operator's rough rectangle around a labelled outline: its bounding box grown by `grow` px
// on every side, clipped to an image of `size`.
inline core::Polygon grownBox(const core::Polygon& outline, double grow, cv::Size size) {
  const cv::Rect2d box = core::boundingBox(outline.outer);
  const double x0 = std::max(0.0, box.x - grow), y0 = std::max(0.0, box.y - grow);
  const double x1 = std::min<double>(size.width, box.x + box.width + grow);
  const double y1 = std::min<double>(size.height, box.y + box.height + grow);
  core::Polygon rect;
  rect.outer = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  return rect;
}

inline core::Polygon ringOf(const nlohmann::json& points) {
  core::Polygon p;
  for (const auto& v : points) p.outer.emplace_back(v.at(0).get<double>(), v.at(1).get<double>());
  return p;
}

// A digest of the running executable: the cached maps are those of this very build of the
// matcher, so a map made before a matcher change is never read after it.
inline std::string executableDigest() {
  static const std::string digest = [] {
    std::ifstream in("/proc/self/exe", std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016zx", std::hash<std::string>{}(bytes));
    return std::string(hex);
  }();
  return digest;
}

// The matcher's map of a pair with the default parameters, read from the cache when this build
// made it, else computed and cached (replacing the pair's maps of other builds).
inline cv::Mat disparityFor(const std::string& name, const std::string& left,
                            const std::string& right, int dmin, int dmax,
                            const std::filesystem::path& cache) {
  namespace fs = std::filesystem;
  const std::string stem = name + "_" + std::to_string(dmin) + "_" + std::to_string(dmax) + "_";
  const fs::path cached = cache / (stem + executableDigest() + ".tif");
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
  for (const auto& entry : fs::directory_iterator(cache)) {
    if (entry.path().filename().string().rfind(stem, 0) == 0) fs::remove(entry.path());
  }
  io::writeFloatGeoTiff(cached.string(), disparity);
  return disparity;
}

// One pair of real_roofs.json: its files, search range, grey images and matcher's map.
struct RealPair {
  std::string name, leftPath, rightPath;
  int dmin = 0, dmax = 0;
  cv::Mat left, right, disparity;
};

// The pairs of real_roofs.json, each loaded on first use.
class RealPairs {
 public:
  RealPairs(const nlohmann::json& labels, std::filesystem::path dataRoot,
            std::filesystem::path cache)
      : labels_(labels), dataRoot_(std::move(dataRoot)), cache_(std::move(cache)) {}

  // nullptr, after a "skipped" line naming the missing image, when the pair's images are absent.
  const RealPair* get(const std::string& pairName) {
    if (const auto it = loaded_.find(pairName); it != loaded_.end()) {
      return it->second ? &*it->second : nullptr;
    }
    const nlohmann::json& pair = labels_.at("pairs").at(pairName);
    RealPair p;
    p.name = pairName;
    p.leftPath = (dataRoot_ / pair.at("left").get<std::string>()).string();
    p.rightPath = (dataRoot_ / pair.at("right").get<std::string>()).string();
    p.dmin = pair.at("disparity_range").at(0);
    p.dmax = pair.at("disparity_range").at(1);
    for (const std::string& path : {p.leftPath, p.rightPath}) {
      if (!std::filesystem::exists(path)) {
        std::printf("skipped %s: %s missing\n", pairName.c_str(), path.c_str());
        loaded_[pairName] = std::nullopt;
        return nullptr;
      }
    }
    p.disparity = disparityFor(pairName, p.leftPath, p.rightPath, p.dmin, p.dmax, cache_);
    p.left = io::readGreyFloat(p.leftPath);
    p.right = io::readGreyFloat(p.rightPath);
    return &*(loaded_[pairName] = std::move(p));
  }

 private:
  const nlohmann::json& labels_;
  std::filesystem::path dataRoot_, cache_;
  std::map<std::string, std::optional<RealPair>> loaded_;
};

}  // namespace delineo::bench
