#include "delineo/delineation/energy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace delineo::delineation {

int IntPolygon::vertexCount() const {
  int n = static_cast<int>(outer.size());
  for (const auto& h : holes) n += static_cast<int>(h.size());
  return n;
}

core::Polygon toPolygon(const IntPolygon& p, cv::Point2d offset) {
  auto convert = [&](const IntRing& ring) {
    core::Ring out;
    out.reserve(ring.size());
    for (const auto& v : ring) out.emplace_back(v.x + offset.x, v.y + offset.y);
    return out;
  };
  core::Polygon out;
  out.outer = convert(p.outer);
  for (const auto& h : p.holes) out.holes.push_back(convert(h));
  return out;
}

double anglePrior(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  const double s2 = std::abs(std::sin(2.0 * theta));
  // Rounding: cos and |sin| are equal at 45°, where both branches give 1.
  return c >= std::abs(s) ? 2.0 - s2 : s2;
}

double vertexAngle(cv::Point prev, cv::Point v, cv::Point next) {
  const double ax = prev.x - v.x, ay = prev.y - v.y;
  const double bx = next.x - v.x, by = next.y - v.y;
  // R is symmetric under θ → 2π - θ, so the unsigned angle in [0, π] is enough.
  return std::atan2(std::abs(ax * by - ay * bx), ax * bx + ay * by);
}

namespace {

float bilinear(const cv::Mat& img, double x, double y) {
  const int w = img.cols, h = img.rows;
  x = std::clamp(x, 0.0, static_cast<double>(w - 1));
  y = std::clamp(y, 0.0, static_cast<double>(h - 1));
  const int x0 = std::min(static_cast<int>(x), w - 1), y0 = std::min(static_cast<int>(y), h - 1);
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = img.ptr<float>(y0);
  const float* r1 = img.ptr<float>(y1);
  return static_cast<float>((1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x1]) +
                            fy * ((1 - fx) * r1[x0] + fx * r1[x1]));
}

constexpr int kGateDepth = 5;  // px sampled inside the contour by the edge gate

// s(x) of the edge gate: 0 below -contrast, 1 above +contrast, linear in between.
double gate(double x, double contrast) { return std::clamp(1.0 + x / contrast, 0.0, 1.0); }

// Left and right edge terms of a→b, whose interior side is n = (-dy, dx): λ·unit·Σ along the
// segment of min(1, |∇I·n|) times the cost-contrast gate, sampled once per pixel of length.
// D = c_ground - c_roof (> 0 where roof-like), the image the edge gate samples.
cv::Mat costDifference(const EnergyImages& im) {
  if (!im.uncappedDifference.empty()) return im.uncappedDifference.clone();
  return im.groundCost - im.roofCost;
}

// `difference`: costDifference(im), computed once by the caller.
std::array<double, 2> edgeTermsOf(const EnergyImages& im, const cv::Mat& difference, const EnergyWeights& w,
                                  cv::Point a, cv::Point b) {
  std::array<double, 2> out{0.0, 0.0};
  const bool left = !im.leftGradX.empty() && !im.leftGradY.empty();
  const bool right = !im.rightGradX.empty() && !im.rightGradY.empty();
  if (!left && !right) return out;
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len = std::hypot(dx, dy);
  if (len <= 0) return out;
  const double nx = -dy / len, ny = dx / len;
  const int samples = std::max(1, static_cast<int>(std::ceil(len)));
  const bool gated = w.edgeContrast > 0;
  for (int i = 0; i < samples; ++i) {
    const double t = (i + 0.5) / samples;
    // Pixel centres are at +0.5: sample the images in their index frame.
    const double px = a.x + t * dx - 0.5, py = a.y + t * dy - 0.5;
    double weight = 1.0;
    if (gated) {
      double in = 0.0;
      for (int k = 1; k <= kGateDepth; ++k) in += bilinear(difference, px + k * nx, py + k * ny);
      weight = gate(in / kGateDepth, w.edgeContrast);
      if (weight <= 0.0) continue;
    }
    if (left) {
      const double g = bilinear(im.leftGradX, px, py) * nx + bilinear(im.leftGradY, px, py) * ny;
      out[0] += std::min(1.0, std::abs(g)) * weight;
    }
    if (right) {
      const double g = bilinear(im.rightGradX, px, py) * nx + bilinear(im.rightGradY, px, py) * ny;
      out[1] += std::min(1.0, std::abs(g)) * weight;
    }
  }
  const double scale = -w.edgeWeight * kEdgeUnit * len / samples;
  return {out[0] * scale, out[1] * scale};
}

