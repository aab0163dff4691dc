// Outlines on the hand-labelled real roofs (tests/bench/data/real_roofs.json): from a rough
// rectangle (the labelled outline's box grown by 30 px, clipped to the image) and the proposed
// roof interval, the active polygon's outline before and after its last stage (regularization),
// and a naive baseline: the matcher's disparities inside the rectangle thresholded at the roof
// interval, closed then opened 7x7, largest component, polygonised (1 px). Prints IoU against the
// labelled outline and vertex counts; `--dump DIR` draws them over the left image, one PNG a roof,
// and `--montage FILE` all roofs in one picture (labelled
// green, rectangle blue, naive cyan, raw yellow, regularized red). Skips cleanly (exit 0) when the
// data folder is missing. Disparity maps are cached as in bench_roof_interval. The matcher's map is
// also the request's disparity map (the map's costs and ground); BENCH_NO_MAP=1 leaves it out.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/error.hpp"
#include "delineo/core/geometry.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/delineation/roof_interval.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/stereo/cost_service.hpp"
#include "bench_image.hpp"
#include "energy_diag.hpp"
#include "real_roofs.hpp"

namespace fs = std::filesystem;
using namespace delineo;

namespace {

double iou(const core::Polygon& a, const core::Polygon& b, cv::Size size) {
  const cv::Mat ma = core::rasterize(a, size), mb = core::rasterize(b, size);
  return static_cast<double>(cv::countNonZero(ma & mb)) / std::max(1, cv::countNonZero(ma | mb));
}

int vertices(const core::Polygon& p) {
  size_t n = p.outer.size();
  for (const auto& h : p.holes) n += h.size();
  return static_cast<int>(n);
}

// The naive recipe: roof-interval pixels of the matcher's map inside the rectangle, closed and
// opened 7x7, the largest component's outline simplified at 1 px. Empty when nothing is left.
core::Polygon naiveOutline(const cv::Mat& disparity, const core::Polygon& rect, int low, int high) {
  const cv::Mat inside = core::rasterize(rect, disparity.size());
  cv::Mat mask = (disparity >= low - 0.5f) & (disparity <= high + 0.5f) & inside;
  const cv::Mat k = cv::getStructuringElement(cv::MORPH_RECT, {7, 7});
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, k);
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, k);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  if (contours.empty()) return {};
  const auto largest = std::max_element(
      contours.begin(), contours.end(),
      [](const auto& a, const auto& b) { return cv::contourArea(a) < cv::contourArea(b); });
  std::vector<cv::Point> simplified;
  cv::approxPolyDP(*largest, simplified, 1.0, true);
  core::Polygon p;
  for (const auto& v : simplified)
    p.outer.emplace_back(v.x + 0.5, v.y + 0.5);  // pixel centres → corners
  return p;
}

cv::Mat drawOutlines(const cv::Mat& left, const cv::Rect& box,
                     const std::vector<std::pair<core::Polygon, cv::Scalar>>& outlines) {
  const cv::Rect crop = cv::Rect(box.x - 10, box.y - 10, box.width + 20, box.height + 20) &
                        cv::Rect(0, 0, left.cols, left.rows);
  const int k = std::max(1, std::min(4, 900 / std::max(crop.width, crop.height)));
  cv::Mat img;
  cv::normalize(left(crop), img, 0, 255, cv::NORM_MINMAX, CV_8U);
  cv::resize(img, img, {}, k, k, cv::INTER_NEAREST);
  cv::cvtColor(img, img, cv::COLOR_GRAY2BGR);
  for (const auto& [p, colour] : outlines) {
    auto ring = [&](const core::Ring& r) {
      std::vector<cv::Point> pts;
      for (const auto& v : r)
        pts.emplace_back(static_cast<int>(std::lround((v.x - crop.x) * k)),
                         static_cast<int>(std::lround((v.y - crop.y) * k)));
      cv::polylines(img, pts, true, colour, 1);
      for (const auto& q : pts) cv::circle(img, q, 2, colour, cv::FILLED);
    };
    if (p.outer.size() >= 3) ring(p.outer);
    for (const auto& h : p.holes) ring(h);
  }
  return img;
}

