// Benchmark of the statistical active polygon on simulated scenes: per-building IoU, p1, PoLiS
// and corner RMS against the ground truth from two initialisations, (a) the true outline's
// bounding rectangle grown by 8 px and (b) the true polygon with every vertex jittered by up to
// 6 px; time per building; speed ratio of the incremental energy over the rasterising reference
// on the same runs. Plain main printing a table; `--tiny` is the ctest smoke run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <nlohmann/json.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/params.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/cost_service.hpp"
#include "delineo/stereo/match.hpp"
#include "bench_image.hpp"
#include "energy_diag.hpp"
#include "delineo/eval/footprint_metrics.hpp"

using namespace delineo;
using namespace delineo::delineation;
using namespace delineo::bench;
namespace {

// CPU time of this thread: the machine may be shared, and the target is per core.
struct Clock {
  using time_point = double;
  static double now() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
  }
};
double ms(double a, double b) { return b - a; }

double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}
double mean(const std::vector<double>& v) {
  double s = 0;
  int n = 0;
  for (double x : v) {
    if (std::isfinite(x)) {
      s += x;
      ++n;
    }
  }
  return n ? s / n : std::nan("");
}

double number(const core::Feature& f, const char* key, double fallback) {
  const auto it = f.attributes.find(key);
  if (it == f.attributes.end()) return fallback;
  if (const auto* i = std::get_if<long long>(&it->second)) return static_cast<double>(*i);
  if (const auto* d = std::get_if<double>(&it->second)) return *d;
  return fallback;
}
std::string text(const core::Feature& f, const char* key) {
  const auto it = f.attributes.find(key);
  if (it == f.attributes.end()) return "-";
  if (const auto* s = std::get_if<std::string>(&it->second)) return *s;
  return "-";
}

struct Scores {
  double iou = 0, p1 = 0, polis = 0, hausdorff = std::nan(""), corner = std::nan("");
};

Scores score(const core::Polygon& pred, const core::Polygon& truth) {
  const auto f = eval::compareFootprints(pred, truth);
  return {f.iou, f.p1, f.polis, f.hausdorff, f.cornerRms};
}

core::Polygon grownBox(const core::Polygon& p, double g) {
  const cv::Rect2d b = core::boundingBox(p.outer);
  return {{{b.x - g, b.y - g}, {b.x + b.width + g, b.y - g}, {b.x + b.width + g, b.y + b.height + g},
           {b.x - g, b.y + b.height + g}},
          {}};
}

core::Polygon jittered(const core::Polygon& p, std::mt19937& rng, double amount) {
  std::uniform_real_distribution<double> u(-amount, amount);
  for (int attempt = 0; attempt < 50; ++attempt) {
    core::Polygon out;
    for (const auto& v : p.outer) out.outer.emplace_back(v.x + u(rng), v.y + u(rng));
    if (core::isSimple(out.outer)) return out;  // holes are left for the courtyard search
  }
  return {p.outer, {}};
}

