// Stereo benchmark: the same pair and range through the adaptive matcher (contour-adaptive
// shapes), the same matcher with plain square windows, and OpenCV SGBM; one run each.
// Prints density, bad-1 / bad-2 on matched non-occluded pixels, bad-2 counting unmatched pixels
// as bad, RMS on flat-roof pixels (all matched, and roofRMS1: those within 1 px, i.e. the
// sub-pixel precision without gross errors) and the roof-outline score (simulated scenes), time.
//
// Roof-outline score ("edge%"): for every roof outline pixel of a simulated scene crossed along
// x (a building pixel xb whose horizontal neighbour xg = xb - dir is ground, with 3 building
// pixels on one side and 3 ground pixels on the other, and a true step |d_roof - d_ground| >= 2
// px), walk the row from xg - 7 dir towards xb + 7 dir and take the first matched pixel whose
// predicted disparity lies on the roof side of the mid-level (d_roof + d_ground) / 2: the
// predicted start of the roof. The outline pixel counts as located when that pixel is within
// 1 px of xb; no roof-side pixel in the walk counts as missed. edge% = located / outline pixels.
//
// Usage: bench_stereo [--size N] [--data DIR] [--methods adaptive,square,sgbm] [--no-data]
//                     [--dump DIR] [--params JSON] [--range N] [--repeat N] [--cpu] [--stages]
//                     [--seed N]
//   --size N   side of the simulated scene (default 1000; the ctest smoke run uses a tiny one)
//   --data DIR real datasets (default ../shared/data beside the repository, or DELINEO_DATA_DIR); skipped cleanly when absent.
//   --dump DIR write error maps (PNG) of the simulated scene per method: green |e| <= 1,
//              yellow 1 < |e| <= 2, red worse, blue unmatched, black not scored; outline pixels
//              white located, magenta roof found inside, cyan outside, orange not found;
//              and outline_METHOD.csv, every scored outline pixel with its outcome;
//              disparity_METHOD.tif, score_METHOD.tif, truth.tif and the views left.tif,
//              right.tif (float32); roof.png, the flat-roof pixels the roof RMS is read on;
//              sloped_roof.png, the sloped facets' pixels --outline-diag reports on.
//   --range N  search at least N disparities on the simulated scene (dmax raised)
//   --params J MatchParams overrides for adaptive and square, e.g. '{"min-score": 0.2}'.
//   --repeat N run the methods N times round-robin, report each one's fastest run (shared
//              machines: the load then hits every method alike).
//   --cpu      also print the CPU time of every run (process CPU clock: with '{"threads": 1}'
//              the adaptive matcher's own cost, insensitive to other processes' load).
//   --stages   print the wall time of each stage the matcher reports (its progress stages),
//              for every run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <functional>
#include <limits>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <nlohmann/json.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/nan_mask.hpp"
#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/stereo/match.hpp"
#include "bench_image.hpp"
#include "delineo/sim/scene.hpp"
#include "shared_data.hpp"

