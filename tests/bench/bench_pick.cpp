// "Pick an above-ground object" on hand-labelled real roofs (tests/bench/data/real_roofs.json):
// a click on the pixel of each roof farthest from its outline, then the object found against the
// hand outline (IoU) and its ground against the roof's ground reference. "before" is the GUI's
// former pick (heights above the 10 % quantile of a 121 px window plus the margin, opened, the
// 4-connected region under the click); "after" is delineation::aboveGroundObjectAt. Heights:
// --metres-per-pixel (0.25 m per px of disparity, the real-pair GUI test's model) turns the
// 2.5 m margin into 10 px. Skips cleanly (exit 0) when the data folder is missing. Disparity maps
// are cached. BENCH_PARAMS='{"max-step": 0}' overrides the pick's parameters (JSON keys as in
// the project file).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"
#include "delineo/delineation/above_ground.hpp"
#include "delineo/io/raster.hpp"
#include "real_roofs.hpp"
#include "shared_data.hpp"

namespace fs = std::filesystem;
using namespace delineo;
using bench::ringOf;

namespace {

double median(std::vector<float> v) {
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

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

// The pixel of the outline farthest from its border: where an operator clicks.
cv::Point clickOf(const core::Polygon& outline, cv::Size size) {
  const cv::Mat inside = core::rasterize(outline, size);
  cv::Mat padded, distance;
  cv::copyMakeBorder(inside, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::distanceTransform(padded, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::Point best;
  cv::minMaxLoc(distance, nullptr, nullptr, nullptr, &best);
  return best - cv::Point(1, 1);
}

// The GUI's former pick, in px of disparity: the region mask (empty when nothing is found).
cv::Mat formerPick(const cv::Mat& map, cv::Point click, double margin, double* ground) {
  const cv::Rect window = cv::Rect(click.x - 60, click.y - 60, 121, 121) & cv::Rect(0, 0, map.cols, map.rows);
  std::vector<float> heights = valuesIn(map(window), cv::Mat(window.size(), CV_8U, cv::Scalar(255)));
  if (heights.empty()) return {};
  std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 10), heights.end());
  *ground = heights[heights.size() / 10];
  cv::Mat above = map > *ground + margin;
  cv::morphologyEx(above, above, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  if (above.at<uchar>(click) == 0) return {};
  cv::Mat mask = cv::Mat::zeros(map.rows + 2, map.cols + 2, CV_8U);
  cv::floodFill(above, mask, click, 255, nullptr, 0, 0, 4 | cv::FLOODFILL_MASK_ONLY | (255 << 8));
  return mask(cv::Rect(1, 1, map.cols, map.rows)).clone();
}

double iou(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty()) return 0.0;
  const double inter = cv::countNonZero(a & b), uni = cv::countNonZero(a | b);
  return uni > 0 ? inter / uni : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  bench::RealRoofsOptions options;
  double metresPerPixel = 0.25;
  for (int i = 1; i < argc; ++i) {
    if (options.take(argc, argv, i)) continue;
    if (!std::strcmp(argv[i], "--metres-per-pixel") && i + 1 < argc && std::atof(argv[i + 1]) > 0) {
      metresPerPixel = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: bench_pick [--data DIR] [--labels real_roofs.json] [--cache DIR] "
                           "[--metres-per-pixel K]\n");
      return 2;
    }
  }
  if (bench::skippedWithoutData(options.dataRoot)) return 0;
  delineation::AboveGroundParams params;
  if (const char* json = std::getenv("BENCH_PARAMS")) core::fromJson(params, nlohmann::json::parse(json));
  const double margin = params.heightMargin / metresPerPixel;
  const nlohmann::json data = bench::readLabels(options.labels);
  bench::RealPairs pairs(data, options.dataRoot, options.cache);
  std::printf("%-18s %9s %6s | %-6s %6s %6s | %-6s %6s %6s %4s %4s %7s %6s\n", "roof", "click", "ground",
              "before", "ground", "err", "after", "ground", "err", "ref", "vtx", "px", "ms");
  int runs = 0, beforeGood = 0, afterGood = 0;
  double beforeSum = 0.0, afterSum = 0.0;
  for (const auto& roof : data.at("roofs")) {
    const bench::RealPair* pair = pairs.get(roof.at("pair"));
    if (!pair) continue;
    const cv::Mat& map = pair->disparity;
    const core::Polygon hand = ringOf(roof.at("outline"));
    const cv::Mat handMask = core::rasterize(hand, map.size());
    const double groundRef = median(valuesIn(map, core::rasterize(ringOf(roof.at("ground")), map.size())));
    const cv::Point click = clickOf(hand, map.size());
    double formerGround = std::nan("");
    const double before = iou(formerPick(map, click, margin, &formerGround), handMask);
    const auto start = std::chrono::steady_clock::now();
    const delineation::AboveGroundObject object = delineation::aboveGroundObjectAt(map, click, metresPerPixel, params);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const double after = object.outcome == delineation::PickOutcome::Found ? iou(object.mask, handMask) : 0.0;
    std::printf("%-18s %4d,%4d %6.1f | %6.3f %6.1f %+6.1f | %6.3f %6.1f %+6.1f %4d %4zu %7d %6.0f\n",
                roof.at("name").get<std::string>().c_str(), click.x, click.y, groundRef, before, formerGround,
                formerGround - groundRef, after, object.groundLevel, object.groundLevel - groundRef,
                object.refinements, object.outline.outer.size(), object.pixels, ms);
    ++runs;
    beforeSum += before, afterSum += after;
    beforeGood += before >= 0.8 ? 1 : 0;
    afterGood += after >= 0.8 ? 1 : 0;
  }
  if (bench::skippedWithoutRoofs(runs, options.dataRoot)) return 0;
  std::printf("\n%d roofs: IoU >= 0.8 before %d, after %d; mean IoU before %.3f, after %.3f\n", runs, beforeGood,
              afterGood, beforeSum / runs, afterSum / runs);
  return 0;
}
