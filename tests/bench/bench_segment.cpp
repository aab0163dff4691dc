// Ground / above-ground segmentation and DTM (segmentation::segmentGround) on simulated scenes
// with a 10 % terrain slope and trees, from the true DEM and from the matcher's DEM
// (stereo::matchStereo over the scene's disparity range, heights by the scene's model).
//
// Scores per scene and mean, against the simulator's labels:
//   found %  above-ground pixels found: predicted above among the true roof and tree pixels
//            that have a height in the DEM segmented;
//   false %  predicted above pixels that are true ground;
//   DTM RMS  (m) DTM minus the true height on every true ground pixel (with a height or not);
//   no-data% the true roof and tree pixels without a height in the DEM (not scored: the
//            segmentation labels no pixel without a height).
// Facade pixels (label 3: walls seen obliquely, a ramp from the ground to the eave) are left out
// of both counts: they are neither ground nor a roof, and a DEM may put them on either side.
//
// Then the time of one 1000 x 1000 px true DEM (--time-size) with its wall time and the peak
// resident memory of the call (the peak is reset before it through /proc/self/clear_refs).
//
//   bench_segment [--tiny] [--scenes N] [--seed FIRST] [--no-matcher] [--time-size N] [--dump DIR]
// BENCH_PARAMS='{...}' overrides the segmentation's parameters.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/params.hpp"
#include "delineo/dem/heights.hpp"
#include "delineo/segmentation/ground.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/match.hpp"
#include "bench_image.hpp"
#include "simulated_match.hpp"

using namespace delineo;

namespace {

struct Score {
  double found = 0, falsePct = 0, dtmRms = 0, ms = 0;
  double noHeight = 0;  // % of the true above-ground pixels without a height in the DEM
  double falseDemError = 0;  // m, mean DEM - true height on the false above-ground pixels
  int iterations = 0, regions = 0;
  bool converged = false;
};

Score score(const segmentation::GroundResult& r, const cv::Mat& dem, const sim::Scene& scene) {
  long truthAbove = 0, hit = 0, predicted = 0, wrong = 0, groundPixels = 0, truthNoHeight = 0;
  double sum2 = 0, wrongError = 0;
  for (int y = 0; y < dem.rows; ++y) {
    for (int x = 0; x < dem.cols; ++x) {
      const int label = scene.labels.at<unsigned char>(y, x);
      if (label == sim::kLabelFacade) continue;
      const bool above = r.aboveGround.at<unsigned char>(y, x) != 0;
      if (label == sim::kLabelGround) {
        const double d = r.dtm.at<float>(y, x) - scene.dem.at<float>(y, x);
        sum2 += d * d;
        ++groundPixels;
      }
      const bool truth = label == sim::kLabelBuilding || label == sim::kLabelVegetation;
      if (!std::isfinite(dem.at<float>(y, x))) {
        truthNoHeight += truth;
        continue;
      }
      if (above && label == sim::kLabelGround) wrongError += dem.at<float>(y, x) - scene.dem.at<float>(y, x);
      truthAbove += truth;
      hit += truth && above;
      predicted += above;
      wrong += above && label == sim::kLabelGround;
    }
  }
  Score s;
  s.found = truthAbove ? 100.0 * hit / truthAbove : 100.0;
  s.falsePct = predicted ? 100.0 * wrong / predicted : 0.0;
  s.dtmRms = groundPixels ? std::sqrt(sum2 / groundPixels) : 0.0;
  s.noHeight = truthAbove + truthNoHeight ? 100.0 * truthNoHeight / (truthAbove + truthNoHeight) : 0.0;
  s.falseDemError = wrong ? wrongError / wrong : 0.0;
  s.iterations = r.iterations;
  s.regions = r.regionCount;
  s.converged = r.converged;
  return s;
}

segmentation::GroundResult timedSegment(const cv::Mat& dem, double gsd, const segmentation::GroundParams& params,
                                        double& ms) {
  const auto t0 = std::chrono::steady_clock::now();
  segmentation::GroundResult r = segmentation::segmentGround(dem, gsd, params);
  ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

void dump(const std::string& dir, const std::string& name, const segmentation::GroundResult& r, const sim::Scene& scene) {
  if (dir.empty()) return;
  cv::Mat view;
  cv::cvtColor(scene.left, view, cv::COLOR_GRAY2BGR);
  for (int y = 0; y < view.rows; ++y) {
    for (int x = 0; x < view.cols; ++x) {
      const int label = scene.labels.at<unsigned char>(y, x);
      const bool above = r.aboveGround.at<unsigned char>(y, x) != 0;
      const bool truth = label == sim::kLabelBuilding || label == sim::kLabelVegetation;
      cv::Vec3b& p = view.at<cv::Vec3b>(y, x);
      if (above && truth) p = cv::Vec3b(p[0] / 2, 200, p[2] / 2);          // found: green
      else if (above && label == sim::kLabelGround) p = cv::Vec3b(0, 0, 230);  // false: red
      else if (!above && truth) p = cv::Vec3b(230, p[1] / 2, 0);               // missed: blue
    }
  }
  bench::writeImage(dir + "/" + name + ".png", view);
}

void printScore(const char* scene, const char* demName, const Score& s) {
  std::printf("%-6s %-8s %8.1f %8.1f %9.3f %9.1f %7d %5d %5s %8.0f\n", scene, demName, s.found, s.falsePct,
              s.dtmRms, s.noHeight, s.regions, s.iterations, s.converged ? "yes" : "no", s.ms);
  if (std::getenv("BENCH_VERBOSE")) std::printf("       DEM error on the false pixels: %+.2f m\n", s.falseDemError);
}

cv::Mat matcherDem(const sim::Scene& scene) { return bench::sceneHeights(scene, bench::matchScene(scene)); }

int simulated(int scenes, int firstSeed, sim::SceneParams sceneParams, const segmentation::GroundParams& params,
              bool withMatcher, const std::string& dumpDir) {
  std::printf("%-6s %-8s %8s %8s %9s %9s %7s %5s %5s %8s\n", "scene", "dem", "found%", "false%", "DTM RMS m",
              "no-data%", "regions", "iter", "conv", "ms");
  std::map<std::string, std::vector<Score>> all;
  for (int s = 0; s < scenes; ++s) {
    sceneParams.seed = firstSeed + s;
    const sim::Scene scene = sim::simulateScene(sceneParams);
    std::map<std::string, cv::Mat> dems{{"true", scene.dem}};
    if (withMatcher) dems["matcher"] = matcherDem(scene);
    for (const auto& [name, dem] : dems) {
      double ms = 0;
      const auto r = timedSegment(dem, scene.gsd, params, ms);
      Score sc = score(r, dem, scene);
      sc.ms = ms;
      if (std::getenv("BENCH_VERBOSE")) {
        for (size_t i = 0; i < r.regionInfo.size(); ++i) {
          const auto& info = r.regionInfo[i];
          if (info.pixels >= 50 || info.above)
            std::printf("    region %zu: %d px, %.2f m%s%s\n", i, info.pixels, info.meanHeight, info.above ? " above" : "",
                        info.oscillating ? " oscillating" : "");
        }
      }
      all[name].push_back(sc);
      printScore(std::to_string(sceneParams.seed).c_str(), name.c_str(), sc);
      dump(dumpDir, "seed" + std::to_string(sceneParams.seed) + "_" + name, r, scene);
    }
  }
  for (const auto& [name, scores] : all) {
    Score mean;
    for (const Score& s : scores) {
      mean.found += s.found / scores.size();
      mean.falsePct += s.falsePct / scores.size();
      mean.dtmRms += s.dtmRms / scores.size();
      mean.ms += s.ms / scores.size();
      mean.noHeight += s.noHeight / scores.size();
    }
    mean.converged = true;
    for (const Score& s : scores) mean.converged = mean.converged && s.converged;
    printScore("mean", name.c_str(), mean);
  }
  return 0;
}

long peakResidentKb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6);
  }
  return -1;
}