// One picture of every roof's panel, each scaled to `height` px and named, `columns` a row.
cv::Mat montage(const std::vector<std::pair<std::string, cv::Mat>>& panels, int height, int columns) {
  std::vector<cv::Mat> rows, row;
  int rowWidth = 0, widest = 0;
  const auto closeRow = [&] {
    if (row.empty()) return;
    cv::Mat r;
    cv::hconcat(row, r);
    rows.push_back(r);
    widest = std::max(widest, r.cols);
    row.clear(), rowWidth = 0;
  };
  for (const auto& [name, panel] : panels) {
    cv::Mat scaled;
    cv::resize(panel, scaled, {std::max(1, panel.cols * height / panel.rows), height}, 0, 0, cv::INTER_AREA);
    cv::copyMakeBorder(scaled, scaled, 22, 4, 4, 4, cv::BORDER_CONSTANT, cv::Scalar(255, 255, 255));
    cv::putText(scaled, name, {6, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    row.push_back(scaled);
    rowWidth += scaled.cols;
    if (static_cast<int>(row.size()) == columns) closeRow();
  }
  closeRow();
  for (cv::Mat& r : rows) {
    if (r.cols < widest) cv::copyMakeBorder(r, r, 0, 0, 0, widest - r.cols, cv::BORDER_CONSTANT, cv::Scalar(255, 255, 255));
  }
  cv::Mat all;
  if (!rows.empty()) cv::vconcat(rows, all);
  return all;
}

double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}


delineation::IntPolygon localPolygon(const core::Polygon& p, cv::Point origin) {
  auto ring = [&](const core::Ring& r) {
    delineation::IntRing out;
    for (const auto& v : r) {
      const cv::Point q(static_cast<int>(std::lround(v.x)) - origin.x,
                        static_cast<int>(std::lround(v.y)) - origin.y);
      if (out.empty() || out.back() != q) out.push_back(q);
    }
    while (out.size() > 1 && out.front() == out.back()) out.pop_back();
    return out;
  };
  delineation::IntPolygon out{ring(p.outer), {}};
  for (const auto& h : p.holes) out.holes.push_back(ring(h));
  return out;
}

double medianIn(const cv::Mat& values, const cv::Mat& mask) {
  std::vector<float> v;
  for (int y = 0; y < values.rows; ++y)
    for (int x = 0; x < values.cols; ++x)
      if (mask.at<uchar>(y, x) && std::isfinite(values.at<float>(y, x)))
        v.push_back(values.at<float>(y, x));
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Disparities by class: ground interval blue, roof interval green, between them yellow, above the
// roof red, below the ground magenta, none black.
cv::Mat disparityClasses(const cv::Mat& d, const delineation::DisparityInterval& ground,
                         const delineation::DisparityInterval& roof) {
  cv::Mat out(d.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < d.rows; ++y) {
    for (int x = 0; x < d.cols; ++x) {
      const float v = d.at<float>(y, x);
      if (!std::isfinite(v)) continue;
      cv::Vec3b c;
      if (v < ground.min - 0.5f)
        c = {255, 0, 255};
      else if (v <= ground.max + 0.5f)
        c = {255, 80, 0};
      else if (v < roof.min - 0.5f)
        c = {0, 220, 255};
      else if (v <= roof.max + 0.5f)
        c = {0, 200, 0};
      else
        c = {0, 0, 255};
      out.at<cv::Vec3b>(y, x) = c;
    }
  }
  return out;
}

// --diag: the energy of the labelled outline against the delineated one on the same prepared
// energy, term by term, the estimated intervals against the roof's ground reference, and where
// they differ (energy_diag.hpp). With --dump, DIR/<roof>_diag.png: the left image, the label
// pairs (bench_delineation's colours, excluded pixels grey) and c_roof < c_ground (white).
void diagnoseRoof(const std::string& name, const cv::Mat& left, const cv::Mat& right,
                  const cv::Mat& map, const delineation::DelineationRequest& request,
                  const delineation::DelineationParams& params, const delineation::DelineationResult& r,
                  const core::Polygon& truth, const core::Polygon& groundRef, const std::string& dumpDir) {
  using namespace delineation;
  stereo::CostParams cp;
  cp.window = params.costWindow;
  cp.brightnessScale = params.costBrightness;
  const auto costs = stereo::CorrelationCostService::compute(left, right, r.roi, request.searchRange->min,
                                                            request.searchRange->max, cp);
  const PreparedEnergy pe = prepareEnergy(*costs, left, right, request, params);
  const IntPolygon truthLocal = localPolygon(truth, r.roi.tl()), rawLocal = localPolygon(r.rawPolygon, r.roi.tl());
  const EnergyWeights w{params.edgeWeight, params.rigidity, params.edgeContrast, params.minAngle, params.minGap};
  const EnergyTerms ft = referenceEnergy(pe.images, w, truthLocal), fr = referenceEnergy(pe.images, w, rawLocal);
  const double groundLevel = medianIn(map, core::rasterize(groundRef, map.size()));
  std::printf("    diag ground ref %.1f, estimated interval %d:%d (level %.1f; searched %d:%d), roof %d:%d "
              "(searched %d:%d), roof d %.1f, side %d, NoMatchCost %.3f, region init %d\n",
              groundLevel, pe.ground.min, pe.ground.max, pe.groundDisparity, pe.groundSearched.min,
              pe.groundSearched.max, request.roof.min, request.roof.max, pe.roofSearched.min, pe.roofSearched.max,
              pe.roofDisparity, pe.images.occlusionSide, pe.images.noMatchCost, pe.regionInit ? 1 : 0);
  for (const auto& [label, t] : {std::pair{"hand", ft}, std::pair{"raw ", fr}}) {
    std::printf("    F(%s) %9.1f = roof %8.1f ground %8.1f band %8.1f edgesL %7.1f edgesR %7.1f shape %6.1f\n",
                label, t.total(), t.term[0], t.term[1], t.term[2], t.term[3], t.term[4], t.term[5]);
  }
  std::printf("    dF hand - raw %+.1f\n", ft.total() - fr.total());
  bench::DiagTable table;
  cv::Mat picture;
  bench::diagnose(pe.images, pe.excluded, truthLocal, rawLocal, table, dumpDir.empty() ? nullptr : &picture);
  bench::printDiag(table, "    ", false);
  if (picture.empty()) return;
  cv::Mat img;
  cv::normalize(left(r.roi), img, 0, 255, cv::NORM_MINMAX, CV_8U);
  cv::cvtColor(img, img, cv::COLOR_GRAY2BGR);
  cv::Mat better = (pe.images.uncappedDifference.empty() ? pe.images.groundCost - pe.images.roofCost
                                                          : pe.images.uncappedDifference) > 0;
  cv::cvtColor(better, better, cv::COLOR_GRAY2BGR);
  better.setTo(cv::Scalar(0, 0, 160), pe.excluded);
  // The matcher's disparities and the cost service's argmin by class.
  auto classes = [&](const cv::Mat& d) { return disparityClasses(d, pe.ground, request.roof); };
  cv::Mat wta;
  costs->bestDisparity().convertTo(wta, CV_32F);
  wta.setTo(std::nanf(""), costs->bestCost() > pe.images.noMatchCost);
  // Six panels (the last blank) on a 3x2 grid, 2x3 for tall regions.
  const int columns = r.roi.height > r.roi.width ? 3 : 2;
  std::vector<cv::Mat> panels{img, picture, better, classes(map(r.roi)), classes(wta),
                              cv::Mat(img.size(), CV_8UC3, cv::Scalar(0, 0, 0))};
  std::vector<cv::Mat> rows;
  for (size_t i = 0; i < panels.size(); i += static_cast<size_t>(columns)) {
    cv::Mat row;
    cv::hconcat(std::vector<cv::Mat>(panels.begin() + static_cast<long>(i),
                                     panels.begin() + static_cast<long>(i) + columns),
                row);
    rows.push_back(row);
  }
  cv::Mat both;
  cv::vconcat(rows, both);
  const int k = std::max(1, std::min(3, 1600 / std::max(both.cols, both.rows)));
  cv::resize(both, both, {}, k, k, cv::INTER_NEAREST);
  for (int panel = 0; panel < 5; ++panel) {
    const cv::Point shift((panel % columns) * r.roi.width, (panel / columns) * r.roi.height);
    auto draw = [&](const IntPolygon& p, cv::Scalar colour) {
      std::vector<cv::Point> pts;
      for (const auto& v : p.outer) pts.emplace_back((v + shift) * k);
      cv::polylines(both, pts, true, colour, 1);
    };
    draw(truthLocal, {255, 255, 255});
    draw(rawLocal, {0, 220, 255});
  }
  bench::writeImage((fs::path(dumpDir) / (name + "_diag.png")).string(), both);
}

// "2,4,6.5" -> {2, 4, 6.5}; stops at the first item that is not a number.
std::vector<double> numbersOf(const char* list) {
  std::vector<double> out;
  for (const char* p = list; *p;) {
    char* end = nullptr;
    const double value = std::strtod(p, &end);
    if (end == p) break;
    out.push_back(value);
    p = *end == ',' ? end + 1 : end;
  }
  return out;
}

struct Options {
  bench::RealRoofsOptions data;
  std::string dumpDir;      // --dump DIR: a picture of each roof's outlines (and of --diag)
  std::string montagePath;  // --montage FILE: every roof's picture in one
  int grow = 30;            // --grow PX: the rectangle is the labelled outline's box grown by PX
  // --ground: the request's ground interval: "estimated" (none given: the active polygon's own
  // estimate), "proposed" (estimateGroundLevel on the matcher's map ± ground-tolerance),
  // "reference" (the labelled ground reference's median ± ground-tolerance, an upper bound) or
  // "below" (the search range's low end to just under the roof interval).
  std::string groundMode = "estimated";
  bool diag = false;  // --diag: energy of the labelled outline vs the delineated one
  std::vector<double> tolerances;  // --tolerances A,B,...: the raw outline regularized at each too
};

// The options, or nothing after the usage line when they are wrong.
std::optional<Options> parseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    if (o.data.take(argc, argv, i)) continue;
    const bool valued = i + 1 < argc;
    if (!std::strcmp(argv[i], "--dump") && valued) {
      o.dumpDir = argv[++i];
    } else if (!std::strcmp(argv[i], "--montage") && valued) {
      o.montagePath = argv[++i];
    } else if (!std::strcmp(argv[i], "--grow") && valued) {
      o.grow = std::atoi(argv[++i]);
    } else if (!std::strcmp(argv[i], "--ground") && valued) {
      o.groundMode = argv[++i];
    } else if (!std::strcmp(argv[i], "--diag")) {
      o.diag = true;
    } else if (!std::strcmp(argv[i], "--tolerances") && valued) {
      o.tolerances = numbersOf(argv[++i]);
    } else {
      std::fprintf(
          stderr,
          "usage: bench_real_outlines [--data DIR] [--labels real_roofs.json] [--cache DIR] "
          "[--grow PX] [--tolerances A,B,...] [--dump DIR] [--montage FILE.png] [--diag] "
          "[--ground estimated|proposed|reference]\n");
      return std::nullopt;
    }
  }
  return o;
}

