// Stage 3 of box-fitting: one box per seed, grown in the segment and fitted to the Canny edges
// over a sweep of orientations.
//
// For each orientation θ the ROI is turned by -θ into a square "frame" where boxes at θ are
// axis-aligned: a box side is then a row or a column segment, and prefix sums along rows and
// columns give, in constant time, how much of a side lies in the segment and its summed edge
// distance. All seeds are evaluated in one frame before the next is built, so only one frame is
// held at a time and the cost of the sweep is the number of frames, not of seeds.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/boxfit/stages.hpp"

namespace delineo::boxfit {

namespace {

constexpr double kPi = 3.14159265358979323846;

// A box in a frame: columns [x0, x1) and rows [y0, y1) (boundaries between pixels).
struct FrameBox {
  int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

class Frame {
 public:
  // `inside` CV_8U 0/1 and `edgeCost` CV_32F (capped edge distance) of the ROI.
  Frame(const cv::Mat& inside, const cv::Mat& edgeCost, double cap, double angleDeg) : angle_(angleDeg) {
    const double diagonal = std::hypot(inside.cols, inside.rows);
    side_ = static_cast<int>(std::ceil(diagonal)) + 2;
    const double t = angleDeg * kPi / 180.0, c = std::cos(t), s = std::sin(t);
    const cv::Point2d roiCentre(0.5 * inside.cols, 0.5 * inside.rows), frameCentre(0.5 * side_, 0.5 * side_);
    // Frame → ROI in continuous coordinates: p = R(θ)(q - frameCentre) + roiCentre.
    toRoi_ = cv::Matx23d(c, -s, roiCentre.x - (c * frameCentre.x - s * frameCentre.y),  //
                         s, c, roiCentre.y - (s * frameCentre.x + c * frameCentre.y));
    toFrame_ = cv::Matx23d(c, s, frameCentre.x - (c * roiCentre.x + s * roiCentre.y),  //
                           -s, c, frameCentre.y - (-s * roiCentre.x + c * roiCentre.y));
    // warpAffine's inverse map works on pixel indices (centre = index + 0.5).
    cv::Matx23d indexMap = toRoi_;
    indexMap(0, 2) += 0.5 * (toRoi_(0, 0) + toRoi_(0, 1)) - 0.5;
    indexMap(1, 2) += 0.5 * (toRoi_(1, 0) + toRoi_(1, 1)) - 0.5;
    const cv::Size size(side_, side_);
    cv::Mat segment, cost;
    cv::warpAffine(inside, segment, indexMap, size, cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                   cv::BORDER_CONSTANT, 0);
    cv::warpAffine(edgeCost, cost, indexMap, size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                   cv::BORDER_CONSTANT, cap);
    buildSums(segment, cost, cap);
  }

  int side() const { return side_; }
  double angle() const { return angle_; }
  cv::Point2d toFrame(const cv::Point2d& p) const { return apply(toFrame_, p); }
  cv::Point2d toRoi(const cv::Point2d& q) const { return apply(toRoi_, q); }

  // Segment pixels in column x, rows [y0, y1); in row y, columns [x0, x1).
  int insideColumn(int x, int y0, int y1) const { return colInside_.at<int>(y1, x) - colInside_.at<int>(y0, x); }
  int insideRow(int y, int x0, int x1) const { return rowInside_.at<int>(y, x1) - rowInside_.at<int>(y, x0); }
  // Summed edge cost of the vertical boundary at x (between columns x-1 and x), rows [y0, y1);
  // of the horizontal boundary at y, columns [x0, x1).
  double costVertical(int x, int y0, int y1) const { return colCost_.at<float>(y1, x) - colCost_.at<float>(y0, x); }
  double costHorizontal(int y, int x0, int x1) const { return rowCost_.at<float>(y, x1) - rowCost_.at<float>(y, x0); }

 private:
  static cv::Point2d apply(const cv::Matx23d& m, const cv::Point2d& p) {
    return {m(0, 0) * p.x + m(0, 1) * p.y + m(0, 2), m(1, 0) * p.x + m(1, 1) * p.y + m(1, 2)};
  }