// Wall time and peak resident memory of one call on a size x size scene's true (and matched) DEM.
void timing(int size, const segmentation::GroundParams& params, bool withMatcher) {
  sim::SceneParams sp = sim::squareSceneParams(size, 1);
  sp.slope = 10.0;
  const sim::Scene scene = sim::simulateScene(sp);
  std::map<std::string, cv::Mat> dems{{"true", scene.dem.clone()}};
  if (withMatcher) dems["matcher"] = matcherDem(scene);
  std::printf("\n%d x %d px, seed 1 (%d buildings, %d trees):\n", size, size, scene.buildingsPlaced,
              scene.treesPlaced);
  for (const auto& [name, dem] : dems) {
    std::ofstream("/proc/self/clear_refs") << "5";  // peak resident memory := current
    const long before = peakResidentKb();
    double ms = 0;
    const auto r = timedSegment(dem, scene.gsd, params, ms);
    const long peak = peakResidentKb();
    const Score sc = score(r, dem, scene);
    const double resultMb = (r.regions.total() * r.regions.elemSize() + r.aboveGround.total() +
                             (r.dtm.total() + r.ndsm.total() + r.demUsed.total()) * sizeof(float)) / 1048576.0;
    std::printf("  %-8s %.0f ms wall; peak resident %.0f MB (+%.0f MB over the %.0f MB before the call), result %.0f MB; "
                "%d regions, %d links (%d across gaps), %d iterations; found %.1f %%, false %.1f %%, DTM RMS %.3f m\n",
                name.c_str(), ms, peak / 1024.0, (peak - before) / 1024.0, before / 1024.0, resultMb, r.regionCount,
                r.links, r.gapLinks, r.iterations, sc.found, sc.falsePct, sc.dtmRms);
  }
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  int scenes = 3, firstSeed = 1, timeSize = 1000;
  bool tiny = false, withMatcher = true;
  std::string dumpDir;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--tiny")) {
      tiny = true;
    } else if (!std::strcmp(argv[i], "--scenes") && i + 1 < argc) {
      scenes = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) {
      firstSeed = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--time-size") && i + 1 < argc) {
      timeSize = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--no-matcher")) {
      withMatcher = false;
    } else if (!std::strcmp(argv[i], "--dump") && i + 1 < argc) {
      dumpDir = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_segment [--tiny] [--scenes N] [--seed FIRST] [--no-matcher] [--time-size N] "
                   "[--dump DIR]\nBENCH_PARAMS='{...}' overrides the segmentation's parameters\n");
      return 2;
    }
  }
  segmentation::GroundParams params;
  if (const char* json = std::getenv("BENCH_PARAMS")) core::fromJson(params, nlohmann::json::parse(json));
  sim::SceneParams sceneParams;
  sceneParams.slope = 10.0;
  if (tiny) {
    scenes = 1;
    sceneParams.width = 240;
    sceneParams.height = 200;
    sceneParams.buildings = 2;
    sceneParams.trees = 2;
    timeSize = 200;
  }
  simulated(scenes, firstSeed, sceneParams, params, withMatcher, dumpDir);
  if (timeSize > 0) timing(timeSize, params, withMatcher);
  return 0;
}