int occlusionAt(const EnergyImages& im, int y, int x) {
  if (im.occlusionWidth.empty()) return 0;
  x = std::clamp(x, 0, im.occlusionWidth.cols - 1);
  return std::max(0, im.occlusionWidth.at<int>(y, x));
}

int pixelIndex(double x, int w) {
  return std::clamp(static_cast<int>(std::ceil(x - 0.5)), 0, w);
}

// Appends the crossings of edge a→b with the pixel-centre lines y + 0.5, rows in [0, h).
template <class Fn>
void forEachCrossing(cv::Point a, cv::Point b, int h, Fn&& fn) {
  if (a.y == b.y) return;
  const cv::Point lo = a.y < b.y ? a : b, hi = a.y < b.y ? b : a;
  const int y0 = std::max(lo.y, 0), y1 = std::min(hi.y, h);
  const double slope = static_cast<double>(hi.x - lo.x) / (hi.y - lo.y);
  for (int y = y0; y < y1; ++y) fn(y, lo.x + (y + 0.5 - lo.y) * slope);
}

double cross(cv::Point o, cv::Point a, cv::Point b) {
  return static_cast<double>(a.x - o.x) * (b.y - o.y) - static_cast<double>(a.y - o.y) * (b.x - o.x);
}
// Integer vertices: the cross products are exact, so core's tolerance never matters.
bool segmentsTouch(cv::Point p1, cv::Point p2, cv::Point p3, cv::Point p4) {
  return core::segmentsIntersect(p1, p2, p3, p4);
}
// Edges s→a and s→b share s: they may only meet there (no fold-back along a common line).
bool adjacentOverlap(cv::Point s, cv::Point a, cv::Point b) {
  if (cross(s, a, b) != 0) return false;
  return static_cast<double>(a.x - s.x) * (b.x - s.x) + static_cast<double>(a.y - s.y) * (b.y - s.y) > 0;
}
double ringArea2(const IntRing& r) {
  double a = 0;
  for (size_t i = 0; i < r.size(); ++i) {
    const auto& p = r[i];
    const auto& q = r[(i + 1) % r.size()];
    a += static_cast<double>(p.x) * q.y - static_cast<double>(q.x) * p.y;
  }
  return a;
}
double pointSegmentDistance(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d ab = b - a;
  const double len2 = ab.dot(ab);
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  const cv::Point2d d = p - (a + t * ab);
  return std::hypot(d.x, d.y);
}
// Segments a-b and p-q that point in nearly opposite directions (more than 135° apart) and come
// closer than `gap`: the two sides of a finger or slit. They do not cross (checked before).
bool antiparallelWithin(cv::Point a, cv::Point b, cv::Point p, cv::Point q, double gap) {
  const cv::Point2d u = b - a, v = q - p;
  if (u.dot(v) > -std::cos(CV_PI / 4) * std::hypot(u.x, u.y) * std::hypot(v.x, v.y)) return false;
  const double d = std::min(std::min(pointSegmentDistance(a, p, q), pointSegmentDistance(b, p, q)),
                            std::min(pointSegmentDistance(p, a, b), pointSegmentDistance(q, a, b)));
  return d < gap;
}
// True when the polygon's interior lies on the (-dy, dx) side of ring r's edges: with y down,
// a ring of positive ringArea2 has its inside there; a hole's polygon interior is its outside.
bool interiorOnLeft(const IntRing& ring, bool hole) { return (ringArea2(ring) > 0) != hole; }
bool insideRing(const IntRing& ring, cv::Point2d p) {
  bool in = false;
  for (size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const auto& a = ring[i];
    const auto& b = ring[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / double(b.y - a.y) + a.x)
      in = !in;
  }
  return in;
}

}  // namespace

