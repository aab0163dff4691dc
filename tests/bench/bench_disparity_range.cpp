// Disparity-range benchmark: stereo::estimateDisparityRange on real pairs and simulated scenes,
// against the disparities each pair really holds. Prints one table: the estimate [dmin, dmax],
// the matches it used, the true disparities' 0.5th..99.5th percentiles ("true span" = their
// difference) and their min..max, the share of true disparities inside the estimate, the width
// ratio (dmax - dmin) / true span, and the estimation's wall-clock and process CPU time (each
// the fastest of --repeat runs; the CPU time counts both threads).
//
// Truth per set:
//   Middlebury Cones   Cones_LEFT_GT.tif, pixels > 0
//   Middlebury Aloe    aloeGT.png (full size, as the 1282x1110 JPEG pair), pixels > 0
//   DublinCity         *_left_gt_disp.png / 256, pixels > 0 (LiDAR, ~23 % of the pixels)
//   Toulouse (no GT)   OpenCV StereoSGBM on the pair itself, searched over -128..127 (ample for
//                      both tiles, whose disparities lie within -5..90): block 5, P1 = 8·25,
//                      P2 = 32·25, 8 directions (MODE_HH), left-right check disp12MaxDiff = 1,
//                      uniqueness ratio 15 %, speckle filter (regions < 200 px within 2 px
//                      removed); pixels it leaves invalid and the 128 px left band it cannot
//                      search are not counted.
//   simulated scenes   the scene's GT disparity, every pixel with a surface (occluded included)
//
// Usage: bench_disparity_range [--data DIR] [--no-data] [--tiny] [--repeat N] [--params JSON]
//                              [--draw DIR] [--only NAME]
//   --data DIR    real datasets (default ../shared/data beside the repository, or DELINEO_DATA_DIR); skipped cleanly when absent
//   --tiny        two small simulated scenes only (the ctest smoke run)
//   --params J    RangeEstimateParams overrides, e.g. '{"detector": "orb"}'
//   --draw DIR    writes DIR/<case>.png: the left image with each match used, coloured from blue
//                 (estimate's low end) to red (high end), and DIR/<case>.csv: each match's
//                 x, y, d and the true disparity there
//   --only NAME   cases whose name contains NAME
//   --seed-offset N  adds N to every simulated scene's seed (held-out scenes)
//   --scene DIR   a scene written by `delineo-cli simulate` instead of the simulated set
//                 (repeatable)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/disparity_range.hpp"
#include "bench_image.hpp"
#include "shared_data.hpp"