// The request from the rectangle: the proposed roof interval, the pair's search range and
// matcher's map (BENCH_NO_MAP=1: none), and the ground interval of --ground.
delineation::DelineationRequest requestFor(const nlohmann::json& roof, const bench::RealPair& pair,
                                           const core::Polygon& rect,
                                           const delineation::RoofIntervalProposal& proposal,
                                           const std::string& groundMode, int groundTolerance) {
  const cv::Mat& map = pair.disparity;
  delineation::DelineationRequest request;
  request.init = rect;
  request.roof = {proposal.low, proposal.high};
  request.searchRange = delineation::DisparityInterval{pair.dmin, pair.dmax};
  if (!std::getenv("BENCH_NO_MAP")) request.disparity = map;
  if (groundMode == "below") {
    request.ground = delineation::DisparityInterval{pair.dmin, proposal.low - 2};
  } else if (groundMode != "estimated") {
    const double level =
        groundMode == "reference"
            ? medianIn(map, core::rasterize(bench::ringOf(roof.at("ground")), map.size()))
            : delineation::estimateGroundLevel(map, rect);
    const int g = static_cast<int>(std::lround(level));
    request.ground = delineation::DisparityInterval{
        g - groundTolerance, std::min(g + groundTolerance, proposal.low - 1)};
  }
  return request;
}