namespace {
using namespace delineo;
namespace fs = std::filesystem;

struct Case {
  std::string name;
  cv::Mat left, right;  // CV_32F
  cv::Mat truth;        // CV_32F, NaN where unknown
  cv::Mat evaluate;     // CV_8U, 1 where scored (known and non-occluded)
  cv::Mat roof;         // CV_8U, 1 on flat-roof pixels (may be empty)
  cv::Mat slopedRoof;   // CV_8U, 1 on sloped roof facets' pixels (may be empty)
  int dmin = 0, dmax = 0;
  struct OutlinePixel {
    int y, xb, dir;  // building pixel xb, ground at xb - dir
    float dRoof, dGround;
  };
  std::vector<OutlinePixel> outline;  // simulated scenes only
};

struct Row {
  double density = 0, bad1 = 0, bad2 = 0, bad2All = 0, roofRms = NAN, roofRmsInliers = NAN,
         edge = NAN, seconds = 0;
};

constexpr int kOutlineWalk = 7;
bool gOutlineDiagnosis = false;  // --outline-diag: where the predicted roof starts

// Where edge% finds the predicted start of the roof for outline pixel o: the x of the first
// matched pixel on the roof side of the mid-level in the walk, or -1 when there is none.
int predictedRoofStart(const cv::Mat& disparity, const Case::OutlinePixel& o) {
  const float mid = 0.5F * (o.dRoof + o.dGround);
  const float sign = o.dRoof > o.dGround ? 1.0F : -1.0F;
  const float* row = disparity.ptr<float>(o.y);
  const int xg = o.xb - o.dir;
  for (int k = -kOutlineWalk; k <= 2 * kOutlineWalk; ++k) {
    const int x = xg + o.dir * k;
    if (x < 0 || x >= disparity.cols) break;
    if (std::isfinite(row[x]) && (row[x] - mid) * sign > 0) return x;
  }
  return -1;
}

// Whether edge% counts outline pixel o as located, from its predicted roof start x.
bool outlineLocated(const Case::OutlinePixel& o, int x) {
  return x >= 0 && std::abs(x - o.xb) <= 1;
}

// Diagnostic only (not part of the metric): histogram of the predicted roof start relative to
// the true outline, in px towards the ground (positive: roof fattened), as edge% walks it.
void outlineDiagnosis(const cv::Mat& disparity, const Case& c) {
  long outside = 0, inside = 0, missed = 0, located = 0;
  long insideBy[2][2] = {};                  // [unmatched only / ground value][ground −x / +x]
  long outsideBy[2] = {}, missedBy[2] = {};  // [ground on −x / on +x]
  // Outline pixels whose ground neighbour the other view does not see (a narrow street or
  // courtyard hidden by the next roof): [located / not located].
  long hiddenGround[2] = {};
  for (const Case::OutlinePixel& o : c.outline) {
    const float mid = 0.5F * (o.dRoof + o.dGround);
    const float sign = o.dRoof > o.dGround ? 1.0F : -1.0F;
    const float* row = disparity.ptr<float>(o.y);
    const int x = predictedRoofStart(disparity, o);
    if (!c.evaluate.empty() && c.evaluate.at<uchar>(o.y, o.xb - o.dir) == 0) {
      ++hiddenGround[outlineLocated(o, x) ? 0 : 1];
    }
    if (x >= 0) {
      const int off = (o.xb - x) * o.dir;  // > 0: roof side found on the ground
      if (std::abs(off) <= 1)
        ++located;
      else if (off > 1) {
        ++outside;
        ++outsideBy[o.dir > 0 ? 0 : 1];
        if (std::getenv("OUTLINE_DUMP_OUTSIDE") != nullptr && outside % 8 == 1) {
          std::printf("      outside y %d xb %d dir %d roof %.1f ground %.1f:", o.y, o.xb, o.dir,
                      o.dRoof, o.dGround);
          for (int step = -3; step <= 8; ++step) {
            const int u = o.xb - o.dir * step;
            if (u >= 0 && u < disparity.cols) std::printf(" %5.1f", row[u]);
          }
          std::printf("\n        left grey:");
          for (int step = -3; step <= 8; ++step) {
            const int u = o.xb - o.dir * step;
            if (u >= 0 && u < disparity.cols) std::printf(" %5.0f", c.left.at<float>(o.y, u));
          }
          std::printf("\n");
        }
      } else {
        ++inside;
        // What covers the roof pixels before the start: no match, or the ground's value.
        bool groundValue = false;
        for (int u = o.xb; u != x; u += o.dir) {
          groundValue = groundValue || (std::isfinite(row[u]) && (row[u] - mid) * sign <= 0);
        }
        ++insideBy[groundValue ? 1 : 0][o.dir > 0 ? 0 : 1];
        if (std::getenv("OUTLINE_DUMP") != nullptr && inside % 8 == 1) {
          std::printf("      y %d xb %d dir %d roof %.1f ground %.1f:", o.y, o.xb, o.dir, o.dRoof,
                      o.dGround);
          for (int step = -3; step <= 8; ++step) {
            const int u = o.xb - o.dir * step;  // < 0: ground, >= 0: roof (inwards)
            if (u >= 0 && u < disparity.cols) std::printf(" %5.1f", row[u]);
          }
          std::printf("\n");
          if (std::getenv("OUTLINE_DUMP_GREY") != nullptr) {
            std::printf("        left grey:");
            for (int step = -3; step <= 8; ++step) {
              const int u = o.xb - o.dir * step;
              if (u >= 0 && u < disparity.cols) std::printf(" %5.0f", c.left.at<float>(o.y, u));
            }
            std::printf("\n");
          }
        }
      }
    } else {
      ++missed;
      ++missedBy[o.dir > 0 ? 0 : 1];
    }
  }
  std::printf(
      "    outline diag: %zu pixels, located %ld, roof starts >=2 px outside %ld, "
      ">=2 px inside %ld, missed %ld\n",
      c.outline.size(), located, outside, inside, missed);
  std::printf(
      "    inside: unmatched only %ld (ground -x %ld, +x %ld), ground value %ld "
      "(ground -x %ld, +x %ld)\n",
      insideBy[0][0] + insideBy[0][1], insideBy[0][0], insideBy[0][1],
      insideBy[1][0] + insideBy[1][1], insideBy[1][0], insideBy[1][1]);
  std::printf("    outside: ground -x %ld, +x %ld; missed: ground -x %ld, +x %ld\n", outsideBy[0],
              outsideBy[1], missedBy[0], missedBy[1]);
  std::printf("    ground beside hidden in the other view: %ld located, %ld not\n", hiddenGround[0],
              hiddenGround[1]);
}

double outlineScore(const cv::Mat& disparity, const Case& c) {
  if (c.outline.empty()) return NAN;
  long located = 0;
  for (const Case::OutlinePixel& o : c.outline) {
    const int x = predictedRoofStart(disparity, o);
    if (outlineLocated(o, x)) ++located;
  }
  return 100.0 * static_cast<double>(located) / static_cast<double>(c.outline.size());
}

void dumpErrors(const cv::Mat& disparity, const Case& c, const std::string& path) {
  cv::Mat img(disparity.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      if (!c.evaluate.at<uchar>(y, x)) continue;
      const float d = disparity.at<float>(y, x);
      cv::Vec3b& px = img.at<cv::Vec3b>(y, x);
      const bool roof = !c.roof.empty() && c.roof.at<uchar>(y, x);
      if (!std::isfinite(d)) {
        px = cv::Vec3b(255, 0, 0);
        continue;
      }
      const double e = std::abs(d - c.truth.at<float>(y, x));
      const uchar dim = roof ? 255 : 140;
      px = e <= 1 ? cv::Vec3b(0, dim, 0) : e <= 2 ? cv::Vec3b(0, 255, 255) : cv::Vec3b(0, 0, 255);
    }
  }
  // Outline pixels by edge% outcome: white located, magenta roof starts >= 2 px inside,
  // cyan >= 2 px outside (on the ground), orange no roof start found.
  for (const Case::OutlinePixel& o : c.outline) {
    const int x = predictedRoofStart(disparity, o);
    const int off = (o.xb - x) * o.dir;  // > 0: roof side found on the ground
    img.at<cv::Vec3b>(o.y, o.xb) = x < 0                ? cv::Vec3b(0, 128, 255)
                                   : std::abs(off) <= 1 ? cv::Vec3b(255, 255, 255)
                                   : off > 1            ? cv::Vec3b(255, 255, 0)
                                                        : cv::Vec3b(255, 0, 255);
  }
  bench::writeImage(path, img);
}

