#include "speckles.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "union_find.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A row's pixels x0..x1 whose left neighbours are within range of them: one piece of a region.
struct Run {
  int y, x0, x1;
};

// Joins each run of row y (ids in `ids`, -1 where unmatched) to the runs of row y − 1 (`upIds`)
// that one of its pixels has an 8-neighbour within `tol` in. A run's pixels mostly meet the same
// run above: it is joined once while they do.
void joinRows(const float* row, const float* up, const std::vector<int>& ids,
              const std::vector<int>& upIds, int w, float tol, int idOffset, int upIdOffset,
              std::vector<int>& parent) {
  int lastRun = -1, lastUp = -1;
  for (int x = 0; x < w; ++x) {
    const int id = ids[static_cast<size_t>(x)];
    if (id < 0) continue;
    if (id != lastRun) {
      lastRun = id;
      lastUp = -1;
    }
    const float d = row[x];
    for (int u = std::max(0, x - 1); u <= std::min(w - 1, x + 1); ++u) {
      const int upId = upIds[static_cast<size_t>(u)];
      // NaN fails the comparison: unmatched pixels never join.
      if (upId < 0 || upId == lastUp || !(std::abs(up[u] - d) <= tol)) continue;
      joinRoots(parent, id + idOffset, upId + upIdOffset);
      lastUp = upId;
    }
  }
}

// The run ids of row y's pixels (-1 where unmatched) from its runs [first, end) of `runs`.
void runIds(const std::vector<Run>& runs, size_t first, size_t end, int w, std::vector<int>& ids) {
  ids.assign(static_cast<size_t>(w), -1);
  for (size_t k = first; k < end; ++k) {
    std::fill(ids.begin() + runs[k].x0, ids.begin() + runs[k].x1 + 1, static_cast<int>(k));
  }
}

// A band of rows' runs (in row order) and their own union-find.
struct Band {
  std::vector<Run> runs;
  std::vector<int> parent;
  size_t firstRowEnd = 0, lastRowStart = 0;  // the runs of its first row, of its last row
};

// removeSpeckles in its steps: the runs of each band of rows, joined within the band
// (findRuns); one union-find over all of them, joined across the bands' borders (joinBands);
// each region's size summed at its root (sizeRegions); the small regions' runs made unmatched
// (removeSmall).
struct SpeckleRegions {
  void findRuns(int threads);
  void findRunsInBand(int rowStart, int rowEnd);
  void joinBands();
  void sizeRegions();
  int removeSmall(cv::Mat& score, int maxSize, int threads);

  cv::Mat& disparity;
  const float tol;
  const int bandRows;
  const int w = disparity.cols, h = disparity.rows;
  std::vector<Band> bandOf = std::vector<Band>(static_cast<size_t>((h + bandRows - 1) / bandRows));
  std::vector<size_t> offset{};  // by band: its first run's index over all runs
  std::vector<int> parent{};     // the union-find over all runs
  std::vector<int> size{};       // at each region's root run: the region's pixels
};

void SpeckleRegions::findRuns(int threads) {
  forRowBands(
      h, threads, [&](int rowStart, int rowEnd) { findRunsInBand(rowStart, rowEnd); }, bandRows);
}

void SpeckleRegions::findRunsInBand(int rowStart, int rowEnd) {
  Band& band = bandOf[static_cast<size_t>(rowStart / bandRows)];
  std::vector<int> ids(static_cast<size_t>(w)), upIds(static_cast<size_t>(w));
  for (int y = rowStart; y < rowEnd; ++y) {
    const float* row = disparity.ptr<float>(y);
    const size_t rowFirst = band.runs.size();
    for (int x = 0; x < w; ++x) {
      const float d = row[x];
      if (!std::isfinite(d)) {
        ids[static_cast<size_t>(x)] = -1;
        continue;
      }
      // NaN fails the comparison: unmatched pixels never join.
      if (x > 0 && std::abs(row[x - 1] - d) <= tol) {
        ++band.runs.back().x1;
      } else {
        band.parent.push_back(static_cast<int>(band.runs.size()));
        band.runs.push_back({y, x, x});
      }
      ids[static_cast<size_t>(x)] = static_cast<int>(band.runs.size()) - 1;
    }
    if (y == rowStart) band.firstRowEnd = band.runs.size();
    band.lastRowStart = rowFirst;
    if (y > rowStart) {
      joinRows(row, disparity.ptr<float>(y - 1), ids, upIds, w, tol, 0, 0, band.parent);
    }
    std::swap(ids, upIds);
  }
}