// Diagnostic picture of one run: the left image around the ROI (3x), with the true outline in
// green, the init in blue and the result in red; beside it the same crop of c_roof < c_ground
// (white: the roof interval matches better).
void dumpPicture(const std::string& path, const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi,
                 const DelineationRequest& req, const core::Polygon& truth, const core::Polygon& result,
                 const core::Polygon& raw, const stereo::CostParams& costParams) {
  const int k = 3;
  cv::Mat crop;
  cv::normalize(left(roi), crop, 0, 255, cv::NORM_MINMAX, CV_8U);
  cv::resize(crop, crop, {}, k, k, cv::INTER_NEAREST);
  cv::cvtColor(crop, crop, cv::COLOR_GRAY2BGR);
  cv::Mat roofBetter;
  DelineationRequest r = req;
  const auto [rs, gs] = costIntervals(r.roof, *r.ground, DelineationParams{}.balanceIntervals);
  const auto costs = stereo::CorrelationCostService::compute(left, right, roi, std::min(rs.min, gs.min),
                                                            std::max(rs.max, gs.max), costParams);
  if (costs) {
    const cv::Mat cr = costs->minCost(rs.min, rs.max), cg = costs->minCost(gs.min, gs.max);
    roofBetter = cr < cg;
    core::Polygon local = truth;
    for (auto& v : local.outer) v -= cv::Point2d(roi.tl());
    for (auto& h : local.holes) for (auto& v : h) v -= cv::Point2d(roi.tl());
    const cv::Mat inside = core::rasterize(local, roi.size());
    std::printf("      diag roof %d:%d ground %d:%d  mean c_roof %.3f c_ground %.3f inside truth; outside %.3f %.3f\n",
                r.roof.min, r.roof.max, r.ground->min, r.ground->max, cv::mean(cr, inside)[0], cv::mean(cg, inside)[0],
                cv::mean(cr, ~inside)[0], cv::mean(cg, ~inside)[0]);
    if (std::getenv("BENCH_DUMP_COSTS")) {
      cv::Mat grey;
      cv::hconcat(cr, cg, grey);
      grey.convertTo(grey, CV_8U, 255.0);
      cv::resize(grey, grey, {}, k, k, cv::INTER_NEAREST);
      bench::writeImage(path.substr(0, path.size() - 4) + "_costs.png", grey);
    }
    cv::resize(roofBetter, roofBetter, {}, k, k, cv::INTER_NEAREST);
    cv::cvtColor(roofBetter, roofBetter, cv::COLOR_GRAY2BGR);
    roofBetter *= 0.6;
  }
  auto draw = [&](cv::Mat& img, const core::Polygon& p, cv::Scalar colour) {
    auto ring = [&](const core::Ring& rg) {
      std::vector<cv::Point> pts;
      for (const auto& v : rg) pts.emplace_back(int(std::lround((v.x - roi.x) * k)), int(std::lround((v.y - roi.y) * k)));
      cv::polylines(img, pts, true, colour, 1);
    };
    ring(p.outer);
    for (const auto& h : p.holes) ring(h);
  };
  for (cv::Mat* img : {&crop, &roofBetter}) {
    if (img->empty()) continue;
    draw(*img, truth, {0, 200, 0});
    draw(*img, req.init, {255, 80, 0});
    draw(*img, raw, {0, 200, 255});
    draw(*img, result, {0, 0, 255});
  }
  cv::Mat both = crop;
  if (!roofBetter.empty()) cv::hconcat(crop, roofBetter, both);
  bench::writeImage(path, both);
}


// Regularization stage: the raw outline's scores beside the regularized ones.
struct RegStats {
  std::vector<double> rawIou, rawCorner, rawRatio, regRatio, energyPerPx;
  std::map<std::string, int> status, reasons;
};

int vertexCount(const core::Polygon& p) {
  size_t n = p.outer.size();
  for (const auto& h : p.holes) n += h.size();
  return static_cast<int>(n);
}

double outlineLength(const core::Polygon& p) {
  auto ring = [](const core::Ring& r) {
    double s = 0;
    for (size_t i = 0; i < r.size(); ++i) s += cv::norm(r[(i + 1) % r.size()] - r[i]);
    return s;
  };
  double s = ring(p.outer);
  for (const auto& h : p.holes) s += ring(h);
  return s;
}

// The first words of a reason (numbers dropped): "energy", "deviation", "round outline", ...
std::string reasonKind(const std::string& reason) {
  const size_t cut = reason.find_first_of("0123456789+(");
  std::string k = reason.substr(0, cut);
  while (!k.empty() && k.back() == ' ') k.pop_back();
  return k;
}

struct Options {
  int scenes = 3, referenceRuns = 3, firstSeed = 1;
  std::string dumpDir;   // --dump DIR: one diagnostic PNG per run
  std::string onlyInit;  // --init box+8|jit6: run one initialisation only
  bool oracleVegetation = false;  // --oracle-vegetation: true tree pixels given as excluded
  // --map: each scene matched (stereo::matchStereo over its ground - 8 .. highest roof + 8 px), the
  // map and that range given with every request, as the GUI and `run` do (the map's costs and ground).
  bool withMap = false;
  bool diag =
      false;  // --diag: spatial decomposition of F(truth) - F(result) (implies BENCH_VERBOSE)
  sim::SceneParams scene;
};