  // Prefix sums: along columns (for vertical sides) and along rows (for horizontal sides). The
  // cost of a boundary is the lower of the two pixels it separates: Canny marks one of them.
  void buildSums(const cv::Mat& segment, const cv::Mat& cost, double cap) {
    const int n = side_;
    colInside_.create(n + 1, n, CV_32S);
    rowInside_.create(n, n + 1, CV_32S);
    colCost_.create(n + 1, n + 1, CV_32F);
    rowCost_.create(n + 1, n + 1, CV_32F);
    colInside_.row(0).setTo(0);
    colCost_.row(0).setTo(0);
    const float capF = static_cast<float>(cap);
    for (int y = 0; y < n; ++y) {
      const uchar* s = segment.ptr<uchar>(y);
      const float* c = cost.ptr<float>(y);
      const int* prevInside = colInside_.ptr<int>(y);
      int* nextInside = colInside_.ptr<int>(y + 1);
      const float* prevCost = colCost_.ptr<float>(y);
      float* nextCost = colCost_.ptr<float>(y + 1);
      int* rowIn = rowInside_.ptr<int>(y);
      float* rowC = rowCost_.ptr<float>(y);
      rowIn[0] = 0;
      rowC[0] = 0;
      for (int x = 0; x < n; ++x) {
        nextInside[x] = prevInside[x] + s[x];
        rowIn[x + 1] = rowIn[x] + s[x];
      }
      for (int x = 0; x <= n; ++x) {
        const float left = x > 0 ? c[x - 1] : capF, right = x < n ? c[x] : capF;
        nextCost[x] = prevCost[x] + std::min(left, right);
      }
      // Horizontal boundary at y (between rows y-1 and y), summed along the row.
      const float* above = y > 0 ? cost.ptr<float>(y - 1) : nullptr;
      for (int x = 0; x < n; ++x) {
        const float up = above ? above[x] : capF;
        rowC[x + 1] = rowC[x] + std::min(up, c[x]);
      }
    }
    // The bottom boundary (y = n) borders the outside only.
    float* last = rowCost_.ptr<float>(n);
    last[0] = 0;
    const float* bottom = cost.ptr<float>(n - 1);
    for (int x = 0; x < n; ++x) last[x + 1] = last[x] + std::min(bottom[x], capF);
  }

  double angle_;
  int side_ = 0;
  cv::Matx23d toRoi_, toFrame_;
  cv::Mat colInside_, rowInside_, colCost_, rowCost_;
};

struct SeedFit {
  FrameBox box;
  double energy = 1e300;
  bool ok = false;
};

struct Fitted {
  Box box;  // ROI coordinates
  bool ok = false;
};

// The summed cost of a box side at a frame boundary: the capped distance of its pixels to the
// nearest edge (the paper's energy) plus, weighted by segment-weight, the cap for each pixel
// where the segment disagrees with the side (a segment pixel just outside it, a non-segment
// pixel just inside it), counted half each. Edges then place a side within the segment's
// blurred border, and where the image has no edge (a roof as bright as the street) or edges
// inside the roof (tiles, ridges) the segment decides.
class SideCosts {
 public:
  SideCosts(const Frame& f, const BoxFitParams& p) : f_(f), weight_(0.5 * p.segmentWeight * p.edgeCap) {}
  // Vertical sides at boundary x over rows [y0, y1): the box lies right of a left side.
  double left(int x, int y0, int y1) const { return f_.costVertical(x, y0, y1) + disagree(column(x, y0, y1), column(x - 1, y0, y1), y1 - y0); }
  double right(int x, int y0, int y1) const { return f_.costVertical(x, y0, y1) + disagree(column(x - 1, y0, y1), column(x, y0, y1), y1 - y0); }
  double top(int y, int x0, int x1) const { return f_.costHorizontal(y, x0, x1) + disagree(row(y, x0, x1), row(y - 1, x0, x1), x1 - x0); }
  double bottom(int y, int x0, int x1) const { return f_.costHorizontal(y, x0, x1) + disagree(row(y - 1, x0, x1), row(y, x0, x1), x1 - x0); }