// BENCH_DUMP_OUTLINES=FILE: one JSON line per roof, the raw outline and the regularization
// stage's own result (before the energy gate), to check that a change of the stage leaves its
// results as they were.
void dumpOutlines(const std::string& name, const delineation::DelineationResult& r,
                  const delineation::DelineationParams& params, const cv::Mat& left) {
  const char* path = std::getenv("BENCH_DUMP_OUTLINES");
  if (!path) return;
  const auto stage = delineation::regularizeOutline(r.rawPolygon, params.regularization, left);
  bench::appendJsonLine(path, {{"roof", name},
                               {"raw", bench::ringsJson(r.rawPolygon)},
                               {"regularized", bench::ringsJson(stage.polygon)},
                               {"status", delineation::toString(stage.status)},
                               {"reason", stage.reason}});
}

// The regularization stage's outline part (without the energy gate) on the raw outline: CPU time
// of this thread in ms, best of 3 (the machine may be shared; BENCH_REG_REPS=N repeats it N
// times, for a profiler). It is run as the stage ran: at the tolerance, then half and a quarter
// of it down to the one it kept (all three when it kept the raw outline).
double regularizationMs(const delineation::DelineationResult& r,
                        const delineation::DelineationParams& params, const cv::Mat& left) {
  const char* repsText = std::getenv("BENCH_REG_REPS");
  const int reps = repsText ? std::max(1, std::atoi(repsText)) : 3;
  const bool kept = r.regularization.status == delineation::RegularizationStatus::Regularized;
  double ms = 1e300;
  for (int rep = 0; rep < reps; ++rep) {
    delineation::RegularizationParams tried = params.regularization;
    const double t0 = cpuMs();
    for (int k = 0; k < 3; ++k, tried.tolerance /= 2) {
      (void)delineation::regularizeOutline(r.rawPolygon, tried, left);
      if (kept && tried.tolerance <= r.regularization.tolerance) break;
    }
    ms = std::min(ms, cpuMs() - t0);
  }
  return ms;
}

