// Benchmark of building vs vegetation, above-ground objects and automatic building proposals
// (docs/dem.md, "Building vs vegetation, objects and proposals") on simulated scenes with a
// sloping terrain: share of the above-ground pixels classified right (with each rule switched
// off in turn), proposals found and false against the true footprints, and with `--chain` the
// active polygon run from each proposal on the matcher's disparity (the whole automatic chain:
// simulate, match, DEM, segment, detect, delineate). `--ground` chooses where the above-ground
// mask and the DTM come from: the ground segmentation of the true DEM (default) or of the
// matcher's DEM, or the simulator's labels (`truth`). `--real DIR` writes overlays
// of the classification on the real RGB tiles. Plain main printing tables; `--tiny` is the
// ctest smoke run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <nlohmann/json.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/params.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/delineation/feature_request.hpp"
#include "delineo/dem/heights.hpp"
#include "delineo/segmentation/detect.hpp"
#include "delineo/segmentation/ground.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/match.hpp"
#include "bench_image.hpp"
#include "simulated_match.hpp"

using namespace delineo;
using namespace delineo::segmentation;

namespace {

// The ground/above-ground segmentation the classification starts from: the above-ground mask
// (CV_8U 255/0), the DTM (CV_32F m), the nDSM (DEM - DTM, NaN no data) and the regions.
struct GroundSegmentation {
  cv::Mat aboveGround, dtm, ndsm, regions;
};

// From the simulator's truth: above ground = every non-ground label; the DTM is the DEM of the
// nearest ground pixel, smoothed over 4 m (the terrain under an object is not seen).
GroundSegmentation truthSegmentation(const sim::Scene& scene) {
  GroundSegmentation s;
  s.aboveGround = scene.labels != sim::kLabelGround;
  cv::Mat distance, nearest;
  cv::distanceTransform(s.aboveGround, distance, nearest, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  // Label k is the k-th zero pixel in scan order: map it back to its height.
  std::vector<float> groundHeights{0.0f};
  for (int y = 0; y < scene.dem.rows; ++y) {
    for (int x = 0; x < scene.dem.cols; ++x) {
      if (s.aboveGround.at<uchar>(y, x) == 0) groundHeights.push_back(scene.dem.at<float>(y, x));
    }
  }
  s.dtm.create(scene.dem.size(), CV_32F);
  for (int y = 0; y < scene.dem.rows; ++y) {
    for (int x = 0; x < scene.dem.cols; ++x) s.dtm.at<float>(y, x) = groundHeights[static_cast<size_t>(nearest.at<int>(y, x))];
  }
  const int side = static_cast<int>(std::lround(4.0 / scene.gsd)) | 1;
  cv::blur(s.dtm, s.dtm, {side, side});
  s.ndsm = scene.dem - s.dtm;
  return s;
}

// The product's segmentation (segmentGround; BENCH_GROUND='{...}' overrides parameters) of a DEM
// in metres.
GroundSegmentation demSegmentation(const cv::Mat& dem, double gsd) {
  GroundParams params;
  if (const char* json = std::getenv("BENCH_GROUND")) core::fromJson(params, nlohmann::json::parse(json));
  const GroundResult g = segmentGround(dem, gsd, params);
  return {g.aboveGround, g.dtm, g.ndsm, g.regions};
}


double iouOf(const core::Polygon& a, const core::Polygon& b, cv::Size size) {
  const cv::Mat ma = core::rasterize(a, size), mb = core::rasterize(b, size);
  return double(cv::countNonZero(ma & mb)) / std::max(1, cv::countNonZero(ma | mb));
}

struct Tally {
  long right = 0, total = 0, rightNoFacade = 0, totalNoFacade = 0;
  long buildingAsVeg = 0, vegAsBuilding = 0, buildings = 0, vegetation = 0;
  long rightFound = 0, totalFound = 0;  // among the true above-ground pixels labelled above-ground
  void add(const cv::Mat& predicted, const cv::Mat& labels) {
    for (int y = 0; y < labels.rows; ++y) {
      for (int x = 0; x < labels.cols; ++x) {
        const uchar l = labels.at<uchar>(y, x);
        if (l == sim::kLabelGround) continue;
        const uchar truth = l == sim::kLabelVegetation ? kClassVegetation : kClassBuilding;
        const uchar p = predicted.at<uchar>(y, x);
        ++total, right += p == truth;
        if (p != kClassGround) ++totalFound, rightFound += p == truth;
        if (l != sim::kLabelFacade) ++totalNoFacade, rightNoFacade += p == truth;
        if (truth == kClassBuilding) ++buildings, buildingAsVeg += p == kClassVegetation;
        if (truth == kClassVegetation) ++vegetation, vegAsBuilding += p == kClassBuilding;
      }
    }
  }
  void print(const char* name) const {
    std::printf("  %-34s %6.2f %%  %6.2f %%  %6.2f %%   %6.2f %%   %6.2f %%\n", name, 100.0 * right / std::max(1L, total),
                100.0 * rightFound / std::max(1L, totalFound),
                100.0 * rightNoFacade / std::max(1L, totalNoFacade), 100.0 * buildingAsVeg / std::max(1L, buildings),
                100.0 * vegAsBuilding / std::max(1L, vegetation));
  }
};

struct ProposalScore {
  int targets = 0, found = 0, proposals = 0, falses = 0;
  std::vector<double> iouFound;
};

// Footprints of at least `minArea` m² found by a proposal of IoU >= 0.5; proposals matching no
// footprint (of any size) at IoU >= 0.5 are false.
void scoreProposals(const std::vector<core::Polygon>& proposals, const sim::Scene& scene, double minArea,
                    ProposalScore& score) {
  std::vector<bool> matched(proposals.size(), false);
  for (const auto& fp : scene.footprints) {
    double best = 0;
    for (size_t i = 0; i < proposals.size(); ++i) {
      const double iou = iouOf(proposals[i], fp.polygon, scene.left.size());
      if (iou >= 0.5) matched[i] = true;
      best = std::max(best, iou);
    }
    if (core::area(fp.polygon) * scene.gsd * scene.gsd < minArea) continue;
    ++score.targets;
    if (best >= 0.5) ++score.found, score.iouFound.push_back(best);
  }
  score.proposals += static_cast<int>(proposals.size());
  for (bool m : matched) score.falses += !m;
}

void printScore(const char* name, const ProposalScore& s) {
  double mean = 0;
  for (double v : s.iouFound) mean += v / std::max<size_t>(1, s.iouFound.size());
  std::printf("  %-34s found %3d / %3d (%5.1f %%)  false %3d / %3d (%5.1f %%)  mean IoU of found %.3f\n", name,
              s.found, s.targets, 100.0 * s.found / std::max(1, s.targets), s.falses, s.proposals,
              100.0 * s.falses / std::max(1, s.proposals), mean);
}

// Classification of a real RGB tile drawn over it: red building, green vegetation.
void overlay(const std::string& path, const cv::Mat& bgr, const cv::Mat& labels) {
  cv::Mat out = bgr.clone();
  cv::Mat tint(bgr.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  tint.setTo(cv::Scalar(0, 0, 255), labels == kClassBuilding);
  tint.setTo(cv::Scalar(0, 255, 0), labels == kClassVegetation);
  cv::addWeighted(bgr, 0.6, tint, 0.4, 0, out);
  cv::Mat dim = bgr * 0.5;
  dim.copyTo(out, labels == kClassGround);
  bench::writeImage(path, out);
}

// The real tiles: on Dublin an above-ground mask from the LiDAR disparity; on Toulouse (no
// truth) the whole tile is classified per pixel, to see the rules alone.
void realTiles(const std::string& dataDir, const std::string& outDir, const ClassifyParams& params) {
  namespace fs = std::filesystem;
  for (const char* folder : {"aerial-dublin", "aerial-toulouse"}) {
    const fs::path dir = fs::path(dataDir) / folder;
    if (!fs::exists(dir)) {
      std::printf("  %s: missing, skipped\n", dir.string().c_str());
      continue;
    }
    for (const auto& entry : fs::directory_iterator(dir)) {
      const std::string name = entry.path().filename().string();
      if (name.size() < 9 || name.substr(name.size() - 9) != "_left.png") continue;
      const cv::Mat bgr = cv::imread(entry.path().string(), cv::IMREAD_COLOR);
      const double gsd = std::string(folder) == "aerial-dublin" ? 0.034 : 0.05;
      cv::Mat above(bgr.size(), CV_8U, cv::Scalar(255));
      cv::Mat ndsm(bgr.size(), CV_32F, cv::Scalar(5.0f));
      const std::string gtPath = entry.path().string().substr(0, entry.path().string().size() - 4) + "_gt_disp.png";
      if (fs::exists(gtPath)) {
        // Dublin: heights from the LiDAR disparity (d/256 px), above ground where it exceeds the
        // tile's 20th percentile by 2.5 m (gsd-scaled disparity ~ height at this obliquity).
        cv::Mat raw = cv::imread(gtPath, cv::IMREAD_UNCHANGED), d;
        raw.convertTo(d, CV_32F, 1.0 / 256.0);
        d.setTo(std::nanf(""), raw == 0);
        std::vector<float> v;
        for (int y = 0; y < d.rows; ++y) {
          for (int x = 0; x < d.cols; ++x) {
            if (std::isfinite(d.at<float>(y, x))) v.push_back(d.at<float>(y, x));
          }
        }
        std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 5), v.end());
        const float ground = v[v.size() / 5];
        ndsm = (d - ground) * gsd;
        above = ndsm > 2.5f;  // NaN compares false
        // The LiDAR covers ~23 %: close the gaps between its lines.
        cv::morphologyEx(above, above, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_RECT, {9, 9}));
      }
      const Classification c = classify(bgr, above, ndsm, gsd, params);
      // Without heights (Toulouse) the whole tile is one region: show the per-pixel rules.
      const cv::Mat& shown = fs::exists(gtPath) ? c.labels : c.pixelLabels;
      const std::string out = outDir + "/classes_" + name;
      overlay(out, bgr, shown);
      const double share = cv::countNonZero(shown == kClassVegetation) / std::max(1.0, double(cv::countNonZero(above)));
      std::printf("  %-40s vegetation %5.1f %% of the mask, overlay %s\n", name.c_str(), 100 * share, out.c_str());
    }
  }
}

