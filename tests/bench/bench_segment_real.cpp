// The scene analysis (segmentation::analyseScene: ground, DTM, classes, objects, proposals) on the
// real aerial pairs of the data folder (docs/dem.md, "Results on the real pairs"):
//   - Dublin: above-ground vs the LiDAR disparity on the pixels where the LiDAR has a value;
//   - every pair: how many hand-labelled roofs (tests/bench/data/real_roofs.json) a proposal
//     covers, how many of them are alone in their proposal (touching buildings merged into one
//     proposal share it), and an overlay PNG (building red, vegetation green, proposals yellow) to
//     look at;
//   - with --delineate, the whole automatic chain: the active polygon run from every proposal (its
//     roof interval and ground, the matcher's map), each labelled roof scored by the best IoU of
//     the outlines.
// Heights come from the matcher's disparity (cached as in bench_real_outlines) through a linear
// model; the pairs come without camera data, so metres per pixel of disparity is the stated
// assumption below. Skips cleanly when the data folder is missing (--data, default
// ../shared/data beside the repository, or DELINEO_DATA_DIR).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/params.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/delineation/feature_request.hpp"
#include "delineo/eval/polygon_measures.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/segmentation/scene.hpp"
#include "bench_image.hpp"
#include "lidar.hpp"
#include "real_roofs.hpp"

using namespace delineo;
namespace fs = std::filesystem;

namespace {

// Metres of height per pixel of disparity and ground sample distance of each pair. Toulouse:
// 5 cm GSD and a base-to-height ratio near 0.2 (a 25 m block spans about 100 px of disparity)
// give 0.25 m/px. Dublin: 3.4 cm GSD, the same ratio gives 0.17 m/px.
struct PairModel {
  double metresPerPixel, gsd;
};
PairModel modelOf(const std::string& pair) {
  if (pair.rfind("dublin", 0) == 0) return {0.17, 0.034};
  return {0.25, 0.05};
}

double percentile(std::vector<float> v, double q) {
  if (v.empty()) return std::nan("");
  const auto k = static_cast<long>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<size_t>(k)];
}

// Above-ground vs the LiDAR: on its valid pixels, above when its disparity exceeds its ground by
// `margin` px. Pixels within half a margin of that threshold are left out (low walls, cars,
// kerbs: neither class is wrong there).
void scoreAgainstLidar(const std::string& gtPath, const cv::Mat& above, const cv::Mat& demValid, double margin) {
  const cv::Mat lidar = bench::readLidarDisparity(gtPath);
  const cv::Mat ground = bench::lidarGround(lidar);
  long right = 0, total = 0, rightH = 0, totalH = 0, tp = 0, fp = 0, fn = 0;
  for (int y = 0; y < lidar.rows; ++y) {
    for (int x = 0; x < lidar.cols; ++x) {
      const float d = lidar.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      const double over = d - ground.at<float>(y, x);
      if (std::abs(over - margin) < margin / 2) continue;
      const bool truth = over > margin, found = above.at<uchar>(y, x) != 0;
      ++total, right += truth == found;
      if (demValid.at<uchar>(y, x)) ++totalH, rightH += truth == found;
      tp += truth && found, fp += !truth && found, fn += truth && !found;
    }
  }
  std::printf("  LiDAR check (margin %.1f px = 2 m): accuracy %.1f %% on %ld px (%.1f %% on the %ld with a height); "
              "above-ground found %.1f %%, false %.1f %%\n",
              margin, 100.0 * right / std::max(1L, total), total, 100.0 * rightH / std::max(1L, totalH), totalH,
              100.0 * tp / std::max(1L, tp + fn), 100.0 * fp / std::max(1L, tp + fp));
}

void drawOverlay(const std::string& path, const cv::Mat& bgr, const segmentation::SceneAnalysis& a) {
  const cv::Mat& classes = a.classes();
  cv::Mat tint = bgr.clone();
  tint.setTo(cv::Scalar(40, 40, 230), classes == segmentation::kClassBuilding);
  tint.setTo(cv::Scalar(40, 200, 40), classes == segmentation::kClassVegetation);
  cv::Mat out;
  cv::addWeighted(bgr, 0.6, tint, 0.4, 0, out);
  for (const auto& f : a.detection.proposals) {
    std::vector<cv::Point> ring;
    for (const auto& p : f.polygon.outer) ring.emplace_back(cvRound(p.x), cvRound(p.y));
    cv::polylines(out, ring, true, cv::Scalar(0, 230, 255), 3);
  }
  bench::writeImage(path, out);
}

