// Benchmark of box-fitting (docs/boxfit.md).
//
// Simulated scenes (default): every building from a rough rectangle (the true outline's box grown
// by 8 px, as the active polygon's benchmark), on the simulator's true DEM and on the DEM of the
// matcher's disparity map; IoU against the true outline, per shape group (rectangles; L, T and
// U; courtyards; angled), time per building (CPU time of the thread), and the whole-image mode
// (no init: every building segment) matched to the truth by overlap.
//
// Real roofs (`--real`): the hand-labelled roofs of tests/bench/data/real_roofs.json from the
// labelled box grown by --grow px (30), heights from the matcher's disparity map (cached as in
// bench_real_outlines) at 0.25 m per px of disparity, beside the active polygon from the same
// rectangle and its proposed roof interval. Skips cleanly when the data folder is missing.
//
// `--dump DIR` draws each run over the left image: true outline green, init blue, segment border
// yellow, seeds magenta, boxes cyan, outline red; beside it the Canny edges and the segment, and
// the heights above the local ground (colour map up to 1.25 x the roof height, segment white).
// `--tiny` is the ctest smoke run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/boxfit/box_fitting.hpp"
#include "delineo/boxfit/stages.hpp"
#include "delineo/core/allocator.hpp"
#include "delineo/core/error.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/delineation/roof_interval.hpp"
#include "delineo/eval/footprint_metrics.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/match.hpp"
#include "bench_image.hpp"
#include "real_roofs.hpp"
#include "shared_data.hpp"

namespace fs = std::filesystem;
using namespace delineo;

namespace {

double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? std::nan("") : s / static_cast<double>(v.size());
}
double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}
double maximum(const std::vector<double>& v) { return v.empty() ? std::nan("") : *std::max_element(v.begin(), v.end()); }

double iou(const core::Polygon& a, const core::Polygon& b) {
  if (a.outer.size() < 3) return 0.0;
  return eval::compareFootprints(a, b).iou;
}

std::string text(const core::Feature& f, const char* key) {
  const auto it = f.attributes.find(key);
  if (it == f.attributes.end()) return "-";
  if (const auto* s = std::get_if<std::string>(&it->second)) return *s;
  return "-";
}

std::string shapeGroup(const std::string& shape) {
  if (shape == "rect") return "rectangles";
  if (shape == "L" || shape == "T" || shape == "U") return "L/T/U";
  return shape;  // courtyard, angled
}

core::Polygon grownBox(const core::Polygon& p, double g, cv::Size size) {
  const cv::Rect2d b = core::boundingBox(p.outer);
  const double x0 = std::max(0.0, b.x - g), y0 = std::max(0.0, b.y - g);
  const double x1 = std::min<double>(size.width, b.x + b.width + g), y1 = std::min<double>(size.height, b.y + b.height + g);
  return {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, {}};
}

void drawRing(cv::Mat& img, const core::Ring& ring, cv::Point2d origin, double k, cv::Scalar colour, int thickness = 1) {
  std::vector<cv::Point> pts;
  for (const auto& v : ring) pts.emplace_back(static_cast<int>(std::lround((v.x - origin.x) * k)), static_cast<int>(std::lround((v.y - origin.y) * k)));
  if (pts.size() >= 2) cv::polylines(img, pts, true, colour, thickness);
}

void drawPolygon(cv::Mat& img, const core::Polygon& p, cv::Point2d origin, double k, cv::Scalar colour, int thickness = 1) {
  drawRing(img, p.outer, origin, k, colour, thickness);
  for (const auto& h : p.holes) drawRing(img, h, origin, k, colour, thickness);
}