// The same raw outline through the public entry point (outline + energy gate) at each tolerance
// of --tolerances: a line each, and its IoU and vertex count under `tolIou` and `tolVertices`.
void regularizeAtTolerances(const std::vector<double>& tolerances, const bench::RealPair& pair,
                            const delineation::DelineationRequest& request,
                            const delineation::DelineationParams& params,
                            const delineation::DelineationResult& r, const core::Polygon& truth,
                            std::map<double, std::vector<double>>& tolIou,
                            std::map<double, std::vector<double>>& tolVertices) {
  const cv::Size size = pair.disparity.size();
  for (double t : tolerances) {
    delineation::DelineationParams other = params;
    other.regularization.tolerance = t;
    const auto g =
        delineation::regularizeBuildingOutline(pair.left, pair.right, request, other, r.rawPolygon);
    std::printf("    tolerance %4.1f px: IoU %.3f, %3d vertices, %s%s%s\n", t,
                iou(g.polygon, truth, size), g.outputVertices,
                delineation::toString(g.status).c_str(), g.reason.empty() ? "" : ": ",
                g.reason.c_str());
    tolIou[t].push_back(iou(g.polygon, truth, size));
    tolVertices[t].push_back(g.outputVertices);
  }
}

// BENCH_VERBOSE: the vertices of the raw and of the regularized outline (the stage's own
// result, before the energy gate).
void printVertices(const delineation::DelineationResult& r,
                   const delineation::DelineationParams& params, const cv::Mat& left) {
  const auto g = delineation::regularizeOutline(r.rawPolygon, params.regularization, left);
  for (const auto& [label, poly] :
       {std::pair{"raw", r.rawPolygon}, std::pair{"regularized", g.polygon}}) {
    std::printf("    %s:", label);
    for (const auto& v : poly.outer) std::printf(" (%.1f,%.1f)", v.x, v.y);
    for (const auto& h : poly.holes) {
      std::printf(" hole");
      for (const auto& v : h) std::printf(" (%.1f,%.1f)", v.x, v.y);
    }
    std::printf("\n");
  }
}

