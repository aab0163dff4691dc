#include "delineo/segmentation/regions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace delineo::segmentation {

namespace {

std::uint64_t pairKey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

// Sorted, unique 4-adjacent pairs of different regions.
std::vector<std::uint64_t> adjacentPairs(const cv::Mat& labels) {
  std::vector<std::uint64_t> pairs;
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const int* below = y + 1 < labels.rows ? labels.ptr<int>(y + 1) : nullptr;
    for (int x = 0; x < labels.cols; ++x) {
      if (l[x] < 0) continue;
      if (x + 1 < labels.cols && l[x + 1] >= 0 && l[x + 1] != l[x]) pairs.push_back(pairKey(l[x], l[x + 1]));
      if (below && below[x] >= 0 && below[x] != l[x]) pairs.push_back(pairKey(l[x], below[x]));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

int findRoot(std::vector<int>& parent, int i) {
  while (parent[static_cast<size_t>(i)] != i) {
    parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
    i = parent[static_cast<size_t>(i)];
  }
  return i;
}

// The height of region `label` read up to `band` px inside it from `p`, walking by (dx, dy):
// the farthest pixel of the walk that is still in the region.
float heightInside(const cv::Mat& labels, const cv::Mat& dem, cv::Point p, int dx, int dy, int label, int band) {
  cv::Point last = p;
  for (int k = 1; k <= band; ++k) {
    const cv::Point q(p.x + k * dx, p.y + k * dy);
    if (q.x < 0 || q.y < 0 || q.x >= labels.cols || q.y >= labels.rows || labels.at<int>(q) != label) break;
    last = q;
  }
  return dem.at<float>(last);
}

struct LinkSum {
  double step = 0.0;  // sum of (height of the lower index) - (height of the higher index)
  int contacts = 0;
  int direct = 0;
};

// Adds one measured contact between regions la (at p, read by walking (dx, dy)) and lb (at q,
// read by walking the other way).
void addContact(std::unordered_map<std::uint64_t, LinkSum>& sums, const cv::Mat& labels, const cv::Mat& dem,
                cv::Point p, cv::Point q, int dx, int dy, int band, bool direct) {
  const int la = labels.at<int>(p), lb = labels.at<int>(q);
  const float ha = heightInside(labels, dem, p, -dx, -dy, la, band);
  const float hb = heightInside(labels, dem, q, dx, dy, lb, band);
  LinkSum& s = sums[pairKey(la, lb)];
  s.step += la < lb ? ha - hb : hb - ha;
  ++s.contacts;
  if (direct) ++s.direct;
}

}  // namespace

cv::Mat steepPixels(const cv::Mat& dem, double maxRise) {
  cv::Mat steep(dem.size(), CV_8U, cv::Scalar(0));
  auto height = [&](int x, int y) {
    return x < 0 || y < 0 || x >= dem.cols || y >= dem.rows ? std::numeric_limits<float>::quiet_NaN()
                                                             : dem.at<float>(y, x);
  };
  // Rise per pixel from the two neighbours along one axis (central, else one-sided, else 0).
  auto rise = [](float before, float here, float after) {
    if (std::isfinite(before) && std::isfinite(after)) return 0.5 * (after - before);
    if (std::isfinite(after)) return static_cast<double>(after - here);
    if (std::isfinite(before)) return static_cast<double>(here - before);
    return 0.0;
  };
  for (int y = 0; y < dem.rows; ++y) {
    for (int x = 0; x < dem.cols; ++x) {
      const float h = dem.at<float>(y, x);
      if (!std::isfinite(h)) continue;
      const double gx = rise(height(x - 1, y), h, height(x + 1, y));
      const double gy = rise(height(x, y - 1), h, height(x, y + 1));
      if (gx * gx + gy * gy > maxRise * maxRise) steep.at<unsigned char>(y, x) = 255;
    }
  }
  return steep;
}

cv::Mat growRegions(const cv::Mat& dem, double maxStep, const cv::Mat& steep, int& count) {
  cv::Mat labels(dem.size(), CV_32S, cv::Scalar(-1));
  const bool split = !steep.empty();
  count = 0;
  std::vector<cv::Point> stack;
  const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  for (int y = 0; y < dem.rows; ++y) {
    for (int x = 0; x < dem.cols; ++x) {
      if (labels.at<int>(y, x) >= 0 || !std::isfinite(dem.at<float>(y, x))) continue;
      const int label = count++;
      labels.at<int>(y, x) = label;
      stack.assign(1, cv::Point(x, y));
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        const float h = dem.at<float>(p);
        for (const cv::Point& d : steps) {
          const cv::Point q = p + d;
          if (q.x < 0 || q.y < 0 || q.x >= dem.cols || q.y >= dem.rows || labels.at<int>(q) >= 0) continue;
          const float hq = dem.at<float>(q);
          if (!std::isfinite(hq) || std::abs(hq - h) > maxStep) continue;
          if (split && steep.at<unsigned char>(q) != steep.at<unsigned char>(p)) continue;
          labels.at<int>(q) = label;
          stack.push_back(q);
        }
      }
    }
  }
  return labels;
}

int mergeSmallRegions(cv::Mat& labels, const cv::Mat& dem, int count, int minPixels) {
  const size_t n = static_cast<size_t>(count);
  std::vector<double> sum(n, 0.0);
  std::vector<int> size(n, 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const float* h = dem.ptr<float>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (l[x] < 0) continue;
      sum[static_cast<size_t>(l[x])] += h[x];
      ++size[static_cast<size_t>(l[x])];
    }
  }
  std::vector<std::vector<int>> neighbours(n);
  for (const std::uint64_t key : adjacentPairs(labels)) {
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    neighbours[static_cast<size_t>(a)].push_back(b);
    neighbours[static_cast<size_t>(b)].push_back(a);
  }
  std::vector<int> parent(n), order(n);
  std::iota(parent.begin(), parent.end(), 0);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return size[static_cast<size_t>(a)] < size[static_cast<size_t>(b)]; });
  for (const int r : order) {
    const size_t ri = static_cast<size_t>(r);
    if (parent[ri] != r || size[ri] >= minPixels) continue;  // already merged, or grown enough
    const double mean = sum[ri] / size[ri];
    int best = -1;
    double bestDiff = 0.0;
    for (const int nb : neighbours[ri]) {
      const int root = findRoot(parent, nb);
      if (root == r) continue;
      const size_t rooti = static_cast<size_t>(root);
      const double diff = std::abs(sum[rooti] / size[rooti] - mean);
      if (best < 0 || diff < bestDiff) best = root, bestDiff = diff;
    }
    if (best < 0) continue;
    const size_t bi = static_cast<size_t>(best);
    parent[ri] = best;
    sum[bi] += sum[ri];
    size[bi] += size[ri];
    neighbours[bi].insert(neighbours[bi].end(), neighbours[ri].begin(), neighbours[ri].end());
    neighbours[ri].clear();
  }
  std::vector<int> compact(n, -1);
  int next = 0;
  for (int r = 0; r < count; ++r) {
    if (findRoot(parent, r) == r) compact[static_cast<size_t>(r)] = next++;
  }
  for (int y = 0; y < labels.rows; ++y) {
    int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (l[x] >= 0) l[x] = compact[static_cast<size_t>(findRoot(parent, l[x]))];
    }
  }
  return next;
}

