// scene.json: what a consumer of a simulated scene directory needs to use it.
#include <filesystem>
#include <fstream>

#include "delineo/core/error.hpp"
#include "delineo/sim/scene.hpp"

namespace delineo::sim {

nlohmann::json sceneDescription(const Scene& scene, const SceneParams& params) {
  nlohmann::json j;
  j["format"] = "delineo-simulated-scene";
  j["version"] = 1;
  j["width"] = scene.left.cols;
  j["height"] = scene.left.rows;
  j["disparity_min"] = scene.disparityMin;
  j["disparity_max"] = scene.disparityMax;
  j["gsd_m"] = scene.gsd;
  j["metres_per_disparity"] = scene.metresPerDisparity;
  j["ground_disparity"] = scene.groundDisparity;
  j["seed"] = scene.seed;
  j["buildings"] = scene.buildingsPlaced;
  j["trees"] = scene.treesPlaced;
  j["convention"] =
      "epipolar rows; x_right = x_left - d; d = Z / metres_per_disparity + ground_disparity; "
      "ground truth in left-image geometry at pixel centres; footprints are roof outlines at "
      "eave height in left-image pixel coordinates";
  j["labels"] = {{"0", "ground"}, {"1", "building roof"}, {"2", "vegetation"}, {"3", "facade"}};
  j["files"] = {{"left", SceneFiles::left},
                {"right", SceneFiles::right},
                {"disparity", SceneFiles::disparity},
                {"disparity_right", SceneFiles::disparityRight},
                {"occlusion", SceneFiles::occlusion},
                {"dem", SceneFiles::dem},
                {"labels", SceneFiles::labels},
                {"footprints", SceneFiles::footprints}};
  j["params"] = core::toJson(params);
  return j;
}

void writeSceneJson(const std::string& path, const Scene& scene, const SceneParams& params) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw core::Error(core::ErrorCode::WriteFailed, "cannot open for writing", path);
  out << sceneDescription(scene, params).dump(2) << "\n";
  out.close();
  if (!out) throw core::Error(core::ErrorCode::WriteFailed, "write failed", path);
}

SceneInfo readSceneJson(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    throw core::Error(core::ErrorCode::FileNotFound, "scene description not found", path);
  }
  std::ifstream in(path, std::ios::binary);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw core::Error(core::ErrorCode::UnreadableFile, std::string("invalid JSON: ") + e.what(), path);
  }
  SceneInfo info;
  try {
    info.width = j.at("width").get<int>();
    info.height = j.at("height").get<int>();
    info.disparityMin = j.at("disparity_min").get<int>();
    info.disparityMax = j.at("disparity_max").get<int>();
    info.gsd = j.at("gsd_m").get<double>();
    info.metresPerDisparity = j.at("metres_per_disparity").get<double>();
    info.groundDisparity = j.at("ground_disparity").get<double>();
    info.seed = j.at("seed").get<int>();
    if (j.contains("params")) core::fromJson(info.params, j.at("params"));
  } catch (const nlohmann::json::exception& e) {
    throw core::Error(core::ErrorCode::UnreadableFile,
                      std::string("not a simulated scene description: ") + e.what(), path);
  } catch (const core::Error& e) {
    throw core::Error(core::ErrorCode::UnreadableFile,
                      std::string("invalid parameters: ") + e.detail(), path);
  }
  return info;
}

}  // namespace delineo::sim
