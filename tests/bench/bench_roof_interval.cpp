// Roof interval and ground level proposal on hand-labelled real roofs (tests/bench/data/
// real_roofs.json). For each roof and each operator rectangle (the outline's box grown by 8, 15
// and 30 px, or by the margins given with --grow, clipped to the image; with --outline, the
// labelled outline itself instead, as a delineated polygon would be, printed as grow -1) it
// prints the roof's main peak (mode of the matcher's
// disparities inside the outline shrunk by 3 px), the proposed interval and whether it holds the
// peak, and the ground level against the roof's ground reference; "before" columns show the
// functions the GUI used until now (polygon percentiles, median of an 8 px ring). Roofs marked
// "heldOut" are counted apart: they were not used to choose the method or its defaults (except
// t51_low_wing for the roof peak's entry test, see tests/bench/data/README.md).
// Skips cleanly (exit 0) when the data folder is missing. Disparity maps are cached.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/error.hpp"
#include "delineo/core/geometry.hpp"
#include "delineo/delineation/roof_interval.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/stereo/match.hpp"
#include "real_roofs.hpp"

namespace fs = std::filesystem;
using namespace delineo;
using bench::ringOf;

namespace {

std::vector<float> valuesIn(const cv::Mat& map, const cv::Mat& mask) {
  std::vector<float> out;
  for (int y = 0; y < map.rows; ++y) {
    for (int x = 0; x < map.cols; ++x) {
      const float v = map.at<float>(y, x);
      if (mask.at<uchar>(y, x) != 0 && std::isfinite(v)) out.push_back(v);
    }
  }
  return out;
}

double quantile(std::vector<float> v, double q) {
  if (v.empty()) return std::nan("");
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// Mode of the disparities inside the outline shrunk by 3 px, in 1 px bins centred on integers.
int mainPeak(const cv::Mat& map, const core::Polygon& outline) {
  cv::Mat inside = core::rasterize(outline, map.size()), depth;
  cv::Mat padded;
  cv::copyMakeBorder(inside, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::distanceTransform(padded, depth, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const cv::Mat core = depth(cv::Rect(1, 1, map.cols, map.rows)) > 3.0f;
  std::map<int, int> counts;
  for (float v : valuesIn(map, core)) ++counts[static_cast<int>(std::lround(v))];
  int best = 0, n = -1;
  for (const auto& [d, c] : counts) {
    if (c > n) best = d, n = c;
  }
  return best;
}

// Before: the polygon's 10th..95th percentiles above "low decile + 30 % of the span".
std::pair<int, int> oldInterval(const cv::Mat& map, const core::Polygon& polygon) {
  std::vector<float> values = valuesIn(map, core::rasterize(polygon, map.size()));
  if (values.size() < 10) return {0, -1};
  const float ground = static_cast<float>(quantile(values, 0.1));
  const float high = static_cast<float>(quantile(values, 0.98));
  const float threshold = ground + std::max(2.0f, 0.3f * (high - ground));
  std::vector<float> above;
  for (float v : values) {
    if (v > threshold) above.push_back(v);
  }
  if (above.size() < 10) above = values;
  return {static_cast<int>(std::floor(quantile(above, 0.1))), static_cast<int>(std::ceil(quantile(above, 0.95)))};
}

// Before: median of an 8 px ring outside the polygon.
double oldGround(const cv::Mat& map, const core::Polygon& polygon) {
  const cv::Mat inside = core::rasterize(polygon, map.size());
  cv::Mat grown;
  cv::dilate(inside, grown, cv::getStructuringElement(cv::MORPH_RECT, {17, 17}));
  return quantile(valuesIn(map, grown & ~inside), 0.5);
}

cv::Mat readGroundTruth(const std::string& path, double scale) {
  io::ReadOptions options;
  options.type = io::PixelType::Float32;
  cv::Mat gt = io::readRaster(path, options).data;
  gt /= scale;
  gt.setTo(std::nanf(""), gt <= 0.0f);
  return gt;
}

// Counts of one set of roofs (the tuning set, or the held-out set marked "heldOut").
struct Tally {
  int runs = 0, oldHits = 0, newHits = 0, oldGroundOk = 0, newGroundOk = 0;
  double oldErrSum = 0.0, newErrSum = 0.0, oldErrMax = 0.0, newErrMax = 0.0;
  void add(bool oldIn, bool newIn, double oldErr, double newErr) {
    ++runs;
    oldHits += oldIn, newHits += newIn;
    oldGroundOk += std::abs(oldErr) <= 2.0, newGroundOk += std::abs(newErr) <= 2.0;
    oldErrSum += std::abs(oldErr), newErrSum += std::abs(newErr);
    oldErrMax = std::max(oldErrMax, std::abs(oldErr)), newErrMax = std::max(newErrMax, std::abs(newErr));
  }
  void print(const char* name) const {
    if (runs == 0) return;
    std::printf("%s, %d runs: interval holds the main peak before %d, after %d; ground within 2 px before %d, after %d; "
                "mean |ground error| before %.1f px, after %.1f px; max after %.1f px\n",
                name, runs, oldHits, newHits, oldGroundOk, newGroundOk, oldErrSum / runs, newErrSum / runs, newErrMax);
  }
};

// "8,15,30" -> {8, 15, 30}; empty when the list holds anything but non-negative integers.
std::vector<int> growsOf(const std::string& list) {
  std::vector<int> out;
  for (size_t start = 0; start <= list.size();) {
    const size_t end = std::min(list.find(',', start), list.size());
    const std::string item = list.substr(start, end - start);
    if (item.empty() || item.find_first_not_of("0123456789") != std::string::npos || item.size() > 6) return {};
    out.push_back(std::stoi(item));
    start = end + 1;
  }
  return out;
}

struct Options {
  bench::RealRoofsOptions data;
  std::vector<int> grows = {8, 15, 30};  // {-1}: the labelled outline itself
};

// The options, or nothing after the usage line when they are wrong.
std::optional<Options> parseOptions(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    if (options.data.take(argc, argv, i)) continue;
    if (!std::strcmp(argv[i], "--grow") && i + 1 < argc && !growsOf(argv[i + 1]).empty()) {
      options.grows = growsOf(argv[++i]);
    } else if (!std::strcmp(argv[i], "--outline")) {
      options.grows = {-1};
    } else {
      std::fprintf(stderr, "usage: bench_roof_interval [--data DIR] [--labels real_roofs.json] [--cache DIR] "
                           "[--grow 8,15,30 | --outline]\n");
      return std::nullopt;
    }
  }
  return options;
}

// The roof's ground reference: the median disparity over its labelled ground polygon, from the
// pair's ground truth when it has one, else from the matcher's map.
double groundReference(const nlohmann::json& pairFiles, const std::string& dataRoot,
                       const cv::Mat& map, const core::Polygon& groundPolygon) {
  if (!pairFiles.contains("ground_truth_disparity")) {
    return quantile(valuesIn(map, core::rasterize(groundPolygon, map.size())), 0.5);
  }
  const cv::Mat gt = readGroundTruth(
      (fs::path(dataRoot) / pairFiles.at("ground_truth_disparity").get<std::string>()).string(),
      pairFiles.value("ground_truth_scale", 1.0));
  return quantile(valuesIn(gt, core::rasterize(groundPolygon, gt.size())), 0.5);
}

// One row per rectangle around the roof (grow -1: its labelled outline), each counted in `tally`:
// the former and the proposed interval and ground against the roof's peak and ground reference.
void runRoof(const nlohmann::json& roof, const cv::Mat& map, double groundRef,
             const std::vector<int>& grows, const delineation::RoofIntervalParams& params,
             Tally& tally) {
  const core::Polygon outline = ringOf(roof.at("outline"));
  const int peak = mainPeak(map, outline);
  for (int grow : grows) {
    const core::Polygon rect = grow < 0 ? outline : bench::grownBox(outline, grow, map.size());
    const auto [ol, oh] = oldInterval(map, rect);
    const double og = oldGround(map, rect);
    const auto p = delineation::proposeRoofInterval(map, rect, params);
    const bool oldIn = ol <= peak && peak <= oh, newIn = p.found && p.low <= peak && peak <= p.high;
    const double oe = og - groundRef, ne = p.groundLevel - groundRef;
    std::printf(
        "%-18s %4d %5d %6.1f | [%3d,%3d] %3s %6.1f %+5.1f | [%3d,%3d] %3s %6.1f %+5.1f %5.1f\n",
        roof.at("name").get<std::string>().c_str(), grow, peak, groundRef, ol, oh,
        oldIn ? "yes" : "NO", og, oe, p.low, p.high, newIn ? "yes" : "NO", p.groundLevel, ne,
        p.peak);
    tally.add(oldIn, newIn, oe, ne);
  }
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  const std::optional<Options> options = parseOptions(argc, argv);
  if (!options) return 2;
  const std::string& dataRoot = options->data.dataRoot;
  if (bench::skippedWithoutData(dataRoot)) return 0;
  delineation::RoofIntervalParams params;
  if (const char* json = std::getenv("BENCH_PARAMS")) core::fromJson(params, nlohmann::json::parse(json));
  const nlohmann::json data = bench::readLabels(options->data.labels);
  std::printf("%-18s %4s %5s %6s | %-9s %3s %6s %5s | %-9s %3s %6s %5s %5s\n", "roof", "grow", "peak", "ground",
              "before", "in", "ground", "err", "after", "in", "ground", "err", "peak*");
  std::map<std::string, Tally> sets;  // by bench::roofSet
  bench::RealPairs pairs(data, dataRoot, options->data.cache);
  bool heldOutShown = false;
  for (const auto& roof : data.at("roofs")) {
    const std::string pairName = roof.at("pair"), set = bench::roofSet(roof);
    if (set == "held-out" && !heldOutShown)
      std::printf("-- held out (see tests/bench/data/README.md) --\n");
    heldOutShown = heldOutShown || set == "held-out";
    const bench::RealPair* pair = pairs.get(pairName);
    if (!pair) continue;
    const double groundRef = groundReference(data.at("pairs").at(pairName), dataRoot,
                                             pair->disparity, ringOf(roof.at("ground")));
    runRoof(roof, pair->disparity, groundRef, options->grows, params, sets[set]);
  }
  if (bench::skippedWithoutRoofs(sets["tuning"].runs + sets["held-out"].runs, dataRoot)) return 0;
  std::printf("\n");
  sets["tuning"].print("tuning set");
  sets["held-out"].print("held-out set");
  return 0;
}
