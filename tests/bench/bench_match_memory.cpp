// Memory of the adaptive matcher on large pairs, whole and in tiles (MatchParams::tile): a
// simulated scene repeated into square pairs of each size, each pair matched in a child process
// of its own. Prints, per size and tile: the peak resident memory the match adds to its inputs
// (MB and bytes per pixel), its CPU and wall time and the share of pixels matched; then the
// memory target of the tiled runs: from one size to the next, the peak grows by at most
// kTargetBytesPerPixel per added pixel (the disparity and score maps, 8 bytes, and some slack):
// the rest is one tile's, whatever the image's size.
//
// Usage: bench_match_memory [--scene N] [--seed N] [--sizes A,B,...] [--tiles T1,T2,...] [--tiny]
//   --scene N   side of the simulated scene repeated into the pairs (default 1024)
//   --sizes     sides of the square pairs (default 2048,3072,4096)
//   --tiles     tile settings matched at each size (default 0,2048: whole, and the default tile)
//   --tiny      a 160 px scene into 200 and 300 px pairs, tiles 0 and 128 (the ctest smoke run)
// Linux only (fork, /proc/self/status, /proc/self/clear_refs).
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/nan_mask.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/match.hpp"

namespace {
using namespace delineo;

constexpr double kTargetBytesPerPixel = 12.0;

struct Options {
  int scene = 1024, seed = 7;
  std::vector<int> sizes{2048, 3072, 4096};
  std::vector<int> tiles{0, stereo::MatchParams{}.tile};
  bool tiny = false;
};

std::vector<int> intList(const std::string& s) {
  std::vector<int> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::stoi(item));
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool hasValue = i + 1 < argc;
    if (a == "--scene" && hasValue) o.scene = std::stoi(argv[++i]);
    else if (a == "--seed" && hasValue) o.seed = std::stoi(argv[++i]);
    else if (a == "--sizes" && hasValue) o.sizes = intList(argv[++i]);
    else if (a == "--tiles" && hasValue) o.tiles = intList(argv[++i]);
    else if (a == "--tiny") o = Options{160, 7, {200, 300}, {0, 128}, true};
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      std::exit(2);
    }
  }
  return o;
}

// A field of /proc/self/status in kB (VmRSS, VmHWM).
long statusKb(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stol(line.substr(field.size() + 1));
  }
  return -1;
}

// The peak resident memory (VmHWM) is set back to the current one.
void resetPeak() {
  std::ofstream("/proc/self/clear_refs") << "5";
}

double processCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The scene's view repeated into a `side` x `side` float32 image.
cv::Mat repeated(const cv::Mat& view, int side) {
  cv::Mat out(side, side, CV_32F);
  for (int y = 0; y < side; y += view.rows) {
    for (int x = 0; x < side; x += view.cols) {
      const cv::Rect r(x, y, std::min(view.cols, side - x), std::min(view.rows, side - y));
      view(cv::Rect(0, 0, r.width, r.height)).convertTo(out(r), CV_32F);
    }
  }
  return out;
}

struct Run {
  double peakMb = 0, cpu = 0, wall = 0, matched = 0;
  int dmin = 0, dmax = 0;
};

// In the child: the scene simulated (in the child: OpenCV's threads do not cross a fork), the
// pair made, then matched; the numbers written to `fd`.
void matchInChild(const Options& o, int side, int tile, int fd) {
  const sim::Scene scene = sim::simulateScene(sim::squareSceneParams(o.scene, o.seed));
  const cv::Mat left = repeated(scene.left, side), right = repeated(scene.right, side);
  stereo::MatchParams p;
  p.dmin = scene.disparityMin;
  p.dmax = scene.disparityMax;
  p.tile = tile;
  const long before = statusKb("VmRSS");
  resetPeak();
  const double cpu0 = processCpuSeconds();
  const auto wall0 = std::chrono::steady_clock::now();
  const stereo::MatchResult r = stereo::matchStereo(left, right, p);
  Run run;
  run.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  run.cpu = processCpuSeconds() - cpu0;
  run.peakMb = static_cast<double>(statusKb("VmHWM") - before) / 1024.0;
  run.matched = 1.0 - static_cast<double>(cv::countNonZero(core::nanMask(r.disparity))) /
                         static_cast<double>(r.disparity.total());
  run.dmin = p.dmin;
  run.dmax = p.dmax;
  const ssize_t written = write(fd, &run, sizeof run);
  _exit(written == static_cast<ssize_t>(sizeof run) ? 0 : 1);
}

Run matchInOwnProcess(const Options& o, int side, int tile) {
  int fds[2];
  if (pipe(fds) != 0) std::exit(1);
  const pid_t child = fork();
  if (child == 0) {
    close(fds[0]);
    matchInChild(o, side, tile, fds[1]);
  }
  close(fds[1]);
  Run run;
  const ssize_t got = read(fds[0], &run, sizeof run);
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  if (got != static_cast<ssize_t>(sizeof run) || status != 0) {
    std::fprintf(stderr, "the match of %d px, tile %d failed\n", side, tile);
    std::exit(1);
  }
  return run;
}

// The tiled runs' growth per added pixel between consecutive sizes, against the target.
bool meetsTarget(const Options& o, const std::map<std::pair<int, int>, Run>& runs) {
  bool ok = true;
  for (const int tile : o.tiles) {
    if (tile == 0) continue;
    for (size_t i = 1; i < o.sizes.size(); ++i) {
      const int a = o.sizes[i - 1], b = o.sizes[i];
      const double added = static_cast<double>(b) * b - static_cast<double>(a) * a;
      const double grown = (runs.at({b, tile}).peakMb - runs.at({a, tile}).peakMb) * 1048576.0;
      const double perPixel = grown / added;
      const bool met = perPixel <= kTargetBytesPerPixel;
      std::printf("tile %d, %d -> %d px: peak grows by %.1f bytes per added pixel (target <= "
                  "%.0f): %s\n",
                  tile, a, b, perPixel, kTargetBytesPerPixel, met ? "met" : "NOT MET");
      ok = ok && met;
    }
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  const Options o = parse(argc, argv);
  std::printf("simulated scene %d px, seed %d, repeated\n", o.scene, o.seed);
  std::printf("%7s %6s %9s %10s %8s %8s %8s %8s\n", "side", "tile", "range", "peak MB", "B/px",
              "cpu s", "wall s", "matched");
  std::map<std::pair<int, int>, Run> runs;
  for (const int side : o.sizes) {
    for (const int tile : o.tiles) {
      const Run r = matchInOwnProcess(o, side, tile);
      runs[{side, tile}] = r;
      std::printf("%7d %6d %4d..%-4d %10.0f %8.1f %8.2f %8.2f %7.1f%%\n", side, tile, r.dmin,
                  r.dmax, r.peakMb,
                  r.peakMb * 1048576.0 / (static_cast<double>(side) * side), r.cpu, r.wall,
                  100.0 * r.matched);
      std::fflush(stdout);
    }
  }
  // The smoke run's sizes are too small for the target to mean anything: it is printed only.
  return meetsTarget(o, runs) || o.tiny ? 0 : 1;
}