// Every scored outline pixel with its outcome, for analysis outside the bench: y, xb, dir,
// true roof and ground disparities, predicted roof start (-1: missed), offset towards the
// ground (px).
void dumpOutline(const cv::Mat& disparity, const Case& c, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return;
  std::fprintf(f, "y,xb,dir,d_roof,d_ground,x_start,offset\n");
  for (const Case::OutlinePixel& o : c.outline) {
    const int x = predictedRoofStart(disparity, o);
    std::fprintf(f, "%d,%d,%d,%.2f,%.2f,%d,%d\n", o.y, o.xb, o.dir, o.dRoof, o.dGround, x,
                 x < 0 ? 0 : (o.xb - x) * o.dir);
  }
  std::fclose(f);
}

Row score(const cv::Mat& disparity, const Case& c, double seconds) {
  Row r;
  r.seconds = seconds;
  long total = 0, matched = 0, bad1 = 0, bad2 = 0, roofN = 0, roofInN = 0;
  double roofSq = 0, roofInSq = 0;
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      if (!c.evaluate.at<uchar>(y, x)) continue;
      ++total;
      const float d = disparity.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      ++matched;
      const double e = std::abs(d - c.truth.at<float>(y, x));
      if (e > 1.0) ++bad1;
      if (e > 2.0) ++bad2;
      if (!c.roof.empty() && c.roof.at<uchar>(y, x)) {
        ++roofN;
        roofSq += e * e;
        if (e <= 1.0) {
          ++roofInN;
          roofInSq += e * e;
        }
      }
    }
  }
  r.density = total ? 100.0 * matched / total : 0;
  r.bad1 = matched ? 100.0 * bad1 / matched : 0;
  r.bad2 = matched ? 100.0 * bad2 / matched : 0;
  r.bad2All = total ? 100.0 * (bad2 + total - matched) / total : 0;
  if (roofN > 0) r.roofRms = std::sqrt(roofSq / roofN);
  if (roofInN > 0) r.roofRmsInliers = std::sqrt(roofInSq / roofInN);
  r.edge = outlineScore(disparity, c);
  return r;
}

