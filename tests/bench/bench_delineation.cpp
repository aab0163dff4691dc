// Benchmark of the statistical active polygon on simulated scenes: per-building IoU, p1, PoLiS
// and corner RMS against the ground truth from two initialisations, (a) the true outline's
// bounding rectangle grown by 8 px and (b) the true polygon with every vertex jittered by up to
// 6 px; time per building; speed ratio of the incremental energy over the rasterising reference
// on the same runs. Plain main printing a table; `--tiny` is the ctest smoke run.
#include <algorithm>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
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

}  // namespace

int main(int argc, char** argv) {
  delineo::core::tuneAllocatorForLargeImages();  // as the CLI and the GUI do
  int scenes = 3, referenceRuns = 3, firstSeed = 1;
  std::string dumpDir;  // --dump DIR: one diagnostic PNG per run
  std::string onlyInit;  // --init box+8|jit6: run one initialisation only
  bool oracleVegetation = false;  // --oracle-vegetation: true tree pixels given as excluded
  // --map: each scene matched (stereo::matchStereo over its ground - 8 .. highest roof + 8 px), the
  // map and that range given with every request, as the GUI and `run` do (the map's costs and ground).
  bool withMap = false;
  bool diag = false;     // --diag: spatial decomposition of F(truth) - F(result) (implies BENCH_VERBOSE)
  std::map<std::string, DiagTable> diagTotals;  // by init
  sim::SceneParams sceneParams;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--tiny")) {
      scenes = 1;
      referenceRuns = 1;
      sceneParams.width = 320;
      sceneParams.height = 240;
      sceneParams.buildings = 3;
      sceneParams.trees = 2;
    } else if (!std::strcmp(argv[i], "--scenes") && i + 1 < argc) {
      scenes = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--dump") && i + 1 < argc) {
      dumpDir = argv[++i];
    } else if (!std::strcmp(argv[i], "--reference-runs") && i + 1 < argc) {
      referenceRuns = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) {
      firstSeed = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--size") && i + 1 < argc &&
               std::sscanf(argv[i + 1], "%dx%d", &sceneParams.width, &sceneParams.height) == 2) {
      ++i;
    } else if (!std::strcmp(argv[i], "--buildings") && i + 1 < argc) {
      sceneParams.buildings = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--trees") && i + 1 < argc) {
      sceneParams.trees = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--oracle-vegetation")) {
      oracleVegetation = true;
    } else if (!std::strcmp(argv[i], "--diag")) {
      diag = true;
    } else if (!std::strcmp(argv[i], "--map")) {
      withMap = true;
    } else if (!std::strcmp(argv[i], "--init") && i + 1 < argc) {
      onlyInit = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_delineation [--tiny] [--scenes N] [--seed FIRST] [--size WxH] "
                   "[--buildings N] "
                   "[--trees N] [--init box+8|jit6] [--reference-runs N] [--dump DIR] [--diag] "
                   "[--oracle-vegetation] [--map]\n");
      return 2;
    }
  }
  if (oracleVegetation) {
    std::printf(
        "ORACLE RUN: the true vegetation pixels are given as excluded (what a perfect vegetation "
        "mask would give; not the method's result)\n");
  }
  DelineationParams params;
  if (const char* json = std::getenv("BENCH_PARAMS")) core::fromJson(params, nlohmann::json::parse(json));
  std::printf("%-5s %-3s %-9s %-6s %-5s %7s %7s %7s %7s %7s %8s %5s %5s\n", "scene", "id", "shape",
              "roof", "init", "IoU", "p1%", "PoLiS", "Hausd", "cornRMS", "ms", "verts", "holes");
  std::map<std::string, std::vector<double>> ious, corners, hausdorffs;
  // Per-group IoU and corner RMS for the breakdown, keyed by "init|group".
  std::map<std::string, std::vector<double>> groupIous, groupCorners;
  std::vector<double> times, regTimes;
  std::map<std::string, RegStats> regStats;  // by init
  int sideOk = 0, sideTotal = 0, failures = 0;
  double fastMs = 0, referenceMs = 0;
  long long fastEvaluations = 0, referenceEvaluations = 0;
  int referenceDone = 0;
  std::mt19937 rng(12345);
  for (int s = 0; s < scenes; ++s) {
    sceneParams.seed = firstSeed + s;
    const sim::Scene scene = sim::simulateScene(sceneParams);
    cv::Mat left, right;
    scene.left.convertTo(left, CV_32F);
    scene.right.convertTo(right, CV_32F);
    cv::Mat map;
    DisparityInterval range{0, 0};
    if (withMap) {
      double low = 1e9, high = -1e9;
      for (const auto& fp : scene.footprints) {
        low = std::min(low, number(fp, "ground_disparity", 0));
        high = std::max(high, number(fp, "roof_disparity_max", 0));
      }
      range = {static_cast<int>(std::floor(low)) - 8, static_cast<int>(std::ceil(high)) + 8};
      stereo::MatchParams mp;
      mp.dmin = range.min;
      mp.dmax = range.max;
      map = stereo::matchStereo(left, right, mp).disparity;
    }
    for (const auto& fp : scene.footprints) {
      const int id = static_cast<int>(number(fp, "id", 0));
      DelineationRequest base;
      // Oracle run: how much of the remaining error trees at roof height explain.
      if (oracleVegetation) base.excludeMask = scene.labels == sim::kLabelVegetation;
      if (withMap) {
        base.disparity = map;
        base.searchRange = range;
      }
      base.roof = {static_cast<int>(std::floor(number(fp, "roof_disparity_min", 0))),
                   static_cast<int>(std::ceil(number(fp, "roof_disparity_max", 0)))};
      const int g = static_cast<int>(std::lround(number(fp, "ground_disparity", 0)));
      base.ground = DisparityInterval{g - params.groundTolerance, g + params.groundTolerance};
      for (const char* initName : {"box+8", "jit6"}) {
        if (!onlyInit.empty() && onlyInit != initName) continue;
        DelineationRequest req = base;
        req.init = std::string(initName) == "box+8" ? grownBox(fp.polygon, 8) : jittered(fp.polygon, rng, 6);
        try {
          const auto t0 = Clock::now();
          const auto r = delineate(left, right, req, params);
          const auto t1 = Clock::now();
          const Scores sc = score(r.polygon, fp.polygon);
          std::string regLine;
          {
            // The same run before its last stage (regularization), and that stage alone timed.
            const Scores raw = score(r.rawPolygon, fp.polygon);
            const auto t2 = Clock::now();
            const RegularizationOutcome again = regularizeOutline(r.rawPolygon, params.regularization, left);
            regTimes.push_back(ms(t2, Clock::now()));
            (void)again;
            const std::string shape = text(fp, "shape");
            const double corners0 = vertexCount(fp.polygon), rawVerts = vertexCount(r.rawPolygon);
            RegStats& st = regStats[initName];
            st.rawIou.push_back(raw.iou);
            st.rawCorner.push_back(raw.corner);
            st.status[toString(r.regularization.status)]++;
            if (r.regularization.status == RegularizationStatus::KeptRaw) st.reasons[reasonKind(r.regularization.reason)]++;
            if (shape != "angled") {
              st.rawRatio.push_back(rawVerts / corners0);
              st.regRatio.push_back(r.vertexCount / corners0);
            }
            const double length = outlineLength(r.rawPolygon);
            if (r.regularization.status != RegularizationStatus::Off && r.regularization.energyChange != 0) {
              st.energyPerPx.push_back(r.regularization.energyChange / length);
            }
            regLine = cv::format("      regularization %s%s%s: IoU raw %.3f, vertices raw %.0f, corner RMS raw %.2f; dF %+.1f (%+.3f/px), "
                        "deviation %.2f px, orientation %.1f deg\n",
                        toString(r.regularization.status).c_str(), r.regularization.reason.empty() ? "" : " - ",
                        r.regularization.reason.c_str(), raw.iou, rawVerts, raw.corner, r.regularization.energyChange,
                        r.regularization.energyChange / length, r.regularization.deviation, r.regularization.orientationDeg);
          }
          std::string regLineCopy = regLine;
          if (const char* path = std::getenv("BENCH_DUMP_OUTLINES")) {
            // One JSON line per run: the true and the raw outline, to compare other regularizers.
            auto rings = [](const core::Polygon& p) {
              nlohmann::json out = nlohmann::json::array();
              for (const core::Ring* outer : {&p.outer}) {
                nlohmann::json ring = nlohmann::json::array();
                for (const auto& v : *outer) ring.push_back({v.x, v.y});
                out.push_back(ring);
              }
              for (const auto& h : p.holes) {
                nlohmann::json ring = nlohmann::json::array();
                for (const auto& v : h) ring.push_back({v.x, v.y});
                out.push_back(ring);
              }
              return out;
            };
            const nlohmann::json line{{"scene", sceneParams.seed}, {"id", id}, {"shape", text(fp, "shape")},
                                      {"init", initName}, {"truth", rings(fp.polygon)}, {"raw", rings(r.rawPolygon)},
                                      {"regularized", rings(r.polygon)}};
            if (FILE* f = std::fopen(path, "a")) {
              std::fprintf(f, "%s\n", line.dump().c_str());
              std::fclose(f);
            }
          }
          ious[initName].push_back(sc.iou);
          corners[initName].push_back(sc.corner);
          hausdorffs[initName].push_back(sc.hausdorff);
          times.push_back(ms(t0, t1));
          {
            const std::string shape = text(fp, "shape"), roofType = text(fp, "roof_type");
            // Issue #4's wording: flat and gable roofs, rectilinear (right-angled) footprints.
            const bool issueSubset = (roofType == "flat" || roofType == "gable") && shape != "angled";
            std::vector<std::string> groups{"roof " + roofType, "shape " + shape};
            if (issueSubset) groups.push_back("flat+gable, rectilinear");
            for (const auto& group : groups) {
              groupIous[std::string(initName) + "|" + group].push_back(sc.iou);
              groupCorners[std::string(initName) + "|" + group].push_back(sc.corner);
            }
          }
          std::printf("%-5d %-3d %-9s %-6s %-5s %7.3f %7.2f %7.2f %7.2f %7.2f %8.1f %5d %5zu\n", sceneParams.seed,
                      id, text(fp, "shape").c_str(), text(fp, "roof_type").c_str(), initName, sc.iou, sc.p1,
                      sc.polis, sc.hausdorff, sc.corner, ms(t0, t1), r.vertexCount, r.polygon.holes.size());
          std::fputs(regLineCopy.c_str(), stdout);
          if (!dumpDir.empty()) {
            dumpPicture(dumpDir + "/s" + std::to_string(sceneParams.seed) + "_b" + std::to_string(id) + "_" +
                            initName + ".png",
                        left, right, r.roi, req, fp.polygon, r.polygon, r.rawPolygon,
                        stereo::CostParams{params.costWindow, 1.0, params.costBrightness});
          }
          if (diag || std::getenv("BENCH_VERBOSE")) {
            const cv::Rect2d a = core::boundingBox(r.polygon.outer), b = core::boundingBox(fp.polygon.outer);
            std::printf("      iterations %d energy %.2f vertices:", r.iterations, r.terms.total());
            for (const auto& v : r.polygon.outer) std::printf(" (%.0f,%.0f)", v.x - r.roi.x, v.y - r.roi.y);
            std::printf("\n");
            std::printf("      bbox pred %.1f %.1f %.1f %.1f truth %.1f %.1f %.1f %.1f\n", a.x, a.y, a.br().x,
                        a.br().y, b.x, b.y, b.br().x, b.br().y);
            // Energy of the true outline (rounded to pixel corners) on the same prepared energy:
            // tells an optimisation failure (truth lower) from an energy failure (truth higher).
            const auto [rsv, gsv] = costIntervals(req.roof, *req.ground, params.balanceIntervals);
            const auto vc = stereo::CorrelationCostService::compute(left, right, r.roi, std::min(rsv.min, gsv.min),
                                                                    std::max(rsv.max, gsv.max),
                                                                    stereo::CostParams{params.costWindow, 1.0, params.costBrightness});
            const PreparedEnergy pe = prepareEnergy(*vc, left, right, req, params);
            auto localRing = [&](const core::Ring& rg) {
              IntRing out;
              for (const auto& v : rg) out.emplace_back(int(std::lround(v.x - r.roi.x)), int(std::lround(v.y - r.roi.y)));
              return out;
            };
            IntPolygon truthLocal{localRing(fp.polygon.outer), {}};
            for (const auto& h : fp.polygon.holes) truthLocal.holes.push_back(localRing(h));
            IntPolygon resultLocal{localRing(r.polygon.outer), {}};
            for (const auto& h : r.polygon.holes) resultLocal.holes.push_back(localRing(h));
            const EnergyWeights w{params.edgeWeight, params.rigidity, params.edgeContrast, params.minAngle, params.minGap};
            for (const auto& [label, poly] : {std::pair{"truth ", truthLocal}, std::pair{"result", resultLocal}}) {
              const EnergyTerms t = referenceEnergy(pe.images, w, poly);
              std::printf("      F(%s) %.2f =", label, t.total());
              for (double v : t.term) std::printf(" %.2f", v);
              std::printf("\n");
            }
            if (diag) {
              DiagTable table;
              cv::Mat picture;
              diagnose(pe.images, pe.excluded, truthLocal, resultLocal, table,
                       dumpDir.empty() ? nullptr : &picture);
              printDiag(table, "      ", false);
              for (const auto& [key, c] : table) {
                DiagCell& total = diagTotals[initName][key];
                total.n += c.n;
                total.dF += c.dF;
                total.cr += c.cr;
                total.cg += c.cg;
              }
              if (!picture.empty()) {
                cv::resize(picture, picture, {}, 3, 3, cv::INTER_NEAREST);
                std::vector<cv::Point> pts;
                for (const auto& v : truthLocal.outer) pts.emplace_back(v.x * 3, v.y * 3);
                cv::polylines(picture, pts, true, {255, 255, 255}, 1);
                bench::writeImage(dumpDir + "/s" + std::to_string(sceneParams.seed) + "_b" + std::to_string(id) + "_" +
                                initName + "_diag.png",
                            picture);
              }
            }
          }
        } catch (const std::exception& e) {
          ++failures;
          std::printf("%-5d %-3d failed: %s\n", sceneParams.seed, id, e.what());
        }
      }
      // Speed ratio and occlusion side on the prepared energy of the box init.
      DelineationRequest req = base;
      req.init = grownBox(fp.polygon, 8);
      try {
        const cv::Rect roi = regionOfInterest(left, right, req, params);
        const auto [roofSearched, groundSearched] = costIntervals(req.roof, *req.ground, params.balanceIntervals);
        const auto costs = stereo::CorrelationCostService::compute(
            left, right, roi, std::min(roofSearched.min, groundSearched.min),
            std::max(roofSearched.max, groundSearched.max), stereo::CostParams{params.costWindow, 1.0, params.costBrightness});
        const PreparedEnergy prepared = prepareEnergy(*costs, left, right, req, params);
        ++sideTotal;
        const int expectedSide = number(fp, "roof_disparity_min", 0) > g ? -1 : +1;
        sideOk += prepared.images.occlusionSide == expectedSide;
        if (referenceDone < referenceRuns) {
          DelineationParams p = params;
          p.courtyards = false;
          const auto t0 = Clock::now();
          const auto fast = optimiseActivePolygon(prepared.images, prepared.init, p);
          const auto t1 = Clock::now();
          const auto ref = optimiseActivePolygon(prepared.images, prepared.init, p, {}, nullptr,
                                                 EnergyMode::Reference);
          const auto t2 = Clock::now();
          fastMs += ms(t0, t1);
          referenceMs += ms(t1, t2);
          fastEvaluations += fast.evaluations;
          referenceEvaluations += ref.evaluations;
          ++referenceDone;
          std::printf("      speed: ROI %dx%d incremental %.1f ms, reference %.1f ms, same result: %s (F %.6f vs %.6f)\n",
                      roi.width, roi.height, ms(t0, t1), ms(t1, t2),
                      fast.polygon.outer == ref.polygon.outer ? "yes" : "no", fast.terms.total(), ref.terms.total());
        }
      } catch (const std::exception& e) {
        std::printf("      speed run failed: %s\n", e.what());
      }
    }
  }
  std::printf("\nsummary\n");
  for (const auto& [name, v] : ious) {
    const auto& h = hausdorffs[name];
    std::printf("  init %-6s buildings %3zu  mean IoU %.3f  median IoU %.3f  median corner RMS %.2f px  "
                "Hausdorff mean %.1f median %.1f max %.1f px\n",
                name.c_str(), v.size(), mean(v), median(v), median(corners[name]), mean(h), median(h),
                h.empty() ? std::nan("") : *std::max_element(h.begin(), h.end()));
  }
  std::printf("  breakdown (mean IoU, median IoU, median corner RMS, runs):\n");
  for (const auto& [key, v] : groupIous) {
    const size_t bar = key.find('|');
    std::printf("    %-6s %-26s %.3f  %.3f  %.2f px  %zu\n", key.substr(0, bar).c_str(), key.substr(bar + 1).c_str(),
                mean(v), median(v), median(groupCorners[key]), v.size());
  }
  std::printf("  regularization (%s; raw = the same runs before it):\n", params.regularization.mode.c_str());
  for (const auto& [name, st] : regStats) {
    std::printf("    init %-6s mean IoU raw %.3f -> %.3f (%+.4f)  median corner RMS raw %.2f -> %.2f px  "
                "median vertices / true corners (rectilinear, %zu) raw %.2f -> %.2f\n",
                name.c_str(), mean(st.rawIou), mean(ious[name]), mean(ious[name]) - mean(st.rawIou), median(st.rawCorner),
                median(corners[name]), st.regRatio.size(), median(st.rawRatio), median(st.regRatio));
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
  if (!regTimes.empty()) {
    std::printf("  regularization time per building: median %.2f ms, max %.2f ms (outline only, without the energy gate)\n",
                median(regTimes), *std::max_element(regTimes.begin(), regTimes.end()));
  }
  std::printf("  median time per building %.1f ms (cost service + optimisation, one core)\n", median(times));
  std::printf("  occlusion side from the data agrees with the geometry: %d / %d\n", sideOk, sideTotal);
  if (referenceDone > 0) {
    std::printf("  speed ratio incremental vs reference: %.1fx (%d runs, %.1f vs %.1f ms; %lld vs %lld evaluations)\n",
                referenceMs / std::max(1e-9, fastMs), referenceDone, fastMs, referenceMs, fastEvaluations,
                referenceEvaluations);
  }
  for (const auto& [name, table] : diagTotals) {
    std::printf("  diag %s: F(truth) - F(result) on pixels labelled differently (truth>result), all runs\n",
                name.c_str());
    printDiag(table, "    ", true);
  }
  std::printf("  failures %d\n", failures);
  return failures == 0 && sideOk == sideTotal ? 0 : 1;
}