// One union-find over all runs, in band order (a run's parent still precedes it), then the
// joins across the band borders.
void SpeckleRegions::joinBands() {
  offset.assign(bandOf.size() + 1, 0);
  for (size_t b = 0; b < bandOf.size(); ++b) offset[b + 1] = offset[b] + bandOf[b].runs.size();
  parent.resize(offset.back());
  for (size_t b = 0; b < bandOf.size(); ++b) {
    const int o = static_cast<int>(offset[b]);
    std::transform(bandOf[b].parent.begin(), bandOf[b].parent.end(),
                   parent.begin() + static_cast<long>(o), [o](int p) { return p + o; });
  }
  std::vector<int> ids, upIds;
  for (size_t b = 1; b < bandOf.size(); ++b) {
    const int y = static_cast<int>(b) * bandRows;
    runIds(bandOf[b].runs, 0, bandOf[b].firstRowEnd, w, ids);
    runIds(bandOf[b - 1].runs, bandOf[b - 1].lastRowStart, bandOf[b - 1].runs.size(), w, upIds);
    joinRows(disparity.ptr<float>(y), disparity.ptr<float>(y - 1), ids, upIds, w, tol,
             static_cast<int>(offset[b]), static_cast<int>(offset[b - 1]), parent);
  }
}

// Flattened in index order (a parent precedes its run, so it is flat already), and the size of
// each region summed at its root.
void SpeckleRegions::sizeRegions() {
  size.assign(parent.size(), 0);
  for (size_t i = 0; i < parent.size(); ++i) {
    parent[i] = parent[static_cast<size_t>(parent[i])];
  }
  for (size_t b = 0; b < bandOf.size(); ++b) {
    for (size_t k = 0; k < bandOf[b].runs.size(); ++k) {
      const Run& run = bandOf[b].runs[k];
      size[static_cast<size_t>(parent[offset[b] + k])] += run.x1 - run.x0 + 1;
    }
  }
}

// The runs of the regions under maxSize pixels made unmatched, by bands of rows; the pixels
// removed.
int SpeckleRegions::removeSmall(cv::Mat& score, int maxSize, int threads) {
  std::atomic<int> removed{0};
  forRowBands(
      h, threads,
      [&](int rowStart, int) {
        const size_t b = static_cast<size_t>(rowStart / bandRows);
        int removedHere = 0;
        for (size_t k = 0; k < bandOf[b].runs.size(); ++k) {
          if (size[static_cast<size_t>(parent[offset[b] + k])] >= maxSize) continue;
          const Run& run = bandOf[b].runs[k];
          std::fill_n(disparity.ptr<float>(run.y) + run.x0, run.x1 - run.x0 + 1, kNaN);
          if (!score.empty())
            std::fill_n(score.ptr<float>(run.y) + run.x0, run.x1 - run.x0 + 1, kNaN);
          removedHere += run.x1 - run.x0 + 1;
        }
        removed += removedHere;
      },
      bandRows);
  return removed;
}
}  // namespace

// Connected regions of matched pixels (8-neighbours within `range` px of each other) smaller
// than `maxSize` pixels become unmatched: isolated islands are mostly wrong matches (repetitive
// texture, windows straddling a step) and a real surface is rarely that small. 8-connected, not
// 4 like OpenCV's filterSpeckles: the matched rim of an otherwise unmatched roof is a diagonal
// staircase that 4-connectivity cuts into pieces at every step of a slanted outline.
int removeSpeckles(cv::Mat& disparity, cv::Mat& score, int maxSize, double range, int threads) {
  CV_Assert(disparity.type() == CV_32F && (score.empty() || score.size() == disparity.size()));
  const int w = disparity.cols, h = disparity.rows;
  if (w == 0 || h == 0 || maxSize <= 1) return 0;
  // Union-find over runs, not pixels: a row's pixels joined to their left neighbours are one
  // run, and a run meets few runs above (a pixel union-find was ~150 instructions a pixel, a
  // flood fill 20 ms at 1 Mpx). Bands of rows on the workers, each with its own runs and
  // union-find; the joins across band borders are made afterwards. The regions, and so the
  // removals, do not depend on the bands.
  SpeckleRegions regions{.disparity = disparity,
                         .tol = static_cast<float>(range),
                         .bandRows = std::max(32, (h + 4 * threads - 1) / (4 * threads))};
  regions.findRuns(threads);
  regions.joinBands();
  regions.sizeRegions();
  return regions.removeSmall(score, maxSize, threads);
}

}  // namespace delineo::stereo::detail