// Where roofRMS's gross errors are: flat-roof pixels off by more than 1 and 5 px, and the share
// of the squared error they carry (ROOF_GROSS set: each one listed).
void roofErrorDiagnosis(const cv::Mat& disparity, const Case& c) {
  long roofN = 0, off1 = 0, off5 = 0;
  double sq = 0, sq5 = 0;
  for (int y = 0; y < c.roof.rows; ++y) {
    for (int x = 0; x < c.roof.cols; ++x) {
      const float d = disparity.at<float>(y, x);
      if (!c.roof.at<uchar>(y, x) || !std::isfinite(d)) continue;
      const double e = std::abs(d - c.truth.at<float>(y, x));
      ++roofN;
      sq += e * e;
      off1 += e > 1 ? 1 : 0;
      if (e > 5) {
        ++off5;
        sq5 += e * e;
        if (std::getenv("ROOF_GROSS") != nullptr) {
          std::printf("      gross %d %d pred %.1f true %.1f\n", x, y, d, c.truth.at<float>(y, x));
        }
      }
    }
  }
  std::printf(
      "    flat-roof matches: %ld, off > 1 px %ld, off > 5 px %ld (%.0f %% of the squared "
      "error)\n",
      roofN, off1, off5, sq > 0 ? 100.0 * sq5 / sq : 0.0);
}

// The matches on sloped roof facets: their RMS error and the share off by more than 1 px.
void slopedRoofDiagnosis(const cv::Mat& disparity, const Case& c) {
  long n = 0, off1 = 0, total = 0;
  double sq = 0;
  for (int y = 0; y < c.slopedRoof.rows; ++y) {
    for (int x = 0; x < c.slopedRoof.cols; ++x) {
      if (!c.slopedRoof.at<uchar>(y, x)) continue;
      ++total;
      const float d = disparity.at<float>(y, x);
      if (!std::isfinite(d)) continue;
      const double e = d - c.truth.at<float>(y, x);
      ++n;
      sq += e * e;
      off1 += std::abs(e) > 1 ? 1 : 0;
    }
  }
  std::printf("    sloped-roof pixels: %ld, matched %ld, RMS %.4f px, off > 1 px %.2f %%\n", total,
              n, n > 0 ? std::sqrt(sq / n) : 0.0, n > 0 ? 100.0 * off1 / n : 0.0);
}