bool isValidPolygon(const IntPolygon& p) {
  const core::Polygon d = toPolygon(p);
  if (!core::isSimple(d.outer)) return false;
  for (size_t h = 0; h < p.holes.size(); ++h) {
    if (!core::isSimple(d.holes[h])) return false;
    if (!insideRing(p.outer, cv::Point2d(p.holes[h][0]))) return false;
    for (size_t k = 0; k < p.holes.size(); ++k) {
      if (k != h && insideRing(p.holes[k], cv::Point2d(p.holes[h][0]))) return false;
    }
  }
  for (size_t r = 0; r < p.ringCount(); ++r) {
    for (size_t s = r + 1; s < p.ringCount(); ++s) {
      const IntRing& a = p.ring(r);
      const IntRing& b = p.ring(s);
      for (size_t i = 0; i < a.size(); ++i) {
        for (size_t j = 0; j < b.size(); ++j) {
          if (segmentsTouch(a[i], a[(i + 1) % a.size()], b[j], b[(j + 1) % b.size()])) return false;
        }
      }
    }
  }
  return true;
}

EnergyTerms referenceEnergy(const EnergyImages& im, const EnergyWeights& w,
                            const IntPolygon& polygon) {
  EnergyTerms t;
  const cv::Mat difference = w.edgeContrast > 0 ? costDifference(im) : cv::Mat();
  const cv::Size size = im.roofCost.size();
  const cv::Mat mask = core::rasterize(toPolygon(polygon), size);
  cv::Mat band(size, CV_8U, cv::Scalar(0));
  for (int y = 0; y < size.height; ++y) {
    const uchar* m = mask.ptr<uchar>(y);
    uchar* b = band.ptr<uchar>(y);
    // Runs of roof pixels on this row, in order.
    std::vector<std::pair<int, int>> runs;
    for (int x = 0; x < size.width;) {
      if (!m[x]) { ++x; continue; }
      int e = x;
      while (e < size.width && m[e]) ++e;
      runs.emplace_back(x, e);
      x = e;
    }
    for (size_t k = 0; k < runs.size(); ++k) {
      if (im.occlusionSide < 0) {
        const int start = runs[k].first;
        const int stop = k == 0 ? 0 : runs[k - 1].second;
        for (int x = std::max(start - occlusionAt(im, y, start), stop); x < start; ++x) b[x] = 255;
      } else {
        const int end = runs[k].second;
        const int stop = k + 1 == runs.size() ? size.width : runs[k + 1].first;
        for (int x = end; x < std::min(end + occlusionAt(im, y, end - 1), stop); ++x) b[x] = 255;
      }
    }
  }
  for (int y = 0; y < size.height; ++y) {
    const uchar* m = mask.ptr<uchar>(y);
    const uchar* b = band.ptr<uchar>(y);
    const float* cr = im.roofCost.ptr<float>(y);
    const float* cg = im.groundCost.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      if (m[x]) t.term[0] += cr[x];
      else if (b[x]) t.term[2] += im.noMatchCost;
      else t.term[1] += cg[x];
    }
  }
  for (size_t r = 0; r < polygon.ringCount(); ++r) {
    const IntRing& ring = polygon.ring(r);
    const size_t n = ring.size();
    const bool inwardLeft = interiorOnLeft(ring, r > 0);
    for (size_t i = 0; i < n; ++i) {
      const cv::Point a = ring[i], b = ring[(i + 1) % n];
      const auto e = inwardLeft ? edgeTermsOf(im, difference, w, a, b) : edgeTermsOf(im, difference, w, b, a);
      t.term[3] += e[0];
      t.term[4] += e[1];
      t.term[5] += w.rigidity * anglePrior(vertexAngle(ring[(i + n - 1) % n], a, b));
    }
  }
  return t;
}

