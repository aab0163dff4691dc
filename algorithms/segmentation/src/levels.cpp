#include "delineo/segmentation/levels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <unordered_map>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/segmentation/regions.hpp"

namespace delineo::segmentation {

namespace {

const cv::Point kSteps[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};  // the first two scan each border once

int rootOf(std::vector<int>& parent, int i) {
  while (parent[static_cast<size_t>(i)] != i) {
    parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
    i = parent[static_cast<size_t>(i)];
  }
  return i;
}

bool inside(const cv::Mat& m, cv::Point p) { return p.x >= 0 && p.y >= 0 && p.x < m.cols && p.y < m.rows; }

// Local region index 0..n-1 per piece pixel, -1 outside the piece. Piece pixels without a region
// take the one of the nearest piece pixel with a region. Returns n.
int localRegions(const cv::Mat& piece, const cv::Mat& regions, cv::Mat& local) {
  local = cv::Mat(piece.size(), CV_32S, cv::Scalar(-1));
  std::unordered_map<int, int> index;
  bool missing = false;
  for (int y = 0; y < piece.rows; ++y) {
    for (int x = 0; x < piece.cols; ++x) {
      if (!piece.at<uchar>(y, x)) continue;
      const int r = regions.at<int>(y, x);
      if (r < 0) {
        missing = true;
        continue;
      }
      local.at<int>(y, x) = index.try_emplace(r, static_cast<int>(index.size())).first->second;
    }
  }
  if (index.empty() || !missing) return static_cast<int>(index.size());
  const cv::Mat withoutRegion = local < 0;
  cv::Mat distance, nearest;
  cv::distanceTransform(withoutRegion, distance, nearest, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  std::vector<int> regionOfLabel(piece.total() + 1, -1);
  for (int y = 0; y < piece.rows; ++y) {
    for (int x = 0; x < piece.cols; ++x) {
      if (!withoutRegion.at<uchar>(y, x)) regionOfLabel[static_cast<size_t>(nearest.at<int>(y, x))] = local.at<int>(y, x);
    }
  }
  for (int y = 0; y < piece.rows; ++y) {
    for (int x = 0; x < piece.cols; ++x) {
      if (piece.at<uchar>(y, x) && withoutRegion.at<uchar>(y, x)) {
        local.at<int>(y, x) = regionOfLabel[static_cast<size_t>(nearest.at<int>(y, x))];
      }
    }
  }
  return static_cast<int>(index.size());
}

// The height up to `band` px inside the local region at `p`, walking by `d`: the farthest pixel
// of the walk still in that region that has a height (NaN when none has: joined gap pixels).
float heightInside(const cv::Mat& local, const cv::Mat& ndsm, cv::Point p, cv::Point d, int band) {
  const int id = local.at<int>(p);
  float height = ndsm.at<float>(p);
  for (int k = 1; k <= band; ++k) {
    const cv::Point q = p + k * d;
    if (!inside(local, q) || local.at<int>(q) != id) break;
    if (std::isfinite(ndsm.at<float>(q))) height = ndsm.at<float>(q);
  }
  return height;
}

struct RegionStats {
  int pixels = 0, steep = 0, outside = 0;  // outside: 4-neighbour contacts with pixels off the piece
  double heightSum = 0.0;
  int heights = 0;
};

struct Border {
  int length = 0;
  std::vector<float> steps;  // m, height of the lower index minus the higher, per measured contact
};

std::uint64_t pairKey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

// The q-quantile (0..1) of `v` (not empty), by partial sort.
float quantile(std::vector<float>& v, double q) {
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

float median(std::vector<float> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The parts after merging: every level smaller than `minPixels` or without contact off the piece
// joins, smallest first, the neighbour it shares most border with. `partOf`: region -> level.
void mergeSmallLevels(std::vector<int>& partOf, const std::vector<RegionStats>& stats,
                      const std::map<std::uint64_t, Border>& borders, double minPixels, const std::vector<bool>& ramp) {
  const size_t n = partOf.size();
  std::vector<long> pixels(n, 0), outside(n, 0);
  for (size_t r = 0; r < n; ++r) {
    pixels[static_cast<size_t>(partOf[r])] += stats[r].pixels;
    outside[static_cast<size_t>(partOf[r])] += stats[r].outside;
  }
  std::vector<std::map<int, long>> shared(n);
  for (const auto& [key, border] : borders) {
    const int a = partOf[static_cast<size_t>(key >> 32)], b = partOf[static_cast<size_t>(key & 0xffffffffu)];
    if (a == b) continue;
    shared[static_cast<size_t>(a)][b] += border.length;
    shared[static_cast<size_t>(b)][a] += border.length;
  }
  std::vector<int> into(n);
  std::iota(into.begin(), into.end(), 0);
  for (;;) {
    int small = -1;
    for (size_t p = 0; p < n; ++p) {
      if (shared[p].empty() || (pixels[p] >= minPixels && outside[p] > 0 && !ramp[p])) continue;
      if (small < 0 || pixels[p] < pixels[static_cast<size_t>(small)]) small = static_cast<int>(p);
    }
    if (small < 0) break;
    const size_t s = static_cast<size_t>(small);
    const int target = std::max_element(shared[s].begin(), shared[s].end(), [](const auto& u, const auto& v) {
                         return u.second < v.second;
                       })->first;
    const size_t t = static_cast<size_t>(target);
    for (const auto& [other, length] : shared[s]) {
      shared[static_cast<size_t>(other)].erase(small);
      if (other == target) continue;
      shared[t][other] += length;
      shared[static_cast<size_t>(other)][target] += length;
    }
    shared[s].clear();
    pixels[t] += pixels[s], outside[t] += outside[s];
    into[s] = target;
  }
  for (int& p : partOf) {
    while (into[static_cast<size_t>(p)] != p) p = into[static_cast<size_t>(p)];
  }
}

// Per region: size, steep pixels, mean height, contacts off the piece; per pair: the border.
struct PieceRegions {
  std::vector<RegionStats> stats;
  std::map<std::uint64_t, Border> borders;
};

// The `n` local regions measured: `steep` marks wall pixels, a border's step is read `band` px
// inside each side.
PieceRegions measureRegions(const cv::Mat& local, const cv::Mat& ndsm, const cv::Mat& steep, int band, int n) {
  PieceRegions measured;
  measured.stats.resize(static_cast<size_t>(n));
  for (int y = 0; y < local.rows; ++y) {
    for (int x = 0; x < local.cols; ++x) {
      const cv::Point p(x, y);
      const int id = local.at<int>(p);
      if (id < 0) continue;
      RegionStats& s = measured.stats[static_cast<size_t>(id)];
      ++s.pixels;
      s.steep += steep.at<uchar>(p) != 0;
      if (const float h = ndsm.at<float>(p); std::isfinite(h)) s.heightSum += h, ++s.heights;
      for (int k = 0; k < 4; ++k) {
        const cv::Point q = p + kSteps[k];
        const int other = inside(local, q) ? local.at<int>(q) : -1;
        if (other < 0) ++s.outside;
        if (other < 0 || other == id || k >= 2) continue;
        Border& b = measured.borders[pairKey(id, other)];
        ++b.length;
        const float ha = heightInside(local, ndsm, p, -kSteps[k], band);
        const float hb = heightInside(local, ndsm, q, kSteps[k], band);
        if (std::isfinite(ha) && std::isfinite(hb)) b.steps.push_back(id < other ? ha - hb : hb - ha);
      }
    }
  }
  return measured;
}

// Levels: non-wall regions joined across borders of a step under δ_0 (`minStep`). A border
// without heights on both sides (unmatched on both) compares the two regions' mean heights
// instead. Returns the union-find parents.
std::vector<int> joinLevels(const PieceRegions& measured, const std::vector<bool>& wall, double minStep) {
  const auto meanHeight = [&](int r) {
    const RegionStats& s = measured.stats[static_cast<size_t>(r)];
    return s.heights > 0 ? s.heightSum / s.heights : std::nan("");
  };
  std::vector<int> parent(measured.stats.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& [key, border] : measured.borders) {
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    if (wall[static_cast<size_t>(a)] || wall[static_cast<size_t>(b)]) continue;
    const double step = border.steps.empty() ? meanHeight(a) - meanHeight(b) : median(border.steps);
    if (!(std::abs(step) >= minStep)) {  // NaN (no height at all): one level
      parent[static_cast<size_t>(rootOf(parent, a))] = rootOf(parent, b);
    }
  }
  return parent;
}

// Walls join the level they touch whose mean height is nearest the wall's top (95th percentile
// of its heights): a wall's ramp hangs from the eave of its roof, and the 1 px steep rim of a
// roof beside a higher one stays with its own roof.
void attachWalls(const cv::Mat& local, const cv::Mat& ndsm, const PieceRegions& measured, const std::vector<bool>& wall,
                 std::vector<int>& parent) {
  const int n = static_cast<int>(wall.size());
  std::vector<std::vector<float>> wallHeights(static_cast<size_t>(n));
  for (int y = 0; y < local.rows; ++y) {
    for (int x = 0; x < local.cols; ++x) {
      const int id = local.at<int>(y, x);
      const float h = ndsm.at<float>(y, x);
      if (id >= 0 && wall[static_cast<size_t>(id)] && std::isfinite(h)) wallHeights[static_cast<size_t>(id)].push_back(h);
    }
  }
  std::vector<double> levelSum(static_cast<size_t>(n), 0.0);
  std::vector<int> levelCount(static_cast<size_t>(n), 0);
  for (int r = 0; r < n; ++r) {
    if (wall[static_cast<size_t>(r)]) continue;
    levelSum[static_cast<size_t>(rootOf(parent, r))] += measured.stats[static_cast<size_t>(r)].heightSum;
    levelCount[static_cast<size_t>(rootOf(parent, r))] += measured.stats[static_cast<size_t>(r)].heights;
  }
  std::vector<int> nearest(static_cast<size_t>(n), -1);
  std::vector<double> nearestGap(static_cast<size_t>(n), 0.0);
  for (const auto& [key, border] : measured.borders) {
    for (const auto& [w, r] : {std::pair{static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu)},
                               std::pair{static_cast<int>(key & 0xffffffffu), static_cast<int>(key >> 32)}}) {
      const size_t wi = static_cast<size_t>(w);
      if (!wall[wi] || wall[static_cast<size_t>(r)] || wallHeights[wi].empty()) continue;
      const size_t level = static_cast<size_t>(rootOf(parent, r));
      if (levelCount[level] == 0) continue;
      std::vector<float>& h = wallHeights[wi];
      const size_t k = h.size() * 95 / 100;
      std::nth_element(h.begin(), h.begin() + static_cast<long>(k), h.end());
      const double gap = std::abs(levelSum[level] / levelCount[level] - h[k]);
      if (nearest[wi] < 0 || gap < nearestGap[wi]) nearest[wi] = static_cast<int>(level), nearestGap[wi] = gap;
    }
  }
  for (size_t w = 0; w < wall.size(); ++w) {
    if (nearest[w] >= 0) parent[w] = nearest[w];
  }
}

// Ramps: levels whose heights span more than 2 δ_0 from their 10th to their 90th percentile
// (a wall seen obliquely but less steep than the wall slope) are no roof of their own.
std::vector<bool> rampLevels(const cv::Mat& local, const cv::Mat& ndsm, const std::vector<int>& partOf,
                             double minStep) {
  const size_t n = partOf.size();
  std::vector<std::vector<float>> levelHeights(n);
  for (int y = 0; y < local.rows; ++y) {
    for (int x = 0; x < local.cols; ++x) {
      const int id = local.at<int>(y, x);
      const float h = ndsm.at<float>(y, x);
      if (id >= 0 && std::isfinite(h)) levelHeights[static_cast<size_t>(partOf[static_cast<size_t>(id)])].push_back(h);
    }
  }
  std::vector<bool> ramp(n, false);
  for (size_t l = 0; l < ramp.size(); ++l) {
    std::vector<float>& h = levelHeights[l];
    if (!h.empty()) ramp[l] = quantile(h, 0.9) - quantile(h, 0.1) > 2.0 * minStep;
  }
  return ramp;
}

// Parts numbered 1..count in scan order into `parts`.
void numberParts(const cv::Mat& local, const std::vector<int>& partOf, cv::Mat& parts, int& count) {
  std::vector<int> number(partOf.size(), 0);
  count = 0;
  for (int y = 0; y < local.rows; ++y) {
    for (int x = 0; x < local.cols; ++x) {
      const int id = local.at<int>(y, x);
      if (id < 0) continue;
      int& k = number[static_cast<size_t>(partOf[static_cast<size_t>(id)])];
      if (k == 0) k = ++count;
      parts.at<int>(y, x) = k;
    }
  }
}

}  // namespace

cv::Mat splitLevels(const cv::Mat& piece, const cv::Mat& regions, const cv::Mat& ndsm, double gsd,
                    const LevelSplit& rules, int& count) {
  cv::Mat parts = cv::Mat::zeros(piece.size(), CV_32S);
  count = cv::countNonZero(piece) > 0 ? 1 : 0;
  cv::Mat local;
  const int n = count > 0 && rules.minStep > 0 && !regions.empty() ? localRegions(piece, regions, local) : 0;
  if (n <= 1) {
    parts.setTo(1, piece);
    return parts;
  }
  const cv::Mat steep = steepPixels(ndsm, std::tan(rules.wallSlope * CV_PI / 180.0) * gsd);
  const int band = std::max(1, static_cast<int>(std::lround(rules.stepBand / gsd)));
  const PieceRegions measured = measureRegions(local, ndsm, steep, band, n);
  std::vector<bool> wall(static_cast<size_t>(n));
  for (size_t i = 0; i < wall.size(); ++i) wall[i] = 2 * measured.stats[i].steep > measured.stats[i].pixels;
  std::vector<int> parent = joinLevels(measured, wall, rules.minStep);
  attachWalls(local, ndsm, measured, wall, parent);
  std::vector<int> partOf(static_cast<size_t>(n));
  for (int r = 0; r < n; ++r) partOf[static_cast<size_t>(r)] = rootOf(parent, r);
  const std::vector<bool> ramp = rampLevels(local, ndsm, partOf, rules.minStep);
  mergeSmallLevels(partOf, measured.stats, measured.borders, rules.minPartArea / (gsd * gsd), ramp);
  numberParts(local, partOf, parts, count);
  return parts;
}

}  // namespace delineo::segmentation