// Records when the matcher enters each progress stage, to print where its wall time goes.
class StageClock : public core::Progress {
 public:
  using Clock = std::chrono::steady_clock;
  using core::Progress::setStage;
  void setStage(const core::Stage& stage) override {
    core::Progress::setStage(stage);
    const std::lock_guard lock(mutex_);
    marks_.push_back({stage.english(), Clock::now(), std::clock()});
  }
  // Each stage's wall seconds, from its start to the next stage's start (the last one to `end`),
  // and the process CPU seconds over the same span: their ratio is how many cores the stage
  // kept busy (a stage near 1.0 on a 2-core machine runs serially).
  void print(const std::string& method, Clock::time_point begin, std::clock_t cpuBegin,
             Clock::time_point end, std::clock_t cpuEnd) const {
    const std::lock_guard lock(mutex_);
    Clock::time_point from = begin;
    std::clock_t cpuFrom = cpuBegin;
    std::string name = "(before the first stage)";
    for (size_t i = 0; i <= marks_.size(); ++i) {
      const Clock::time_point to = i < marks_.size() ? marks_[i].wall : end;
      const std::clock_t cpuTo = i < marks_.size() ? marks_[i].cpu : cpuEnd;
      const double seconds = std::chrono::duration<double>(to - from).count();
      const double cpu = static_cast<double>(cpuTo - cpuFrom) / CLOCKS_PER_SEC;
      if (i > 0 || seconds > 1e-4)
        std::printf("    %s %-42s %7.3f s  cpu %7.3f s\n", method.c_str(), name.c_str(), seconds,
                    cpu);
      if (i < marks_.size()) {
        name = marks_[i].name;
        from = marks_[i].wall;
        cpuFrom = marks_[i].cpu;
      }
    }
  }

 private:
  struct Mark {
    std::string name;
    Clock::time_point wall;
    std::clock_t cpu;
  };
  mutable std::mutex mutex_;
  std::vector<Mark> marks_;
};

bool gStageTimes = false;

