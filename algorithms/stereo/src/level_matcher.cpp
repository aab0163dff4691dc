// One level of the adaptive-window NCC matcher.
//
// Two paths share the per-pixel search intervals:
//  - pixels whose template window holds no contour pixel (or all pixels when adaptive shapes are
//    off) use a square window; a band of rows is swept disparity by disparity with running
//    column sums of the product image, so a correlation costs O(1) per pixel and disparity;
//  - pixels with a contour inside their window get the adaptive shape S (4-connected flood fill
//    from the centre that does not cross contour pixels) and a direct NCC over S.
// Memory is bounded by a few rows per band: no cost volume is stored.
#include "level_matcher.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace delineo::stereo::detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kBandRows = 32;
// Variance (grey levels², images normalised to ~0..255) under which a window is flat: its NCC
// is meaningless.
constexpr double kFlatVariance = 0.01;

// Mean and standard deviation of every square window that lies inside the image and holds only
// valid pixels; ok = 0 elsewhere.
struct WindowStats {
  cv::Mat mean, sd;  // CV_32F
  cv::Mat ok;        // CV_8U
};

WindowStats windowStats(const cv::Mat& img, const cv::Mat& valid, int window) {
  cv::Mat sum, sqsum, count;
  cv::integral(img, sum, sqsum, CV_64F, CV_64F);
  cv::integral(valid, count, CV_32S);
  const int r = window / 2;
  const double n = static_cast<double>(window) * window;
  WindowStats s{cv::Mat(img.size(), CV_32F, cv::Scalar(0)), cv::Mat(img.size(), CV_32F, cv::Scalar(0)),
                cv::Mat(img.size(), CV_8U, cv::Scalar(0))};
  for (int y = r; y < img.rows - r; ++y) {
    const double* s0 = sum.ptr<double>(y - r);
    const double* s1 = sum.ptr<double>(y + r + 1);
    const double* q0 = sqsum.ptr<double>(y - r);
    const double* q1 = sqsum.ptr<double>(y + r + 1);
    const int* c0 = count.ptr<int>(y - r);
    const int* c1 = count.ptr<int>(y + r + 1);
    for (int x = r; x < img.cols - r; ++x) {
      const int a = x - r, b = x + r + 1;
      const int cnt = c1[b] - c1[a] - c0[b] + c0[a];
      if (cnt != static_cast<int>(n)) continue;
      const double m = (s1[b] - s1[a] - s0[b] + s0[a]) / n;
      const double var = (q1[b] - q1[a] - q0[b] + q0[a]) / n - m * m;
      if (var < kFlatVariance) continue;
      s.mean.at<float>(y, x) = static_cast<float>(m);
      s.sd.at<float>(y, x) = static_cast<float>(std::sqrt(var));
      s.ok.at<uchar>(y, x) = 1;
    }
  }
  return s;
}

// Best peak of one pixel's correlation surface with its 3x3 neighbourhood, built while the
// disparities are visited in increasing order.
struct PeakTracker {
  float best = -std::numeric_limits<float>::infinity();
  int bestD = 0;
  int bestK = 0;
  float prev[3] = {kNaN, kNaN, kNaN};   // scores at d - 1, per line shift
  float nb[3][3] = {{kNaN, kNaN, kNaN}, {kNaN, kNaN, kNaN}, {kNaN, kNaN, kNaN}};

  void reset() { *this = PeakTracker{}; }

  // scores[k] for line shift index k at disparity d; firstOfInterval: d - 1 was not visited.
  void update(int d, const float* scores, int K, bool firstOfInterval) {
    if (firstOfInterval) std::fill(prev, prev + 3, kNaN);
    if (d == bestD + 1) std::copy(scores, scores + K, nb[2]);
    int k = 0;
    float m = -std::numeric_limits<float>::infinity();
    for (int i = 0; i < K; ++i) {
      if (scores[i] > m) {  // NaN never wins
        m = scores[i];
        k = i;
      }
    }
    if (m > best) {
      best = m;
      bestD = d;
      bestK = k;
      std::copy(prev, prev + 3, nb[0]);
      std::fill(nb[1], nb[1] + 3, kNaN);
      std::copy(scores, scores + K, nb[1]);
      std::fill(nb[2], nb[2] + 3, kNaN);
    }
    std::fill(prev, prev + 3, kNaN);
    std::copy(scores, scores + K, prev);
  }
};