// The options, or nothing after the usage line when they are wrong.
std::optional<Options> parseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const bool valued = i + 1 < argc;
    if (!std::strcmp(argv[i], "--tiny")) {
      o.scenes = 1;
      o.referenceRuns = 1;
      o.scene.width = 320;
      o.scene.height = 240;
      o.scene.buildings = 3;
      o.scene.trees = 2;
    } else if (!std::strcmp(argv[i], "--scenes") && valued) {
      o.scenes = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--dump") && valued) {
      o.dumpDir = argv[++i];
    } else if (!std::strcmp(argv[i], "--reference-runs") && valued) {
      o.referenceRuns = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--seed") && valued) {
      o.firstSeed = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--size") && valued &&
               std::sscanf(argv[i + 1], "%dx%d", &o.scene.width, &o.scene.height) == 2) {
      ++i;
    } else if (!std::strcmp(argv[i], "--buildings") && valued) {
      o.scene.buildings = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--trees") && valued) {
      o.scene.trees = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--oracle-vegetation")) {
      o.oracleVegetation = true;
    } else if (!std::strcmp(argv[i], "--diag")) {
      o.diag = true;
    } else if (!std::strcmp(argv[i], "--map")) {
      o.withMap = true;
    } else if (!std::strcmp(argv[i], "--init") && valued) {
      o.onlyInit = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_delineation [--tiny] [--scenes N] [--seed FIRST] [--size WxH] "
                   "[--buildings N] "
                   "[--trees N] [--init box+8|jit6] [--reference-runs N] [--dump DIR] [--diag] "
                   "[--oracle-vegetation] [--map]\n");
      return std::nullopt;
    }
  }
  return o;
}

// What the summary needs of every run.
struct Totals {
  std::map<std::string, std::vector<double>> ious, corners, hausdorffs;  // by init
  // Per-group IoU and corner RMS for the breakdown, keyed by "init|group".
  std::map<std::string, std::vector<double>> groupIous, groupCorners;
  std::vector<double> times, regTimes;
  std::map<std::string, RegStats> regStats;     // by init
  std::map<std::string, DiagTable> diagTotals;  // by init
  int sideOk = 0, sideTotal = 0, failures = 0;
  // The incremental energy against the rasterising reference, on the first --reference-runs.
  double fastMs = 0, referenceMs = 0;
  long long fastEvaluations = 0, referenceEvaluations = 0;
  int referenceDone = 0;
};

// A scene's images as float and, with --map, its matcher's map and the range it searched.
struct SceneImages {
  cv::Mat left, right, map;
  DisparityInterval range{0, 0};
};

SceneImages sceneImages(const sim::Scene& scene, bool withMap) {
  SceneImages images;
  scene.left.convertTo(images.left, CV_32F);
  scene.right.convertTo(images.right, CV_32F);
  if (!withMap) return images;
  double low = 1e9, high = -1e9;
  for (const auto& fp : scene.footprints) {
    low = std::min(low, number(fp, "ground_disparity", 0));
    high = std::max(high, number(fp, "roof_disparity_max", 0));
  }
  images.range = {static_cast<int>(std::floor(low)) - 8, static_cast<int>(std::ceil(high)) + 8};
  stereo::MatchParams mp;
  mp.dmin = images.range.min;
  mp.dmax = images.range.max;
  images.map = stereo::matchStereo(images.left, images.right, mp).disparity;
  return images;
}

int groundDisparity(const core::Feature& fp) {
  return static_cast<int>(std::lround(number(fp, "ground_disparity", 0)));
}

