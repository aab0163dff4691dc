// Benchmark of DEM enhancement from footprints (docs/dem-enhancement.md).
//
// Simulated scenes: the matcher's disparity turned into heights by the height model
// (project::HeightModel, as the GUI derives its DEM), enhanced from the true footprints and from
// the active polygon's outlines (initialised on the true outline's box grown by 8 px); RMS height
// error against the simulator's DEM near the walls (pixels within --eval-band px of a true
// outline, on both sides), on the roofs (inside, farther) and on the ground (outside, farther),
// before and after, on the pixels where both DEMs and the truth have a height.
// Real pairs (skipped without the data folder): the hand-labelled roofs of
// tests/bench/data/real_roofs.json on the Toulouse pairs, with the roof heights' spread and the
// share of the outer band at roof height before and after; --png DIR writes the DEMs before and
// after (colour and hillshade, outlines in white) to look at. Dublin against its LiDAR, with its
// hand-labelled roof and with the footprints the LiDAR gives.
// `--tiny` is the ctest smoke run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <nlohmann/json.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/nan_mask.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/dem/enhance.hpp"
#include "delineo/project/project.hpp"
#include "delineo/segmentation/objects.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/match.hpp"
#include "bench_image.hpp"
#include "lidar.hpp"
#include "real_roofs.hpp"
#include "shared_data.hpp"

using namespace delineo;
namespace fs = std::filesystem;