void runCase(const Case& c, const std::vector<std::string>& methods, const std::string& dump,
             const nlohmann::json& overrides, int repeat, bool printCpu) {
  std::printf("\n%s: %dx%d, range %d..%d\n", c.name.c_str(), c.left.cols, c.left.rows, c.dmin,
              c.dmax);
  std::printf("  %-10s %8s %8s %8s %10s %9s %9s %7s %8s\n", "method", "density%", "bad1%", "bad2%",
              "bad2+unm%", "roofRMS", "roofRMS1", "edge%", "time s");
  auto paramsFor = [&](const std::string& m) {
    stereo::MatchParams p;
    p.dmin = c.dmin;
    p.dmax = c.dmax;
    if (m == "sgbm") {
      p.method = "sgbm";
    } else {
      core::fromJson(p, overrides);
    }
    if (m == "square") p.adaptive = false;
    return p;
  };
  // With --repeat, the methods run round-robin and each keeps its fastest run: on a shared
  // machine the load then hits every method alike, and the ratios stay meaningful.
  std::vector<double> best(methods.size(), std::numeric_limits<double>::infinity());
  std::vector<cv::Mat> disparity(methods.size()), scores(methods.size());
  for (int rep = 0; rep < repeat; ++rep) {
    for (size_t i = 0; i < methods.size(); ++i) {
      const stereo::MatchParams p = paramsFor(methods[i]);
      const auto start = std::chrono::steady_clock::now();
      const std::clock_t cpu0 = std::clock();
      StageClock stages;
      const stereo::MatchResult result = stereo::matchStereo(c.left, c.right, p, &stages);
      const auto end = std::chrono::steady_clock::now();
      best[i] = std::min(best[i], std::chrono::duration<double>(end - start).count());
      if (gStageTimes) stages.print(methods[i], start, cpu0, end, std::clock());
      disparity[i] = result.disparity;
      scores[i] = result.score;
      if (printCpu) {
        std::printf("  cpu %s %.3f s\n", methods[i].c_str(),
                    static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC);
      }
    }
  }
  for (size_t i = 0; i < methods.size(); ++i) {
    const std::string& m = methods[i];
    const Row r = score(disparity[i], c, best[i]);
    std::printf("  %-10s %8.1f %8.2f %8.2f %10.2f %9.4f %9.4f %7.1f %8.2f\n", m.c_str(), r.density,
                r.bad1, r.bad2, r.bad2All, r.roofRms, r.roofRmsInliers, r.edge, r.seconds);
    if (gOutlineDiagnosis && !c.outline.empty()) {
      outlineDiagnosis(disparity[i], c);
      roofErrorDiagnosis(disparity[i], c);
      if (!c.slopedRoof.empty()) slopedRoofDiagnosis(disparity[i], c);
    }
    if (!dump.empty() && !c.outline.empty()) {
      cv::Mat grey;
      c.left.convertTo(grey, CV_8U);
      bench::writeImage(dump + "/left.png", grey);
      dumpErrors(disparity[i], c, dump + "/errors_" + m + ".png");
      dumpOutline(disparity[i], c, dump + "/outline_" + m + ".csv");
      bench::writeImage(dump + "/disparity_" + m + ".tif", disparity[i]);
      if (!scores[i].empty()) bench::writeImage(dump + "/score_" + m + ".tif", scores[i]);
      if (i == 0) {
        bench::writeImage(dump + "/truth.tif", c.truth);
        if (!c.roof.empty()) bench::writeImage(dump + "/roof.png", c.roof * 255);
        if (!c.slopedRoof.empty()) bench::writeImage(dump + "/sloped_roof.png", c.slopedRoof * 255);
        bench::writeImage(dump + "/left.tif", c.left);
        bench::writeImage(dump + "/right.tif", c.right);
      }
    }
  }
  // The speed target is a ratio measured in this run: print it at full precision.
  const auto at = [&](const char* name) {
    const auto it = std::find(methods.begin(), methods.end(), name);
    return it == methods.end() ? -1.0 : best[static_cast<size_t>(it - methods.begin())];
  };
  if (at("adaptive") > 0 && at("sgbm") > 0) {
    std::printf("  time adaptive %.3f s / sgbm %.3f s = %.2fx\n", at("adaptive"), at("sgbm"),
                at("adaptive") / at("sgbm"));
  }
}