struct Options {
  int scenes = 4, firstSeed = 1;
  bool chain = false;  // --chain: the matcher and the active polygon from each proposal
  std::string ground = "true-dem";        // --ground true-dem|matcher|truth
  std::string realDir, realOut = "/tmp";  // --real DIR [--real-out DIR]: overlays on real tiles
  sim::SceneParams scene = [] {
    sim::SceneParams p;
    p.width = 800;
    p.height = 600;
    p.buildings = 14;
    p.trees = 24;
    p.slope = 10.0;
    return p;
  }();
  DetectParams detect;
};

// The options, or nothing after the usage line when they are wrong.
std::optional<Options> parseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const bool valued = i + 1 < argc;
    if (!std::strcmp(argv[i], "--tiny")) {
      o.scenes = 1;
      o.scene.width = 320;
      o.scene.height = 240;
      o.scene.buildings = 3;
      o.scene.trees = 3;
    } else if (!std::strcmp(argv[i], "--scenes") && valued) {
      o.scenes = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--seed") && valued) {
      o.firstSeed = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--chain")) {
      o.chain = true;
    } else if (!std::strcmp(argv[i], "--growth") && valued) {
      o.detect.growth = std::atof(argv[++i]);
    } else if (!std::strcmp(argv[i], "--ground") && valued) {
      o.ground = argv[++i];
    } else if (!std::strcmp(argv[i], "--real") && valued) {
      o.realDir = argv[++i];
    } else if (!std::strcmp(argv[i], "--real-out") && valued) {
      o.realOut = argv[++i];
    } else {
      std::fprintf(stderr, "usage: bench_detect [--tiny] [--scenes N] [--seed FIRST] [--chain] [--growth PX] "
                           "[--ground true-dem|matcher|truth] [--real DATA_DIR [--real-out DIR]]\n");
      return std::nullopt;
    }
  }
  if (o.ground != "true-dem" && o.ground != "matcher" && o.ground != "truth") {
    std::fprintf(stderr, "--ground takes true-dem, matcher or truth\n");
    return std::nullopt;
  }
  return o;
}