// The request both inits of a building share: the true roof interval, the ground tolerance around
// the true ground, with --map the scene's map and range, and in the oracle run the true
// vegetation excluded (how much of the remaining error trees at roof height explain).
DelineationRequest baseRequest(const core::Feature& fp, const sim::Scene& scene,
                               const SceneImages& images, bool oracleVegetation,
                               const DelineationParams& params) {
  DelineationRequest base;
  if (oracleVegetation) base.excludeMask = scene.labels == sim::kLabelVegetation;
  if (!images.map.empty()) {
    base.disparity = images.map;
    base.searchRange = images.range;
  }
  base.roof = {static_cast<int>(std::floor(number(fp, "roof_disparity_min", 0))),
               static_cast<int>(std::ceil(number(fp, "roof_disparity_max", 0)))};
  const int g = groundDisparity(fp);
  base.ground = DisparityInterval{g - params.groundTolerance, g + params.groundTolerance};
  return base;
}

// The prepared energy of a request on `roi`, from a cost service over its roof and ground
// intervals, as delineate builds it.
PreparedEnergy preparedEnergy(const cv::Mat& left, const cv::Mat& right,
                              const DelineationRequest& req, const cv::Rect& roi,
                              const DelineationParams& params) {
  const auto [roof, ground] = costIntervals(req.roof, *req.ground, params.balanceIntervals);
  const auto costs = stereo::CorrelationCostService::compute(
      left, right, roi, std::min(roof.min, ground.min), std::max(roof.max, ground.max),
      stereo::CostParams{params.costWindow, 1.0, params.costBrightness});
  return prepareEnergy(*costs, left, right, req, params);
}

// The regularization stage of a run: the raw outline's scores, vertex ratio and the stage's
// energy change per px of outline in `st`, the stage's outline part alone timed in `regTimes`;
// returns the run's "regularization" line.
std::string regularizationLine(const core::Feature& fp, const DelineationResult& r,
                               const DelineationParams& params, const cv::Mat& left, RegStats& st,
                               std::vector<double>& regTimes) {
  const Scores raw = score(r.rawPolygon, fp.polygon);
  const auto t2 = Clock::now();
  (void)regularizeOutline(r.rawPolygon, params.regularization, left);
  regTimes.push_back(ms(t2, Clock::now()));
  const double corners0 = vertexCount(fp.polygon), rawVerts = vertexCount(r.rawPolygon);
  st.rawIou.push_back(raw.iou);
  st.rawCorner.push_back(raw.corner);
  st.status[toString(r.regularization.status)]++;
  if (r.regularization.status == RegularizationStatus::KeptRaw)
    st.reasons[reasonKind(r.regularization.reason)]++;
  if (text(fp, "shape") != "angled") {
    st.rawRatio.push_back(rawVerts / corners0);
    st.regRatio.push_back(r.vertexCount / corners0);
  }
  const double length = outlineLength(r.rawPolygon);
  if (r.regularization.status != RegularizationStatus::Off && r.regularization.energyChange != 0) {
    st.energyPerPx.push_back(r.regularization.energyChange / length);
  }
  return cv::format(
      "      regularization %s%s%s: IoU raw %.3f, vertices raw %.0f, corner RMS raw %.2f; dF %+.1f "
      "(%+.3f/px), "
      "deviation %.2f px, orientation %.1f deg\n",
      toString(r.regularization.status).c_str(), r.regularization.reason.empty() ? "" : " - ",
      r.regularization.reason.c_str(), raw.iou, rawVerts, raw.corner, r.regularization.energyChange,
      r.regularization.energyChange / length, r.regularization.deviation,
      r.regularization.orientationDeg);
}

// BENCH_DUMP_OUTLINES=FILE: one JSON line per run, the true, raw and regularized outlines, to
// compare other regularizers.
void dumpOutlines(int seed, int id, const core::Feature& fp, const char* initName,
                  const DelineationResult& r) {
  const char* path = std::getenv("BENCH_DUMP_OUTLINES");
  if (!path) return;
  appendJsonLine(path, {{"scene", seed},
                        {"id", id},
                        {"shape", text(fp, "shape")},
                        {"init", initName},
                        {"truth", ringsJson(fp.polygon)},
                        {"raw", ringsJson(r.rawPolygon)},
                        {"regularized", ringsJson(r.polygon)}});
}