namespace {
using namespace delineo;
namespace fs = std::filesystem;

struct Case {
  std::string name;
  cv::Mat left, right;  // CV_32F
  cv::Mat truth;        // CV_32F, NaN where unknown
};

cv::Mat readFloat(const fs::path& p) {
  return io::readGreyFloat(p.string());
}

// Grey values without the nodata → NaN conversion: Cones_LEFT/RIGHT.tif declare nodata = 255.
cv::Mat readFloatKeepingNodata(const fs::path& p) {
  io::ReadOptions keep;
  keep.toGrey = true;
  cv::Mat out;
  io::readRaster(p.string(), keep).data.convertTo(out, CV_32F);
  return out;
}

cv::Mat positiveOnly(const cv::Mat& truth) {
  cv::Mat out = truth.clone();
  out.setTo(std::numeric_limits<float>::quiet_NaN(), ~(truth > 0));
  return out;
}

// The Toulouse reference: SGBM with its own checks (see the header comment).
cv::Mat sgbmTruth(const cv::Mat& left, const cv::Mat& right) {
  constexpr int kMin = -128, kCount = 256, kBlock = 5;
  cv::Mat l8, r8;
  left.convertTo(l8, CV_8U);
  right.convertTo(r8, CV_8U);
  auto sgbm = cv::StereoSGBM::create(kMin, kCount, kBlock, 8 * kBlock * kBlock,
                                     32 * kBlock * kBlock, 1, 0, 15, 200, 2,
                                     cv::StereoSGBM::MODE_HH);
  cv::Mat raw;
  sgbm->compute(l8, r8, raw);
  cv::Mat d;
  raw.convertTo(d, CV_32F, 1.0 / 16.0);
  d.setTo(std::numeric_limits<float>::quiet_NaN(), raw < kMin * 16);
  return d;
}

std::vector<Case> realCases(const fs::path& data) {
  std::vector<Case> cases;
  const fs::path cones = data / "middlebury-cones";
  if (fs::exists(cones / "Cones_LEFT.tif") && fs::exists(cones / "Cones_LEFT_GT.tif")) {
    cases.push_back({"Cones", readFloatKeepingNodata(cones / "Cones_LEFT.tif"),
                     readFloatKeepingNodata(cones / "Cones_RIGHT.tif"),
                     positiveOnly(readFloat(cones / "Cones_LEFT_GT.tif"))});
  }
  const fs::path aloe = data / "middlebury-aloe";
  if (fs::exists(aloe / "aloeL.jpg") && fs::exists(aloe / "aloeGT.png")) {
    cases.push_back({"Aloe", readFloat(aloe / "aloeL.jpg"), readFloat(aloe / "aloeR.jpg"),
                     positiveOnly(readFloat(aloe / "aloeGT.png"))});
  }
  const fs::path dublin = data / "aerial-dublin";
  if (fs::exists(dublin / "dublin_0004_left.png") &&
      fs::exists(dublin / "dublin_0004_left_gt_disp.png")) {
    cv::Mat truth;
    io::readRaster((dublin / "dublin_0004_left_gt_disp.png").string()).data.convertTo(
        truth, CV_32F, 1.0 / 256.0);
    cases.push_back({"Dublin", readFloat(dublin / "dublin_0004_left.png"),
                     readFloat(dublin / "dublin_0004_right.png"), positiveOnly(truth)});
  }
  const fs::path toulouse = data / "aerial-toulouse";
  for (const char* tile : {"0032", "0051"}) {
    const std::string stem = std::string("31_15083_31_15084_") + tile;
    if (!fs::exists(toulouse / (stem + "_left.png"))) continue;
    Case c{std::string("Toulouse ") + tile, readFloat(toulouse / (stem + "_left.png")),
           readFloat(toulouse / (stem + "_right.png")), {}};
    c.truth = sgbmTruth(c.left, c.right);
    cases.push_back(c);
  }
  return cases;
}

struct SimSpec {
  std::string family;
  int seed;
};

// 20 scenes: the stereo benchmark's square scenes (1000 x 1000), the simulator's default scene
// (640 x 480), small scenes where one building is a large part of the image (320 x 240, 4
// buildings and 3 trees requested, as the CLI's end-to-end tests), steep scenes (heights 2.5x
// larger in disparity, ground at negative disparity) and strongly sloped terrain with relief;
// for --tiny, square scenes of 240 x 240.
sim::SceneParams simParams(const SimSpec& s) {
  if (s.family == "tiny") return sim::squareSceneParams(240, s.seed);
  sim::SceneParams p = sim::squareSceneParams(1000, s.seed);
  if (s.family == "default") {
    p = sim::SceneParams{};
    p.seed = s.seed;
  } else if (s.family == "small") {
    p = sim::SceneParams{};
    p.seed = s.seed;
    p.width = 320;
    p.height = 240;
    p.buildings = 4;
    p.trees = 3;
  } else if (s.family == "steep") {
    p.metresPerDisparity = 0.2;
    p.groundDisparity = -20;
    p.slope = 8;
  } else if (s.family == "slope") {
    p.slope = 20;
    p.undulation = 3;
    p.groundDisparity = 40;
  }
  return p;
}

Case simCase(const SimSpec& s, const sim::SceneParams& p) {
  const sim::Scene scene = sim::simulateScene(p);
  Case c;
  c.name = "sim " + s.family + " " + std::to_string(s.seed);
  scene.left.convertTo(c.left, CV_32F);
  scene.right.convertTo(c.right, CV_32F);
  c.truth = scene.disparity;
  return c;
}

std::vector<float> finiteValues(const cv::Mat& m) {
  std::vector<float> v;
  for (int y = 0; y < m.rows; ++y) {
    const float* p = m.ptr<float>(y);
    for (int x = 0; x < m.cols; ++x) {
      if (std::isfinite(p[x])) v.push_back(p[x]);
    }
  }
  std::sort(v.begin(), v.end());
  return v;
}

float percentile(const std::vector<float>& sorted, double q) {
  return sorted[static_cast<size_t>(std::lround(q * static_cast<double>(sorted.size() - 1)))];
}

void drawMatches(const fs::path& file, const Case& c, const stereo::RangeEstimate& r) {
  cv::Mat grey, bgr;
  cv::normalize(c.left, grey, 0, 255, cv::NORM_MINMAX, CV_8U);
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  const double span = std::max(1, r.dmax - r.dmin);
  for (const cv::Point3f& p : r.points) {
    const double t = std::clamp((p.z - r.dmin) / span, 0.0, 1.0);
    const cv::Scalar colour(255 * (1 - t), 255 * (1 - std::abs(2 * t - 1)), 255 * t);
    cv::circle(bgr, {cvRound(p.x), cvRound(p.y)}, 3, colour, -1, cv::LINE_AA);
  }
  bench::writeImage(file.string(), bgr);
}

struct Row {
  bool ok = false;
  std::string error;
  stereo::RangeEstimate estimate;
  double ms = 0, cpuMs = 0;
  float p005 = 0, p995 = 0, tmin = 0, tmax = 0;
  double inside = 0, ratio = 0;
};

Row evaluate(const Case& c, const stereo::RangeEstimateParams& params, int repeat) {
  Row row;
  row.ms = row.cpuMs = 1e300;
  try {
    for (int k = 0; k < repeat; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::clock_t c0 = std::clock();
      row.estimate = stereo::estimateDisparityRange(c.left, c.right, params);
      const std::clock_t c1 = std::clock();
      const auto t1 = std::chrono::steady_clock::now();
      row.ms = std::min(row.ms, std::chrono::duration<double, std::milli>(t1 - t0).count());
      row.cpuMs = std::min(row.cpuMs, 1000.0 * static_cast<double>(c1 - c0) / CLOCKS_PER_SEC);
    }
    row.ok = true;
  } catch (const core::Error& e) {
    row.error = e.what();
  }
  const std::vector<float> t = finiteValues(c.truth);
  if (t.empty()) return row;
  row.p005 = percentile(t, 0.005);
  row.p995 = percentile(t, 0.995);
  row.tmin = t.front();
  row.tmax = t.back();
  if (!row.ok) return row;
  const auto lo = std::lower_bound(t.begin(), t.end(), static_cast<float>(row.estimate.dmin));
  const auto hi = std::upper_bound(t.begin(), t.end(), static_cast<float>(row.estimate.dmax));
  row.inside = 100.0 * static_cast<double>(hi - lo) / static_cast<double>(t.size());
  row.ratio = (row.estimate.dmax - row.estimate.dmin) / std::max(1e-6, double(row.p995 - row.p005));
  return row;
}

struct Options {
  std::string data = bench::defaultDataRoot();
  bool useData = true, tiny = false;
  int repeat = 1, seedOffset = 0;
  std::vector<std::string> sceneDirs;
  std::string draw, only;
  stereo::RangeEstimateParams params;
};

// The options, or nothing after the usage line (or the parameters' error) when they are wrong.
std::optional<Options> parseOptions(int argc, char** argv) {
  Options o;
  nlohmann::json overrides = nlohmann::json::object();
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--data" && i + 1 < argc)
      o.data = argv[++i];
    else if (a == "--no-data")
      o.useData = false;
    else if (a == "--tiny")
      o.tiny = true;
    else if (a == "--repeat" && i + 1 < argc)
      o.repeat = std::max(1, std::atoi(argv[++i]));
    else if (a == "--params" && i + 1 < argc) overrides = nlohmann::json::parse(argv[++i]);
    else if (a == "--draw" && i + 1 < argc)
      o.draw = argv[++i];
    else if (a == "--only" && i + 1 < argc)
      o.only = argv[++i];
    else if (a == "--seed-offset" && i + 1 < argc)
      o.seedOffset = std::atoi(argv[++i]);
    else if (a == "--scene" && i + 1 < argc)
      o.sceneDirs.push_back(argv[++i]);
    else {
      std::fprintf(stderr, "usage: bench_disparity_range [--data DIR] [--no-data] [--tiny] "
                           "[--repeat N] [--params JSON] [--draw DIR] [--only NAME] [--seed-offset N] "
                           "[--scene DIR]\n");
      return std::nullopt;
    }
  }
  try {
    core::fromJson(o.params, overrides);
  } catch (const core::Error& e) {
    std::fprintf(stderr, "bench_disparity_range: %s\n", e.what());
    return std::nullopt;
  }
  return o;
}