PolygonEnergy::PolygonEnergy(const EnergyImages& images, const EnergyWeights& weights)
    : images_(images), weights_(weights), size_(images.roofCost.size()) {
  if (weights.edgeContrast > 0) costDifference_ = costDifference(images);
  CV_Assert(images.roofCost.type() == CV_32F && images.groundCost.type() == CV_32F &&
            images.groundCost.size() == size_);
  const int w = size_.width;
  roofPrefix_.assign(static_cast<size_t>(size_.height) * (w + 1), 0.0);
  groundPrefix_.assign(roofPrefix_.size(), 0.0);
  for (int y = 0; y < size_.height; ++y) {
    const float* cr = images.roofCost.ptr<float>(y);
    const float* cg = images.groundCost.ptr<float>(y);
    double* pr = &roofPrefix_[static_cast<size_t>(y) * (w + 1)];
    double* pg = &groundPrefix_[static_cast<size_t>(y) * (w + 1)];
    for (int x = 0; x < w; ++x) {
      pr[x + 1] = pr[x] + cr[x];
      pg[x + 1] = pg[x] + cg[x];
    }
  }
}

PolygonEnergy::RowTerms PolygonEnergy::rowTerms(int y, const std::vector<double>& xs) const {
  const int w = size_.width;
  const double* pr = &roofPrefix_[static_cast<size_t>(y) * (w + 1)];
  const double* pg = &groundPrefix_[static_cast<size_t>(y) * (w + 1)];
  // Even-odd pairing of the sorted crossings gives the roof runs [l, r) of the row.
  int runs[2 * 64];
  std::vector<int> bigRuns;
  int* run = runs;
  const size_t pairs = xs.size() / 2;
  if (pairs > 64) {
    bigRuns.resize(2 * pairs);
    run = bigRuns.data();
  }
  int count = 0;
  for (size_t k = 0; k < pairs; ++k) {
    const int l = pixelIndex(xs[2 * k], w), r = pixelIndex(xs[2 * k + 1], w);
    if (l >= r) continue;
    run[2 * count] = l;
    run[2 * count + 1] = r;
    ++count;
  }
  RowTerms t;
  double groundOut = 0.0;
  int bandPixels = 0;
  for (int k = 0; k < count; ++k) {
    const int l = run[2 * k], r = run[2 * k + 1];
    t.roof += pr[r] - pr[l];
    groundOut += pg[r] - pg[l];
    int b0, b1;
    if (images_.occlusionSide < 0) {
      b1 = l;
      b0 = std::max(l - occlusionAt(images_, y, l), k == 0 ? 0 : run[2 * k - 1]);
    } else {
      b0 = r;
      b1 = std::min(r + occlusionAt(images_, y, r - 1), k + 1 == count ? w : run[2 * k + 2]);
    }
    if (b1 > b0) {
      groundOut += pg[b1] - pg[b0];
      bandPixels += b1 - b0;
    }
  }
  t.ground = pg[w] - groundOut;
  t.band = static_cast<double>(images_.noMatchCost) * bandPixels;
  return t;
}

const std::array<double, 2>& PolygonEnergy::edgeTerms(cv::Point a, cv::Point b, bool inwardLeft) const {
  if (!inwardLeft) std::swap(a, b);
  // Vertices lie in [0, W] x [0, H] (validated moves), so 16 bits per coordinate suffice; the key
  // keeps the direction so that results are bit-identical to the reference's.
  const auto coord = [](int v) { return static_cast<std::uint64_t>(static_cast<std::uint16_t>(v)); };
  const std::uint64_t key = coord(a.x) | coord(a.y) << 16 | coord(b.x) << 32 | coord(b.y) << 48;
  if (edgeCache_.size() > (1u << 20)) edgeCache_.clear();  // bounded memory on huge runs
  auto [it, inserted] = edgeCache_.try_emplace(key);
  if (inserted) it->second = edgeTermsOf(images_, costDifference_, weights_, a, b);
  return it->second;
}

double PolygonEnergy::vertexPrior(const IntRing& ring, int i) const {
  const int n = static_cast<int>(ring.size());
  return weights_.rigidity *
         anglePrior(vertexAngle(ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]));
}

void PolygonEnergy::setPolygon(const IntPolygon& polygon) {
  polygon_ = polygon;
  rebuild();
}