// The run's IoU and corner RMS under its groups: its roof type, its shape and issue #4's subset
// (flat and gable roofs, rectilinear, i.e. right-angled, footprints).
void addToBreakdown(const core::Feature& fp, const std::string& initName, const Scores& sc,
                    Totals& totals) {
  const std::string shape = text(fp, "shape"), roofType = text(fp, "roof_type");
  const bool issueSubset = (roofType == "flat" || roofType == "gable") && shape != "angled";
  std::vector<std::string> groups{"roof " + roofType, "shape " + shape};
  if (issueSubset) groups.push_back("flat+gable, rectilinear");
  for (const auto& group : groups) {
    totals.groupIous[initName + "|" + group].push_back(sc.iou);
    totals.groupCorners[initName + "|" + group].push_back(sc.corner);
  }
}

// The path of a run's pictures without their ending: DIR/s<seed>_b<id>_<init>.
std::string runPicturePath(const std::string& dumpDir, int seed, int id, const char* initName) {
  return dumpDir + "/s" + std::to_string(seed) + "_b" + std::to_string(id) + "_" + initName;
}

// A polygon in ROI pixel coordinates, its vertices rounded.
IntPolygon roiPolygon(const core::Polygon& p, const cv::Rect& roi) {
  auto ring = [&](const core::Ring& rg) {
    IntRing out;
    for (const auto& v : rg)
      out.emplace_back(int(std::lround(v.x - roi.x)), int(std::lround(v.y - roi.y)));
    return out;
  };
  IntPolygon out{ring(p.outer), {}};
  for (const auto& h : p.holes) out.holes.push_back(ring(h));
  return out;
}

// --diag: where F(truth) and F(result) differ (energy_diag.hpp), added to the init's totals in
// `diagTotals`; with --dump, the picture of it with the true outline in white.
void diagnoseRun(const PreparedEnergy& pe, const IntPolygon& truthLocal,
                 const IntPolygon& resultLocal, const std::string& picturePath,
                 const std::string& initName, std::map<std::string, DiagTable>& diagTotals) {
  DiagTable table;
  cv::Mat picture;
  diagnose(pe.images, pe.excluded, truthLocal, resultLocal, table,
           picturePath.empty() ? nullptr : &picture);
  printDiag(table, "      ", false);
  for (const auto& [key, c] : table) {
    DiagCell& cell = diagTotals[initName][key];
    cell.n += c.n;
    cell.dF += c.dF;
    cell.cr += c.cr;
    cell.cg += c.cg;
  }
  if (picture.empty()) return;
  cv::resize(picture, picture, {}, 3, 3, cv::INTER_NEAREST);
  std::vector<cv::Point> pts;
  for (const auto& v : truthLocal.outer) pts.emplace_back(v.x * 3, v.y * 3);
  cv::polylines(picture, pts, true, {255, 255, 255}, 1);
  bench::writeImage(picturePath, picture);
}

// BENCH_VERBOSE or --diag: the result's vertices and box against the truth's, and the energy of
// the true outline (rounded to pixel corners) beside the result's on the same prepared energy:
// tells an optimisation failure (truth lower) from an energy failure (truth higher).
void explainRun(const core::Feature& fp, const DelineationResult& r, const DelineationRequest& req,
                const SceneImages& images, const DelineationParams& params, const Options& options,
                const std::string& picturePath, const std::string& initName, Totals& totals) {
  const cv::Rect2d a = core::boundingBox(r.polygon.outer), b = core::boundingBox(fp.polygon.outer);
  std::printf("      iterations %d energy %.2f vertices:", r.iterations, r.terms.total());
  for (const auto& v : r.polygon.outer) std::printf(" (%.0f,%.0f)", v.x - r.roi.x, v.y - r.roi.y);
  std::printf("\n");
  std::printf("      bbox pred %.1f %.1f %.1f %.1f truth %.1f %.1f %.1f %.1f\n", a.x, a.y, a.br().x,
              a.br().y, b.x, b.y, b.br().x, b.br().y);
  const PreparedEnergy pe = preparedEnergy(images.left, images.right, req, r.roi, params);
  const IntPolygon truthLocal = roiPolygon(fp.polygon, r.roi),
                   resultLocal = roiPolygon(r.polygon, r.roi);
  const EnergyWeights w{params.edgeWeight, params.rigidity, params.edgeContrast, params.minAngle,
                        params.minGap};
  for (const auto& [label, poly] :
       {std::pair{"truth ", truthLocal}, std::pair{"result", resultLocal}}) {
    const EnergyTerms t = referenceEnergy(pe.images, w, poly);
    std::printf("      F(%s) %.2f =", label, t.total());
    for (double v : t.term) std::printf(" %.2f", v);
    std::printf("\n");
  }
  if (options.diag)
    diagnoseRun(pe, truthLocal, resultLocal, picturePath, initName, totals.diagTotals);
}

