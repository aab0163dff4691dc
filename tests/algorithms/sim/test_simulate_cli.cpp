// Runs the real delineo-cli process and reads its files back through delineo::io.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <sys/wait.h>

#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/sim/scene.hpp"

namespace {
namespace fs = std::filesystem;
using namespace delineo;

int runCli(const std::string& arguments) {
  const std::string command = std::string("\"") + DELINEO_CLI_PATH + "\" " + arguments + " 2>/dev/null";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool identical(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  cv::Mat diff;
  cv::compare(a, b, diff, cv::CMP_NE);
  // NaN != NaN: count only positions where not both are NaN.
  if (a.depth() == CV_32F) {
    for (int y = 0; y < a.rows; ++y) {
      for (int x = 0; x < a.cols; ++x) {
        const float u = a.at<float>(y, x), v = b.at<float>(y, x);
        if (!(u == v || (std::isnan(u) && std::isnan(v)))) return false;
      }
    }
    return true;
  }
  return cv::countNonZero(diff) == 0;
}
}  // namespace

TEST(SimulateCli, WritesEveryFileMatchingTheLibrary) {
  const fs::path dir = fs::temp_directory_path() / "delineo_simulate_cli_test";
  fs::remove_all(dir);
  ASSERT_EQ(runCli("simulate --out \"" + dir.string() +
                   "\" --seed 17 --width 256 --height 192 --buildings 5 --trees 6 --slope 2 --noise 1"),
            0);
  sim::SceneParams p;
  p.seed = 17;
  p.width = 256;
  p.height = 192;
  p.buildings = 5;
  p.trees = 6;
  p.slope = 2;
  p.noise = 1;
  const sim::Scene scene = sim::simulateScene(p);
  auto file = [&](const char* name) { return (dir / name).string(); };
  EXPECT_TRUE(identical(io::readRaster(file(sim::SceneFiles::left)).data, scene.left));
  EXPECT_TRUE(identical(io::readRaster(file(sim::SceneFiles::right)).data, scene.right));
  EXPECT_TRUE(identical(io::readRaster(file(sim::SceneFiles::occlusion)).data, scene.occlusion));
  EXPECT_TRUE(identical(io::readRaster(file(sim::SceneFiles::labels)).data, scene.labels));
  io::ReadOptions asFloat;
  asFloat.type = io::PixelType::Float32;
  EXPECT_TRUE(identical(io::readRaster(file(sim::SceneFiles::disparity), asFloat).data, scene.disparity));
  EXPECT_TRUE(identical(io::readRaster(file(sim::SceneFiles::dem), asFloat).data, scene.dem));
  EXPECT_TRUE(identical(io::readRaster(file(sim::SceneFiles::disparityRight), asFloat).data,
                        scene.disparityRight));

  const auto features = io::readFeatures(file(sim::SceneFiles::footprints));
  ASSERT_EQ(features.size(), scene.footprints.size());
  for (size_t i = 0; i < features.size(); ++i) {
    ASSERT_EQ(features[i].polygon.outer.size(), scene.footprints[i].polygon.outer.size());
    EXPECT_EQ(features[i].polygon.holes.size(), scene.footprints[i].polygon.holes.size());
    EXPECT_NEAR(core::area(features[i].polygon), core::area(scene.footprints[i].polygon), 1e-6);
    EXPECT_EQ(features[i].attributes.at("shape"), scene.footprints[i].attributes.at("shape"));
  }

  const sim::SceneInfo info = sim::readSceneJson(file(sim::SceneFiles::description));
  EXPECT_EQ(info.disparityMin, scene.disparityMin);
  EXPECT_EQ(info.disparityMax, scene.disparityMax);
  EXPECT_EQ(info.params.buildings, 5);
  fs::remove_all(dir);
}

TEST(SimulateCli, RejectsInvalidValuesAndMissingOut) {
  EXPECT_EQ(runCli("simulate --seed 3"), 2);  // --out is required: usage error
  const fs::path dir = fs::temp_directory_path() / "delineo_simulate_cli_bad";
  EXPECT_EQ(runCli("simulate --out \"" + dir.string() + "\" --width 5"), 3);  // invalid value
  EXPECT_EQ(runCli("simulate --out \"" + dir.string() + "\" --slope abc"), 2);
  fs::remove_all(dir);
}