void dump(const std::string& path, const cv::Mat& left, const boxfit::BoxFitBuilding* b, const cv::Rect& roiHint,
          const core::Polygon& truth, const core::Polygon& init, const boxfit::BoxFitParams& params,
          const core::Polygon* other = nullptr) {
  const cv::Rect roi = b ? b->roi : roiHint;
  const int k = std::max(1, std::min(4, 900 / std::max(roi.width, roi.height)));
  cv::Mat img;
  cv::normalize(left(roi), img, 0, 255, cv::NORM_MINMAX, CV_8U);
  const cv::Mat edges = boxfit::boxEdges(left(roi), params);
  cv::resize(img, img, {}, k, k, cv::INTER_NEAREST);
  cv::cvtColor(img, img, cv::COLOR_GRAY2BGR);
  cv::Mat side(roi.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  if (b && !b->diagnostics.segment.empty()) {
    side.setTo(cv::Scalar(70, 70, 70), b->diagnostics.segment);
    side.setTo(cv::Scalar(160, 0, 160), boxfit::skeletonSeeds(b->diagnostics.segment, params).skeleton);
  }
  side.setTo(cv::Scalar(255, 255, 255), edges);
  cv::resize(side, side, {}, k, k, cv::INTER_NEAREST);
  const cv::Point2d origin(roi.x, roi.y);
  for (cv::Mat* m : {&img, &side}) {
    drawPolygon(*m, truth, origin, k, {0, 200, 0});
    drawPolygon(*m, init, origin, k, {255, 80, 0});
    if (other) drawPolygon(*m, *other, origin, k, {0, 220, 255});
    if (!b) continue;
    for (const auto& box : b->boxes) drawRing(*m, box.corners(), origin, k, {255, 255, 0});
    for (const auto& s : b->diagnostics.seeds) cv::circle(*m, cv::Point2d((s.x - origin.x) * k, (s.y - origin.y) * k), 2, {255, 0, 255}, cv::FILLED);
    drawPolygon(*m, b->outline, origin, k, {0, 0, 255}, 2);
  }
  if (b && !b->diagnostics.segment.empty()) {
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(b->diagnostics.segment.clone(), contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
    for (auto& c : contours) {
      for (auto& p : c) p = p * k + cv::Point(k / 2, k / 2);
    }
    cv::drawContours(img, contours, -1, {0, 255, 255}, 1);
  }
  cv::Mat both;
  cv::hconcat(img, side, both);
  if (b && !b->diagnostics.aboveGround.empty()) {
    // Third panel: heights above the local ground, 0 to 1.25 x the roof height (colour map),
    // with the segment's border (white) and the truth (green).
    cv::Mat h8;
    b->diagnostics.aboveGround.convertTo(h8, CV_8U, 255.0 / (1.25 * std::max(0.1, b->diagnostics.roofHeight)));
    cv::Mat heights;
    cv::applyColorMap(h8, heights, cv::COLORMAP_JET);
    cv::resize(heights, heights, {}, k, k, cv::INTER_NEAREST);
    drawPolygon(heights, truth, origin, k, {0, 255, 0});
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(b->diagnostics.segment.clone(), contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
    for (auto& c : contours) {
      for (auto& p : c) p = p * k + cv::Point(k / 2, k / 2);
    }
    cv::drawContours(heights, contours, -1, {255, 255, 255}, 1);
    cv::hconcat(both, heights, both);
  }
  bench::writeImage(path, both);
}

struct Tally {
  std::map<std::string, std::vector<double>> iou;  // by group, and "all"
  std::vector<double> ms;
  std::map<std::string, std::vector<double>> msByGroup;
  int failed = 0;
};

void printTally(const char* name, const Tally& t) {
  std::printf("  %s: mean IoU", name);
  for (const char* g : {"rectangles", "L/T/U", "courtyard", "angled", "all"}) {
    const auto it = t.iou.find(g);
    if (it != t.iou.end()) std::printf("  %s %.3f (%zu)", g, mean(it->second), it->second.size());
  }
  std::printf("; no outline %d\n", t.failed);
  std::printf("    time per building: median %.0f ms, max %.0f ms; L/T/U median %.0f max %.0f ms\n", median(t.ms), maximum(t.ms),
              median(t.msByGroup.count("L/T/U") ? t.msByGroup.at("L/T/U") : std::vector<double>{}),
              maximum(t.msByGroup.count("L/T/U") ? t.msByGroup.at("L/T/U") : std::vector<double>{}));
}

int simulated(int scenes, int firstSeed, sim::SceneParams sceneParams, const boxfit::BoxFitParams& params,
              const std::string& dumpDir, bool withMatcher) {
  std::printf("%-5s %-3s %-9s %-6s %-7s %7s %6s %5s %5s %6s %s\n", "scene", "id", "shape", "roof", "dem", "IoU", "ms",
              "boxes", "verts", "E px", "note");
  std::map<std::string, Tally> tallies;  // by DEM source
  std::map<std::string, std::vector<double>> autoIou;
  std::map<std::string, int> autoFound, autoFalse, autoTruth;
  for (int s = 0; s < scenes; ++s) {
    sceneParams.seed = firstSeed + s;
    const sim::Scene scene = sim::simulateScene(sceneParams);
    cv::Mat left;
    scene.left.convertTo(left, CV_32F);
    std::map<std::string, cv::Mat> dems{{"true", scene.dem}};
    if (withMatcher) {
      stereo::MatchParams mp;
      mp.dmin = scene.disparityMin;
      mp.dmax = scene.disparityMax;
      cv::Mat right;
      scene.right.convertTo(right, CV_32F);
      const auto match = stereo::matchStereo(left, right, mp);
      dems["matcher"] = boxfit::heightsFromDisparity(match.disparity, scene.groundDisparity, scene.metresPerDisparity);
    }
    for (const auto& [demName, dem] : dems) {
      Tally& tally = tallies[demName];
      for (const auto& fp : scene.footprints) {
        const int id = static_cast<int>(std::get<long long>(fp.attributes.at("id")));
        const std::string shape = text(fp, "shape"), group = shapeGroup(shape);
        boxfit::BoxFitRequest request;
        request.init = grownBox(fp.polygon, 8, left.size());
        const double t0 = cpuMs();
        const auto result = boxfit::fitBoxes(dem, left, request, params);
        const double ms = cpuMs() - t0;
        const boxfit::BoxFitBuilding* b = result.buildings.empty() ? nullptr : &result.buildings.front();
        const double score = b ? iou(b->outline, fp.polygon) : 0.0;
        tally.iou[group].push_back(score);
        tally.iou["all"].push_back(score);
        tally.ms.push_back(ms);
        tally.msByGroup[group].push_back(ms);
        tally.failed += b == nullptr;
        std::printf("%-5d %-3d %-9s %-6s %-7s %7.3f %6.0f %5zu %5d %6.2f %s\n", sceneParams.seed, id, shape.c_str(),
                    text(fp, "roof_type").c_str(), demName.c_str(), score, ms, b ? b->boxes.size() : 0,
                    b ? b->diagnostics.vertices : 0, b ? b->energy : 0.0, b ? "" : result.message.c_str());
        if (b && std::getenv("BENCH_VERBOSE")) {
          const auto& d = b->diagnostics;
          // Where the outline and the segment go wrong: area outside the truth (extra) and truth
          // area they miss, in % of the truth's area.
          const cv::Mat t = core::rasterize(fp.polygon, left.size()) > 0;
          const cv::Mat o = core::rasterize(b->outline, left.size()) > 0;
          cv::Mat sg = cv::Mat::zeros(left.size(), CV_8U);
          d.segment.copyTo(sg(b->roi));
          const double ta = std::max(1, cv::countNonZero(t));
          std::printf("      outline extra %.0f %% missed %.0f %%; segment extra %.0f %% missed %.0f %%\n",
                      100.0 * cv::countNonZero(o & ~t) / ta, 100.0 * cv::countNonZero(t & ~o) / ta,
                      100.0 * cv::countNonZero(sg & ~t) / ta, 100.0 * cv::countNonZero(t & ~sg) / ta);
          std::printf("      roof %.1f m thr %.1f m seg %d px skel %d junctions %d seeds %zu skipped %d angles %d "
                      "main %.0f deg (%d boxes) merged %d px; ms seg %.1f seeds %.1f boxes %.1f outline %.1f\n",
                      d.roofHeight, d.threshold, d.segmentArea, d.skeletonPixels, d.junctions, d.seeds.size(), d.seedsSkipped, d.anglesEvaluated, d.mainOrientationDeg, d.boxesAtMainOrientation, d.mergedArea,
                      d.segmentMs, d.seedsMs, d.boxesMs, d.outlineMs);
        }
        if (!dumpDir.empty()) {
          dump(dumpDir + "/s" + std::to_string(sceneParams.seed) + "_b" + std::to_string(id) + "_" + demName + ".png", left, b,
               grownBox(fp.polygon, 24, left.size()).outer.empty() ? cv::Rect() : cv::Rect(core::boundingBox(grownBox(fp.polygon, 24, left.size()).outer)),
               fp.polygon, request.init, params);
        }
      }
      // Whole-image mode: every segment, matched to the truth by overlap.
      const auto all = boxfit::fitBoxes(dem, left, {}, params);
      std::vector<core::Polygon> predicted, truth;
      for (const auto& b : all.buildings) predicted.push_back(b.outline);
      for (const auto& fp : scene.footprints) truth.push_back(fp.polygon);
      eval::FootprintMetricsParams mp;
      mp.matchIou = 0.5;
      const auto ev = eval::evaluateFootprints(predicted, truth, mp);
      for (const auto& m : ev.matches) autoIou[demName].push_back(m.scores.iou);
      autoFound[demName] += static_cast<int>(ev.matches.size());
      autoFalse[demName] += static_cast<int>(ev.falsePredictions.size());
      autoTruth[demName] += static_cast<int>(truth.size());
    }
  }
  std::printf("\nsummary (init: true outline's box + 8 px)\n");
  for (const auto& [name, t] : tallies) printTally((name + " DEM").c_str(), t);
  std::printf("  whole-image mode (no init; matched at IoU > 0.5):\n");
  for (const auto& [name, v] : autoIou) {
    std::printf("    %s DEM: %d of %d buildings found, mean IoU of the found %.3f, %d other outlines (trees, merged)\n",
                name.c_str(), autoFound[name], autoTruth[name], mean(v), autoFalse[name]);
  }
  return 0;
}

int real(const std::string& dataRoot, const std::string& labels, const std::string& cache, int grow,
         const boxfit::BoxFitParams& params, const std::string& dumpDir, bool withActive) {
  if (!fs::is_directory(dataRoot)) {
    std::printf("skipped: no data folder %s\n", dataRoot.c_str());
    return 0;
  }
  std::ifstream in(labels);
  const nlohmann::json data = nlohmann::json::parse(in);
  constexpr double kMetresPerPixel = 0.25;  // as the GUI scenario's height model on Toulouse
  bench::RealPairs pairs(data, dataRoot, cache);
  std::map<std::string, std::vector<double>> boxIou, activeIou, boxMs, boxVerts, activeVerts;
  std::printf("%-18s %-9s | %-7s %5s %5s %6s | %-7s %5s | %s\n", "roof", "set", "boxfit", "verts", "boxes", "ms", "active",
              "verts", "note");
  for (const auto& roof : data.at("roofs")) {
    const std::string name = roof.at("name"), pairName = roof.at("pair");
    if (const char* only = std::getenv("BENCH_ONLY"); only && name != only) continue;
    const bench::RealPair* pair = pairs.get(pairName);
    if (!pair) continue;
    const int dmin = pair->dmin, dmax = pair->dmax;
    const cv::Mat& disparity = pair->disparity;
    const cv::Mat heights = boxfit::heightsFromDisparity(disparity, 0.0, kMetresPerPixel);
    const core::Polygon truth = bench::ringOf(roof.at("outline"));
    const core::Polygon rect = grownBox(truth, grow, disparity.size());
    const std::string set = roof.value("heldOut", false) ? "held-out" : "tuning";
    boxfit::BoxFitRequest request;
    request.init = rect;
    const double t0 = cpuMs();
    const auto result = boxfit::fitBoxes(heights, pair->left, request, params);
    const double ms = cpuMs() - t0;
    const boxfit::BoxFitBuilding* b = result.buildings.empty() ? nullptr : &result.buildings.front();
    const double bi = b ? iou(b->outline, truth) : 0.0;
    boxIou[set].push_back(bi);
    boxMs[set].push_back(ms);
    if (b) boxVerts[set].push_back(b->diagnostics.vertices);
    double ai = std::nan("");
    int av = 0;
    core::Polygon active;
    if (withActive) {
      const auto proposal = delineation::proposeRoofInterval(disparity, rect, delineation::RoofIntervalParams{});
      if (proposal.found) {
        delineation::DelineationRequest dr;
        dr.init = rect;
        dr.roof = {proposal.low, proposal.high};
        dr.searchRange = delineation::DisparityInterval{dmin, dmax};
        dr.disparity = disparity;  // as the GUI and `run` give it (the map's costs and ground)
        try {
          const auto r = delineation::delineate(pair->left, pair->right, dr, {});
          active = r.polygon;
          ai = iou(r.polygon, truth);
          av = r.vertexCount;
          activeIou[set].push_back(ai);
          activeVerts[set].push_back(av);
        } catch (const core::Error& e) {
          std::printf("  active polygon failed: %s\n", e.what());
        }
      }
    }
    std::printf("%-18s %-9s | %7.3f %5d %5zu %6.0f | %7.3f %5d | %s\n", name.c_str(), set.c_str(), bi,
                b ? b->diagnostics.vertices : 0, b ? b->boxes.size() : 0, ms, ai, av, b ? "" : result.message.c_str());
    if (!dumpDir.empty()) {
      dump((fs::path(dumpDir) / (name + ".png")).string(), pair->left, b, cv::Rect(core::boundingBox(rect.outer)), truth,
           rect, params, withActive ? &active : nullptr);
    }
  }
  std::printf("\nreal roofs (rectangle = labelled box + %d px, heights at %.2f m per px of disparity):\n", grow, kMetresPerPixel);
  for (const auto& [set, v] : boxIou) {
    std::printf("  %s, %zu roofs: box-fitting mean IoU %.3f, median vertices %.0f, time median %.0f ms max %.0f ms",
                set.c_str(), v.size(), mean(v), median(boxVerts[set]), median(boxMs[set]), maximum(boxMs[set]));
    if (withActive) std::printf("; active polygon mean IoU %.3f, median vertices %.0f", mean(activeIou[set]), median(activeVerts[set]));
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  int scenes = 3, firstSeed = 1, grow = 30;
  bool tiny = false, realMode = false, withMatcher = true, withActive = true;
  std::string dumpDir, dataRoot = bench::defaultDataRoot(), labels = DELINEO_BENCH_DATA_DIR "/real_roofs.json";
  std::string cache = bench::defaultDisparityCache().string();
  sim::SceneParams sceneParams;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--tiny")) {
      tiny = true;
    } else if (!std::strcmp(argv[i], "--scenes") && i + 1 < argc) {
      scenes = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) {
      firstSeed = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--dump") && i + 1 < argc) {
      dumpDir = argv[++i];
    } else if (!std::strcmp(argv[i], "--no-matcher")) {
      withMatcher = false;
    } else if (!std::strcmp(argv[i], "--real")) {
      realMode = true;
    } else if (!std::strcmp(argv[i], "--no-active")) {
      withActive = false;
    } else if (!std::strcmp(argv[i], "--grow") && i + 1 < argc) {
      grow = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--data") && i + 1 < argc) {
      dataRoot = argv[++i];
    } else if (!std::strcmp(argv[i], "--cache") && i + 1 < argc) {
      cache = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_boxfit [--tiny] [--scenes N] [--seed FIRST] [--no-matcher] [--dump DIR]\n"
                   "       bench_boxfit --real [--grow PX] [--no-active] [--data DIR] [--cache DIR] [--dump DIR]\n"
                   "BENCH_PARAMS='{...}' overrides box-fitting parameters; BENCH_VERBOSE=1 prints the diagnostics\n");
      return 2;
    }
  }
  boxfit::BoxFitParams params;
  if (const char* json = std::getenv("BENCH_PARAMS")) core::fromJson(params, nlohmann::json::parse(json));
  if (realMode) return real(dataRoot, labels, cache, grow, params, dumpDir, withActive);
  if (tiny) {
    scenes = 1;
    sceneParams.width = 320;
    sceneParams.height = 240;
    sceneParams.buildings = 3;
    sceneParams.trees = 2;
  }
  return simulated(scenes, firstSeed, sceneParams, params, dumpDir, withMatcher);
}