// The active polygon from every proposal; per labelled roof of the pair, the best IoU of the
// outlines (0 when none overlaps it), and the mean over the roofs reached (IoU >= 0.5).
void delineateProposals(const bench::RealPair& pair, const nlohmann::json& roofs,
                        const std::vector<core::Feature>& proposals) {
  const delineation::DisparityInterval range{pair.dmin, pair.dmax};
  const delineation::DelineationParams params;
  std::vector<core::Polygon> outlines;
  for (const auto& f : proposals) {
    try {
      auto req = delineation::featureRequest(f, params.groundTolerance);
      if (!req) continue;
      req->disparity = pair.disparity;
      req->searchRange = range;
      outlines.push_back(delineation::delineate(pair.left, pair.right, *req, params).polygon);
    } catch (const std::exception& e) {
      std::printf("  proposal %.0f failed: %s\n", core::numberProperty(f, "id", 9e15).value_or(-1), e.what());
    }
  }
  double sum = 0;
  int reached = 0, labelled = 0;
  std::printf("  automatic outlines (%zu from %zu proposals), best IoU per labelled roof:", outlines.size(),
              proposals.size());
  for (const auto& roof : roofs.at("roofs")) {
    if (roof.at("pair") != pair.name) continue;
    const core::Polygon truth = bench::ringOf(roof.at("outline"));
    double best = 0;
    for (const auto& o : outlines) best = std::max(best, eval::intersectionOverUnion(o, truth));
    std::printf(" %s %.3f", roof.at("name").get<std::string>().c_str(), best);
    ++labelled;
    if (best >= 0.5) sum += best, ++reached;
  }
  std::printf("\n  reached (IoU >= 0.5): %d of %d labelled roofs, mean IoU %.3f\n", reached, labelled,
              reached > 0 ? sum / reached : std::nan(""));
}

struct Options {
  bench::RealRoofsOptions data;
  std::string out = "/tmp";  // --out DIR: the overlay PNGs
  bool delineate = false;    // --delineate: the active polygon from every proposal
};

// The options, or nothing after the usage line when they are wrong.
std::optional<Options> parseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    if (o.data.take(argc, argv, i)) continue;
    if (!std::strcmp(argv[i], "--out") && i + 1 < argc) {
      o.out = argv[++i];
    } else if (!std::strcmp(argv[i], "--delineate")) {
      o.delineate = true;
    } else {
      std::fprintf(stderr,
                   "usage: bench_segment_real [--data DIR] [--labels real_roofs.json] "
                   "[--out DIR] [--cache DIR] [--delineate]\n");
      return std::nullopt;
    }
  }
  return o;
}

// The defaults, with BENCH_PARAMS='{"segment": {...}, "classify": {...}, "objects": {...},
// "detect": {...}}' overrides.
segmentation::SceneParams sceneParams() {
  segmentation::SceneParams params;
  const char* text = std::getenv("BENCH_PARAMS");
  if (!text) return params;
  const nlohmann::json j = nlohmann::json::parse(text);
  if (j.contains("segment")) core::fromJson(params.ground, j.at("segment"));
  if (j.contains("classify")) core::fromJson(params.classify, j.at("classify"));
  if (j.contains("objects")) core::fromJson(params.objects, j.at("objects"));
  if (j.contains("detect")) core::fromJson(params.detect, j.at("detect"));
  return params;
}

// Heights from the matcher's map: its median is the zero, `metresPerPixel` the scale (NaN stays
// NaN).
cv::Mat demOf(const cv::Mat& disparity, double metresPerPixel) {
  std::vector<float> finite;
  for (auto it = disparity.begin<float>(); it != disparity.end<float>(); ++it) {
    if (std::isfinite(*it)) finite.push_back(*it);
  }
  const double base = percentile(finite, 0.5);
  return (disparity - base) * metresPerPixel;
}

