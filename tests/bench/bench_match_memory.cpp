// Memory of the adaptive matcher on large pairs, whole and in tiles (MatchParams::tile): a
// simulated scene repeated into square pairs of each size, each pair matched in a child process
// of its own. Prints, per size and tile: the peak resident memory the match adds to its inputs
// (MB and bytes per pixel), its CPU and wall time and the share of pixels matched. For a tiled
// run, also the memory target: its peak is at most that of the whole match of a pair the size
// of its largest tile crop ("one tile"), plus the disparity and score maps of the whole image
// (8 bytes per pixel), plus kTargetSlack of one tile's.
//
// Usage: bench_match_memory [--scene N] [--seed N] [--sizes A,B,...] [--tiles T1,T2,...]
//                           [--whole-up-to N] [--tiny]
//   --scene N   side of the simulated scene repeated into the pairs (default 1024)
//   --sizes     sides of the square pairs (default 4096,6144,8192)
//   --tiles     tile settings matched at each size (default 0,2048: whole, and the default tile)
//   --whole-up-to N  whole matches (tile 0) only up to this side (default 4096: 8192 takes 11 GB)
//   --tiny      a 160 px scene into 200 and 300 px pairs, tiles 0 and 128 (the ctest smoke run)
// Linux only (fork, /proc/self/status, /proc/self/clear_refs).
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/allocator.hpp"
#include "delineo/core/nan_mask.hpp"
#include "delineo/sim/scene.hpp"
#include "delineo/stereo/match.hpp"
#include "match_tiles.hpp"

namespace {
using namespace delineo;

constexpr double kTargetSlack = 0.15;  // measured: 6-10 % above one tile plus the maps

struct Options {
  int scene = 1024, seed = 7;
  std::vector<int> sizes{4096, 6144, 8192};
  std::vector<int> tiles{0, stereo::MatchParams{}.tile};
  int wholeUpTo = 4096;
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
    else if (a == "--whole-up-to" && hasValue) o.wholeUpTo = std::stoi(argv[++i]);
    else if (a == "--tiny") o = Options{160, 7, {200, 300}, {0, 128}, 300, true};
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

// The scene's view repeated into a float32 image of `size`.
cv::Mat repeated(const cv::Mat& view, cv::Size size) {
  cv::Mat out(size, CV_32F);
  for (int y = 0; y < size.height; y += view.rows) {
    for (int x = 0; x < size.width; x += view.cols) {
      const cv::Rect r(x, y, std::min(view.cols, size.width - x),
                       std::min(view.rows, size.height - y));
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
void matchInChild(const Options& o, cv::Size size, int tile, int fd) {
  const sim::Scene scene = sim::simulateScene(sim::squareSceneParams(o.scene, o.seed));
  const cv::Mat left = repeated(scene.left, size), right = repeated(scene.right, size);
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

Run matchInOwnProcess(const Options& o, cv::Size size, int tile) {
  int fds[2];
  if (pipe(fds) != 0) std::exit(1);
  const pid_t child = fork();
  if (child == 0) {
    close(fds[0]);
    matchInChild(o, size, tile, fds[1]);
  }
  close(fds[1]);
  Run run;
  const ssize_t got = read(fds[0], &run, sizeof run);
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  if (got != static_cast<ssize_t>(sizeof run) || status != 0) {
    std::fprintf(stderr, "the match of %dx%d px, tile %d failed\n", size.width, size.height,
                 tile);
    std::exit(1);
  }
  return run;
}

// The largest crop of the tiles an image of `side` px is matched in (the matcher's own grid).
cv::Size largestCrop(int side, int tile, const Run& run) {
  const int levels = stereo::autoLevels(run.dmin, run.dmax);
  const auto tiles = stereo::detail::matchTileGrid(
      {side, side}, tile, stereo::detail::matchTileContext(levels), run.dmin, run.dmax,
      1 << (levels - 1));
  cv::Size largest(0, 0);
  for (const auto& t : tiles) {
    if (t.crop.area() > largest.area()) largest = t.crop.size();
  }
  return largest;
}

// A tiled run against one tile's memory (the whole match of its largest crop, run here) plus the
// image's two maps: printed, and whether it holds.
bool meetsTarget(const Options& o, int side, int tile, const Run& tiled) {
  const cv::Size crop = largestCrop(side, tile, tiled);
  const Run oneTile = matchInOwnProcess(o, crop, 0);
  const double maps = 8.0 * side * side / 1048576.0;
  const double target = oneTile.peakMb * (1 + kTargetSlack) + maps;
  const bool met = tiled.peakMb <= target;
  std::printf("  target: one tile (%dx%d whole: %.0f MB) + %.0f %% + maps %.0f MB = %.0f MB; "
              "peak %.0f MB: %s\n",
              crop.width, crop.height, oneTile.peakMb, 100 * kTargetSlack, maps, target,
              tiled.peakMb, met ? "met" : "NOT MET");
  return met;
}

}  // namespace

int main(int argc, char** argv) {
  core::tuneAllocatorForLargeImages();
  const Options o = parse(argc, argv);
  std::printf("simulated scene %d px, seed %d, repeated\n", o.scene, o.seed);
  std::printf("%7s %6s %9s %10s %8s %8s %8s %8s\n", "side", "tile", "range", "peak MB", "B/px",
              "cpu s", "wall s", "matched");
  bool ok = true;
  for (const int side : o.sizes) {
    for (const int tile : o.tiles) {
      if (tile == 0 && side > o.wholeUpTo) continue;
      const Run r = matchInOwnProcess(o, {side, side}, tile);
      std::printf("%7d %6d %4d..%-4d %10.0f %8.1f %8.2f %8.2f %7.1f%%\n", side, tile, r.dmin,
                  r.dmax, r.peakMb, r.peakMb * 1048576.0 / (static_cast<double>(side) * side),
                  r.cpu, r.wall, 100.0 * r.matched);
      if (stereo::detail::matchesInTiles({side, side}, tile)) {
        ok = meetsTarget(o, side, tile, r) && ok;
      }
      std::fflush(stdout);
    }
  }
  // The smoke run's sizes are too small for the target to mean anything: it is printed only.
  return ok || o.tiny ? 0 : 1;
}