class LevelMatcher {
 public:
  LevelMatcher(const LevelInput& in, const LevelSettings& s, LevelOutput& out)
      : in_(in), s_(s), out_(out), W_(in.ref.cols), H_(in.ref.rows), r_(s.window / 2),
        n_(s.window * s.window), K_(2 * s.lineShift + 1) {
    refStats_ = windowStats(in.ref, in.refValid, s.window);
    otherStats_ = windowStats(in.other, in.otherValid, s.window);
    cv::multiply(in.other, in.other, otherSq_);
    if (s.adaptive) {
      cv::Mat edges = in.refEdges != 0;
      cv::dilate(edges, nearEdge_,
                 cv::getStructuringElement(cv::MORPH_RECT, cv::Size(s.window, s.window)));
    } else {
      nearEdge_ = cv::Mat::zeros(in.ref.size(), CV_8U);
    }
    out.disparity = cv::Mat(in.ref.size(), CV_32F, cv::Scalar(kNaN));
    out.lineShift = cv::Mat(in.ref.size(), CV_32F, cv::Scalar(kNaN));
    out.score = cv::Mat(in.ref.size(), CV_32F, cv::Scalar(kNaN));
  }

  bool run(core::Progress* progress) {
    const int bands = (H_ + kBandRows - 1) / kBandRows;
    std::atomic<int> next{0}, done{0};
    std::atomic<bool> canceled{false};
    auto worker = [&] {
      for (int b = next++; b < bands; b = next++) {
        if (canceled.load() || core::isCanceled(progress)) {
          canceled.store(true);
          return;
        }
        matchBand(b * kBandRows, std::min(H_, (b + 1) * kBandRows));
        core::report(progress, static_cast<double>(++done) / bands);
      }
    };
    const int threads = std::max(1, std::min(s_.threads, bands));
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
    return !canceled.load() && !core::isCanceled(progress);
  }

 private:
  enum PathKind : uchar { kSkip = 0, kSquare = 1, kShape = 2 };