// One initialisation of one building: its row and "regularization" line, its scores in `totals`,
// its outlines (BENCH_DUMP_OUTLINES), its picture (--dump) and the details of BENCH_VERBOSE and
// --diag; a "failed" row when it throws.
void runInit(const core::Feature& fp, const char* initName, const DelineationRequest& base,
             const SceneImages& images, int seed, const Options& options,
             const DelineationParams& params, std::mt19937& rng, Totals& totals) {
  const int id = static_cast<int>(number(fp, "id", 0));
  DelineationRequest req = base;
  req.init =
      std::string(initName) == "box+8" ? grownBox(fp.polygon, 8) : jittered(fp.polygon, rng, 6);
  try {
    const auto t0 = Clock::now();
    const auto r = delineate(images.left, images.right, req, params);
    const auto t1 = Clock::now();
    const Scores sc = score(r.polygon, fp.polygon);
    const std::string regLine =
        regularizationLine(fp, r, params, images.left, totals.regStats[initName], totals.regTimes);
    dumpOutlines(seed, id, fp, initName, r);
    totals.ious[initName].push_back(sc.iou);
    totals.corners[initName].push_back(sc.corner);
    totals.hausdorffs[initName].push_back(sc.hausdorff);
    totals.times.push_back(ms(t0, t1));
    addToBreakdown(fp, initName, sc, totals);
    std::printf("%-5d %-3d %-9s %-6s %-5s %7.3f %7.2f %7.2f %7.2f %7.2f %8.1f %5d %5zu\n", seed, id,
                text(fp, "shape").c_str(), text(fp, "roof_type").c_str(), initName, sc.iou, sc.p1,
                sc.polis, sc.hausdorff, sc.corner, ms(t0, t1), r.vertexCount,
                r.polygon.holes.size());
    std::fputs(regLine.c_str(), stdout);
    const std::string picturePath =
        options.dumpDir.empty() ? "" : runPicturePath(options.dumpDir, seed, id, initName);
    if (!picturePath.empty()) {
      dumpPicture(picturePath + ".png", images.left, images.right, r.roi, req, fp.polygon,
                  r.polygon, r.rawPolygon,
                  stereo::CostParams{params.costWindow, 1.0, params.costBrightness});
    }
    if (options.diag || std::getenv("BENCH_VERBOSE")) {
      explainRun(fp, r, req, images, params, options,
                 picturePath.empty() ? "" : picturePath + "_diag.png", initName, totals);
    }
  } catch (const std::exception& e) {
    ++totals.failures;
    std::printf("%-5d %-3d failed: %s\n", seed, id, e.what());
  }
}

