// Plain regions matched by their shape (plain_regions.hpp).
#include "plain_regions.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "radiometry.hpp"

namespace delineo::stereo::detail {

namespace {

constexpr int kWindow = 5;          // px, side of the local standard deviation's window
constexpr double kSigmas = 3.0;     // a plain pixel's deviation is within this many noise sigmas
constexpr double kMinDeviation = 1.5;  // grey levels: floor of that limit (8-bit quantisation)
constexpr double kSharedRows = 0.8;  // share of its rows a region shares with its pair
constexpr double kGreyTolerance = 20.0;  // grey levels, of the views' 0..255 stretches
constexpr int kShiftSearch = 2;     // px, shifts tried around the centroids' difference (plus
                                    // a tenth of the regions' width: leaks move a centroid)
constexpr double kClearlyBetter = 0.15;  // overlap: a pairing's lead over the regions' next one

struct Region {
  int label = 0;
  cv::Rect box;
  int area = 0;
  double cx = 0, cy = 0;
  double grey = 0;
};

struct LabelledView {
  cv::Mat labels;  // CV_32S, 0 = not plain
  std::vector<Region> regions;
};

LabelledView plainRegions(const cv::Mat& grey, const cv::Mat& mask, int minArea) {
  cv::Mat f, mean, square;
  grey.convertTo(f, CV_32F);
  cv::boxFilter(f, mean, CV_32F, {kWindow, kWindow});
  cv::sqrBoxFilter(f, square, CV_32F, {kWindow, kWindow});
  const cv::Mat variance = square - mean.mul(mean);
  const double limit = std::max(kSigmas * noiseSigma(grey), kMinDeviation);
  cv::Mat plain = (variance <= limit * limit) & (mask != 0);
  // One pixel off every region: splits thin bridges between plain areas and drops the outline
  // pixels, whose grey mixes both sides.
  cv::erode(plain, plain, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  LabelledView view;
  cv::Mat stats, centroids;
  const int count = cv::connectedComponentsWithStats(plain, view.labels, stats, centroids, 4, CV_32S);
  for (int i = 1; i < count; ++i) {
    Region r;
    r.area = stats.at<int>(i, cv::CC_STAT_AREA);
    if (r.area < minArea) continue;
    r.label = i;
    r.box = {stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
             stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT)};
    r.cx = centroids.at<double>(i, 0);
    r.cy = centroids.at<double>(i, 1);
    r.grey = cv::mean(grey(r.box), view.labels(r.box) == i)[0];
    view.regions.push_back(r);
  }
  return view;
}

// Intersection over union of left region `a` and right region `b` moved by `dx` (a left pixel
// x meets the right pixel x - dx).
double overlap(const LabelledView& left, const Region& a, const LabelledView& right,
               const Region& b, int dx) {
  int inter = 0;
  for (int y = a.box.y; y < a.box.y + a.box.height; ++y) {
    const int* la = left.labels.ptr<int>(y);
    const int* lb = right.labels.ptr<int>(y);
    const int x0 = std::max(a.box.x, dx), x1 = std::min(a.box.x + a.box.width, right.labels.cols + dx);
    for (int x = x0; x < x1; ++x) inter += (la[x] == a.label && lb[x - dx] == b.label) ? 1 : 0;
  }
  return inter / static_cast<double>(a.area + b.area - inter);
}

// Worth an overlap test: the regions share most of their rows (a plain region may leak into a
// plain neighbour in one view only), have about the same area and grey level.
bool comparable(const Region& a, const Region& b) {
  const double ratio = static_cast<double>(a.area) / b.area;
  const int shared = std::min(a.box.br().y, b.box.br().y) - std::max(a.box.y, b.box.y);
  return shared >= kSharedRows * std::max(a.box.height, b.box.height) && ratio >= 0.7 &&
         ratio <= 1 / 0.7 && std::abs(a.grey - b.grey) <= kGreyTolerance;
}

struct Pairing {
  size_t left = 0, right = 0;
  int dx = 0;
  double overlap = 0;
};

// Samples of a paired left region: one per grid cell holding a tenth of the cell in the region,
// at those pixels' mean position; the centroid when no cell qualifies.
void addSamples(const LabelledView& left, const Region& r, int dx,
                const PlainRegionSettings& settings, std::vector<RegionSample>& out) {
  const cv::Size size = left.labels.size();
  const double cellW = static_cast<double>(size.width) / settings.grid;
  const double cellH = static_cast<double>(size.height) / settings.grid;
  auto full = [&](double v) { return static_cast<float>((v + 0.5) / settings.scale - 0.5); };
  const float d = static_cast<float>(dx / settings.scale);
  const size_t before = out.size();
  const int cx0 = static_cast<int>(r.box.x / cellW), cx1 = static_cast<int>((r.box.br().x - 1) / cellW);
  const int cy0 = static_cast<int>(r.box.y / cellH), cy1 = static_cast<int>((r.box.br().y - 1) / cellH);
  for (int cy = cy0; cy <= cy1; ++cy) {
    for (int cx = cx0; cx <= cx1; ++cx) {
      const cv::Rect cell = cv::Rect(static_cast<int>(std::ceil(cx * cellW)),
                                     static_cast<int>(std::ceil(cy * cellH)),
                                     static_cast<int>(std::ceil(cellW)),
                                     static_cast<int>(std::ceil(cellH))) & r.box;
      double sx = 0, sy = 0;
      int n = 0;
      for (int y = cell.y; y < cell.br().y; ++y) {
        const int* l = left.labels.ptr<int>(y);
        for (int x = cell.x; x < cell.br().x; ++x) {
          if (l[x] != r.label) continue;
          sx += x;
          sy += y;
          ++n;
        }
      }
      if (n >= 0.1 * cellW * cellH) out.push_back({full(sx / n), full(sy / n), d});
    }
  }
  if (out.size() == before) out.push_back({full(r.cx), full(r.cy), d});
}

}  // namespace

std::vector<RegionSample> matchPlainRegions(const cv::Mat& leftGrey, const cv::Mat& leftMask,
                                            const cv::Mat& rightGrey, const cv::Mat& rightMask,
                                            const PlainRegionSettings& settings) {
  const int minArea = std::max(16, static_cast<int>(settings.minAreaShare *
                                                    static_cast<double>(leftGrey.total())));
  const LabelledView left = plainRegions(leftGrey, leftMask, minArea);
  const LabelledView right = plainRegions(rightGrey, rightMask, minArea);
  // Every pairing that overlaps enough, then per region its best two overlaps.
  std::vector<Pairing> good;
  struct BestTwo {
    double first = 0, second = 0;
    void add(double v) {
      if (v > first) {
        second = first;
        first = v;
      } else if (v > second) {
        second = v;
      }
    }
  };
  std::vector<BestTwo> bestLeft(left.regions.size()), bestRight(right.regions.size());
  for (size_t i = 0; i < left.regions.size(); ++i) {
    const Region& a = left.regions[i];
    for (size_t j = 0; j < right.regions.size(); ++j) {
      const Region& b = right.regions[j];
      if (!comparable(a, b)) continue;
      const int guess = static_cast<int>(std::lround(a.cx - b.cx));
      const int search = kShiftSearch + std::max(a.box.width, b.box.width) / 10;
      Pairing p{i, j, guess, 0};
      for (int dx = guess - search; dx <= guess + search; ++dx) {
        const double o = overlap(left, a, right, b, dx);
        if (o > p.overlap) {
          p.overlap = o;
          p.dx = dx;
        }
      }
      // The overlap must peak inside the shifts tried: at their end the true shift may lie
      // beyond (a region cut by the image border or leaking into a neighbour in one view only
      // has its centroid moved).
      if (p.overlap < settings.minOverlap || std::abs(p.dx - guess) == search) continue;
      good.push_back(p);
      bestLeft[i].add(p.overlap);
      bestRight[j].add(p.overlap);
    }
  }
  // Kept: the best pairing of both its regions, clearly better than their next one (repeated
  // shapes on the same rows, such as a roof's parallel plain strips, are left out).
  std::vector<RegionSample> samples;
  for (const Pairing& p : good) {
    const BestTwo& l = bestLeft[p.left];
    const BestTwo& r = bestRight[p.right];
    if (p.overlap < l.first || p.overlap < r.first) continue;
    if (l.second > p.overlap - kClearlyBetter || r.second > p.overlap - kClearlyBetter) continue;
    addSamples(left, left.regions[p.left], p.dx, settings, samples);
  }
  return samples;
}

}  // namespace delineo::stereo::detail