void PolygonEnergy::rebuild() {
  ringOffset_.clear();
  ringInwardLeft_.clear();
  int total = 0;
  for (size_t r = 0; r < polygon_.ringCount(); ++r) {
    ringOffset_.push_back(total);
    ringInwardLeft_.push_back(interiorOnLeft(polygon_.ring(r), r > 0));
    total += static_cast<int>(polygon_.ring(r).size());
  }
  edgeTerms_.assign(total, {0.0, 0.0});
  vertexPriors_.assign(total, 0.0);
  rowCrossings_.assign(size_.height, {});
  for (size_t r = 0; r < polygon_.ringCount(); ++r) {
    const IntRing& ring = polygon_.ring(r);
    const int n = static_cast<int>(ring.size());
    for (int i = 0; i < n; ++i) {
      const int id = ringOffset_[r] + i;
      const cv::Point a = ring[i], b = ring[(i + 1) % n];
      edgeTerms_[id] = edgeTerms(a, b, ringInwardLeft_[r]);
      vertexPriors_[id] = vertexPrior(ring, i);
      forEachCrossing(a, b, size_.height,
                      [&](int y, double x) { rowCrossings_[y].push_back({x, id}); });
    }
  }
  rowTerms_.assign(size_.height, {});
  std::vector<double> xs;
  for (int y = 0; y < size_.height; ++y) {
    auto& c = rowCrossings_[y];
    std::sort(c.begin(), c.end(), [](const Crossing& p, const Crossing& q) { return p.x < q.x; });
    xs.clear();
    for (const auto& k : c) xs.push_back(k.x);
    rowTerms_[y] = rowTerms(y, xs);
  }
}

EnergyTerms PolygonEnergy::terms() const {
  EnergyTerms t;
  for (const auto& r : rowTerms_) {
    t.term[0] += r.roof;
    t.term[1] += r.ground;
    t.term[2] += r.band;
  }
  for (const auto& e : edgeTerms_) {
    t.term[3] += e[0];
    t.term[4] += e[1];
  }
  for (double p : vertexPriors_) t.term[5] += p;
  return t;
}

IntPolygon PolygonEnergy::changed(const Change& c) const {
  IntPolygon out = polygon_;
  const IntRing& ring = polygon_.ring(c.ring);
  const int n = static_cast<int>(ring.size());
  IntRing next;
  next.reserve(n - c.removeCount + c.inserted.size());
  if (c.first + c.removeCount <= n) {  // keeps vertex order so that sweeps stay in place
    next.insert(next.end(), ring.begin(), ring.begin() + c.first);
    next.insert(next.end(), c.inserted.begin(), c.inserted.end());
    next.insert(next.end(), ring.begin() + c.first + c.removeCount, ring.end());
  } else {  // the replaced run wraps past the end: the inserted vertices start the ring
    next.insert(next.end(), c.inserted.begin(), c.inserted.end());
    next.insert(next.end(), ring.begin() + (c.first + c.removeCount - n), ring.begin() + c.first);
  }
  out.ring(c.ring) = std::move(next);
  return out;
}

