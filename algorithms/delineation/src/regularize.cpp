#include "delineo/delineation/regularize.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>
#include <type_traits>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"

namespace delineo::delineation {

namespace {

using core::Error;
using core::ErrorCode;

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
// Lines closer than this in direction are one direction (merged or joined by a connector): the
// intersection of two lines a few degrees apart lies far away. Also the snapping range of
// any-angle mode.
constexpr double kParallelAngle = 8.0 * kPi / 180.0;
// Consecutive pieces along one direction whose offsets differ by less than this are one line;
// farther apart they are joined by a perpendicular connector (a jog the short-edge step may merge).
constexpr double kJogMerge = 1.0;

cv::Point2d direction(double angle) {
  return {std::cos(angle), std::sin(angle)};
}
cv::Point2d normal(double angle) {
  return {-std::sin(angle), std::cos(angle)};
}
double cross(cv::Point2d a, cv::Point2d b) {
  return a.x * b.y - a.y * b.x;
}

// Squared distance from p to the segment ab; segmentDistance is its root.
double segmentDistance2(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d ab = b - a;
  const double len2 = ab.dot(ab);
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  const cv::Point2d d = p - (a + t * ab);
  return d.dot(d);
}

double segmentDistance(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  return std::sqrt(segmentDistance2(p, a, b));
}

double ringDistance(cv::Point2d p, const core::Ring& ring) {
  double best = kInf;
  for (size_t i = 0; i < ring.size(); ++i)
    best = std::min(best, segmentDistance(p, ring[i], ring[(i + 1) % ring.size()]));
  return best;
}

// Farthest point of `result` (its vertices and samples every `step` px along its edges) from the
// outline `input`. Exact up to `stopAbove`; above it, any value above `stopAbove`.
// Edges in `skip` (end points as {ax, ay, bx, by}) are left out.
using EdgeKey = std::array<double, 4>;
EdgeKey edgeKey(cv::Point2d a, cv::Point2d b) {
  return {a.x, a.y, b.x, b.y};
}
// A set of edges (exact end points): open addressing on the bits of the coordinates, so that
// the many lookups while removing short edges cost no comparison chains and no allocation.
class EdgeSet {
 public:
  // Empties the set, with room for n keys without growing.
  void reset(size_t n) {
    size_t capacity = 16;
    while (capacity < 2 * n + 2) capacity *= 2;
    if (slots_.size() < capacity) slots_.resize(capacity);
    used_.assign(std::max(capacity, slots_.size()), 0);
    size_ = 0;
  }
  void insert(const EdgeKey& k) {
    if (2 * (size_ + 1) > slots_.size()) grow();
    size_t i = hash(k) & (slots_.size() - 1);
    while (used_[i]) {
      if (slots_[i] == k) return;
      i = (i + 1) & (slots_.size() - 1);
    }
    slots_[i] = k, used_[i] = 1, ++size_;
  }
  bool count(const EdgeKey& k) const {
    if (slots_.empty()) return false;
    for (size_t i = hash(k) & (slots_.size() - 1); used_[i]; i = (i + 1) & (slots_.size() - 1)) {
      if (slots_[i] == k) return true;
    }
    return false;
  }

 private:
  static size_t hash(const EdgeKey& k) {
    uint64_t h = 1469598103934665603ull;
    for (double v : k) {
      const double z = v + 0.0;  // -0.0 and 0.0 are equal: one hash
      uint64_t bits = 0;
      std::memcpy(&bits, &z, sizeof bits);
      h = (h ^ bits) * 1099511628211ull;
      h ^= h >> 29;
    }
    return static_cast<size_t>(h);
  }
  void grow() {
    std::vector<EdgeKey> old;
    std::vector<char> oldUsed;
    old.swap(slots_), oldUsed.swap(used_);
    slots_.assign(std::max<size_t>(16, 2 * old.size()), EdgeKey{});
    used_.assign(slots_.size(), 0);
    size_ = 0;
    for (size_t i = 0; i < old.size(); ++i) {
      if (oldUsed[i]) insert(old[i]);
    }
  }
  std::vector<EdgeKey> slots_;
  std::vector<char> used_;
  size_t size_ = 0;
};

// The edges of a ring bucketed on a square grid: distances to the ring near a point without
// visiting every edge (an outline cleaned on the pixel grid has hundreds).
class EdgeGrid {
 public:
  explicit EdgeGrid(const core::Ring& ring, double cell = 8.0) : ring_(ring), cell_(cell) {
    const cv::Rect2d box = core::boundingBox(ring);
    origin_ = {box.x, box.y};
    cols_ = static_cast<int>(box.width / cell) + 1;
    rows_ = static_cast<int>(box.height / cell) + 1;
    cells_.resize(static_cast<size_t>(cols_ * rows_));
    for (size_t k = 0; k < ring.size(); ++k) {
      const cv::Point2d p = ring[k], q = ring[(k + 1) % ring.size()];
      const int x0 = col(std::min(p.x, q.x)), x1 = col(std::max(p.x, q.x));
      const int y0 = row(std::min(p.y, q.y)), y1 = row(std::max(p.y, q.y));
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x)
          cells_[static_cast<size_t>(y * cols_ + x)].push_back(static_cast<int>(k));
      }
    }
  }
  // Distance from p to the ring when it is at most `limit`, else some value above `limit` (the
  // least distance to the edges in the cells within `limit`). The cells within half a cell are
  // searched first: an edge in no searched cell lies farther than the searched reach, so a
  // distance within that reach is already the least.
  double distance(cv::Point2d p, double limit) const {
    const double near = std::min(limit, 0.5 * cell_);
    const double d = distanceWithin(p, near);
    return d <= near ? d : distanceWithin(p, limit);
  }
  const core::Ring& ring() const { return ring_; }

 private:
  // The least distance from p to the edges in the cells within `reach` of p.
  double distanceWithin(cv::Point2d p, double reach) const {
    double best = kInf;  // squared until the end (the root of the least is the least root)
    const int x0 = col(p.x - reach), x1 = col(p.x + reach), y0 = row(p.y - reach),
              y1 = row(p.y + reach);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        for (int k : cells_[static_cast<size_t>(y * cols_ + x)]) {
          best =
              std::min(best, segmentDistance2(p, ring_[static_cast<size_t>(k)],
                                              ring_[(static_cast<size_t>(k) + 1) % ring_.size()]));
        }
      }
    }
    return std::sqrt(best);
  }
  int col(double x) const {
    return std::clamp(static_cast<int>(std::floor((x - origin_.x) / cell_)), 0, cols_ - 1);
  }
  int row(double y) const {
    return std::clamp(static_cast<int>(std::floor((y - origin_.y) / cell_)), 0, rows_ - 1);
  }
  const core::Ring& ring_;
  double cell_;
  cv::Point2d origin_;
  int cols_ = 1, rows_ = 1;
  std::vector<std::vector<int>> cells_;
};