  void matchBand(int y0, int y1) {
    const int rows = y1 - y0;
    std::vector<uchar> kind(static_cast<size_t>(rows) * W_, kSkip);
    // Adaptive shapes of this band, stored as offsets into the window (row-major, W x W).
    std::vector<std::vector<int>> shapes(static_cast<size_t>(rows) * W_);
    std::vector<uchar> mask(static_cast<size_t>(n_));
    std::vector<int> queue(static_cast<size_t>(n_));
    int dLo = std::numeric_limits<int>::max(), dHi = std::numeric_limits<int>::min();
    std::vector<int> rowLo(rows, dLo), rowHi(rows, dHi);
    for (int y = y0; y < y1; ++y) {
      const int* lo = in_.lo.ptr<int>(y);
      const int* hi = in_.hi.ptr<int>(y);
      const uchar* ok = refStats_.ok.ptr<uchar>(y);
      const uchar* near = nearEdge_.ptr<uchar>(y);
      for (int x = 0; x < W_; ++x) {
        const size_t i = static_cast<size_t>(y - y0) * W_ + x;
        if (lo[x] > hi[x] || !ok[x]) continue;
        if (near[x]) {
          std::vector<int> shape = buildShape(x, y, mask, queue);
          if (static_cast<int>(shape.size()) >= s_.minShape &&
              static_cast<int>(shape.size()) < n_) {
            shapes[i] = std::move(shape);
            kind[i] = kShape;
            continue;
          }
        }
        kind[i] = kSquare;
        dLo = std::min(dLo, lo[x]);
        dHi = std::max(dHi, hi[x]);
        rowLo[y - y0] = std::min(rowLo[y - y0], lo[x]);
        rowHi[y - y0] = std::max(rowHi[y - y0], hi[x]);
      }
    }
    if (dLo <= dHi) sweepSquare(y0, y1, dLo, dHi, kind, rowLo, rowHi);
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < W_; ++x) {
        const size_t i = static_cast<size_t>(y - y0) * W_ + x;
        if (kind[i] == kShape) matchShape(x, y, shapes[i]);
      }
    }
  }

  // Window pixels 4-connected to the centre without crossing a contour pixel. Contour pixels
  // themselves are left out: a step edge's contour pixel usually carries the brighter side's
  // grey level, and keeping it would let the step dominate the correlation of the other side.
  // A centre on a contour propagates to both sides (its side is undecidable). Returns offsets
  // relative to the centre in image row-major units (dy * W + dx).
  std::vector<int> buildShape(int x, int y, std::vector<uchar>& mask, std::vector<int>& queue) {
    const int w = s_.window;
    std::fill(mask.begin(), mask.end(), 0);
    int head = 0, tail = 0;
    const int centre = r_ * w + r_;
    mask[centre] = 1;
    queue[tail++] = centre;
    std::vector<int> offsets;
    offsets.reserve(static_cast<size_t>(n_));
    while (head < tail) {
      const int p = queue[head++];
      const int px = p % w, py = p / w;
      offsets.push_back((py - r_) * W_ + (px - r_));
      const int nx[4] = {px - 1, px + 1, px, px};
      const int ny[4] = {py, py, py - 1, py + 1};
      for (int k = 0; k < 4; ++k) {
        if (nx[k] < 0 || nx[k] >= w || ny[k] < 0 || ny[k] >= w) continue;
        const int q = ny[k] * w + nx[k];
        if (mask[q]) continue;
        mask[q] = 1;  // visited
        const int ix = x + nx[k] - r_, iy = y + ny[k] - r_;
        if (!in_.refValid.at<uchar>(iy, ix) || in_.refEdges.at<uchar>(iy, ix) != 0) continue;
        queue[tail++] = q;
      }
    }
    return offsets;
  }

  // Adds sign * ref(yy, x) * other(yy + dy, x - d) to col[x] for every x where both exist.
  void addProductRow(float* col, int yy, int dy, int d, float sign) const {
    if (yy < 0 || yy >= H_ || yy + dy < 0 || yy + dy >= H_) return;
    const float* a = in_.ref.ptr<float>(yy);
    const float* b = in_.other.ptr<float>(yy + dy);
    const int xs = std::max(0, d), xe = std::min(W_, W_ + d);
    for (int x = xs; x < xe; ++x) col[x] += sign * a[x] * b[x - d];
  }

  void sweepSquare(int y0, int y1, int dLo, int dHi, const std::vector<uchar>& kind,
                   const std::vector<int>& rowLo, const std::vector<int>& rowHi) {
    const int rows = y1 - y0;
    const int L = s_.lineShift;
    std::vector<PeakTracker> trackers(static_cast<size_t>(rows) * W_);
    std::vector<float> col(static_cast<size_t>(K_) * W_);
    std::vector<double> prefix(static_cast<size_t>(W_) + 1);
    std::vector<float> scores(static_cast<size_t>(K_) * W_);
    const float invN = 1.0F / static_cast<float>(n_);
    for (int d = dLo; d <= dHi; ++d) {
      std::fill(col.begin(), col.end(), 0.0F);
      for (int k = 0; k < K_; ++k) {
        for (int yy = y0 - r_; yy <= y0 + r_; ++yy) addProductRow(&col[k * W_], yy, k - L, d, 1);
      }
      for (int y = y0; y < y1; ++y) {
        if (y > y0) {
          for (int k = 0; k < K_; ++k) {
            addProductRow(&col[k * W_], y + r_, k - L, d, 1.0F);
            addProductRow(&col[k * W_], y - r_ - 1, k - L, d, -1.0F);
          }
        }
        const int ry = y - y0;
        if (d < rowLo[ry] || d > rowHi[ry]) continue;
        const int* lo = in_.lo.ptr<int>(y);
        const int* hi = in_.hi.ptr<int>(y);
        const float* meanA = refStats_.mean.ptr<float>(y);
        const float* sdA = refStats_.sd.ptr<float>(y);
        for (int k = 0; k < K_; ++k) {
          const int yb = y + k - L;
          float* sc = &scores[k * W_];
          const float* c = &col[k * W_];
          prefix[0] = 0.0;
          for (int x = 0; x < W_; ++x) prefix[x + 1] = prefix[x] + c[x];
          const bool rowInside = yb >= 0 && yb < H_;
          const float* meanB = rowInside ? otherStats_.mean.ptr<float>(yb) : nullptr;
          const float* sdB = rowInside ? otherStats_.sd.ptr<float>(yb) : nullptr;
          const uchar* okB = rowInside ? otherStats_.ok.ptr<uchar>(yb) : nullptr;
          for (int x = 0; x < W_; ++x) {
            sc[x] = kNaN;
            if (!rowInside || kind[static_cast<size_t>(ry) * W_ + x] != kSquare || d < lo[x] ||
                d > hi[x]) {
              continue;
            }
            const int xb = x - d;
            if (xb < 0 || xb >= W_ || !okB[xb]) continue;
            const float sab = static_cast<float>(prefix[x + r_ + 1] - prefix[x - r_]);
            sc[x] = (sab * invN - meanA[x] * meanB[xb]) / (sdA[x] * sdB[xb]);
          }
        }
        float column[3];
        for (int x = 0; x < W_; ++x) {
          if (kind[static_cast<size_t>(ry) * W_ + x] != kSquare || d < lo[x] || d > hi[x]) continue;
          for (int k = 0; k < K_; ++k) column[k] = scores[k * W_ + x];
          trackers[static_cast<size_t>(ry) * W_ + x].update(d, column, K_, d == lo[x]);
        }
      }
    }
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < W_; ++x) {
        const size_t i = static_cast<size_t>(y - y0) * W_ + x;
        if (kind[i] == kSquare) finish(x, y, trackers[i]);
      }
    }
  }

  void matchShape(int x, int y, const std::vector<int>& shape) {
    const int L = s_.lineShift;
    const int w = s_.window;
    const int lo = in_.lo.at<int>(y, x), hi = in_.hi.at<int>(y, x);
    // Template T = (A - mean_S) / sd_S on S and 0 elsewhere, and the indicator M of S, both
    // dense w x w: NCC = sum(T * B) / (|S| sd_S(B)). Dense rows keep the inner loops
    // element-wise (vectorisable) instead of gathers over S.
    const float* base = in_.ref.ptr<float>(y) + x;
    double sum = 0, sq = 0;
    for (int off : shape) {
      const double v = base[off];
      sum += v;
      sq += v * v;
    }
    const double count = static_cast<double>(shape.size());
    const double mean = sum / count;
    const double var = sq / count - mean * mean;
    if (var < kFlatVariance) return;
    const double sd = std::sqrt(var);
    std::vector<float> templ(static_cast<size_t>(n_), 0.0F), mask(static_cast<size_t>(n_), 0.0F);
    for (int off : shape) {
      // off = dy * W + dx with |dx|, |dy| <= r: recover the window cell.
      const int dy = (off + r_ * W_ + r_) / W_ - r_;
      const int dx = off - dy * W_;
      const size_t cell = static_cast<size_t>((dy + r_) * w + (dx + r_));
      templ[cell] = static_cast<float>((base[off] - mean) / sd);
      mask[cell] = 1.0F;
    }
    // First and last window rows holding part of S: rows outside are skipped.
    int rowFirst = w, rowLast = -1;
    for (int v = 0; v < w; ++v) {
      for (int u = 0; u < w; ++u) {
        if (mask[static_cast<size_t>(v * w + u)] != 0.0F) {
          rowFirst = std::min(rowFirst, v);
          rowLast = std::max(rowLast, v);
        }
      }
    }
    PeakTracker tracker;
    float column[3];
    const float invCount = static_cast<float>(1.0 / count);
    std::vector<float> accB(static_cast<size_t>(w)), accBB(static_cast<size_t>(w)),
        accTB(static_cast<size_t>(w));
    for (int d = lo; d <= hi; ++d) {
      for (int k = 0; k < K_; ++k) {
        column[k] = kNaN;
        const int yb = y + k - L, xb = x - d;
        if (yb < 0 || yb >= H_ || xb < 0 || xb >= W_ || !otherStats_.ok.at<uchar>(yb, xb)) continue;
        std::fill(accB.begin(), accB.end(), 0.0F);
        std::fill(accBB.begin(), accBB.end(), 0.0F);
        std::fill(accTB.begin(), accTB.end(), 0.0F);
        for (int v = rowFirst; v <= rowLast; ++v) {
          const float* b = in_.other.ptr<float>(yb + v - r_) + xb - r_;
          const float* b2 = otherSq_.ptr<float>(yb + v - r_) + xb - r_;
          const float* m = &mask[static_cast<size_t>(v * w)];
          const float* t = &templ[static_cast<size_t>(v * w)];
          for (int u = 0; u < w; ++u) {
            accB[u] += m[u] * b[u];
            accBB[u] += m[u] * b2[u];
            accTB[u] += t[u] * b[u];
          }
        }
        float sB = 0, sBB = 0, sTB = 0;
        for (int u = 0; u < w; ++u) {
          sB += accB[u];
          sBB += accBB[u];
          sTB += accTB[u];
        }
        const float meanB = sB * invCount;
        const float varB = sBB * invCount - meanB * meanB;
        if (varB < static_cast<float>(kFlatVariance)) continue;
        column[k] = sTB * invCount / std::sqrt(varB);
      }
      tracker.update(d, column, K_, d == lo);
    }
    finish(x, y, tracker);
  }

  void finish(int x, int y, const PeakTracker& t) {
    if (!(t.best >= static_cast<float>(s_.minScore))) return;
    const int lo = in_.lo.at<int>(y, x), hi = in_.hi.at<int>(y, x);
    // A peak on the border of a guided interval is a slope, not a peak: the true maximum lies
    // outside the interval.
    if ((t.bestD == lo && lo > in_.dmin) || (t.bestD == hi && hi < in_.dmax)) return;
    float du = 0, dv = 0;
    if (s_.subpixel) {
      float s[3][3];
      bool lineNeighbours = true;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          const int k = t.bestK + j - 1;
          s[i][j] = (k >= 0 && k < K_) ? t.nb[i][k] : kNaN;
          if (j != 1 && !std::isfinite(s[i][j])) lineNeighbours = false;
        }
      }
      const cv::Point2f off = subpixelPeak(s, lineNeighbours);
      du = off.x;
      dv = off.y;
    }
    out_.disparity.at<float>(y, x) = static_cast<float>(t.bestD) + du;
    out_.lineShift.at<float>(y, x) = static_cast<float>(t.bestK - s_.lineShift) + dv;
    out_.score.at<float>(y, x) = std::min(t.best, 1.0F);
  }

  const LevelInput& in_;
  const LevelSettings& s_;
  LevelOutput& out_;
  const int W_, H_, r_, n_, K_;
  WindowStats refStats_, otherStats_;
  cv::Mat otherSq_;
  cv::Mat nearEdge_;
};

}  // namespace