// The real pairs (unless --no-data or --tiny; a line says when the data folder is missing) and
// the scenes of --scene.
std::vector<Case> realAndSceneCases(const Options& o) {
  std::vector<Case> cases;
  if (o.useData && !o.tiny) {
    if (fs::is_directory(o.data))
      cases = realCases(o.data);
    else
      std::printf("(real data skipped: %s not found)\n", o.data.c_str());
  }
  for (const std::string& dir : o.sceneDirs) {
    const fs::path d(dir);
    cases.push_back({"scene " + d.filename().string(), readFloat(d / sim::SceneFiles::left),
                     readFloat(d / sim::SceneFiles::right),
                     readFloat(d / sim::SceneFiles::disparity)});
  }
  return cases;
}

// The simulated scenes: none with --scene, two tiny ones with --tiny, else the 20 of simParams
// (their seeds moved by --seed-offset).
std::vector<SimSpec> simSpecs(const Options& o) {
  std::vector<SimSpec> specs;
  if (!o.sceneDirs.empty()) return specs;
  if (o.tiny) return {{"tiny", 1}, {"tiny", 2}};
  const int offset = o.seedOffset;
  for (int s = 1; s <= 5; ++s) specs.push_back({"square", offset + s});
  for (int s = 1; s <= 4; ++s) specs.push_back({"default", offset + s});
  for (int s = 1; s <= 5; ++s) specs.push_back({"small", offset + s});
  for (int s = 1; s <= 3; ++s) specs.push_back({"steep", offset + s});
  for (int s = 1; s <= 3; ++s) specs.push_back({"slope", offset + s});
  return specs;
}