// Calls f(point) for the vertices of `ring` and its points every `step` px along each edge
// (edges in `skip` left out), in ring order, until f returns false.
template <class F>
void forEachSample(const core::Ring& ring, const EdgeSet* skip, double step, F&& f) {
  for (size_t i = 0; i < ring.size(); ++i) {
    const cv::Point2d a = ring[i], b = ring[(i + 1) % ring.size()];
    if (skip && skip->count(edgeKey(a, b))) continue;
    const int steps = std::max(1, static_cast<int>(std::ceil(cv::norm(b - a) / step)));
    for (int s = 0; s < steps; ++s) {
      if (!f(a + (b - a) * (static_cast<double>(s) / steps))) return;
    }
  }
}

// Farthest sample of `result` (see forEachSample) from the outline `input`: exact up to
// `stopAbove`; above it, the first sample's distance above `stopAbove`. The distance to the
// input changes by at most as much as the sample moves, so a sample closer to the last measured
// one than that one's margin below the maximum so far cannot raise the maximum and is not
// measured; a first pass over every 8th sample finds a high maximum early. When that pass meets
// a distance above `stopAbove`, every sample is measured in order (which one is first matters).
double maxDeviation(const core::Ring& result, const EdgeGrid& input, double stopAbove,
                    const EdgeSet* skip = nullptr, double step = 1.0) {
  const double limit = stopAbove + 1.0;
  double worst = 0;
  size_t k = 0;
  bool above = false;
  forEachSample(result, skip, step, [&](cv::Point2d p) {
    if (k++ % 8 == 0) worst = std::max(worst, input.distance(p, limit));
    above = worst > stopAbove;
    return !above;
  });
  if (above) {
    worst = 0;
    forEachSample(result, skip, step, [&](cv::Point2d p) {
      worst = std::max(worst, input.distance(p, limit));
      return worst <= stopAbove;
    });
    return worst;
  }
  cv::Point2d last(kInf, kInf);
  double lastDistance = kInf;
  forEachSample(result, skip, step, [&](cv::Point2d p) {
    if (lastDistance + cv::norm(p - last) <= worst - 1e-9) return true;  // (rounding)
    last = p;
    lastDistance = input.distance(p, limit);
    worst = std::max(worst, lastDistance);
    return worst <= stopAbove;
  });
  return worst;
}

// Mean distance between two outlines, both ways (input vertices to the result, result samples to
// the input, capped at `limit`): the tie-break between candidates with as many vertices.
double meanDistance(const core::Ring& result, const EdgeGrid& input, double limit) {
  double sum = 0;
  int n = 0;
  for (const auto& p : input.ring()) sum += ringDistance(p, result), ++n;
  for (size_t i = 0; i < result.size(); ++i) {
    const cv::Point2d a = result[i], b = result[(i + 1) % result.size()];
    const int steps = std::max(1, static_cast<int>(std::ceil(cv::norm(b - a) / 2.0)));
    for (int s = 0; s < steps; ++s) {
      sum += std::min(limit, input.distance(a + (b - a) * (static_cast<double>(s) / steps), limit));
      ++n;
    }
  }
  return n ? sum / n : 0.0;
}

// ---- Dominant orientation -------------------------------------------------------------------

struct Vote {
  double angle;  // radians, modulo π/2
  double weight;
};

double mod90(double angle) {
  const double q = kPi / 2;
  double a = std::fmod(angle, q);
  if (a < 0) a += q;
  return a;
}

std::vector<size_t> breakpoints(const core::Ring& ring, double epsilon);

// The chords of the outline simplified at `epsilon` px (Douglas-Peucker), weighted by length: a
// ragged outline's single edges zigzag around the true direction, its chords do not.
void outlineVotes(const core::Ring& ring, double epsilon, std::vector<Vote>& votes, double& total) {
  if (ring.size() < 3) return;
  const std::vector<size_t> breaks = breakpoints(ring, epsilon);
  for (size_t b = 0; b < breaks.size(); ++b) {
    const cv::Point2d e = ring[breaks[(b + 1) % breaks.size()]] - ring[breaks[b]];
    const double len = std::hypot(e.x, e.y);
    if (len < 1e-9) continue;
    votes.push_back({mod90(std::atan2(e.y, e.x)), len});
    total += len;
  }
}

// The 5x5 Sobel gradients at `count` (at most 5) pixels (xs[s], ys[s]) of a single-channel
// image of pixel type T (NaN read as 0). Each pixel's sums run in the same order; the pixels
// side by side let their sums proceed together.
template <class T>
void sobel5(const cv::Mat& image, const int* xs, const int* ys, int count, double* gx, double* gy) {
  static const double w[5] = {1, 4, 6, 4, 1}, d[5] = {-1, -2, 0, 2, 1};
  double v[5][5][5];  // [j][i][sample]
  for (int s = 0; s < count; ++s) {
    gx[s] = 0, gy[s] = 0;
    for (int j = 0; j < 5; ++j) {
      const T* row = image.ptr<T>(ys[s] + j - 2) + (xs[s] - 2);
      for (int i = 0; i < 5; ++i) {
        double value = row[i];
        if constexpr (std::is_floating_point_v<T>) value = std::isfinite(value) ? value : 0.0;
        v[j][i][s] = value;
      }
    }
  }
  for (int j = 0; j < 5; ++j) {
    for (int i = 0; i < 5; ++i) {
      for (int s = 0; s < count; ++s) {
        gx[s] += w[j] * d[i] * v[j][i][s];
        gy[s] += d[j] * w[i] * v[j][i][s];
      }
    }
  }
}