 private:
  int column(int x, int y0, int y1) const { return x >= 0 && x < f_.side() ? f_.insideColumn(x, y0, y1) : 0; }
  int row(int y, int x0, int x1) const { return y >= 0 && y < f_.side() ? f_.insideRow(y, x0, x1) : 0; }
  double disagree(int insideIn, int insideOut, int length) const { return weight_ * ((length - insideIn) + insideOut); }
  const Frame& f_;
  double weight_;
};

// Grows the box from a square around the seed while each new row or column is mostly in the
// segment, then moves each side onto the best-fitting edge near where it stopped.
SeedFit fitInFrame(const Frame& f, const Seed& seed, const BoxFitParams& params) {
  SeedFit fit;
  const cv::Point2d q = f.toFrame(cv::Point2d(seed.point) + cv::Point2d(0.5, 0.5));
  const int cx = static_cast<int>(std::floor(q.x)), cy = static_cast<int>(std::floor(q.y));
  const int n = f.side();
  const int half = static_cast<int>(std::ceil(0.5 * seed.window));
  const int wx0 = std::max(0, cx - half), wx1 = std::min(n, cx + half + 1);
  const int wy0 = std::max(0, cy - half), wy1 = std::min(n, cy + half + 1);
  const int h0 = std::max(1, static_cast<int>(seed.depth / std::sqrt(2.0) - 0.5));
  FrameBox b{std::max(wx0, cx - h0 + 1), std::min(wx1, cx + h0), std::max(wy0, cy - h0 + 1), std::min(wy1, cy + h0)};
  if (b.width() < 1 || b.height() < 1) return fit;
  const double need = params.stripInside;
  for (bool grew = true; grew;) {
    grew = false;
    if (b.x0 > wx0 && f.insideColumn(b.x0 - 1, b.y0, b.y1) >= need * b.height()) --b.x0, grew = true;
    if (b.x1 < wx1 && f.insideColumn(b.x1, b.y0, b.y1) >= need * b.height()) ++b.x1, grew = true;
    if (b.y0 > wy0 && f.insideRow(b.y0 - 1, b.x0, b.x1) >= need * b.width()) --b.y0, grew = true;
    if (b.y1 < wy1 && f.insideRow(b.y1, b.x0, b.x1) >= need * b.width()) ++b.y1, grew = true;
  }
  // Snapping: each side takes, within snap-inward / snap-outward of where the segment stopped it,
  // the position of lowest cost (a small pull towards the grown position breaks ties). Two
  // rounds, since each side's length depends on the others.
  const FrameBox grown = b;
  constexpr double kPull = 0.01;  // px of edge distance per px moved
  const int in = params.snapInward, out = params.snapOutward;
  const SideCosts side(f, params);
  for (int round = 0; round < 2; ++round) {
    auto best = [&](int from, int to, int home, auto cost) {
      int pos = home;
      double lowest = 1e300;
      for (int v = from; v <= to; ++v) {
        const double c = cost(v) + kPull * std::abs(v - home);
        if (c < lowest) lowest = c, pos = v;
      }
      return pos;
    };
    const double h = b.height(), w = b.width();
    b.x0 = best(std::max(wx0, grown.x0 - out), std::min(b.x1 - 2, grown.x0 + in), grown.x0,
                [&](int x) { return side.left(x, b.y0, b.y1) / h; });
    b.x1 = best(std::max(b.x0 + 2, grown.x1 - in), std::min(wx1, grown.x1 + out), grown.x1,
                [&](int x) { return side.right(x, b.y0, b.y1) / h; });
    b.y0 = best(std::max(wy0, grown.y0 - out), std::min(b.y1 - 2, grown.y0 + in), grown.y0,
                [&](int y) { return side.top(y, b.x0, b.x1) / w; });
    b.y1 = best(std::max(b.y0 + 2, grown.y1 - in), std::min(wy1, grown.y1 + out), grown.y1,
                [&](int y) { return side.bottom(y, b.x0, b.x1) / w; });
  }
  if (b.width() < 2 || b.height() < 2) return fit;
  const double sum = side.left(b.x0, b.y0, b.y1) + side.right(b.x1, b.y0, b.y1) + side.top(b.y0, b.x0, b.x1) +
                     side.bottom(b.y1, b.x0, b.x1);
  fit.box = b;
  fit.energy = sum / (2.0 * (b.width() + b.height()));
  fit.ok = true;
  return fit;
}

Box toBox(const Frame& f, const FrameBox& b, double energy, const Seed& seed) {
  Box box;
  box.centre = f.toRoi({0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1)});
  box.length = b.width();
  box.width = b.height();
  box.angleDeg = f.angle();
  box.energy = energy;
  box.seed = cv::Point2d(seed.point) + cv::Point2d(0.5, 0.5);
  return box;
}

// Angles on the grid of `step` degrees in [0, 90).
int angleKey(double deg, double resolution) {
  const int steps = static_cast<int>(std::lround(90.0 / resolution));
  int k = static_cast<int>(std::lround(deg / resolution)) % steps;
  return k < 0 ? k + steps : k;
}

// Capped distance to the nearest edge, with the image's own border counting as an edge on the
// sides where the ROI touches it (a building cut by the border has no edge there).
cv::Mat edgeCost(const cv::Mat& edges, const cv::Vec4b& imageBorder, double cap) {
  const int l = imageBorder[0] ? 1 : 0, t = imageBorder[1] ? 1 : 0, r = imageBorder[2] ? 1 : 0,
            b = imageBorder[3] ? 1 : 0;
  cv::Mat padded;
  cv::copyMakeBorder(edges, padded, t, b, l, r, cv::BORDER_CONSTANT, 255);
  cv::Mat distance;
  cv::distanceTransform(padded == 0, distance, cv::DIST_L2, 5);
  cv::Mat cost = distance(cv::Rect(l, t, edges.cols, edges.rows)).clone();
  cv::min(cost, cap, cost);
  return cost;
}

// The building's main orientation: the peak of the boxes' orientations (modulo 90°, weighted
// by area, smoothed over ±2°).
double mainOrientation(const std::vector<Box>& boxes) {
  std::vector<double> histogram(90, 0.0);
  for (const auto& b : boxes) {
    histogram[static_cast<size_t>(angleKey(b.angleDeg, 1.0))] += b.area();
  }
  int best = 0;
  double top = -1;
  for (int a = 0; a < 90; ++a) {
    double s = 0;
    for (int k = -2; k <= 2; ++k) s += histogram[static_cast<size_t>((a + k + 90) % 90)];
    if (s > top) top = s, best = a;
  }
  return best;
}

}  // namespace

core::Ring Box::corners() const {
  const double t = angleDeg * kPi / 180.0;
  const cv::Point2d u(std::cos(t), std::sin(t)), v(-std::sin(t), std::cos(t));
  const cv::Point2d a = 0.5 * length * u, b = 0.5 * width * v;
  return {centre - a - b, centre + a - b, centre + a + b, centre - a + b};
}

core::Ring Box::cornersWithin(cv::Size size) const {
  // Sutherland-Hodgman against the four sides of the image.
  core::Ring ring = corners();
  const auto clip = [&ring](auto inside, auto cross) {
    core::Ring out;
    for (size_t i = 0; i < ring.size(); ++i) {
      const cv::Point2d& a = ring[i];
      const cv::Point2d& b = ring[(i + 1) % ring.size()];
      if (inside(a)) out.push_back(a);
      if (inside(a) != inside(b)) out.push_back(cross(a, b));
    }
    ring = std::move(out);
  };
  const double w = size.width, h = size.height;
  const auto atX = [](double x) {
    return [x](const cv::Point2d& a, const cv::Point2d& b) { return cv::Point2d(x, a.y + (x - a.x) * (b.y - a.y) / (b.x - a.x)); };
  };
  const auto atY = [](double y) {
    return [y](const cv::Point2d& a, const cv::Point2d& b) { return cv::Point2d(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y), y); };
  };
  clip([](const cv::Point2d& p) { return p.x >= 0.0; }, atX(0.0));
  clip([w](const cv::Point2d& p) { return p.x <= w; }, atX(w));
  clip([](const cv::Point2d& p) { return p.y >= 0.0; }, atY(0.0));
  clip([h](const cv::Point2d& p) { return p.y <= h; }, atY(h));
  return ring.size() >= 3 ? ring : core::Ring{};
}