namespace {

// The steps of PolygonEnergy::delta() that need none of its state, in the order it runs them.

// The change's new local chain: prev2, prev, inserted..., next, next2.
inline void newLocalChain(const IntRing& ring, const PolygonEnergy::Change& c,
                          std::vector<cv::Point>& chain) {
  const int n = static_cast<int>(ring.size());
  auto at = [&](int i) { return ring[((c.first + i) % n + n) % n]; };
  chain.clear();
  chain.push_back(at(-2));
  chain.push_back(at(-1));
  for (const auto& v : c.inserted) chain.push_back(v);
  chain.push_back(at(c.removeCount));
  chain.push_back(at(c.removeCount + 1));
}

// Ids of the old edges (first vertex at -1 .. removeCount-1) and of the vertices whose prior
// changes (-1 .. removeCount), each sorted without repeats. `offset`: the ring's first id.
inline void replacedIds(const PolygonEnergy::Change& c, int n, int offset,
                        std::vector<int>& oldEdges, std::vector<int>& oldVertices) {
  auto idOf = [&](int i) { return offset + ((c.first + i) % n + n) % n; };
  oldEdges.clear();
  for (int i = -1; i < c.removeCount; ++i) oldEdges.push_back(idOf(i));
  std::sort(oldEdges.begin(), oldEdges.end());
  oldEdges.erase(std::unique(oldEdges.begin(), oldEdges.end()), oldEdges.end());
  oldVertices.clear();
  for (int i = -1; i <= c.removeCount; ++i) oldVertices.push_back(idOf(i));
  std::sort(oldVertices.begin(), oldVertices.end());
  oldVertices.erase(std::unique(oldVertices.begin(), oldVertices.end()), oldVertices.end());
}

// Rows crossed by an old or a new edge, [yLow, yHigh) within the image. Both chains run from
// at(-1) to at(removeCount) without a break, so together they cross exactly the rows between
// the lowest and the highest of their vertices.
inline std::pair<int, int> changedRows(const IntRing& ring, const PolygonEnergy::Change& c,
                                       const std::vector<cv::Point>& chain, int height) {
  const int n = static_cast<int>(ring.size());
  const int m = static_cast<int>(c.inserted.size());
  auto at = [&](int i) { return ring[((c.first + i) % n + n) % n]; };
  int yLow = chain[1].y, yHigh = chain[1].y;
  for (int i = 0; i <= c.removeCount; ++i) {
    yLow = std::min(yLow, at(i).y);
    yHigh = std::max(yHigh, at(i).y);
  }
  for (int i = 2; i <= m + 2; ++i) {
    yLow = std::min(yLow, chain[i].y);
    yHigh = std::max(yHigh, chain[i].y);
  }
  yLow = std::max(yLow, 0);
  yHigh = std::min(yHigh, height);
  return {yLow, yHigh};
}

// The new edges' crossings with rows [yLow, yHigh), bucketed by row (counting sort: start
// offsets per row, then fill). On return start[r] points past row r's crossings in `addedX`;
// row r's begin at start[r - 1] (0 for r = 0).
inline void bucketNewCrossings(const std::vector<cv::Point>& chain, int m, int yLow, int yHigh,
                               int height, std::vector<int>& start, std::vector<double>& addedX) {
  const int rowCount = yHigh - yLow;
  start.assign(static_cast<size_t>(rowCount) + 1, 0);
  for (int i = 1; i <= m + 1; ++i) {
    forEachCrossing(chain[i], chain[i + 1], height, [&](int y, double) { ++start[y - yLow + 1]; });
  }
  for (int r = 0; r < rowCount; ++r) start[r + 1] += start[r];
  addedX.resize(static_cast<size_t>(start[rowCount]));
  for (int i = 1; i <= m + 1; ++i) {
    forEachCrossing(chain[i], chain[i + 1], height, [&](int y, double x) {
      addedX[static_cast<size_t>(start[y - yLow]++)] = x;
    });
  }
}

}  // namespace

// The two steps of delta() that use its state are always inlined into it, as when they were its
// body: delta() runs for every candidate of the optimiser.

// Edge terms and priors: the old ones out, the new ones in. Old edges and priors from
// scratch_'s ids; new edges chain[1]→chain[2] ... chain[m+1]→chain[m+2]; new priors at
// chain[1..m+2].
__attribute__((always_inline)) inline double PolygonEnergy::contourDelta(const Change& c) const {
  const DeltaScratch& s = scratch_;
  const std::vector<cv::Point>& chain = s.chain;
  const int m = static_cast<int>(c.inserted.size());
  double d = 0.0;
  for (int e : s.oldEdges) d -= edgeTerms_[e][0] + edgeTerms_[e][1];
  for (int v : s.oldVertices) d -= vertexPriors_[v];
  for (int i = 1; i <= m + 1; ++i) {
    const auto& e = edgeTerms(chain[i], chain[i + 1], ringInwardLeft_[c.ring]);
    d += e[0] + e[1];
  }
  for (int i = 1; i <= m + 2; ++i) {
    d += weights_.rigidity * anglePrior(vertexAngle(chain[i - 1], chain[i], chain[i + 1]));
  }
  return d;
}