// Gradient directions (modulo 90°, the same as the edge directions) of the image within 2 px of
// the outline (every 2 px along it, five offsets across it) that run along the outline, weighted
// by the gradient magnitude above the median of the samples (flat texture's noise votes nothing).
// The gradient is the 5x5 Sobel (the 3x3 one leans about 1° towards the pixel axes on sharp edges),
// computed at the sampled pixels only (a large building's box is mostly roof).
void imageVotes(const core::Polygon& outline, const cv::Mat& image, std::vector<Vote>& votes,
                double& total) {
  std::vector<float> magnitudes;
  std::vector<Vote> local;
  void (*gradient)(const cv::Mat&, const int*, const int*, int, double*, double*) = nullptr;
  switch (image.depth()) {
    case CV_8U: gradient = sobel5<uchar>; break;
    case CV_16U: gradient = sobel5<ushort>; break;
    case CV_16S: gradient = sobel5<short>; break;
    case CV_32F: gradient = sobel5<float>; break;
    case CV_64F: gradient = sobel5<double>; break;
    default: return;  // refused by regularizeOutline
  }
  auto sample = [&](double gx, double gy, double along) {
    const double m = std::hypot(gx, gy);
    magnitudes.push_back(static_cast<float>(m));
    // Only edges running along the outline (gradient across it, within 20°) vote: texture on
    // the roof or the ground beside it points anywhere.
    const double edge = std::atan2(gy, gx) + kPi / 2;
    if (std::abs(std::sin(edge - along)) > std::sin(kPi / 9)) return;
    local.push_back({mod90(edge), m});
  };
  auto walk = [&](const core::Ring& ring) {
    for (size_t i = 0; i < ring.size(); ++i) {
      const cv::Point2d a = ring[i], b = ring[(i + 1) % ring.size()];
      const double len = cv::norm(b - a);
      if (len < 1e-9) continue;
      const cv::Point2d n(-(b - a).y / len, (b - a).x / len);
      const double along = std::atan2(b.y - a.y, b.x - a.x);
      const int steps = static_cast<int>(std::ceil(len / 2));
      for (int s = 0; s < steps; ++s) {
        const cv::Point2d p = a + (b - a) * (static_cast<double>(s) / steps);
        int xs[5], ys[5], count = 0;
        for (int o = -2; o <= 2; ++o) {
          const cv::Point2d q = p + n * static_cast<double>(o);
          const int x = static_cast<int>(std::floor(q.x)), y = static_cast<int>(std::floor(q.y));
          if (x < 2 || y < 2 || x >= image.cols - 2 || y >= image.rows - 2) continue;
          xs[count] = x, ys[count] = y, ++count;
        }
        double gx[5], gy[5];
        gradient(image, xs, ys, count, gx, gy);
        for (int k = 0; k < count; ++k) sample(gx[k], gy[k], along);
      }
    }
  };
  walk(outline.outer);
  for (const auto& h : outline.holes) walk(h);
  if (magnitudes.empty()) return;
  std::nth_element(magnitudes.begin(),
                   magnitudes.begin() + static_cast<long>(magnitudes.size() / 2), magnitudes.end());
  const double floor = magnitudes[magnitudes.size() / 2];
  for (auto& v : local) {
    v.weight = std::max(0.0, v.weight - floor);
    if (v.weight > 0) {
      votes.push_back(v);
      total += v.weight;
    }
  }
}

// Peak of the votes: histogram of 1° bins smoothed over ±6°, then refined (below). Zigzags of a
// pixel-grid outline vote ±7° around the true direction; the smoothing merges the two lobes, the
// mean centres them.
double votePeak(const std::vector<Vote>& votes) {
  constexpr int kBins = 90;
  std::vector<double> hist(kBins, 0.0), smooth(kBins, 0.0);
  for (const auto& v : votes)
    hist[std::min(kBins - 1, static_cast<int>(v.angle * 180.0 / kPi))] += v.weight;
  for (int b = 0; b < kBins; ++b) {
    for (int k = -6; k <= 6; ++k)
      smooth[b] += hist[(b + k + kBins) % kBins] * std::exp(-0.5 * k * k / 9.0);
  }
  const int peak =
      static_cast<int>(std::max_element(smooth.begin(), smooth.end()) - smooth.begin());
  double centre = (peak + 0.5) * kPi / 180.0;
  auto offset = [&](const Vote& v) {
    double d = v.angle - centre;
    return d - std::round(d / (kPi / 2)) * (kPi / 2);
  };
  // The circular mean within 10°, then 5° of the peak, each window centred on the previous mean;
  // last the weighted median within 5°: a few chords a couple of degrees off (a jog the
  // simplification straddles) do not pull the direction of the rest.
  for (const double window : {10.0, 5.0}) {
    double s = 0, c = 0;
    for (const auto& v : votes) {
      if (std::abs(offset(v)) > window * kPi / 180.0) continue;
      s += v.weight * std::sin(4 * v.angle);
      c += v.weight * std::cos(4 * v.angle);
    }
    if (s == 0 && c == 0) break;
    centre = mod90(0.25 * std::atan2(s, c));
  }
  std::vector<std::pair<double, double>> near;  // (offset, weight)
  double total = 0;
  for (const auto& v : votes) {
    const double d = offset(v);
    if (std::abs(d) > 5.0 * kPi / 180.0) continue;
    near.emplace_back(d, v.weight);
    total += v.weight;
  }
  std::sort(near.begin(), near.end());
  double acc = 0;
  for (const auto& [d, w] : near) {
    acc += w;
    if (acc >= 0.5 * total) {
      centre += d;
      break;
    }
  }
  return mod90(centre);
}

// ---- Lines along the outline ----------------------------------------------------------------

struct Line {
  double angle = 0;      // direction of travel along the ring, radians (set with setAngle)
  cv::Point2d dir{1, 0}, nrm{0, 1};  // direction(angle) and normal(angle), computed once
  double offset = 0;     // normal(angle) · p for the points p of the line
  double weight = 0;     // px of input outline behind it
  cv::Point2d centroid;  // length-weighted centre of that outline (offset = normal · centroid)
  cv::Point2d start;     // input point where its piece of outline starts (connectors go there)
  bool fixed = false;    // along the image border: keeps its direction and offset
  void setAngle(double a) {
    angle = a;
    dir = direction(a);
    nrm = normal(a);
  }
};

bool parallel(const Line& a, const Line& b) {
  return std::abs(std::sin(a.angle - b.angle)) < std::sin(kParallelAngle);
}
bool sameDirection(const Line& a, const Line& b) {
  return std::cos(a.angle - b.angle) > 0;
}

Line merged(const Line& a, const Line& b) {
  if (b.fixed && !a.fixed) return merged(b, a);
  Line m = a;
  m.weight = a.weight + b.weight;
  if (a.fixed) return m;
  const double w = m.weight > 0 ? m.weight : 1.0, wa = m.weight > 0 ? a.weight : 0.5,
               wb = m.weight > 0 ? b.weight : 0.5;
  m.centroid = (a.centroid * wa + b.centroid * wb) / w;
  const cv::Point2d d =
      a.dir * wa + b.dir * wb;  // same angle when snapped
  m.setAngle(std::atan2(d.y, d.x));
  m.offset = m.nrm.dot(m.centroid);
  return m;
}

cv::Point2d intersection(const Line& a, const Line& b) {
  const cv::Point2d na = a.nrm, nb = b.nrm;
  const double det = cross(na, nb);
  return {(a.offset * nb.y - b.offset * na.y) / det, (na.x * b.offset - nb.x * a.offset) / det};
}