namespace {

// The sweep over orientations of fitSeedBoxes: every seed fitted in one frame per angle, the
// angles kept per seed, and the choice of each seed's box.
class SeedBoxSweep {
 public:
  SeedBoxSweep(const cv::Mat& segment, const cv::Mat& edges, const std::vector<Seed>& seeds,
               const BoxFitParams& params, const cv::Vec4b& imageBorder, core::Progress* progress,
               BoxFitting& out)
      : seeds_(seeds), params_(params), progress_(progress), out_(out), fits_(seeds.size()) {
    inside_ = segment / 255;
    cost_ = edgeCost(edges, imageBorder, params.edgeCap);
    resolution_ = params.angleResolution > 0 ? std::min(params.angleResolution, params.angleStep) : params.angleStep;
  }

  // Sweep over a quarter turn (a box at θ + 90° is the same box). False when canceled.
  bool quarterTurn() {
    std::set<int> sweep;
    for (double a = 0; a < 90.0 - 1e-9; a += params_.angleStep) sweep.insert(angleKey(a, resolution_));
    return evaluate(sweep, everySeed(sweep.size()), 0.0, 0.6);
  }

  // Refinement around each seed's best angle on the resolution grid. False when canceled.
  bool refineBestAngles() {
    if (!(params_.angleResolution > 0 && resolution_ < params_.angleStep)) return true;
    std::map<int, std::vector<size_t>> wanted;
    const int reach = static_cast<int>(std::ceil(params_.angleStep / resolution_)) - 1;
    for (size_t s = 0; s < seeds_.size(); ++s) {
      const int key = bestKey(s);
      if (key < 0) continue;
      for (int d = -reach; d <= reach; ++d) {
        const int k = angleKey((key + d) * resolution_, resolution_);
        if (!done_.count(k)) wanted[k].push_back(s);
      }
    }
    std::set<int> keys;
    std::vector<std::vector<size_t>> who;
    for (auto& [k, list] : wanted) keys.insert(k), who.push_back(list);
    return evaluate(keys, who, 0.6, 0.9);
  }