// The scores of one set of roofs (bench::roofSet).
struct SetScores {
  std::vector<double> naiveIou, rawIou, regIou, naiveV, rawV, regV;
  int regularized = 0;
};

// What the summary needs of every roof run.
struct Totals {
  std::map<std::string, SetScores> sets;
  std::vector<double> regMs;
  std::map<double, std::vector<double>> tolIou, tolVertices;
  std::vector<std::pair<std::string, cv::Mat>> panels;  // for --montage
  int runs = 0;
};

// One roof's outlines from the rectangle: its row, the extra lines of --tolerances, --diag and
// BENCH_VERBOSE, its scores in `totals` and its picture (--dump, --montage).
void runRoof(const nlohmann::json& roof, const bench::RealPair& pair, const Options& options,
             const delineation::DelineationParams& params, Totals& totals) {
  const std::string name = roof.at("name");
  const cv::Mat& map = pair.disparity;
  const core::Polygon truth = bench::ringOf(roof.at("outline"));
  const core::Polygon rect = bench::grownBox(truth, options.grow, map.size());
  const auto proposal =
      delineation::proposeRoofInterval(map, rect, delineation::RoofIntervalParams{});
  if (!proposal.found) {
    std::printf("%-18s no roof interval proposed\n", name.c_str());
    return;
  }
  const core::Polygon naive = naiveOutline(map, rect, proposal.low, proposal.high);
  const delineation::DelineationRequest request =
      requestFor(roof, pair, rect, proposal, options.groundMode, params.groundTolerance);
  try {
    const auto r = delineation::delineate(pair.left, pair.right, request, params);
    dumpOutlines(name, r, params, pair.left);
    const double ms = regularizationMs(r, params, pair.left);
    const double ni = naive.outer.empty() ? 0.0 : iou(naive, truth, map.size());
    const double ri = iou(r.rawPolygon, truth, map.size()), gi = iou(r.polygon, truth, map.size());
    std::printf(
        "%-18s [%3d,%3d] | %6.3f %5d | %6.3f %5d | %6.3f %5d | %6.2f ms %s%s%s (dF %+.1f, %.1f "
        "deg)\n",
        name.c_str(), proposal.low, proposal.high, ni, vertices(naive), ri, vertices(r.rawPolygon),
        gi, r.vertexCount, ms, delineation::toString(r.regularization.status).c_str(),
        r.regularization.reason.empty() ? "" : ": ", r.regularization.reason.c_str(),
        r.regularization.energyChange, r.regularization.orientationDeg);
    regularizeAtTolerances(options.tolerances, pair, request, params, r, truth, totals.tolIou,
                           totals.tolVertices);
    if (options.diag) {
      diagnoseRoof(name, pair.left, pair.right, map, request, params, r, truth,
                   bench::ringOf(roof.at("ground")), options.dumpDir);
    }
    if (std::getenv("BENCH_VERBOSE")) printVertices(r, params, pair.left);
    SetScores& set = totals.sets[bench::roofSet(roof)];
    set.naiveIou.push_back(ni), set.rawIou.push_back(ri), set.regIou.push_back(gi);
    set.naiveV.push_back(vertices(naive)), set.rawV.push_back(vertices(r.rawPolygon));
    set.regV.push_back(r.vertexCount);
    set.regularized += r.regularization.status == delineation::RegularizationStatus::Regularized;
    totals.regMs.push_back(ms);
    ++totals.runs;
    if (options.dumpDir.empty() && options.montagePath.empty()) return;
    const cv::Point2d from = rect.outer[0], to = rect.outer[2];
    const cv::Mat panel =
        drawOutlines(pair.left,
                     cv::Rect(static_cast<int>(from.x), static_cast<int>(from.y),
                              static_cast<int>(to.x - from.x), static_cast<int>(to.y - from.y)),
                     {{rect, {255, 80, 0}},
                      {truth, {0, 200, 0}},
                      {naive, {255, 255, 0}},
                      {r.rawPolygon, {0, 220, 255}},
                      {r.polygon, {0, 0, 255}}});
    if (!options.dumpDir.empty()) {
      bench::writeImage((fs::path(options.dumpDir) / (name + ".png")).string(), panel);
    }
    totals.panels.emplace_back(name, panel);
  } catch (const core::Error& e) {
    std::printf("%-18s failed: %s\n", name.c_str(), e.what());
  }
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? std::nan("") : s / static_cast<double>(v.size());
}