core::Ring vertices(const std::vector<Line>& lines) {
  core::Ring ring;
  const size_t n = lines.size();
  for (size_t k = 0; k < n; ++k) ring.push_back(intersection(lines[(k + n - 1) % n], lines[k]));
  return ring;
}

// Length of each line's edge, signed along its direction (negative: the edge runs backwards, a
// fold).
std::vector<double> edgeLengths(const std::vector<Line>& lines, const core::Ring& ring) {
  std::vector<double> out(lines.size());
  for (size_t k = 0; k < lines.size(); ++k)
    out[k] = lines[k].dir.dot(ring[(k + 1) % ring.size()] - ring[k]);
  return out;
}

// Makes consecutive lines non-parallel: same direction → merged (or, with `connectors` and
// offsets more than kJogMerge apart, joined by a perpendicular line through the junction);
// opposite directions (a zero-width spike or slit) → both removed. False when fewer than
// `minLines` remain.
bool tidy(std::vector<Line>& lines, bool connectors, size_t minLines) {
  // Each pass handles the first parallel pair from the start of the ring. A change at (i, i+1)
  // leaves the pairs before i-1 as they were (non-parallel), so the next pass resumes at i-1;
  // a change across the ring's end (j = 0) moves every index and starts over.
  size_t resume = 0;
  for (size_t guard = 0; guard < 4 * lines.size() + 8 && lines.size() >= minLines; ++guard) {
    bool changed = false;
    for (size_t i = std::min(resume, lines.size()); i < lines.size() && lines.size() >= minLines; ++i) {
      const size_t j = (i + 1) % lines.size();
      resume = j == 0 ? 0 : (i > 0 ? i - 1 : 0);
      if (!parallel(lines[i], lines[j])) continue;
      if (!sameDirection(lines[i], lines[j])) {
        const size_t first = std::max(i, j), second = std::min(i, j);
        lines.erase(lines.begin() + static_cast<long>(first));
        lines.erase(lines.begin() + static_cast<long>(second));
      } else {
        const double gap = lines[i].nrm.dot(lines[j].centroid) - lines[i].offset;
        if (connectors && std::abs(gap) > kJogMerge) {
          Line c;
          c.setAngle(lines[i].angle + (gap > 0 ? kPi / 2 : -kPi / 2));
          c.start = c.centroid = lines[j].start;
          c.offset = c.nrm.dot(c.centroid);
          lines.insert(lines.begin() + static_cast<long>(i) + 1, c);
        } else {
          lines[i] = merged(lines[i], lines[j]);
          lines.erase(lines.begin() + static_cast<long>(j));
        }
      }
      changed = true;
      break;
    }
    if (!changed) return lines.size() >= minLines;
  }
  return lines.size() >= minLines;
}

// Douglas-Peucker on a closed ring: indices of the kept vertices, in ring order.
void simplifyRange(const core::Ring& ring, size_t i0, size_t i1, double epsilon,
                   std::vector<char>& keep) {
  const size_t n = ring.size();
  const size_t span = (i1 + n - i0) % n;
  if (span < 2) return;
  double worst = -1;
  size_t at = i0;
  for (size_t s = 1; s < span; ++s) {
    const size_t k = (i0 + s) % n;
    const double d = segmentDistance(ring[k], ring[i0], ring[i1]);
    if (d > worst) worst = d, at = k;
  }
  if (worst <= epsilon) return;
  keep[at] = 1;
  simplifyRange(ring, i0, at, epsilon, keep);
  simplifyRange(ring, at, i1, epsilon, keep);
}

std::vector<size_t> breakpoints(const core::Ring& ring, double epsilon) {
  const size_t n = ring.size();
  // Start from the vertex farthest from the first one, and the one farthest from that.
  size_t a = 0;
  double far = -1;
  for (size_t k = 0; k < n; ++k) {
    const double d = cv::norm(ring[k] - ring[0]);
    if (d > far) far = d, a = k;
  }
  size_t b = a;
  far = -1;
  for (size_t k = 0; k < n; ++k) {
    const double d = cv::norm(ring[k] - ring[a]);
    if (d > far) far = d, b = k;
  }
  std::vector<char> keep(n, 0);
  keep[a] = keep[b] = 1;
  simplifyRange(ring, a, b, epsilon, keep);
  simplifyRange(ring, b, a, epsilon, keep);
  std::vector<size_t> out;
  for (size_t k = 0; k < n; ++k) {
    if (keep[k]) out.push_back(k);
  }
  return out;
}

// Per edge k of a ring (from vertex k to k+1): its norm, and the length-weighted doubled-angle
// terms of its axis; computed once per ring for all the pieces and candidates that sum them.
struct RingEdgeTerms {
  std::vector<double> norm, len, s2, c2;
  explicit RingEdgeTerms(const core::Ring& ring) {
    const size_t n = ring.size();
    norm.resize(n), len.resize(n), s2.resize(n), c2.resize(n);
    for (size_t k = 0; k < n; ++k) {
      const cv::Point2d e = ring[(k + 1) % n] - ring[k];
      norm[k] = cv::norm(e);
      len[k] = std::hypot(e.x, e.y);
      const double a = std::atan2(e.y, e.x);
      s2[k] = len[k] * std::sin(2 * a);
      c2[k] = len[k] * std::cos(2 * a);
    }
  }
};

struct RingContext {
  RegularizationMode mode;
  double theta;     // dominant orientation, radians in [0, π/2)
  cv::Size bounds;  // image size, or empty
  const RingEdgeTerms* edges = nullptr;  // of the ring being regularized
};

// The allowed direction nearest to `angle`; any-angle mode snaps only within kParallelAngle.
double snapped(double angle, const RingContext& ctx) {
  const double step = ctx.mode == RegularizationMode::RightAnglesAndDiagonals ? kPi / 4 : kPi / 2;
  const double k = std::round((angle - ctx.theta) / step);
  const double s = ctx.theta + k * step;
  if (ctx.mode == RegularizationMode::AnyAngle && std::abs(angle - s) > kParallelAngle)
    return angle;
  return s;
}