  // Each seed's best box; the building's main orientation (reported, and counted among the boxes).
  void keepBestBoxes() {
    std::vector<int> chosen(seeds_.size(), -1);
    std::vector<Box> best;
    for (size_t s = 0; s < seeds_.size(); ++s) {
      chosen[s] = bestKey(s);
      if (chosen[s] >= 0) best.push_back(fits_[s][chosen[s]].box);
    }
    if (best.empty()) return;
    out_.mainOrientationDeg = mainOrientation(best);
    const int mainKey = angleKey(out_.mainOrientationDeg, resolution_);
    // Deepest seeds first; a seed inside an earlier box adds nothing (skip-covered).
    for (size_t s = 0; s < seeds_.size(); ++s) {
      if (chosen[s] < 0) continue;
      const Box& box = fits_[s][chosen[s]].box;
      if (params_.skipCovered) {
        const cv::Point2d p = box.seed;
        const bool covered = std::any_of(out_.boxes.begin(), out_.boxes.end(), [&](const Box& b) {
          const core::Ring c = b.corners();
          return cv::pointPolygonTest(std::vector<cv::Point2f>(c.begin(), c.end()), cv::Point2f(p), false) > 0;
        });
        if (covered) {
          ++out_.seedsSkipped;
          continue;
        }
      }
      out_.boxes.push_back(box);
      out_.boxesAtMainOrientation += chosen[s] == mainKey;
    }
  }

 private:
  // Fits the seeds `who[k]` in the frame of the k-th of `keys`, progress going from `from` to
  // `to`. False when canceled.
  bool evaluate(const std::set<int>& keys, const std::vector<std::vector<size_t>>& who, double from, double to) {
    size_t k = 0;
    for (int key : keys) {
      if (core::isCanceled(progress_)) return false;
      const Frame frame(inside_, cost_, params_.edgeCap, key * resolution_);
      ++out_.anglesEvaluated;
      done_.insert(key);
      for (size_t s : who[k]) {
        const SeedFit fit = fitInFrame(frame, seeds_[s], params_);
        fits_[s][key] = {fit.ok ? toBox(frame, fit.box, fit.energy, seeds_[s]) : Box{}, fit.ok};
      }
      ++k;
      core::report(progress_, from + (to - from) * static_cast<double>(k) / static_cast<double>(keys.size()));
    }
    return true;
  }

  std::vector<std::vector<size_t>> everySeed(size_t count) const {
    std::vector<size_t> all(seeds_.size());
    for (size_t s = 0; s < all.size(); ++s) all[s] = s;
    return std::vector<std::vector<size_t>>(count, all);
  }

  // A seed's best angle: the box of lowest energy, the largest among equals (without edges every
  // angle costs the cap, and the box that fills the segment wins).
  int bestKey(size_t s) const {
    double lowest = 1e300;
    for (const auto& [k, fit] : fits_[s]) {
      if (fit.ok) lowest = std::min(lowest, fit.box.energy);
    }
    int key = -1;
    double area = -1;
    for (const auto& [k, fit] : fits_[s]) {
      if (fit.ok && fit.box.energy <= lowest && fit.box.area() > area) area = fit.box.area(), key = k;
    }
    return key;
  }

  const std::vector<Seed>& seeds_;
  const BoxFitParams& params_;
  core::Progress* progress_;
  BoxFitting& out_;
  cv::Mat inside_, cost_;    // the segment as 0/1, the capped edge distance
  double resolution_ = 0.0;  // degrees between angle keys
  // Per seed: the fit at every evaluated angle (key on the resolution grid).
  std::vector<std::map<int, Fitted>> fits_;
  std::set<int> done_;  // the angle keys evaluated
};

}  // namespace

BoxFitting fitSeedBoxes(const cv::Mat& segment, const cv::Mat& edges, const std::vector<Seed>& seeds,
                        const BoxFitParams& params, const cv::Vec4b& imageBorder, core::Progress* progress) {
  BoxFitting out;
  if (seeds.empty()) return out;
  SeedBoxSweep sweep(segment, edges, seeds, params, imageBorder, progress, out);
  if (!sweep.quarterTurn() || !sweep.refineBestAngles()) {
    out.status = core::RunStatus::Canceled;
    return out;
  }
  sweep.keepBestBoxes();
  return out;
}

}  // namespace delineo::boxfit