// Each row of [yLow, yHigh) re-evaluated with its old crossings of the replaced edges swapped
// for the new ones, its change added to `d` (row by row, in this order: the sum's rounding is
// part of the result).
__attribute__((always_inline)) inline void PolygonEnergy::addRowChanges(int yLow, int yHigh,
                                                                        double& d) const {
  DeltaScratch& s = scratch_;
  const std::vector<int>& oldEdges = s.oldEdges;
  const std::vector<int>& start = s.addedCount;
  const std::vector<double>& addedX = s.addedX;
  std::vector<double>& xs = s.xs;
  for (int y = yLow; y < yHigh; ++y) {
    xs.clear();
    for (const auto& k : rowCrossings_[y]) {
      if (!std::binary_search(oldEdges.begin(), oldEdges.end(), k.edge)) xs.push_back(k.x);
    }
    const int r = y - yLow;
    for (int j = r == 0 ? 0 : start[r - 1]; j < start[r]; ++j) xs.push_back(addedX[static_cast<size_t>(j)]);
    std::sort(xs.begin(), xs.end());
    const RowTerms now = rowTerms(y, xs);
    const RowTerms& before = rowTerms_[y];
    d += (now.roof - before.roof) + (now.ground - before.ground) + (now.band - before.band);
  }
}

double PolygonEnergy::delta(const Change& c) const {
  const IntRing& ring = polygon_.ring(c.ring);
  const int n = static_cast<int>(ring.size());
  const int m = static_cast<int>(c.inserted.size());
  if (n - c.removeCount + m < 3) return std::numeric_limits<double>::infinity();
  DeltaScratch& s = scratch_;
  newLocalChain(ring, c, s.chain);
  replacedIds(c, n, ringOffset_[c.ring], s.oldEdges, s.oldVertices);
  double d = contourDelta(c);
  // Area terms: rows crossed by an old or a new edge.
  const auto [yLow, yHigh] = changedRows(ring, c, s.chain, size_.height);
  if (yLow >= yHigh) return d;
  bucketNewCrossings(s.chain, m, yLow, yHigh, size_.height, s.addedCount, s.addedX);
  addRowChanges(yLow, yHigh, d);
  return d;
}

namespace {

// The steps of PolygonEnergy::valid(), in the order it runs them. `nr` is the changed ring of
// `after`, its changed edges start at the vertices `changedEdges`.

// Every inserted vertex within [0, W] x [0, H] and, with a mask, at a corner of an allowed pixel.
inline bool insertedVerticesAllowed(const std::vector<cv::Point>& inserted, cv::Size size,
                                    const cv::Mat& allowed) {
  for (const auto& v : inserted) {
    if (v.x < 0 || v.y < 0 || v.x > size.width || v.y > size.height) return false;
    if (!allowed.empty()) {
      bool near = false;
      for (int y = std::max(v.y - 1, 0); y <= std::min(v.y, size.height - 1) && !near; ++y) {
        for (int x = std::max(v.x - 1, 0); x <= std::min(v.x, size.width - 1) && !near; ++x) {
          near = allowed.at<uchar>(y, x) != 0;
        }
      }
      if (!near) return false;
    }
  }
  return true;
}

// A changed edge that is empty, folds back on a neighbour or touches another edge of any ring.
inline bool changedEdgesTouch(const IntPolygon& after, int changedRing,
                              const std::vector<int>& changedEdges) {
  const IntRing& nr = after.ring(changedRing);
  const int newN = static_cast<int>(nr.size());
  for (int e : changedEdges) {
    const cv::Point a = nr[e], b = nr[(e + 1) % newN];
    if (a == b) return true;
    for (int j = 0; j < newN; ++j) {
      if (j == e) continue;
      const cv::Point p = nr[j], q = nr[(j + 1) % newN];
      if (j == (e + 1) % newN) {  // shares b
        if (adjacentOverlap(b, a, q)) return true;
      } else if ((j + 1) % newN == e) {  // shares a
        if (adjacentOverlap(a, b, p)) return true;
      } else if (segmentsTouch(a, b, p, q)) {
        return true;
      }
    }
    for (size_t r = 0; r < after.ringCount(); ++r) {
      if (static_cast<int>(r) == changedRing) continue;
      const IntRing& other = after.ring(r);
      for (size_t j = 0; j < other.size(); ++j) {
        if (segmentsTouch(a, b, other[j], other[(j + 1) % other.size()])) return true;
      }
    }
  }
  return false;
}

// The change leaves a vertex around it sharper than `minAngle` degrees and sharper than the
// sharpest one there before (a sharp initial polygon can still improve). The inserted run
// starts at `start` in `nr`.
inline bool sharperSpike(const IntRing& ring, const PolygonEnergy::Change& c, const IntRing& nr,
                         int start, double minAngle) {
  const int n = static_cast<int>(ring.size());
  const int m = static_cast<int>(c.inserted.size());
  const int newN = static_cast<int>(nr.size());
  double oldMin = CV_PI, newMin = CV_PI;
  for (int i = -1; i <= c.removeCount; ++i) {
    const int k = ((c.first + i) % n + n) % n;
    oldMin = std::min(oldMin, vertexAngle(ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]));
  }
  for (int i = -1; i <= m; ++i) {
    const int k = ((start + i) % newN + newN) % newN;
    newMin = std::min(newMin, vertexAngle(nr[(k + newN - 1) % newN], nr[k], nr[(k + 1) % newN]));
  }
  return newMin < minAngle * CV_PI / 180.0 && newMin < oldMin;
}