// The image border line that the piece ring[i0..i1] lies on (within 0.5 px), if any.
bool borderLine(const core::Ring& ring, size_t i0, size_t i1, const RingContext& ctx, Line& line) {
  if (ctx.bounds.empty()) return false;
  const size_t n = ring.size();
  const double w = ctx.bounds.width, h = ctx.bounds.height;
  for (int side = 0; side < 4; ++side) {
    bool all = true;
    for (size_t k = i0;; k = (k + 1) % n) {
      const cv::Point2d p = ring[k];
      const double d = side == 0   ? std::abs(p.x)
                       : side == 1 ? std::abs(p.x - w)
                       : side == 2 ? std::abs(p.y)
                                   : std::abs(p.y - h);
      if (d > 0.5) {
        all = false;
        break;
      }
      if (k == i1) break;
    }
    if (!all) continue;
    const cv::Point2d chord = ring[i1] - ring[i0];
    const bool vertical = side < 2;
    line.setAngle(vertical ? (chord.y >= 0 ? kPi / 2 : -kPi / 2) : (chord.x >= 0 ? 0.0 : kPi));
    line.centroid = side == 0   ? cv::Point2d(0, 0)
                    : side == 1 ? cv::Point2d(w, 0)
                    : side == 2 ? cv::Point2d(0, 0)
                                : cv::Point2d(0, h);
    line.offset = line.nrm.dot(line.centroid);
    line.fixed = true;
    return true;
  }
  return false;
}

// The line of the piece ring[i0..i1]: the image border when the piece runs along it; else the
// length-weighted axis of its edges, oriented along its chord and snapped, at the length-weighted
// mean offset of the edges that run within 30° of that direction (corner chamfers and zigzags
// across the edge do not pull it).
Line lineOfPiece(const core::Ring& ring, size_t i0, size_t i1, const RingContext& ctx) {
  const size_t n = ring.size();
  const RingEdgeTerms& edges = *ctx.edges;
  Line line;
  line.start = ring[i0];
  for (size_t k = i0; k != i1; k = (k + 1) % n) line.weight += edges.norm[k];
  if (borderLine(ring, i0, i1, ctx, line)) return line;
  double s2 = 0, c2 = 0;
  for (size_t k = i0; k != i1; k = (k + 1) % n) {
    s2 += edges.s2[k];
    c2 += edges.c2[k];
  }
  double angle = 0.5 * std::atan2(s2, c2);
  if (direction(angle).dot(ring[i1] - ring[i0]) < 0) angle += kPi;
  line.setAngle(snapped(angle, ctx));
  cv::Point2d sum(0, 0);
  double weight = 0;
  for (int pass = 0; pass < 2 && weight == 0; ++pass) {
    for (size_t k = i0; k != i1; k = (k + 1) % n) {
      const cv::Point2d e = ring[(k + 1) % n] - ring[k];
      const double len = edges.len[k];
      if (len < 1e-9) continue;
      if (pass == 0 && line.dir.dot(e) < std::cos(kPi / 6) * len) continue;
      sum += len * 0.5 * (ring[k] + ring[(k + 1) % n]);
      weight += len;
    }
  }
  line.centroid = weight > 0 ? sum / weight : 0.5 * (ring[i0] + ring[i1]);
  line.offset = line.nrm.dot(line.centroid);
  return line;
}

// Lines of the pieces between breakpoints; a piece whose vertices stray farther than `limit`
// from its (snapped) line is split at its vertex farthest from its chord, until each fits or is
// a single edge. A slanted piece in right-angles mode becomes a staircase that the short-edge
// step may then merge.
void addPieceLines(const core::Ring& ring, size_t i0, size_t i1, const RingContext& ctx,
                   double limit, int depth, std::vector<Line>& lines) {
  const size_t n = ring.size();
  const Line line = lineOfPiece(ring, i0, i1, ctx);
  const size_t span = (i1 + n - i0) % n;
  if (span >= 2 && !line.fixed && depth < 12) {
    const cv::Point2d nrm = line.nrm;
    double far = 0;
    for (size_t k = i0;; k = (k + 1) % n) {
      far = std::max(far, std::abs(nrm.dot(ring[k]) - line.offset));
      if (k == i1) break;
    }
    if (far > limit) {
      size_t at = (i0 + 1) % n;
      double worst = -1;
      for (size_t k = (i0 + 1) % n; k != i1; k = (k + 1) % n) {
        const double d = segmentDistance(ring[k], ring[i0], ring[i1]);
        if (d > worst) worst = d, at = k;
      }
      addPieceLines(ring, i0, at, ctx, limit, depth + 1, lines);
      addPieceLines(ring, at, i1, ctx, limit, depth + 1, lines);
      return;
    }
  }
  lines.push_back(line);
}

std::vector<Line> piecesToLines(const core::Ring& ring, const std::vector<size_t>& breaks,
                                const RingContext& ctx, double limit) {
  std::vector<Line> lines;
  for (size_t b = 0; b < breaks.size(); ++b) {
    addPieceLines(ring, breaks[b], breaks[(b + 1) % breaks.size()], ctx, limit, 0, lines);
  }
  return lines;
}

bool insideBounds(const core::Ring& ring, cv::Size bounds) {
  if (bounds.empty()) return true;
  return std::all_of(ring.begin(), ring.end(), [&](const cv::Point2d& p) {
    return p.x >= -1e-6 && p.y >= -1e-6 && p.x <= bounds.width + 1e-6 &&
           p.y <= bounds.height + 1e-6;
  });
}

// isSimple() for a ring whose edges in `unchanged` are known not to cross each other: only the
// other edges are tested (against all).
bool simpleAround(const core::Ring& ring, const EdgeSet& unchanged) {
  const size_t n = ring.size();
  if (n < 3) return false;
  for (size_t i = 0; i < n; ++i) {
    const cv::Point2d a = ring[i], b = ring[(i + 1) % n];
    if (unchanged.count(edgeKey(a, b))) continue;
    for (size_t j = 0; j < n; ++j) {
      if (j == i || j == (i + 1) % n || (j + 1) % n == i) continue;  // itself and its neighbours
      if (core::segmentsIntersect(a, b, ring[j], ring[(j + 1) % n])) return false;
    }
    // Adjacent edges must not fold back onto each other.
    const cv::Point2d prev = ring[(i + n - 1) % n], next = ring[(i + 2) % n];
    if (cross(a - prev, b - a) == 0 && (a - prev).dot(b - a) < 0) return false;
    if (cross(b - a, next - b) == 0 && (b - a).dot(next - b) < 0) return false;
  }
  return true;
}