// On the prepared energy of a building's box init: the occlusion side found from the data
// against the geometry's and, while fewer than --reference-runs were made, the incremental
// energy's speed against the rasterising reference's (courtyards off), with whether both reach
// the same outline.
void speedAndSide(const core::Feature& fp, const DelineationRequest& base,
                  const SceneImages& images, const DelineationParams& params, int referenceRuns,
                  Totals& totals) {
  DelineationRequest req = base;
  req.init = grownBox(fp.polygon, 8);
  try {
    const cv::Rect roi = regionOfInterest(images.left, images.right, req, params);
    const PreparedEnergy prepared = preparedEnergy(images.left, images.right, req, roi, params);
    ++totals.sideTotal;
    const int expectedSide = number(fp, "roof_disparity_min", 0) > groundDisparity(fp) ? -1 : +1;
    totals.sideOk += prepared.images.occlusionSide == expectedSide;
    if (totals.referenceDone >= referenceRuns) return;
    DelineationParams p = params;
    p.courtyards = false;
    const auto t0 = Clock::now();
    const auto fast = optimiseActivePolygon(prepared.images, prepared.init, p);
    const auto t1 = Clock::now();
    const auto ref = optimiseActivePolygon(prepared.images, prepared.init, p, {}, nullptr,
                                           EnergyMode::Reference);
    const auto t2 = Clock::now();
    totals.fastMs += ms(t0, t1);
    totals.referenceMs += ms(t1, t2);
    totals.fastEvaluations += fast.evaluations;
    totals.referenceEvaluations += ref.evaluations;
    ++totals.referenceDone;
    std::printf(
        "      speed: ROI %dx%d incremental %.1f ms, reference %.1f ms, same result: %s (F %.6f vs "
        "%.6f)\n",
        roi.width, roi.height, ms(t0, t1), ms(t1, t2),
        fast.polygon.outer == ref.polygon.outer ? "yes" : "no", fast.terms.total(),
        ref.terms.total());
  } catch (const std::exception& e) {
    std::printf("      speed run failed: %s\n", e.what());
  }
}

// Every building of a scene from each init, then its speed and occlusion-side run.
void runScene(const sim::Scene& scene, const Options& options, const DelineationParams& params,
              std::mt19937& rng, Totals& totals) {
  const SceneImages images = sceneImages(scene, options.withMap);
  for (const auto& fp : scene.footprints) {
    const DelineationRequest base =
        baseRequest(fp, scene, images, options.oracleVegetation, params);
    for (const char* initName : {"box+8", "jit6"}) {
      if (!options.onlyInit.empty() && options.onlyInit != initName) continue;
      runInit(fp, initName, base, images, scene.seed, options, params, rng, totals);
    }
    speedAndSide(fp, base, images, params, options.referenceRuns, totals);
  }
}

// The values under `key`; none when it has none.
const std::vector<double>& valuesAt(const std::map<std::string, std::vector<double>>& values,
                                    const std::string& key) {
  static const std::vector<double> none;
  const auto it = values.find(key);
  return it == values.end() ? none : it->second;
}

// Per init: IoU, corner RMS and Hausdorff distance; then the breakdown by group.
void printScores(const Totals& totals) {
  for (const auto& [name, v] : totals.ious) {
    const auto& h = valuesAt(totals.hausdorffs, name);
    std::printf(
        "  init %-6s buildings %3zu  mean IoU %.3f  median IoU %.3f  median corner RMS %.2f px  "
        "Hausdorff mean %.1f median %.1f max %.1f px\n",
        name.c_str(), v.size(), mean(v), median(v), median(valuesAt(totals.corners, name)), mean(h),
        median(h), h.empty() ? std::nan("") : *std::max_element(h.begin(), h.end()));
  }
  std::printf("  breakdown (mean IoU, median IoU, median corner RMS, runs):\n");
  for (const auto& [key, v] : totals.groupIous) {
    const size_t bar = key.find('|');
    std::printf("    %-6s %-26s %.3f  %.3f  %.2f px  %zu\n", key.substr(0, bar).c_str(),
                key.substr(bar + 1).c_str(), mean(v), median(v),
                median(valuesAt(totals.groupCorners, key)), v.size());
  }
}