Case simulated(int size, int seed) {
  const sim::Scene scene = sim::simulateScene(sim::squareSceneParams(size, seed));
  Case c;
  c.name = "simulated scene (seed " + std::to_string(seed) + ", default noise)";
  scene.left.convertTo(c.left, CV_32F);
  scene.right.convertTo(c.right, CV_32F);
  c.truth = scene.disparity;
  const cv::Mat scored = (scene.occlusion == 0) & (scene.disparity == scene.disparity);
  // Flat roofs away from their outlines: building label, eroded by 2 px, with a constant true
  // disparity within 2 px (gable and hip roofs and the steps between roof sections excluded).
  cv::Mat building = scene.labels == sim::kLabelBuilding;
  cv::erode(building, building, cv::Mat::ones(5, 5, CV_8U));
  cv::Mat gx, gy;
  cv::Mat truthFilled = scene.disparity.clone();
  truthFilled.setTo(0, core::nanMask(scene.disparity));
  cv::Sobel(truthFilled, gx, CV_32F, 1, 0);
  cv::Sobel(truthFilled, gy, CV_32F, 0, 1);
  cv::Mat flat = (cv::abs(gx) < 1e-3) & (cv::abs(gy) < 1e-3);
  // Away from steps inside a roof too (sections of different heights, superstructures): the
  // same 2 px as from the outline.
  cv::erode(flat, flat, cv::Mat::ones(5, 5, CV_8U));
  c.roof = building & flat & scored;
  c.roof /= 255;
  // Sloped facets (gable and hip roofs) away from their outlines, ridges and hips: building
  // pixels whose true disparity is planar (second derivatives zero) but not level.
  cv::Mat gxx, gyy, gxy;
  cv::Sobel(truthFilled, gxx, CV_32F, 2, 0);
  cv::Sobel(truthFilled, gyy, CV_32F, 0, 2);
  cv::Sobel(truthFilled, gxy, CV_32F, 1, 1);
  cv::Mat planar = (cv::abs(gxx) < 1e-3) & (cv::abs(gyy) < 1e-3) & (cv::abs(gxy) < 1e-3) & ~flat;
  cv::erode(planar, planar, cv::Mat::ones(5, 5, CV_8U));
  c.slopedRoof = building & planar & scored;
  c.slopedRoof /= 255;
  c.evaluate = scored / 255;
  c.dmin = scene.disparityMin;
  c.dmax = scene.disparityMax;
  auto label = [&](int y, int x) {
    return x >= 0 && x < size ? scene.labels.at<uchar>(y, x) : uchar{255};
  };
  for (int y = 0; y < size; ++y) {
    for (int xb = 0; xb < size; ++xb) {
      for (const int dir : {-1, 1}) {
        bool clean = true;
        for (int k = 0; k < 3 && clean; ++k) {
          clean = label(y, xb + dir * k) == sim::kLabelBuilding &&
                  label(y, xb - dir * (k + 1)) == sim::kLabelGround;
        }
        if (!clean) continue;
        const float dRoof = scene.disparity.at<float>(y, xb);
        const float dGround = scene.disparity.at<float>(y, xb - dir);
        if (!(std::abs(dRoof - dGround) >= 2.0F)) continue;  // also rejects NaN
        c.outline.push_back({y, xb, dir, dRoof, dGround});
      }
    }
  }
  return c;
}

cv::Mat readFloat(const fs::path& p) {
  return io::readGreyFloat(p.string());
}

// Grey values as float without the nodata → NaN conversion: Cones_LEFT/RIGHT.tif declare
// nodata = 255, which would turn every white pixel into a hole.
cv::Mat readFloatKeepingNodata(const fs::path& p) {
  io::ReadOptions keep;
  keep.type = io::PixelType::Keep;
  keep.toGrey = true;
  cv::Mat out;
  io::readRaster(p.string(), keep).data.convertTo(out, CV_32F);
  return out;
}