// Removes the shortest edges (below minEdge, folds first) one at a time while the result stays
// simple and the edges the removal changes stay within the tolerance of the input (the whole
// ring is judged at the end: a removal may come before the one that brings a far edge back).
void removeShortEdges(std::vector<Line>& lines, const EdgeGrid& input,
                      const RegularizationParams& params, const RingContext& ctx, size_t minLines) {
  std::set<std::array<EdgeKey, 3>> failed;
  EdgeSet unchanged;
  for (size_t round = 0; round < 4 * input.ring().size() + 16; ++round) {
    const core::Ring ring = vertices(lines);
    unchanged.reset(ring.size());
    for (size_t i = 0; i < ring.size(); ++i)
      unchanged.insert(edgeKey(ring[i], ring[(i + 1) % ring.size()]));
    const std::vector<double> lengths = edgeLengths(lines, ring);
    std::vector<size_t> order;
    for (size_t k = 0; k < lines.size(); ++k) {
      if (lengths[k] < params.minEdge) order.push_back(k);
    }
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return lengths[a] < lengths[b]; });
    bool removed = false;
    for (size_t k : order) {
      // A removal that failed with the same edge and neighbours fails again: skip it.
      const size_t n = ring.size();
      const std::array<EdgeKey, 3> around{edgeKey(ring[(k + n - 1) % n], ring[k]),
                                          edgeKey(ring[k], ring[(k + 1) % n]),
                                          edgeKey(ring[(k + 1) % n], ring[(k + 2) % n])};
      if (failed.count(around)) continue;
      failed.insert(around);
      std::vector<Line> trial = lines;
      trial.erase(trial.begin() + static_cast<long>(k));
      if (!tidy(trial, false, minLines)) continue;
      const core::Ring r = vertices(trial);
      if (!simpleAround(r, unchanged) || !insideBounds(r, ctx.bounds)) continue;
      // Sampled every 2 px here (within 1 px of the exact value); the final check samples every px.
      if (maxDeviation(r, input, params.tolerance, &unchanged, 2.0) > params.tolerance) continue;
      lines = std::move(trial);
      removed = true;
      break;
    }
    if (!removed) return;
  }
}

struct RingCandidate {
  core::Ring ring;
  double deviation = kInf;
  double mean = kInf;
  std::string failure;  // empty when it passes the ring's own checks
};

std::string formatPx(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

// Clamps vertices a hair outside the image (rounding of lines along its border) onto it.
void clampToBounds(core::Ring& ring, cv::Size bounds) {
  if (bounds.empty()) return;
  for (auto& p : ring) {
    if (p.x < 0 && p.x > -0.5) p.x = 0;
    if (p.y < 0 && p.y > -0.5) p.y = 0;
    if (p.x > bounds.width && p.x < bounds.width + 0.5) p.x = bounds.width;
    if (p.y > bounds.height && p.y < bounds.height + 0.5) p.y = bounds.height;
  }
}

RingCandidate regularizeRingAt(const core::Ring& input, const EdgeGrid& grid, double epsilon,
                               const RegularizationParams& params, const RingContext& ctx) {
  const size_t minLines = ctx.mode == RegularizationMode::RightAngles ? 4 : 3;
  RingCandidate c;
  std::vector<size_t> breaks = breakpoints(input, epsilon);
  if (breaks.size() < 3) {
    c.failure = "too few edges";
    return c;
  }
  std::vector<Line> lines = piecesToLines(input, breaks, ctx, 0.8 * params.tolerance);
  if (!tidy(lines, true, minLines)) {
    c.failure = "too few edges";
    return c;
  }
  removeShortEdges(lines, grid, params, ctx, minLines);
  c.ring = vertices(lines);
  clampToBounds(c.ring, ctx.bounds);
  if (!core::isSimple(c.ring)) {
    c.failure = "self-intersection";
    return c;
  }
  if (!insideBounds(c.ring, ctx.bounds)) {
    c.failure = "outside the image";
    return c;
  }
  c.deviation = maxDeviation(c.ring, grid, 4 * params.tolerance + 10);
  if (c.deviation > params.tolerance + 1e-9) {
    c.failure =
        "deviation " + formatPx(c.deviation) + " px > " + formatPx(params.tolerance) + " px";
    return c;
  }
  c.mean = meanDistance(c.ring, grid, params.tolerance + 1.0);
  return c;
}

// The best of the candidates from several segmentation tolerances: fewest vertices, then the
// closest to the input. The coarsest tolerance merges noise, the finer ones keep small wings.
RingCandidate regularizeRing(const core::Ring& input, const RegularizationParams& params,
                             const RingContext& ctx) {
  std::vector<double> epsilons;
  for (double f : {1.0, 0.6, 0.35}) {
    const double e = std::max(0.5, f * params.tolerance);
    if (epsilons.empty() || e < epsilons.back() - 1e-9) epsilons.push_back(e);
  }
  RingCandidate best, firstFailure;
  const EdgeGrid grid(input);
  const RingEdgeTerms edges(input);
  RingContext ringCtx = ctx;
  ringCtx.edges = &edges;
  for (double e : epsilons) {
    RingCandidate c = regularizeRingAt(input, grid, e, params, ringCtx);
    if (!c.failure.empty()) {
      if (firstFailure.failure.empty()) firstFailure = std::move(c);
      continue;
    }
    if (best.ring.empty() || c.ring.size() < best.ring.size() ||
        (c.ring.size() == best.ring.size() && c.mean < best.mean)) {
      best = std::move(c);
    }
  }
  return best.ring.empty() ? firstFailure : best;
}

core::Ring cleaned(const core::Ring& ring) {
  core::Ring out;
  for (const auto& p : ring) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      throw Error(ErrorCode::InvalidParameter,
                  "the outline to regularize has a non-finite coordinate");
    }
    if (out.empty() || cv::norm(p - out.back()) > 1e-9) out.push_back(p);
  }
  while (out.size() > 1 && cv::norm(out.front() - out.back()) <= 1e-9) out.pop_back();
  return out;
}

bool ringsApart(const core::Polygon& p) {
  std::vector<const core::Ring*> rings{&p.outer};
  for (const auto& h : p.holes) rings.push_back(&h);
  for (size_t a = 0; a < rings.size(); ++a) {
    for (size_t b = a + 1; b < rings.size(); ++b) {
      const core::Ring& ra = *rings[a];
      const core::Ring& rb = *rings[b];
      for (size_t i = 0; i < ra.size(); ++i) {
        for (size_t j = 0; j < rb.size(); ++j) {
          if (core::segmentsIntersect(ra[i], ra[(i + 1) % ra.size()], rb[j],
                                      rb[(j + 1) % rb.size()]))
            return false;
        }
      }
    }
  }
  auto inside = [](const core::Ring& ring, cv::Point2d q) {
    std::vector<cv::Point2f> contour;
    for (const auto& v : ring)
      contour.emplace_back(static_cast<float>(v.x), static_cast<float>(v.y));
    return cv::pointPolygonTest(
               contour, cv::Point2f(static_cast<float>(q.x), static_cast<float>(q.y)), false) > 0;
  };
  for (size_t h = 0; h < p.holes.size(); ++h) {
    if (!inside(p.outer, p.holes[h].front())) return false;
    for (size_t g = 0; g < p.holes.size(); ++g) {
      if (g != h && inside(p.holes[g], p.holes[h].front())) return false;
    }
  }
  return true;
}