// --draw DIR: DIR/<case>.png, the matches over the left image, and DIR/<case>.csv, each match's
// x, y, d and the true disparity there.
void drawCase(const std::string& dir, const Case& c, const stereo::RangeEstimate& estimate) {
  std::string file = c.name;
  std::replace(file.begin(), file.end(), ' ', '_');
  drawMatches(fs::path(dir) / (file + ".png"), c, estimate);
  std::FILE* csv = std::fopen((fs::path(dir) / (file + ".csv")).string().c_str(), "w");
  if (csv == nullptr) return;
  std::fprintf(csv, "x,y,d,truth\n");
  for (const cv::Point3f& p : estimate.points) {
    const float t = c.truth.at<float>(std::clamp(cvRound(p.y), 0, c.truth.rows - 1),
                                      std::clamp(cvRound(p.x), 0, c.truth.cols - 1));
    std::fprintf(csv, "%.1f,%.1f,%.2f,%.2f\n", p.x, p.y, p.z, t);
  }
  std::fclose(csv);
}

bool selected(const std::string& caseName, const std::string& only) {
  return only.empty() || caseName.find(only) != std::string::npos;
}

// One case's row (and drawing); false when the estimate failed.
bool runCase(const Case& c, const Options& o) {
  if (!selected(c.name, o.only)) return true;
  const Row r = evaluate(c, o.params, o.repeat);
  char size[32], est[32], kp[32], span[32], minmax[32];
  std::snprintf(size, sizeof size, "%dx%d", c.left.cols, c.left.rows);
  std::snprintf(span, sizeof span, "%.1f..%.1f", r.p005, r.p995);
  std::snprintf(minmax, sizeof minmax, "%.1f..%.1f", r.tmin, r.tmax);
  if (!r.ok) {
    std::printf("%-16s %9s  FAILED: %s\n", c.name.c_str(), size, r.error.c_str());
    return false;
  }
  std::snprintf(est, sizeof est, "%d..%d", r.estimate.dmin, r.estimate.dmax);
  std::snprintf(kp, sizeof kp, "%d/%d", r.estimate.keypointsLeft, r.estimate.keypointsRight);
  std::printf("%-16s %9s %11s %6d %11s %15s %15s %8.2f %6.2f %7.0f %7.0f\n", c.name.c_str(), size,
              est, r.estimate.matches, kp, span, minmax, r.inside, r.ratio, r.ms, r.cpuMs);
  std::fflush(stdout);
  if (!o.draw.empty()) drawCase(o.draw, c, r.estimate);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  const std::optional<Options> options = parseOptions(argc, argv);
  if (!options) return 2;
  const std::vector<Case> cases = realAndSceneCases(*options);
  const std::vector<SimSpec> specs = simSpecs(*options);
  std::printf("%-16s %9s %11s %6s %11s %15s %15s %8s %6s %7s %7s\n", "case", "size",
              "estimate", "match", "kp L/R", "true p0.5..99.5", "true min..max", "inside%",
              "width", "ms", "cpu ms");
  int failed = 0;
  for (const Case& c : cases) failed += !runCase(c, *options);
  for (const SimSpec& s : specs) {
    // Only the selected scenes are simulated.
    if (!selected("sim " + s.family + " " + std::to_string(s.seed), options->only)) continue;
    failed += !runCase(simCase(s, simParams(s)), *options);
  }
  return failed > 0 ? 1 : 0;
}