// The means and medians of each set, the montage, the regularization's time and the scores at
// each tolerance of --tolerances.
void printSummary(const Totals& totals, const Options& options) {
  for (const auto& [name, set] : totals.sets) {
    std::printf(
        "\n%s, %zu roofs (rectangle = labelled box + %d px): mean IoU naive %.3f, raw %.3f, "
        "regularized %.3f; median vertices naive %.0f, raw %.0f, regularized %.0f; %d "
        "regularized",
        name.c_str(), set.rawIou.size(), options.grow, mean(set.naiveIou), mean(set.rawIou),
        mean(set.regIou), median(set.naiveV), median(set.rawV), median(set.regV), set.regularized);
  }
  if (!options.montagePath.empty()) {
    bench::writeImage(options.montagePath, montage(totals.panels, 260, 5));
    std::printf("\nwrote %s\n", options.montagePath.c_str());
  }
  std::printf("\nregularization time median %.2f ms, max %.2f ms\n", median(totals.regMs),
              *std::max_element(totals.regMs.begin(), totals.regMs.end()));
  for (const auto& [t, v] : totals.tolIou) {
    std::printf("  tolerance %4.1f px: mean IoU %.3f, median vertices %.0f\n", t, mean(v),
                median(totals.tolVertices.at(t)));
  }
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  const std::optional<Options> options = parseOptions(argc, argv);
  if (!options) return 2;
  if (bench::skippedWithoutData(options->data.dataRoot)) return 0;
  delineation::DelineationParams params;
  if (const char* json = std::getenv("BENCH_PARAMS"))
    core::fromJson(params, nlohmann::json::parse(json));
  const nlohmann::json data = bench::readLabels(options->data.labels);
  std::printf("%-18s %-9s | %-13s | %-13s | %-13s | %-11s %s\n", "roof", "interval", "naive IoU/v",
              "raw IoU/v", "regular. IoU/v", "reg ms", "regularization");
  bench::RealPairs pairs(data, options->data.dataRoot, options->data.cache);
  Totals totals;
  for (const auto& roof : data.at("roofs")) {
    const std::string name = roof.at("name");
    if (const char* only = std::getenv("BENCH_ONLY"); only && name != only) continue;
    const bench::RealPair* pair = pairs.get(roof.at("pair"));
    if (pair) runRoof(roof, *pair, *options, params, totals);
  }
  if (bench::skippedWithoutRoofs(totals.runs, options->data.dataRoot)) return 0;
  printSummary(totals, *options);
  return 0;
}