// The outline without its spikes, fingers and slits narrower than `minWidth` px: rasterized
// (1 px), opened then closed with a disk of that diameter; the largest component's outline and
// its holes, simplified at 0.5 px. False (and `out` untouched) when nothing of at least
// minWidth² px² changed: the corners the disk rounds are not thin parts.
// True when two non-adjacent edges of the ring pointing opposite ways (more than 135° apart)
// come closer than `width`: the two sides of a spike, finger or slit.
bool hasThinParts(const core::Ring& ring, double width) {
  const size_t n = ring.size();
  for (size_t i = 0; i < n; ++i) {
    const cv::Point2d a = ring[i], b = ring[(i + 1) % n], u = b - a;
    for (size_t j = i + 2; j < n; ++j) {
      if ((j + 1) % n == i) continue;
      const cv::Point2d c = ring[j], d = ring[(j + 1) % n], v = d - c;
      if (u.dot(v) > -std::cos(kPi / 4) * cv::norm(u) * cv::norm(v)) continue;
      const double gap = std::min({segmentDistance(a, c, d), segmentDistance(b, c, d),
                                   segmentDistance(c, a, b), segmentDistance(d, a, b)});
      if (gap < width) return true;
    }
  }
  return false;
}

// True when an 8-connected component of the non-zero pixels of `mask` (CV_8U) has at least
// `area` pixels. A flood fill from each pixel not yet reached, stopped at that size: the changed
// pixels of an opening are few and scattered along the outline, and labelling the whole raster
// (connectedComponentsWithStats) cost more than the rest of the stage on a large roof.
bool hasComponentOfArea(const cv::Mat& mask, double area) {
  cv::Mat seen = cv::Mat::zeros(mask.size(), CV_8U);
  std::vector<cv::Point> stack;
  for (int y = 0; y < mask.rows; ++y) {
    const uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (!m[x] || seen.at<uchar>(y, x)) continue;
      int count = 0;
      seen.at<uchar>(y, x) = 1;
      stack.assign(1, cv::Point(x, y));
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        if (++count >= area) return true;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = p.x + dx, qy = p.y + dy;
            if (qx < 0 || qy < 0 || qx >= mask.cols || qy >= mask.rows) continue;
            if (!mask.at<uchar>(qy, qx) || seen.at<uchar>(qy, qx)) continue;
            seen.at<uchar>(qy, qx) = 1;
            stack.emplace_back(qx, qy);
          }
        }
      }
    }
  }
  return false;
}

bool withoutThinParts(const core::Polygon& in, double minWidth, core::Polygon& out) {
  const int r = static_cast<int>(std::floor(minWidth / 2));
  if (r < 1) return false;
  bool thinSides = hasThinParts(in.outer, minWidth);
  for (const auto& h : in.holes) thinSides = thinSides || hasThinParts(h, minWidth);
  if (!thinSides) return false;  // the raster below is the expensive part
  const cv::Rect2d box = core::boundingBox(in.outer);
  const cv::Point2d origin(std::floor(box.x) - 2 * r - 2, std::floor(box.y) - 2 * r - 2);
  const cv::Size size(static_cast<int>(std::ceil(box.width)) + 4 * r + 6,
                      static_cast<int>(std::ceil(box.height)) + 4 * r + 6);
  core::Polygon local = in;
  for (auto& v : local.outer) v -= origin;
  for (auto& h : local.holes) {
    for (auto& v : h) v -= origin;
  }
  const cv::Mat mask = core::rasterize(local, size);
  cv::Mat cleaned;
  const cv::Mat disk = cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1});
  cv::morphologyEx(mask, cleaned, cv::MORPH_OPEN, disk);
  cv::morphologyEx(cleaned, cleaned, cv::MORPH_CLOSE, disk);
  if (!hasComponentOfArea(mask != cleaned, minWidth * minWidth)) return false;
  std::vector<std::vector<cv::Point>> contours;
  std::vector<cv::Vec4i> hierarchy;
  cv::findContours(cleaned, contours, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE);
  int largest = -1;
  double largestArea = 0;
  for (size_t i = 0; i < contours.size(); ++i) {
    if (hierarchy[i][3] >= 0) continue;  // a hole
    const double a = cv::contourArea(contours[i]);
    if (a > largestArea) largestArea = a, largest = static_cast<int>(i);
  }
  if (largest < 0) return false;
  // Contour points are centres of border pixels: half a pixel inside the outline (outside for a
  // hole); moved out along the local normal they are back on the pixel border.
  auto toRing = [&](const std::vector<cv::Point>& c) {
    std::vector<cv::Point2f> simplified;
    std::vector<cv::Point2f> pts(c.begin(), c.end());
    cv::approxPolyDP(pts, simplified, 0.5, true);
    core::Ring ring;
    for (const auto& v : simplified) ring.emplace_back(v.x + 0.5 + origin.x, v.y + 0.5 + origin.y);
    return ring;
  };
  out = core::Polygon{toRing(contours[static_cast<size_t>(largest)]), {}};
  for (int h = hierarchy[static_cast<size_t>(largest)][2]; h >= 0;
       h = hierarchy[static_cast<size_t>(h)][0]) {
    if (contours[static_cast<size_t>(h)].size() >= 3)
      out.holes.push_back(toRing(contours[static_cast<size_t>(h)]));
  }
  return out.outer.size() >= 3;
}

// Smallest distance between two rings (vertex to edge, both ways).
double ringGap(const core::Ring& a, const core::Ring& b) {
  double best = kInf;
  for (const auto& p : a) best = std::min(best, ringDistance(p, b));
  for (const auto& p : b) best = std::min(best, ringDistance(p, a));
  return best;
}

// Radius of the circle the ring follows, or 0 when it does not: every point (sampled every px)
// within max(0.4 tolerance, 5 % of the radius) of the least-squares circle (Kasa's fit). A
// square's corners lie 17 % of the radius off its circle.
double roundRadius(const core::Ring& ring, double tolerance) {
  std::vector<cv::Point2d> pts;
  for (size_t i = 0; i < ring.size(); ++i) {
    const cv::Point2d a = ring[i], b = ring[(i + 1) % ring.size()];
    const int steps = std::max(1, static_cast<int>(std::ceil(cv::norm(b - a))));
    for (int s = 0; s < steps; ++s) pts.push_back(a + (b - a) * (static_cast<double>(s) / steps));
  }
  cv::Point2d mean(0, 0);
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  // x² + y² + D x + E y + F = 0 in coordinates centred on the mean (better conditioned).
  cv::Matx33d a = cv::Matx33d::zeros();
  cv::Vec3d rhs(0, 0, 0);
  for (const auto& q : pts) {
    const cv::Point2d p = q - mean;
    const cv::Vec3d row(p.x, p.y, 1.0);
    a += row * row.t();
    rhs += row * -(p.x * p.x + p.y * p.y);
  }
  cv::Mat solution;
  if (!cv::solve(cv::Mat(a), cv::Mat(rhs), solution, cv::DECOMP_SVD)) return 0;
  const cv::Vec3d def(solution.at<double>(0), solution.at<double>(1), solution.at<double>(2));
  const cv::Point2d centre(-def[0] / 2, -def[1] / 2);
  const double r2 = centre.dot(centre) - def[2];
  if (r2 <= 0) return 0;
  const double radius = std::sqrt(r2);
  const double allowed = std::max(0.4 * tolerance, 0.05 * radius);
  for (const auto& q : pts) {
    if (std::abs(cv::norm(q - mean - centre) - radius) > allowed) return 0;
  }
  return radius;
}