RegionGraph buildRegionGraph(const cv::Mat& labels, const cv::Mat& dem, int count, int bandPx, int maxGapRunPx) {
  RegionGraph graph;
  graph.labels = labels;
  graph.regions.assign(static_cast<size_t>(count), Region{});
  std::vector<double> sums(static_cast<size_t>(count), 0.0);
  std::unordered_map<std::uint64_t, LinkSum> links;
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const float* h = dem.ptr<float>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (l[x] < 0) continue;
      Region& r = graph.regions[static_cast<size_t>(l[x])];
      if (r.pixels == 0) r.minHeight = r.maxHeight = h[x];
      ++r.pixels;
      sums[static_cast<size_t>(l[x])] += h[x];
      r.minHeight = std::min(r.minHeight, h[x]);
      r.maxHeight = std::max(r.maxHeight, h[x]);
      if (x + 1 < labels.cols && l[x + 1] >= 0 && l[x + 1] != l[x]) {
        addContact(links, labels, dem, {x, y}, {x + 1, y}, 1, 0, bandPx, true);
      }
      if (y + 1 < labels.rows) {
        const int below = labels.at<int>(y + 1, x);
        if (below >= 0 && below != l[x]) addContact(links, labels, dem, {x, y}, {x, y + 1}, 0, 1, bandPx, true);
      }
    }
    // Runs of no data along the row, linked from the pixel before to the pixel after.
    for (int x = 0; x < labels.cols && maxGapRunPx > 0;) {
      if (l[x] >= 0) {
        ++x;
        continue;
      }
      int end = x;
      while (end < labels.cols && l[end] < 0) ++end;
      if (x > 0 && end < labels.cols && end - x <= maxGapRunPx && l[x - 1] != l[end]) {
        // The walk from each end goes away from the run: the helper walks (dx) from the far end.
        const int la = l[x - 1], lb = l[end];
        const float ha = heightInside(labels, dem, {x - 1, y}, -1, 0, la, bandPx);
        const float hb = heightInside(labels, dem, {end, y}, 1, 0, lb, bandPx);
        LinkSum& s = links[pairKey(la, lb)];
        s.step += la < lb ? ha - hb : hb - ha;
        ++s.contacts;
      }
      x = end;
    }
  }
  for (size_t i = 0; i < graph.regions.size(); ++i) {
    if (graph.regions[i].pixels > 0) graph.regions[i].meanHeight = sums[i] / graph.regions[i].pixels;
  }
  graph.links.reserve(links.size());
  for (const auto& [key, s] : links) {
    RegionLink link;
    link.a = static_cast<int>(key >> 32);
    link.b = static_cast<int>(key & 0xffffffffu);
    link.step = s.step / s.contacts;
    link.contacts = s.contacts;
    link.acrossGap = s.direct == 0;
    graph.gapLinks += link.acrossGap ? 1 : 0;
    graph.links.push_back(link);
  }
  // Deterministic order, whatever the hash map's.
  std::sort(graph.links.begin(), graph.links.end(),
            [](const RegionLink& u, const RegionLink& v) { return u.a != v.a ? u.a < v.a : u.b < v.b; });
  return graph;
}

}  // namespace delineo::segmentation