namespace {

double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

struct Rms {
  double sum = 0;
  long long n = 0;
  double value() const { return n > 0 ? std::sqrt(sum / static_cast<double>(n)) : std::nan(""); }
};

// Evaluation regions from the true footprints: walls = within `band` px of an outline on either
// side; roofs and ground beyond.
struct Regions {
  cv::Mat walls, roofs, ground;
};
Regions regionsOf(const std::vector<core::Polygon>& footprints, cv::Size size, int band) {
  cv::Mat inside = cv::Mat::zeros(size, CV_8U);
  for (const auto& p : footprints) inside |= core::rasterize(p, size);
  cv::Mat depth, away;
  cv::distanceTransform(inside, depth, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::distanceTransform(inside == 0, away, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  Regions r;
  r.walls = (inside & (depth <= band)) | ((inside == 0) & (away <= band));
  r.roofs = inside & (depth > band);
  r.ground = (inside == 0) & (away > band);
  return r;
}

// Squared errors of `before` and `after` against `truth` on `mask`, where all three have a value.
void tally(const cv::Mat& before, const cv::Mat& after, const cv::Mat& truth, const cv::Mat& mask,
           Rms& b, Rms& a) {
  for (int y = 0; y < truth.rows; ++y) {
    for (int x = 0; x < truth.cols; ++x) {
      if (mask.at<uchar>(y, x) == 0) continue;
      const double t = truth.at<float>(y, x), u = before.at<float>(y, x), v = after.at<float>(y, x);
      if (!std::isfinite(t) || !std::isfinite(u) || !std::isfinite(v)) continue;
      b.sum += (u - t) * (u - t);
      a.sum += (v - t) * (v - t);
      ++b.n;
      ++a.n;
    }
  }
}

core::Polygon grownBox(const core::Polygon& p, double grow) {
  const cv::Rect2d b = core::boundingBox(p.outer);
  core::Polygon box;
  box.outer = {{b.x - grow, b.y - grow},
               {b.br().x + grow, b.y - grow},
               {b.br().x + grow, b.br().y + grow},
               {b.x - grow, b.br().y + grow}};
  return box;
}

double number(const core::Feature& f, const char* key) {
  const auto it = f.attributes.find(key);
  if (it == f.attributes.end()) return 0.0;
  if (const auto* d = std::get_if<double>(&it->second)) return *d;
  if (const auto* i = std::get_if<long long>(&it->second)) return static_cast<double>(*i);
  return 0.0;
}

cv::Mat heightsFrom(const cv::Mat& disparity, const project::HeightModel& model) {
  cv::Mat dem(disparity.size(), CV_32F);
  for (int y = 0; y < dem.rows; ++y) {
    for (int x = 0; x < dem.cols; ++x) {
      dem.at<float>(y, x) = static_cast<float>(model.heightAt(disparity.at<float>(y, x)));
    }
  }
  return dem;
}

// Outlines by the active polygon, one per true footprint (failures left out); `raw` takes the
// active polygon's own outline instead of the regularized one. `index` receives the true
// footprint of each outline.
std::vector<core::Polygon> activePolygonOutlines(const sim::Scene& scene, bool raw, int& failed,
                                                 std::vector<size_t>& index) {
  cv::Mat left, right;
  scene.left.convertTo(left, CV_32F);
  scene.right.convertTo(right, CV_32F);
  const delineation::DelineationParams params;
  std::vector<core::Polygon> out;
  for (size_t k = 0; k < scene.footprints.size(); ++k) {
    const auto& fp = scene.footprints[k];
    delineation::DelineationRequest req;
    req.init = grownBox(fp.polygon, 8);
    req.roof = {static_cast<int>(std::floor(number(fp, "roof_disparity_min"))),
                static_cast<int>(std::ceil(number(fp, "roof_disparity_max")))};
    const int g = static_cast<int>(std::lround(number(fp, "ground_disparity")));
    req.ground = delineation::DisparityInterval{g - params.groundTolerance, g + params.groundTolerance};
    try {
      const auto result = delineation::delineate(left, right, req, params);
      out.push_back(raw ? result.rawPolygon : result.polygon);
      index.push_back(k);
    } catch (const core::Error& e) {
      std::fprintf(stderr, "active polygon failed: %s\n", e.what());
      ++failed;
    }
  }
  return out;
}

// Colour by height between lo and hi, shaded by a hillshade (sun from the north-west), NaN black.
cv::Mat render(const cv::Mat& dem, double lo, double hi, double gsd) {
  cv::Mat filled = dem.clone();
  filled.setTo(static_cast<float>(lo), core::nanMask(dem));
  cv::Mat dx, dy;
  cv::Sobel(filled, dx, CV_32F, 1, 0, 3, 1.0 / (8.0 * gsd));
  cv::Sobel(filled, dy, CV_32F, 0, 1, 3, 1.0 / (8.0 * gsd));
  cv::Mat grey;
  filled.convertTo(grey, CV_8U, 255.0 / (hi - lo), -lo * 255.0 / (hi - lo));
  cv::Mat colour;
  cv::applyColorMap(grey, colour, cv::COLORMAP_VIRIDIS);
  const cv::Vec3d sun = cv::normalize(cv::Vec3d(-1, -1, 1.2));
  for (int y = 0; y < dem.rows; ++y) {
    for (int x = 0; x < dem.cols; ++x) {
      auto& c = colour.at<cv::Vec3b>(y, x);
      if (!std::isfinite(dem.at<float>(y, x))) {
        c = {0, 0, 0};
        continue;
      }
      const cv::Vec3d n = cv::normalize(cv::Vec3d(-dx.at<float>(y, x), -dy.at<float>(y, x), 1));
      const double shade = 0.35 + 0.65 * std::max(0.0, n.dot(sun));
      for (int k = 0; k < 3; ++k) c[k] = cv::saturate_cast<uchar>(c[k] * shade);
    }
  }
  return colour;
}

void drawOutlines(cv::Mat& image, const std::vector<core::Polygon>& outlines) {
  for (const auto& p : outlines) {
    std::vector<cv::Point> pts;
    for (const auto& v : p.outer) pts.emplace_back(cvRound(v.x), cvRound(v.y));
    cv::polylines(image, pts, true, cv::Scalar(255, 255, 255), 1);
  }
}


// Per building k (pixels nearest to true footprint k): the outline's IoU with the truth, its
// pixels outside the truth and the truth's pixels it misses, and the RMS near the walls and on
// the roof before and after.
void printPerBuilding(int seed, const std::vector<core::Polygon>& truth,
                      const std::vector<core::Polygon>& outlines, const std::vector<size_t>& index,
                      const Regions& regions, const cv::Mat& before, const cv::Mat& after,
                      const cv::Mat& trueDem) {
  const cv::Size size = before.size();
  cv::Mat nearest(size, CV_32S, cv::Scalar(-1)), best(size, CV_32F, cv::Scalar(1e9));
  std::vector<cv::Mat> inside;
  for (size_t k = 0; k < truth.size(); ++k) {
    inside.push_back(core::rasterize(truth[k], size));
    cv::Mat away;
    cv::distanceTransform(inside[k] == 0, away, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    const cv::Mat closer = away < best;
    away.copyTo(best, closer);
    nearest.setTo(static_cast<int>(k), closer);
  }
  for (size_t i = 0; i < outlines.size(); ++i) {
    const size_t k = index[i];
    const cv::Mat mine = nearest == static_cast<int>(k);
    const cv::Mat got = core::rasterize(outlines[i], size);
    const int both = cv::countNonZero(got & inside[k]), extra = cv::countNonZero(got & ~inside[k]),
              missed = cv::countNonZero(inside[k] & ~got);
    Rms wb, wa, rb, ra;
    tally(before, after, trueDem, regions.walls & mine, wb, wa);
    tally(before, after, trueDem, regions.roofs & mine, rb, ra);
    std::printf("seed %d building %2zu: IoU %.3f extra %4d missed %4d | walls %6.3f -> %6.3f | "
                "roofs %6.3f -> %6.3f\n",
                seed, k, static_cast<double>(both) / (both + extra + missed), extra, missed,
                wb.value(), wa.value(), rb.value(), ra.value());
  }
}

// Error profile across the true outlines: RMS and mean error of `dem` at each signed distance
// from the nearest true outline (negative inside), accumulated into `sum`, `sq`, `n`.
struct Profile {
  static constexpr int kReach = 8;
  double sum[2 * kReach + 1] = {}, sq[2 * kReach + 1] = {};
  long long n[2 * kReach + 1] = {};
  void add(const cv::Mat& dem, const cv::Mat& before, const cv::Mat& truthDem,
           const cv::Mat& signedDistance) {
    for (int y = 0; y < dem.rows; ++y) {
      for (int x = 0; x < dem.cols; ++x) {
        const int d = static_cast<int>(std::lround(signedDistance.at<float>(y, x)));
        const double e = dem.at<float>(y, x) - truthDem.at<float>(y, x);
        if (std::abs(d) > kReach || !std::isfinite(e) || !std::isfinite(before.at<float>(y, x))) continue;
        sum[d + kReach] += e;
        sq[d + kReach] += e * e;
        ++n[d + kReach];
      }
    }
  }
  void print(const char* name) const {
    std::printf("%-14s", name);
    for (int i = 0; i <= 2 * kReach; ++i) {
      std::printf(" %5.1f/%4.1f", n[i] ? sum[i] / n[i] : 0.0, n[i] ? std::sqrt(sq[i] / n[i]) : 0.0);
    }
    std::printf("\n");
  }
};

struct SimTotals {
  Profile profiles[3];  // before, after with true footprints, after with the active polygon's
  // [source][region]: source 0 = true footprints, 1 = active polygon; region walls/roofs/ground.
  Rms before[2][3], after[2][3];
  double enhanceMs = 0;
  int scenes = 0, buildings = 0, failed = 0, smallWindows = 0;
};

struct SimOptions {
  int scenes = 4, firstSeed = 1, size = 400, evalBand = 3;
  double obliquity = 0.0;
  bool activePolygon = true;
  bool rawOutlines = false;  // the active polygon's own outlines instead of the regularized ones
  bool perBuilding = false;
  std::string pngDir;
};

// Before | after (true footprints) | after (active polygon) with the true outlines in white and
// the active polygon's in red.
void writeScenePng(const std::string& dir, int seed, const cv::Mat& truthDem,
                   const std::vector<cv::Mat>& dems, const std::vector<core::Polygon>& truth,
                   const std::vector<core::Polygon>& active) {
  double lo = 0, hi = 0;
  cv::minMaxLoc(truthDem, &lo, &hi, nullptr, nullptr, core::numberMask(truthDem));
  std::vector<cv::Mat> panels;
  for (const cv::Mat& dem : dems) {
    cv::Mat panel = render(dem, lo, hi, 0.25);
    drawOutlines(panel, truth);
    for (const auto& p : active) {
      std::vector<cv::Point> pts;
      for (const auto& v : p.outer) pts.emplace_back(cvRound(v.x), cvRound(v.y));
      cv::polylines(panel, pts, true, cv::Scalar(0, 0, 255), 1);
    }
    panels.push_back(panel);
  }
  // Last panel: where the last enhancement made the error exceed 2 m (red) or brought it under
  // (green), over the true outlines.
  cv::Mat changes(truthDem.size(), CV_8UC3, cv::Scalar(40, 40, 40));
  for (int y = 0; y < truthDem.rows; ++y) {
    for (int x = 0; x < truthDem.cols; ++x) {
      const float t = truthDem.at<float>(y, x), b = dems.front().at<float>(y, x), a = dems.back().at<float>(y, x);
      if (!std::isfinite(b)) continue;
      const bool badBefore = std::abs(b - t) > 2, badAfter = std::abs(a - t) > 2;
      changes.at<cv::Vec3b>(y, x) = badAfter && !badBefore   ? cv::Vec3b(0, 0, 255)
                                    : badBefore && !badAfter ? cv::Vec3b(0, 200, 0)
                                    : badAfter               ? cv::Vec3b(0, 200, 255)
                                                             : cv::Vec3b(90, 90, 90);
    }
  }
  drawOutlines(changes, truth);
  panels.push_back(changes);
  cv::Mat all;
  cv::hconcat(panels, all);
  // One zoomed crop per building, the three panels side by side.
  for (size_t k = 0; k < truth.size(); ++k) {
    const cv::Rect2d b = core::boundingBox(truth[k].outer);
    const cv::Rect box = cv::Rect(cvFloor(b.x) - 12, cvFloor(b.y) - 12, cvCeil(b.width) + 24,
                                  cvCeil(b.height) + 24) &
                         cv::Rect(0, 0, truthDem.cols, truthDem.rows);
    std::vector<cv::Mat> crops;
    for (const cv::Mat& panel : panels) {
      cv::Mat zoomed;
      cv::resize(panel(box), zoomed, cv::Size(), 4, 4, cv::INTER_NEAREST);
      crops.push_back(zoomed);
    }
    cv::Mat row;
    cv::hconcat(crops, row);
    bench::writeImage((fs::path(dir) / ("sim_seed" + std::to_string(seed) + "_b" + std::to_string(k) + ".png")).string(), row);
  }
  const std::string path = (fs::path(dir) / ("sim_seed" + std::to_string(seed) + ".png")).string();
  bench::writeImage(path, all);
  std::printf("wrote %s (before, after with true, after with active-polygon outlines)\n", path.c_str());
}

void runSimulated(const SimOptions& o, const dem::EnhanceParams& params, SimTotals& totals) {
  for (int s = 0; s < o.scenes; ++s) {
    const int seed = o.firstSeed + s;
    sim::SceneParams sp = sim::squareSceneParams(o.size, seed);
    sp.leftObliquity = o.obliquity;
    const sim::Scene scene = sim::simulateScene(sp);
    stereo::MatchParams mp;
    mp.dmin = scene.disparityMin;
    mp.dmax = scene.disparityMax;
    cv::Mat left, right;
    scene.left.convertTo(left, CV_32F);
    scene.right.convertTo(right, CV_32F);
    const cv::Mat disparity = stereo::matchStereo(left, right, mp).disparity;
    project::HeightModel model;
    model.groundDisparity = scene.groundDisparity;
    model.metresPerPixel = scene.metresPerDisparity;
    const cv::Mat before = heightsFrom(disparity, model);
    std::vector<core::Polygon> truth;
    std::vector<size_t> trueIndex;
    for (const auto& f : scene.footprints) {
      truth.push_back(f.polygon);
      trueIndex.push_back(trueIndex.size());
    }
    const Regions regions = regionsOf(truth, before.size(), o.evalBand);
    cv::Mat signedDistance;
    {
      cv::Mat inside = cv::Mat::zeros(before.size(), CV_8U);
      for (const auto& p : truth) inside |= core::rasterize(p, before.size());
      cv::Mat depth, away;
      cv::distanceTransform(inside, depth, cv::DIST_L2, cv::DIST_MASK_PRECISE);
      cv::distanceTransform(inside == 0, away, cv::DIST_L2, cv::DIST_MASK_PRECISE);
      signedDistance = away - depth;
    }
    totals.profiles[0].add(before, before, scene.dem, signedDistance);
    std::vector<cv::Mat> dems{before};
    std::vector<core::Polygon> active;
    for (int source = 0; source < (o.activePolygon ? 2 : 1); ++source) {
      std::vector<size_t> index = trueIndex;
      if (source == 1) {
        index.clear();
        active = activePolygonOutlines(scene, o.rawOutlines, totals.failed, index);
      }
      const std::vector<core::Polygon>& outlines = source == 0 ? truth : active;
      const double t0 = cpuMs();
      const dem::EnhanceResult r = dem::enhanceDem(before, outlines, params);
      if (source == 0) {
        totals.enhanceMs += cpuMs() - t0;
        for (const auto& f : r.footprints) totals.smallWindows += f.window == params.smallWindow;
      }
      const cv::Mat* masks[3] = {&regions.walls, &regions.roofs, &regions.ground};
      for (int k = 0; k < 3; ++k) {
        tally(before, r.dem, scene.dem, *masks[k], totals.before[source][k], totals.after[source][k]);
      }
      if (o.perBuilding) {
        std::printf("%s footprints:\n", source == 0 ? "true" : "active polygon");
        printPerBuilding(seed, truth, outlines, index, regions, before, r.dem, scene.dem);
      }
      totals.profiles[source + 1].add(r.dem, before, scene.dem, signedDistance);
      dems.push_back(r.dem);
    }
    if (!o.pngDir.empty()) writeScenePng(o.pngDir, seed, scene.dem, dems, truth, active);
    totals.buildings += static_cast<int>(scene.footprints.size());
    ++totals.scenes;
  }
}

void printSimulated(const SimTotals& t, double obliquity, int evalBand, bool withActivePolygon) {
  std::printf("simulated: %d scenes, %d buildings, left obliquity %.2f, walls = within %d px of "
              "a true outline; %d roofs of %d on the small window; enhancement %.1f ms per scene "
              "(CPU)\n",
              t.scenes, t.buildings, obliquity, evalBand, t.smallWindows, t.buildings,
              t.enhanceMs / std::max(t.scenes, 1));
  std::printf("%-16s | %-8s %8s %8s %10s\n", "footprints", "region", "before", "after",
              "pixels");
  const char* sources[2] = {"true", "active polygon"};
  const char* regions[3] = {"walls", "roofs", "ground"};
  for (int s = 0; s < (withActivePolygon ? 2 : 1); ++s) {
    for (int k = 0; k < 3; ++k) {
      std::printf("%-16s | %-8s %8.3f %8.3f %10lld\n", sources[s], regions[k],
                  t.before[s][k].value(), t.after[s][k].value(), t.before[s][k].n);
    }
  }
  if (withActivePolygon) std::printf("active polygon failures: %d\n", t.failed);
  std::printf("mean/RMS error [m] by signed distance to the true outline, -%d..%d px (inside < 0)\n",
              Profile::kReach, Profile::kReach);
  t.profiles[0].print("before");
  t.profiles[1].print("after true");
  if (withActivePolygon) t.profiles[2].print("after active");
}

// --- real pairs -------------------------------------------------------------------------------

double percentileOf(std::vector<float> v, double q) {
  if (v.empty()) return std::nan("");
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<size_t>(k)];
}

std::vector<float> valuesIn(const cv::Mat& dem, const cv::Mat& mask) {
  std::vector<float> v;
  for (int y = 0; y < dem.rows; ++y) {
    for (int x = 0; x < dem.cols; ++x) {
      if (mask.at<uchar>(y, x) != 0 && std::isfinite(dem.at<float>(y, x))) v.push_back(dem.at<float>(y, x));
    }
  }
  return v;
}

void runReal(const std::string& dataRoot, const std::string& labels, const std::string& cache,
             const std::string& pngDir, const dem::EnhanceParams& params) {
  std::ifstream in(labels);
  const nlohmann::json data = nlohmann::json::parse(in);
  std::printf("\nreal pairs (heights: 0.25 m per px of disparity above the median disparity of "
              "the roofs' ground references; roof spread = 90th - 10th percentile inside the "
              "outline beyond the wall band; outer band at roof height = share of the %d px "
              "band outside the outline above the middle of ground and roof)\n",
              params.wallBand);
  std::printf("%-20s %6s %7s | %-15s | %-15s\n", "roof", "window", "h [m]", "spread b/a [m]",
              "band@roof b/a");
  for (const auto& [pairName, pair] : data.at("pairs").items()) {
    if (pairName.rfind("toulouse", 0) != 0) continue;
    const std::string left = (fs::path(dataRoot) / pair.at("left").get<std::string>()).string();
    const std::string right = (fs::path(dataRoot) / pair.at("right").get<std::string>()).string();
    if (!fs::exists(left) || !fs::exists(right)) {
      std::printf("skipped %s: %s missing\n", pairName.c_str(), left.c_str());
      continue;
    }
    const cv::Mat disparity = bench::disparityFor(pairName, left, right, pair.at("disparity_range").at(0),
                                                  pair.at("disparity_range").at(1), cache);
    std::vector<core::Polygon> roofs, grounds;
    std::vector<std::string> names;
    for (const auto& roof : data.at("roofs")) {
      if (roof.at("pair") != pairName) continue;
      roofs.push_back(bench::ringOf(roof.at("outline")));
      grounds.push_back(bench::ringOf(roof.at("ground")));
      names.push_back(roof.at("name"));
    }
    cv::Mat groundMask = cv::Mat::zeros(disparity.size(), CV_8U);
    for (const auto& g : grounds) groundMask |= core::rasterize(g, disparity.size());
    project::HeightModel model;
    model.groundDisparity = percentileOf(valuesIn(disparity, groundMask), 0.5);
    model.metresPerPixel = 0.25;
    model.gsd = 0.05;
    const cv::Mat before = heightsFrom(disparity, model);
    const double t0 = cpuMs();
    const dem::EnhanceResult r = dem::enhanceDem(before, roofs, params);
    const double ms = cpuMs() - t0;
    for (size_t i = 0; i < roofs.size(); ++i) {
      const cv::Mat inside = core::rasterize(roofs[i], before.size());
      cv::Mat depth, away;
      cv::distanceTransform(inside, depth, cv::DIST_L2, cv::DIST_MASK_PRECISE);
      cv::distanceTransform(inside == 0, away, cv::DIST_L2, cv::DIST_MASK_PRECISE);
      const cv::Mat roofCore = inside & (depth > params.wallBand);
      const cv::Mat band = (inside == 0) & (away <= params.wallBand);
      const double roofH = percentileOf(valuesIn(before, roofCore), 0.5);
      const double groundH = percentileOf(valuesIn(before, core::rasterize(grounds[i], before.size())), 0.5);
      auto spread = [&](const cv::Mat& dem) {
        const auto v = valuesIn(dem, roofCore);
        return percentileOf(v, 0.9) - percentileOf(v, 0.1);
      };
      auto atRoof = [&](const cv::Mat& dem) {
        const auto v = valuesIn(dem, band);
        const double mid = 0.5 * (roofH + groundH);
        return v.empty() ? std::nan("")
                         : static_cast<double>(std::count_if(v.begin(), v.end(), [&](float h) { return h > mid; })) /
                               static_cast<double>(v.size());
      };
      std::printf("%-20s %6d %7.1f | %6.2f / %6.2f | %6.2f / %6.2f\n", names[i].c_str(),
                  r.footprints[i].window, roofH - groundH, spread(before), spread(r.dem),
                  atRoof(before), atRoof(r.dem));
    }
    std::printf("%s: gradient threshold %.3f m/px, enhancement %.0f ms (CPU)\n", pairName.c_str(),
                r.gradientThreshold, ms);
    if (!pngDir.empty()) {
      const auto all = valuesIn(before, core::numberMask(before));
      const double lo = percentileOf(all, 0.01), hi = percentileOf(all, 0.99);
      cv::Mat a = render(before, lo, hi, model.gsd), b = render(r.dem, lo, hi, model.gsd);
      drawOutlines(a, roofs);
      drawOutlines(b, roofs);
      cv::Mat both;
      cv::hconcat(a, b, both);
      const std::string path = (fs::path(pngDir) / (pairName + "_dem_before_after.png")).string();
      bench::writeImage(path, both);
      std::printf("wrote %s (left: before, right: after)\n", path.c_str());
    }
  }
}

// The building footprints the LiDAR gives, as the simulated scenes' true footprints: the sparse
// LiDAR disparity (NaN where none) filled from its nearest value, the pixels more than `margin`
// px of disparity above its ground plane (bench::lidarGround), opened 7x7; each component of at
// least 2000 px traced (segmentation::traceMask, 1 px simplification, holes of 2000 px kept).
// Trees standing at building height join their building.
std::vector<core::Polygon> lidarFootprints(const cv::Mat& lidar, double margin) {
  cv::Mat distance, nearest;
  const cv::Mat valid = lidar == lidar;
  cv::distanceTransform(valid == 0, distance, nearest, cv::DIST_L2, 5, cv::DIST_LABEL_PIXEL);
  std::vector<float> valueOf(static_cast<size_t>(cv::countNonZero(valid)) + 2, 0.0f);
  for (int y = 0; y < lidar.rows; ++y) {
    for (int x = 0; x < lidar.cols; ++x) {
      if (valid.at<uchar>(y, x) != 0) valueOf[static_cast<size_t>(nearest.at<int>(y, x))] = lidar.at<float>(y, x);
    }
  }
  const cv::Mat ground = bench::lidarGround(lidar);
  cv::Mat above(lidar.size(), CV_8U);
  for (int y = 0; y < lidar.rows; ++y) {
    for (int x = 0; x < lidar.cols; ++x) {
      const float d = valueOf[static_cast<size_t>(nearest.at<int>(y, x))];
      above.at<uchar>(y, x) = d - ground.at<float>(y, x) > margin ? 255 : 0;
    }
  }
  cv::morphologyEx(above, above, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {7, 7}));
  cv::Mat labels;
  const int count = cv::connectedComponents(above, labels, 8, CV_32S);
  std::vector<core::Polygon> footprints;
  for (int k = 1; k < count; ++k) {
    const cv::Mat component = labels == k;
    if (cv::countNonZero(component) < 2000) continue;
    core::Polygon footprint = segmentation::traceMask(component, 1.0, 2000.0);
    if (footprint.outer.size() >= 3) footprints.push_back(std::move(footprint));
  }
  return footprints;
}

// The matcher's disparity map (as heights, 1 unit per px of disparity) before and after
// enhancement with `footprints`, scored on the LiDAR's valid pixels in the wall band (wallBand px
// on both sides of the outlines), the roofs' cores and everywhere else.
void scoreAgainstLidar(const char* what, const cv::Mat& disparity, const cv::Mat& truth, const cv::Mat& lidar,
                       const std::vector<core::Polygon>& footprints, const dem::EnhanceParams& params,
                       const std::string& png) {
  const dem::EnhanceResult r = dem::enhanceDem(disparity, footprints, params);
  if (!png.empty()) {
    // Heights in px of disparity: 0.2 px of image per px of disparity (0.034 / 0.17 m) shades them.
    cv::Mat a = render(disparity, 0, 150, 0.2), b = render(r.dem, 0, 150, 0.2), both;
    drawOutlines(a, footprints);
    drawOutlines(b, footprints);
    cv::hconcat(a, b, both);
    bench::writeImage(png, both);
    std::printf("wrote %s (left: before, right: after)\n", png.c_str());
  }
  cv::Mat inside = cv::Mat::zeros(disparity.size(), CV_8U);
  for (const auto& f : footprints) inside |= core::rasterize(f, disparity.size());
  cv::Mat depth, away;
  cv::distanceTransform(inside, depth, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::distanceTransform(inside == 0, away, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const double band = params.wallBand;
  const cv::Mat wall = ((inside != 0) & (depth <= band)) | ((inside == 0) & (away <= band));
  const cv::Mat core = (inside != 0) & (depth > band);
  const cv::Mat elsewhere = (inside == 0) & (away > band);
  // RMS of (dem - truth) over LiDAR pixels of `mask` with a value in `dem` (and in `also` when
  // given: both DEMs scored on the same pixels), and their count.
  auto rms = [&](const cv::Mat& dem, const cv::Mat& mask, const cv::Mat& also = cv::Mat()) {
    double sum = 0;
    int n = 0;
    for (int y = 0; y < dem.rows; ++y) {
      for (int x = 0; x < dem.cols; ++x) {
        const float d = dem.at<float>(y, x);
        if (mask.at<uchar>(y, x) == 0 || lidar.at<uchar>(y, x) == 0 || !std::isfinite(d)) continue;
        if (!also.empty() && !std::isfinite(also.at<float>(y, x))) continue;
        const double e = d - truth.at<float>(y, x);
        sum += e * e;
        ++n;
      }
    }
    return std::make_pair(n > 0 ? std::sqrt(sum / n) : std::nan(""), n);
  };
  std::printf("\ndublin_0004 against the LiDAR disparity, %s (%zu outline(s)); RMS in px of disparity, "
              "before / after: on the LiDAR pixels both have (pixels) | on those each has (pixels)\n",
              what, footprints.size());
  const std::pair<const char*, cv::Mat> zones[] = {{"wall band", wall}, {"roof core", core}, {"elsewhere", elsewhere}};
  for (const auto& [name, mask] : zones) {
    const auto [bc, n] = rms(disparity, mask, r.dem);
    const auto [ac, nc] = rms(r.dem, mask, disparity);
    const auto [b, nb] = rms(disparity, mask);
    const auto [a, na] = rms(r.dem, mask);
    std::printf("  %-10s %7.3f / %7.3f (%d) | %7.3f (%d) / %7.3f (%d)\n", name, bc, ac, n, b, nb, a, na);
    (void)nc;
  }
}

// Dublin against its LiDAR, enhanced with the hand outline of the one labelled roof, then with the
// building footprints the LiDAR itself gives (margin 2 m: 11.8 px of disparity at 0.17 m per px).
void runDublin(const std::string& dataRoot, const nlohmann::json& data, const std::string& cache,
               const std::string& pngDir, const dem::EnhanceParams& params) {
  const auto pairIt = data.at("pairs").find("dublin_0004");
  if (pairIt == data.at("pairs").end()) return;
  const nlohmann::json& pair = *pairIt;
  const std::string left = (fs::path(dataRoot) / pair.at("left").get<std::string>()).string();
  const std::string right = (fs::path(dataRoot) / pair.at("right").get<std::string>()).string();
  const std::string truthPath = (fs::path(dataRoot) / pair.at("ground_truth_disparity").get<std::string>()).string();
  if (!fs::exists(left) || !fs::exists(right) || !fs::exists(truthPath)) {
    std::printf("skipped dublin_0004: %s missing\n", left.c_str());
    return;
  }
  const cv::Mat disparity = bench::disparityFor("dublin_0004", left, right, pair.at("disparity_range").at(0),
                                                pair.at("disparity_range").at(1), cache);
  const cv::Mat truth = bench::readLidarDisparity(truthPath);
  const cv::Mat lidar = truth == truth;  // NaN: no LiDAR value
  std::vector<core::Polygon> roofs;
  for (const auto& roof : data.at("roofs")) {
    if (roof.at("pair") == "dublin_0004") roofs.push_back(bench::ringOf(roof.at("outline")));
  }
  const auto png = [&pngDir](const char* name) {
    return pngDir.empty() ? std::string() : (fs::path(pngDir) / name).string();
  };
  scoreAgainstLidar("hand outline", disparity, truth, lidar, roofs, params, png("dublin_0004_hand_dem_before_after.png"));
  scoreAgainstLidar("LiDAR footprints", disparity, truth, lidar, lidarFootprints(truth, 2.0 / 0.17), params,
                    png("dublin_0004_lidar_dem_before_after.png"));
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  SimOptions sim;
  bool tiny = false;
  std::string dataRoot = bench::defaultDataRoot(), labels = DELINEO_BENCH_DATA_DIR "/real_roofs.json";
  std::string cache = bench::defaultDisparityCache().string(), pngDir;
  dem::EnhanceParams params;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool more = i + 1 < argc;
    if (a == "--tiny") tiny = true;
    else if (a == "--scenes" && more) sim.scenes = std::atoi(argv[++i]);
    else if (a == "--seed" && more) sim.firstSeed = std::atoi(argv[++i]);
    else if (a == "--size" && more) sim.size = std::atoi(argv[++i]);
    else if (a == "--eval-band" && more) sim.evalBand = std::atoi(argv[++i]);
    else if (a == "--left-obliquity" && more) sim.obliquity = std::atof(argv[++i]);
    else if (a == "--no-active-polygon") sim.activePolygon = false;
    else if (a == "--raw-outlines") sim.rawOutlines = true;
    else if (a == "--per-building") sim.perBuilding = true;
    else if (a == "--params" && more) core::fromJson(params, nlohmann::json::parse(argv[++i]));
    else if (a == "--data" && more) dataRoot = argv[++i];
    else if (a == "--labels" && more) labels = argv[++i];
    else if (a == "--cache" && more) cache = argv[++i];
    else if (a == "--png" && more) pngDir = argv[++i];
    else {
      std::fprintf(stderr,
                   "usage: bench_enhance [--tiny] [--scenes N] [--seed S] [--size PX] "
                   "[--eval-band PX] [--left-obliquity A] [--no-active-polygon] [--raw-outlines] "
                   "[--per-building] [--params JSON] [--data DIR] [--labels FILE] [--cache DIR] "
                   "[--png DIR]\n");
      return 2;
    }
  }
  if (tiny) {
    sim.scenes = 1;
    sim.size = 200;
    sim.activePolygon = false;
  }
  sim.pngDir = pngDir;
  SimTotals totals;
  runSimulated(sim, params, totals);
  printSimulated(totals, sim.obliquity, sim.evalBand, sim.activePolygon);
  if (tiny) return 0;
  if (!fs::is_directory(dataRoot)) {
    std::printf("real pairs skipped: no data folder %s\n", dataRoot.c_str());
    return 0;
  }
  runReal(dataRoot, labels, cache, pngDir, params);
  std::ifstream in(labels);
  runDublin(dataRoot, nlohmann::json::parse(in), cache, pngDir, params);
  return 0;
}