// The classification with every rule, then with each switched off in turn.
struct Variant {
  const char* name;
  ClassifyParams params;
  bool majority;
};
std::vector<Variant> ablations(const ClassifyParams& classifyParams) {
  std::vector<Variant> variants;
  variants.push_back({"all rules, region majority", classifyParams, true});
  variants.push_back({"all rules, per pixel", classifyParams, false});
  ClassifyParams p = classifyParams;
  p.darkLevel = 0;
  variants.push_back({"no dark-textured rule", p, true});
  p = classifyParams;
  p.darkLevel = 255;
  variants.push_back({"textured at any brightness", p, true});
  p = classifyParams;
  p.minObjectArea = 0;
  variants.push_back({"no small-piece absorption", p, true});
  return variants;
}

// What the tables need of every scene.
struct Totals {
  std::vector<Tally> tallies;  // per variant
  ProposalScore gtScore, chainScore;
  double classifyMs = 0;  // of the first variant, all scenes
};

// The automatic chain: the matcher's map gives the intervals, the active polygon starts from
// each proposal; the outlines scored against the footprints.
void runChain(const sim::Scene& scene, const cv::Mat& map, const GroundSegmentation& seg,
              const ClassifyParams& classifyParams, const ObjectParams& objectParams,
              const DetectParams& detectParams, ProposalScore& score) {
  cv::Mat left, right;
  scene.left.convertTo(left, CV_32F);
  scene.right.convertTo(right, CV_32F);
  const Detection dm = detectBuildings(scene.left, seg.aboveGround, seg.ndsm, scene.gsd, map,
                                       seg.regions, classifyParams, objectParams, detectParams);
  std::vector<core::Polygon> outlines;
  delineation::DelineationParams params;
  for (const auto& f : dm.proposals) {
    try {
      auto req = delineation::featureRequest(f, params.groundTolerance);
      if (!req) continue;
      req->disparity = map;
      req->searchRange = delineation::DisparityInterval{scene.disparityMin, scene.disparityMax};
      outlines.push_back(delineation::delineate(left, right, *req, params).polygon);
    } catch (const std::exception& e) {
      std::printf("  scene %d proposal %.0f failed: %s\n", scene.seed,
                  core::numberProperty(f, "id", 9e15).value_or(-1), e.what());
    }
  }
  scoreProposals(outlines, scene, 100.0, score);
}