int vertexCount(const core::Polygon& p) {
  size_t n = p.outer.size();
  for (const auto& h : p.holes) n += h.size();
  return static_cast<int>(n);
}

}  // namespace

void RegularizationParams::validate() const {
  core::checkDeclaredRanges(*this);
}

RegularizationMode regularizationMode(const std::string& name) {
  if (name == "none") return RegularizationMode::None;
  if (name == "right-angles") return RegularizationMode::RightAngles;
  if (name == "right-angles-and-diagonals") return RegularizationMode::RightAnglesAndDiagonals;
  if (name == "any-angle") return RegularizationMode::AnyAngle;
  throw Error(ErrorCode::InvalidParameter,
              "regularize = '" + name +
                  "' is not one of right-angles|right-angles-and-diagonals|any-angle|none");
}

std::string toString(RegularizationStatus status) {
  switch (status) {
    case RegularizationStatus::Regularized:
      return "regularized";
    case RegularizationStatus::KeptRaw:
      return "kept-raw";
    case RegularizationStatus::Off:
      break;
  }
  return "off";
}

double dominantOrientation(const core::Polygon& outline, const cv::Mat& image,
                           double imageEdgeWeight, double epsilon) {
  std::vector<Vote> shape, edges;
  double shapeTotal = 0, edgeTotal = 0;
  outlineVotes(outline.outer, epsilon, shape, shapeTotal);
  for (const auto& h : outline.holes) outlineVotes(h, epsilon, shape, shapeTotal);
  if (!image.empty() && imageEdgeWeight > 0 && image.channels() == 1)
    imageVotes(outline, image, edges, edgeTotal);
  // Both sources normalised to a total weight of 1 (then the image's scaled by its weight).
  std::vector<Vote> votes;
  for (const auto& v : shape) votes.push_back({v.angle, v.weight / std::max(shapeTotal, 1e-12)});
  for (const auto& v : edges)
    votes.push_back({v.angle, imageEdgeWeight * v.weight / std::max(edgeTotal, 1e-12)});
  if (votes.empty()) return 0.0;
  return votePeak(votes);
}

RegularizationOutcome regularizeOutline(const core::Polygon& outline,
                                        const RegularizationParams& params, const cv::Mat& image,
                                        std::optional<double> orientation) {
  params.validate();
  const RegularizationMode mode = regularizationMode(params.mode);
  core::Polygon input{cleaned(outline.outer), {}};
  for (const auto& h : outline.holes) input.holes.push_back(cleaned(h));
  if (input.outer.size() < 3 || core::area(core::Polygon{input.outer, {}}) <= 1e-9) {
    throw Error(
        ErrorCode::InvalidParameter,
        "the outline to regularize is not a polygon (fewer than 3 distinct vertices or zero area)");
  }
  if (!image.empty() &&
      (image.channels() != 1 ||
       (image.depth() != CV_8U && image.depth() != CV_16U && image.depth() != CV_16S &&
        image.depth() != CV_32F && image.depth() != CV_64F))) {
    throw Error(ErrorCode::UnsupportedInput,
                "regularization reads the edges of a single-band 8-bit, 16-bit or floating-point "
                "image only");
  }
  RegularizationOutcome out;
  out.polygon = outline;
  out.inputVertices = out.outputVertices = vertexCount(outline);
  if (mode == RegularizationMode::None) return out;
  out.tolerance = params.tolerance;

  const double theta = orientation ? mod90(*orientation)
                                   : dominantOrientation(input, image, params.imageEdgeWeight,
                                                         std::max(0.5, 0.5 * params.tolerance));
  RingContext ctx{mode, theta, image.size()};
  out.orientationDeg = ctx.theta * 180.0 / kPi;
  auto keep = [&](const std::string& reason) {
    out.status = RegularizationStatus::KeptRaw;
    out.reason = reason;
    return out;
  };
  if (const double radius = roundRadius(input.outer, params.tolerance); radius > 0) {
    return keep("round outline (a circle of radius " + formatPx(radius) + " px)");
  }
  // Spikes, fingers and slits thinner than min-width go first; the tolerance then applies to
  // the outline without them.
  core::Polygon target = input;
  withoutThinParts(input, params.minWidth, target);
  const RingCandidate outer = regularizeRing(target.outer, params, ctx);
  if (!outer.failure.empty()) return keep(outer.failure);
  core::Polygon result{outer.ring, {}};
  out.deviation = outer.deviation;
  for (const auto& hole : target.holes) {
    // A hole that cannot be regularized is kept as it is: a ragged courtyard should not cost
    // the building its clean outline. One closer than 1 px to the outer ring is dropped: it is a
    // notch, not a courtyard.
    if (hole.size() < 3) continue;
    const RingCandidate h = regularizeRing(hole, params, ctx);
    const core::Ring& ring = h.failure.empty() ? h.ring : hole;
    if (ringGap(ring, result.outer) < 1.0) continue;
    result.holes.push_back(ring);
    if (h.failure.empty()) out.deviation = std::max(out.deviation, h.deviation);
  }
  if (!ringsApart(result)) return keep("self-intersection");
  const double before = core::area(input), after = core::area(result);
  out.areaRatio = before > 0 ? after / before : 0.0;
  if (std::abs(out.areaRatio - 1.0) * 100.0 > params.maxAreaChange) {
    return keep("area change " + formatPx(100.0 * (out.areaRatio - 1.0)) + " % beyond " +
                formatPx(params.maxAreaChange) + " %");
  }
  if (vertexCount(result) > vertexCount(input)) return keep("more vertices than the input");
  out.polygon = std::move(result);
  out.outputVertices = vertexCount(out.polygon);
  out.status = RegularizationStatus::Regularized;
  return out;
}

namespace {

// Intersection of the lines through a with direction u and through b with direction v; false
// when they are parallel.
}  // namespace

}  // namespace delineo::delineation