// Per init: the scores before the regularization stage and after it, its outcomes and the energy
// change it made.
void printRegularization(const Totals& totals, const DelineationParams& params) {
  std::printf("  regularization (%s; raw = the same runs before it):\n", params.regularization.mode.c_str());
  for (const auto& [name, st] : totals.regStats) {
    const std::vector<double>& ious = valuesAt(totals.ious, name);
    std::printf(
        "    init %-6s mean IoU raw %.3f -> %.3f (%+.4f)  median corner RMS raw %.2f -> %.2f px  "
        "median vertices / true corners (rectilinear, %zu) raw %.2f -> %.2f\n",
        name.c_str(), mean(st.rawIou), mean(ious), mean(ious) - mean(st.rawIou),
        median(st.rawCorner), median(valuesAt(totals.corners, name)), st.regRatio.size(),
        median(st.rawRatio), median(st.regRatio));
    std::printf("      status:");
    for (const auto& [k, n] : st.status) std::printf(" %s %d", k.c_str(), n);
    std::printf("; kept raw because:");
    for (const auto& [k, n] : st.reasons) std::printf(" %s %d", k.c_str(), n);
    std::vector<double> e = st.energyPerPx;
    std::sort(e.begin(), e.end());
    if (!e.empty()) {
      std::printf("; dF per px of outline: median %+.3f, 90 %% %+.3f, max %+.3f", median(e),
                  e[static_cast<size_t>(0.9 * (e.size() - 1))], e.back());
    }
    std::printf("\n");
  }
}

void printSummary(const Totals& totals, const DelineationParams& params) {
  std::printf("\nsummary\n");
  printScores(totals);
  printRegularization(totals, params);
  if (!totals.regTimes.empty()) {
    std::printf(
        "  regularization time per building: median %.2f ms, max %.2f ms (outline only, without "
        "the energy gate)\n",
        median(totals.regTimes), *std::max_element(totals.regTimes.begin(), totals.regTimes.end()));
  }
  std::printf("  median time per building %.1f ms (cost service + optimisation, one core)\n",
              median(totals.times));
  std::printf("  occlusion side from the data agrees with the geometry: %d / %d\n", totals.sideOk,
              totals.sideTotal);
  if (totals.referenceDone > 0) {
    std::printf(
        "  speed ratio incremental vs reference: %.1fx (%d runs, %.1f vs %.1f ms; %lld vs %lld "
        "evaluations)\n",
        totals.referenceMs / std::max(1e-9, totals.fastMs), totals.referenceDone, totals.fastMs,
        totals.referenceMs, totals.fastEvaluations, totals.referenceEvaluations);
  }
  for (const auto& [name, table] : totals.diagTotals) {
    std::printf("  diag %s: F(truth) - F(result) on pixels labelled differently (truth>result), all runs\n",
                name.c_str());
    printDiag(table, "    ", true);
  }
  std::printf("  failures %d\n", totals.failures);
}

}  // namespace

int main(int argc, char** argv) {
  delineo::core::tuneAllocatorForLargeImages();  // as the CLI and the GUI do
  const std::optional<Options> options = parseOptions(argc, argv);
  if (!options) return 2;
  if (options->oracleVegetation) {
    std::printf(
        "ORACLE RUN: the true vegetation pixels are given as excluded (what a perfect vegetation "
        "mask would give; not the method's result)\n");
  }
  DelineationParams params;
  if (const char* json = std::getenv("BENCH_PARAMS"))
    core::fromJson(params, nlohmann::json::parse(json));
  std::printf("%-5s %-3s %-9s %-6s %-5s %7s %7s %7s %7s %7s %8s %5s %5s\n", "scene", "id", "shape",
              "roof", "init", "IoU", "p1%", "PoLiS", "Hausd", "cornRMS", "ms", "verts", "holes");
  Totals totals;
  std::mt19937 rng(12345);
  sim::SceneParams sceneParams = options->scene;
  for (int s = 0; s < options->scenes; ++s) {
    sceneParams.seed = options->firstSeed + s;
    runScene(sim::simulateScene(sceneParams), *options, params, rng, totals);
  }
  printSummary(totals, params);
  return totals.failures == 0 && totals.sideOk == totals.sideTotal ? 0 : 1;
}