std::vector<Case> realCases(const fs::path& data) {
  std::vector<Case> cases;
  const fs::path cones = data / "middlebury-cones";
  if (fs::exists(cones / "Cones_LEFT.tif") && fs::exists(cones / "Occlusion_LEFT.png")) {
    Case c;
    c.name = "Middlebury Cones (quarter size)";
    c.left = readFloatKeepingNodata(cones / "Cones_LEFT.tif");
    c.right = readFloatKeepingNodata(cones / "Cones_RIGHT.tif");
    c.truth = readFloat(cones / "Cones_LEFT_GT.tif");
    const cv::Mat occ = readFloat(cones / "Occlusion_LEFT.png");
    c.evaluate = (occ > 0) & (c.truth > 0);
    c.evaluate /= 255;
    c.dmin = 0;
    c.dmax = 60;
    cases.push_back(c);
  }
  const fs::path aloe = data / "middlebury-aloe";
  if (fs::exists(aloe / "aloeL.jpg") && fs::exists(aloe / "aloeGT.png")) {
    Case c;
    c.name = "Middlebury Aloe (full size)";
    c.left = readFloat(aloe / "aloeL.jpg");
    c.right = readFloat(aloe / "aloeR.jpg");
    c.truth = readFloat(aloe / "aloeGT.png");
    c.evaluate = c.truth > 0;
    c.evaluate /= 255;
    double mx = 0;
    cv::minMaxLoc(c.truth, nullptr, &mx);
    c.dmin = 0;
    c.dmax = static_cast<int>(std::ceil(mx)) + 8;
    cases.push_back(c);
  }
  const fs::path dublin = data / "aerial-dublin";
  if (fs::exists(dublin / "dublin_0004_left.png") &&
      fs::exists(dublin / "dublin_0004_left_gt_disp.png")) {
    Case c;
    c.name = "DublinCity aerial tile (LiDAR GT, scored where valid)";
    c.left = readFloat(dublin / "dublin_0004_left.png");
    c.right = readFloat(dublin / "dublin_0004_right.png");
    io::ReadOptions keep;
    const io::Raster gt = io::readRaster((dublin / "dublin_0004_left_gt_disp.png").string(), keep);
    gt.data.convertTo(c.truth, CV_32F, 1.0 / 256.0);
    c.evaluate = c.truth > 0;
    c.evaluate /= 255;
    c.dmin = 0;
    c.dmax = 150;
    cases.push_back(c);
  }
  return cases;
}

}  // namespace
int main(int argc, char** argv) {
  // As the CLI and the GUI do (architecture.md, "Process set-up").
  delineo::core::tuneAllocatorForLargeImages();
  int size = 1000;
  std::string data = bench::defaultDataRoot();
  bool useData = true;
  std::string dump;
  int range = 0;
  int repeat = 1;
  int seed = 1;  // simulated scene; other seeds are held-out scenes for the tuned constants
  bool printCpu = false;
  nlohmann::json overrides = nlohmann::json::object();
  std::vector<std::string> methods = {"adaptive", "square", "sgbm"};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--size" && i + 1 < argc) {
      size = std::atoi(argv[++i]);
    } else if (a == "--data" && i + 1 < argc) {
      data = argv[++i];
    } else if (a == "--seed" && i + 1 < argc) {
      seed = std::atoi(argv[++i]);
    } else if (a == "--range" && i + 1 < argc) {
      range = std::atoi(argv[++i]);
    } else if (a == "--dump" && i + 1 < argc) {
      dump = argv[++i];
      // Made here, so that a wrong path fails at once with its name, not as unreadable dumps.
      std::error_code made;
      std::filesystem::create_directories(dump, made);
      if (made) {
        std::fprintf(stderr, "bench_stereo: cannot create dump directory %s: %s\n", dump.c_str(),
                     made.message().c_str());
        return 2;
      }
    } else if (a == "--params" && i + 1 < argc) {
      overrides = nlohmann::json::parse(argv[++i]);
    } else if (a == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--outline-diag") {
      gOutlineDiagnosis = true;
    } else if (a == "--stages") {
      gStageTimes = true;
    } else if (a == "--cpu") {
      printCpu = true;
    } else if (a == "--no-data") {
      useData = false;
    } else if (a == "--methods" && i + 1 < argc) {
      methods.clear();
      std::string list = argv[++i];
      size_t start = 0;
      while (start <= list.size()) {
        size_t comma = list.find(',', start);
        if (comma == std::string::npos) comma = list.size();
        methods.push_back(list.substr(start, comma - start));
        start = comma + 1;
      }
    } else {
      std::fprintf(stderr,
                   "usage: bench_stereo [--size N] [--data DIR] [--no-data] "
                   "[--methods adaptive,square,sgbm] [--dump DIR] [--params JSON] [--range N] "
                   "[--repeat N] [--cpu] [--stages] [--seed N]\n");
      return 2;
    }
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // rows appear as they are measured
  std::printf(
      "bench_stereo: adaptive = contour-adaptive shapes, square = same matcher with "
      "square windows, sgbm = OpenCV StereoSGBM (3-way)\n");
  Case sim = simulated(size, seed);
  if (range > sim.dmax - sim.dmin + 1) sim.dmax = sim.dmin + range - 1;
  runCase(sim, methods, dump, overrides, repeat, printCpu);
  if (useData) {
    if (!fs::exists(data)) {
      std::printf("\nreal datasets: skipped (%s not found)\n", data.c_str());
    } else {
      for (const Case& c : realCases(data)) runCase(c, methods, "", overrides, repeat, printCpu);
    }
  }
  return 0;
}