cv::Point2f subpixelPeak(const float s[3][3], bool haveLineNeighbours) {
  bool all = haveLineNeighbours;
  for (int i = 0; i < 3 && all; ++i) {
    for (int j = 0; j < 3; ++j) all = all && std::isfinite(s[i][j]);
  }
  if (all) {
    // Least-squares quadratic a + b u + c v + e u² + f v² + g uv over the 3x3 grid.
    double rowSum[3] = {0, 0, 0}, colSum[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        rowSum[i] += s[i][j];
        colSum[j] += s[i][j];
      }
    }
    const double b = (rowSum[2] - rowSum[0]) / 6.0;
    const double c = (colSum[2] - colSum[0]) / 6.0;
    const double e = (rowSum[2] + rowSum[0] - 2.0 * rowSum[1]) / 6.0;
    const double f = (colSum[2] + colSum[0] - 2.0 * colSum[1]) / 6.0;
    const double g = (s[2][2] - s[2][0] - s[0][2] + s[0][0]) / 4.0;
    const double det = 4.0 * e * f - g * g;
    if (e < 0 && det > 0) {
      const double u = (g * c - 2.0 * f * b) / det;
      const double v = (g * b - 2.0 * e * c) / det;
      if (std::abs(u) <= 1.0 && std::abs(v) <= 1.0) {
        return {static_cast<float>(u), static_cast<float>(v)};
      }
    }
  }
  // Separable parabolas through the peak row and column.
  auto parabola = [](float m, float c0, float p) -> float {
    if (!std::isfinite(m) || !std::isfinite(p)) return 0.0F;
    const float denom = m - 2.0F * c0 + p;
    if (!(denom < 0.0F)) return 0.0F;
    return std::clamp(0.5F * (m - p) / denom, -1.0F, 1.0F);
  };
  return {parabola(s[0][1], s[1][1], s[2][1]), parabola(s[1][0], s[1][1], s[1][2])};
}

bool matchLevel(const LevelInput& in, const LevelSettings& settings, LevelOutput& out,
                core::Progress* progress) {
  LevelMatcher matcher(in, settings, out);
  return matcher.run(progress);
}

}  // namespace delineo::stereo::detail