// One scene: its segmentation (--ground), each variant's classification, the proposals from the
// true disparity and, with --chain, the automatic chain.
void runScene(const sim::Scene& scene, const Options& o, const std::vector<Variant>& variants,
              const ClassifyParams& classifyParams, Totals& totals) {
  const ObjectParams objectParams;
  const bool needMap = o.chain || o.ground == "matcher";
  const cv::Mat map = needMap ? bench::matchScene(scene) : cv::Mat();
  const GroundSegmentation seg = o.ground == "truth" ? truthSegmentation(scene)
                                 : o.ground == "matcher"
                                     ? demSegmentation(bench::sceneHeights(scene, map), scene.gsd)
                                     : demSegmentation(scene.dem, scene.gsd);
  for (size_t v = 0; v < variants.size(); ++v) {
    const auto t0 = cv::getTickCount();
    const Classification c =
        classify(scene.left, seg.aboveGround, seg.ndsm, scene.gsd, variants[v].params, seg.regions);
    if (v == 0) totals.classifyMs += 1e3 * double(cv::getTickCount() - t0) / cv::getTickFrequency();
    totals.tallies[v].add(variants[v].majority ? c.labels : c.pixelLabels, scene.labels);
  }
  // Proposals with the true disparity (intervals and ground from the truth).
  const Detection d =
      detectBuildings(scene.left, seg.aboveGround, seg.ndsm, scene.gsd, scene.disparity,
                      seg.regions, classifyParams, objectParams, o.detect);
  std::vector<core::Polygon> polygons;
  for (const auto& f : d.proposals) polygons.push_back(f.polygon);
  scoreProposals(polygons, scene, 100.0, totals.gtScore);
  if (o.chain) runChain(scene, map, seg, classifyParams, objectParams, o.detect, totals.chainScore);
}

void printTables(const Options& o, const std::vector<Variant>& variants, const Totals& totals) {
  std::printf(
      "building vs vegetation on %d scenes %dx%d, slope %.0f %%, above-ground mask and DTM: %s\n",
      o.scenes, o.scene.width, o.scene.height, o.scene.slope,
      o.ground == "truth"     ? "true labels"
      : o.ground == "matcher" ? "segmented matcher DEM"
                              : "segmented true DEM");
  std::printf("  %-34s %8s  %8s  %8s  %9s  %9s\n", "variant", "right", "of found", "no facade", "bld->veg",
              "veg->bld");
  for (size_t v = 0; v < variants.size(); ++v) totals.tallies[v].print(variants[v].name);
  std::printf("  classification time %.0f ms per scene\n",
              totals.classifyMs / std::max(1, o.scenes));
  std::printf("proposals (buildings >= 100 m2, IoU >= 0.5)\n");
  printScore("from the true disparity", totals.gtScore);
  if (o.chain) printScore("matcher + active polygon", totals.chainScore);
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  std::optional<Options> options = parseOptions(argc, argv);
  if (!options) return 2;
  ClassifyParams classifyParams;
  if (const char* json = std::getenv("BENCH_CLASSIFY"))
    core::fromJson(classifyParams, nlohmann::json::parse(json));
  if (!options->realDir.empty()) {
    std::printf("real tiles (%s)\n", options->realDir.c_str());
    realTiles(options->realDir, options->realOut, classifyParams);
    return 0;
  }
  const std::vector<Variant> variants = ablations(classifyParams);
  Totals totals;
  totals.tallies.resize(variants.size());
  for (int s = 0; s < options->scenes; ++s) {
    options->scene.seed = options->firstSeed + s;
    runScene(sim::simulateScene(options->scene), *options, variants, classifyParams, totals);
  }
  printTables(*options, variants, totals);
  return 0;
}