// The pair's labelled roofs against the proposals: a roof is proposed when one proposal holds at
// least half of it, and alone when its proposal holds no other proposed roof. Returns the mask of
// all the pair's labelled roofs.
cv::Mat scoreLabelledRoofs(const std::string& pairName, const nlohmann::json& roofs,
                           const std::vector<core::Feature>& proposals, cv::Size size) {
  int labelled = 0, covered = 0;
  cv::Mat allRoofs(size, CV_8U, cv::Scalar(0));
  std::vector<cv::Mat> proposalMasks;
  for (const auto& f : proposals) proposalMasks.push_back(core::rasterize(f.polygon, size));
  std::vector<int> holder;  // per covered roof, the proposal holding it
  std::vector<std::string> holderRoof;
  for (const auto& roof : roofs.at("roofs")) {
    if (roof.at("pair") != pairName) continue;
    const cv::Mat r = core::rasterize(bench::ringOf(roof.at("outline")), size);
    allRoofs |= r;
    double best = 0;
    int bestProposal = -1;
    for (size_t k = 0; k < proposalMasks.size(); ++k) {
      const double cover =
          cv::countNonZero(r & proposalMasks[k]) / std::max(1.0, double(cv::countNonZero(r)));
      if (cover > best) best = cover, bestProposal = static_cast<int>(k);
    }
    const std::string name = roof.at("name");
    ++labelled, covered += best >= 0.5;
    if (best >= 0.5) holder.push_back(bestProposal), holderRoof.push_back(name);
    if (best < 0.5) std::printf("  roof %s not proposed (best cover %.2f)\n", name.c_str(), best);
  }
  int alone = 0;
  for (size_t i = 0; i < holder.size(); ++i) {
    const long sharing = std::count(holder.begin(), holder.end(), holder[i]);
    alone += sharing == 1;
    if (sharing > 1)
      std::printf("  roof %s shares proposal %d with %ld other roof(s)\n", holderRoof[i].c_str(),
                  holder[i], sharing - 1);
  }
  std::printf("  hand-labelled roofs proposed: %d of %d\n", covered, labelled);
  std::printf("  roofs alone in their proposal: %d of %d\n", alone, labelled);
  return allRoofs;
}

// The scene analysis of one pair on its DEM from the matcher's map: its summary line, the
// labelled roofs proposed, the above-ground share on and off them, the LiDAR check (Dublin), the
// automatic outlines (--delineate) and the overlay picture.
void runPair(const bench::RealPair& pair, const nlohmann::json& pairFiles,
             const nlohmann::json& roofs, const Options& options,
             const segmentation::SceneParams& params) {
  const PairModel model = modelOf(pair.name);
  const cv::Mat dem = demOf(pair.disparity, model.metresPerPixel);
  const cv::Mat image = io::readImage8(pair.leftPath);
  const auto t0 = cv::getTickCount();
  const segmentation::SceneAnalysis a =
      segmentation::analyseScene(dem, image, model.gsd, params, pair.disparity);
  const double ms = 1e3 * double(cv::getTickCount() - t0) / cv::getTickFrequency();
  int buildings = 0;
  for (const auto& o : a.detection.objects.objects)
    buildings += o.cls == segmentation::kClassBuilding;
  std::printf(
      "%s (%.2f m/px of disparity, gsd %.3f m): %d regions, %d rounds, above ground %.1f %%, %d "
      "building "
      "and %zu vegetation objects, %zu proposals, %.0f ms\n",
      pair.name.c_str(), model.metresPerPixel, model.gsd, a.ground.regionCount, a.ground.iterations,
      100.0 * cv::countNonZero(a.ground.aboveGround) / double(dem.total()), buildings,
      a.detection.objects.objects.size() - static_cast<size_t>(buildings),
      a.detection.proposals.size(), ms);
  const cv::Mat allRoofs = scoreLabelledRoofs(pair.name, roofs, a.detection.proposals, dem.size());
  // Above-ground outside every labelled roof (shaded streets, alleys, trees, facades, and any
  // building left unlabelled) against the labelled roofs' pixels found above-ground.
  const cv::Mat above = a.ground.aboveGround != 0;
  std::printf(
      "  above-ground: %.1f %% of the labelled roofs' pixels; outside them %.1f %% of the tile\n",
      100.0 * cv::countNonZero(above & allRoofs) / std::max(1, cv::countNonZero(allRoofs)),
      100.0 * cv::countNonZero(above & ~allRoofs) / double(dem.total()));
  if (pairFiles.contains("ground_truth_disparity")) {
    const fs::path gt =
        fs::path(options.data.dataRoot) / pairFiles.at("ground_truth_disparity").get<std::string>();
    if (fs::exists(gt))
      scoreAgainstLidar(gt.string(), a.ground.aboveGround, dem == dem, 2.0 / model.metresPerPixel);
  }
  if (options.delineate) delineateProposals(pair, roofs, a.detection.proposals);
  const std::string png = (fs::path(options.out) / ("scene_" + pair.name + ".png")).string();
  cv::Mat bgr = image;
  if (bgr.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  drawOverlay(png, bgr, a);
  std::printf("  overlay %s\n", png.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  const std::optional<Options> options = parseOptions(argc, argv);
  if (!options) return 2;
  if (bench::skippedWithoutData(options->data.dataRoot)) return 0;
  const nlohmann::json roofs = bench::readLabels(options->data.labels);
  const segmentation::SceneParams params = sceneParams();
  bench::RealPairs pairs(roofs, options->data.dataRoot, options->data.cache);
  for (const auto& [name, files] : roofs.at("pairs").items()) {
    if (const bench::RealPair* pair = pairs.get(name))
      runPair(*pair, files, roofs, *options, params);
  }
  return 0;
}