// A changed edge closer than `minGap` to a non-adjacent edge pointing the opposite way: a
// finger or slit.
inline bool narrowGap(const IntPolygon& after, int changedRing,
                      const std::vector<int>& changedEdges, double minGap) {
  const IntRing& nr = after.ring(changedRing);
  const int newN = static_cast<int>(nr.size());
  for (int e : changedEdges) {
    const cv::Point a = nr[e], b = nr[(e + 1) % newN];
    for (size_t r = 0; r < after.ringCount(); ++r) {
      const IntRing& other = after.ring(r);
      const int k = static_cast<int>(other.size());
      for (int j = 0; j < k; ++j) {
        if (static_cast<int>(r) == changedRing && (j == e || j == (e + 1) % newN || (j + 1) % newN == e)) continue;
        if (antiparallelWithin(a, b, other[j], other[(j + 1) % k], minGap)) return true;
      }
    }
  }
  return false;
}

// A ring may jump over a whole small ring without crossing it: keep holes inside the outer
// ring and outside each other.
inline bool ringsStayNested(const IntPolygon& after, int changedRing) {
  const IntRing& nr = after.ring(changedRing);
  if (changedRing == 0) {
    for (const auto& h : after.holes) {
      if (!insideRing(nr, cv::Point2d(h[0]))) return false;
    }
  } else {
    if (!insideRing(after.outer, cv::Point2d(nr[0]))) return false;
    for (size_t r = 1; r < after.ringCount(); ++r) {
      if (static_cast<int>(r) == changedRing) continue;
      if (insideRing(nr, cv::Point2d(after.ring(r)[0]))) return false;
      if (insideRing(after.ring(r), cv::Point2d(nr[0]))) return false;
    }
  }
  return true;
}

}  // namespace

bool PolygonEnergy::valid(const Change& c) const {
  const IntRing& ring = polygon_.ring(c.ring);
  const int n = static_cast<int>(ring.size());
  const int m = static_cast<int>(c.inserted.size());
  const int newN = n - c.removeCount + m;
  if (newN < 3) return false;
  if (!insertedVerticesAllowed(c.inserted, size_, images_.allowed)) return false;
  const IntPolygon after = changed(c);
  const IntRing& nr = after.ring(c.ring);
  // In `nr` the inserted run starts at `start`; the changed edges start at start-1 .. start+m-1.
  const int start = c.first + c.removeCount <= n ? c.first : 0;
  std::vector<int> changedEdges;
  for (int i = -1; i < m; ++i) changedEdges.push_back(((start + i) % newN + newN) % newN);
  if (changedEdgesTouch(after, c.ring, changedEdges)) return false;
  const double before = ringArea2(ring), now = ringArea2(nr);
  if (now == 0 || (before > 0) != (now > 0)) return false;
  // Shape limits: no spike tip sharper than minAngle (unless the sharpest angle around the
  // change gets blunter, so that a sharp initial polygon can still improve) and no finger or
  // slit narrower than minGap.
  if (weights_.minAngle > 0 && sharperSpike(ring, c, nr, start, weights_.minAngle)) return false;
  if (weights_.minGap > 0 && narrowGap(after, c.ring, changedEdges, weights_.minGap)) return false;
  return ringsStayNested(after, c.ring);
}

void PolygonEnergy::apply(const Change& c) {
  polygon_ = changed(c);
  rebuild();
}

}  // namespace delineo::delineation
