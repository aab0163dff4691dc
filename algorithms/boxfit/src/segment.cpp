// Stage 1 of box-fitting: the building segment from the DEM, and the image's Canny edges.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/boxfit/stages.hpp"

namespace delineo::boxfit {

namespace {

cv::Mat disk(int radius) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * radius + 1, 2 * radius + 1});
}

// Fills the NaN runs of each line of `m` (rows of a CV_32F matrix) with the lower end value.
void fillRuns(cv::Mat& m) {
  for (int y = 0; y < m.rows; ++y) {
    float* row = m.ptr<float>(y);
    int x = 0;
    while (x < m.cols) {
      if (!std::isnan(row[x])) {
        ++x;
        continue;
      }
      const int start = x;
      while (x < m.cols && std::isnan(row[x])) ++x;
      const bool hasLeft = start > 0, hasRight = x < m.cols;
      if (!hasLeft && !hasRight) continue;  // the whole line: left to the other direction
      const float value = hasLeft && hasRight ? std::min(row[start - 1], row[x])
                          : hasLeft           ? row[start - 1]
                                              : row[x];
      std::fill(row + start, row + x, value);
    }
  }
}

// Holes of `mask` (CV_8U) not touching its border and smaller than `maxArea`, filled.
void fillSmallHoles(cv::Mat& mask, int maxArea) {
  cv::Mat background = mask == 0, labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(background, labels, stats, centroids, 4, CV_32S);
  std::vector<uchar> fill(static_cast<size_t>(n), 0);
  for (int i = 1; i < n; ++i) {
    const int x = stats.at<int>(i, cv::CC_STAT_LEFT), y = stats.at<int>(i, cv::CC_STAT_TOP);
    const int w = stats.at<int>(i, cv::CC_STAT_WIDTH), h = stats.at<int>(i, cv::CC_STAT_HEIGHT);
    const bool touches = x == 0 || y == 0 || x + w == mask.cols || y + h == mask.rows;
    fill[static_cast<size_t>(i)] = !touches && stats.at<int>(i, cv::CC_STAT_AREA) < maxArea;
  }
  for (int y = 0; y < mask.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (fill[static_cast<size_t>(l[x])]) m[x] = 255;
    }
  }
}

// Median gradient magnitude of an 8-bit image (Sobel 3x3), from a histogram.
double medianGradient(const cv::Mat& dx, const cv::Mat& dy) {
  constexpr int kBins = 2048;
  constexpr double kMax = 1500.0;
  std::vector<int> histogram(kBins, 0);
  for (int y = 0; y < dx.rows; ++y) {
    const short* gx = dx.ptr<short>(y);
    const short* gy = dy.ptr<short>(y);
    for (int x = 0; x < dx.cols; ++x) {
      const double m = std::hypot(static_cast<double>(gx[x]), static_cast<double>(gy[x]));
      ++histogram[static_cast<size_t>(std::min(kBins - 1, static_cast<int>(m / kMax * kBins)))];
    }
  }
  const long long total = static_cast<long long>(dx.total());
  long long below = 0;
  for (int b = 0; b < kBins; ++b) {
    below += histogram[static_cast<size_t>(b)];
    if (2 * below >= total) return (b + 0.5) * kMax / kBins;
  }
  return kMax;
}

}  // namespace

cv::Mat fillHeightGaps(const cv::Mat& heights) {
  cv::Mat filled;
  heights.convertTo(filled, CV_32F);
  fillRuns(filled);
  cv::Mat columns = filled.t();
  fillRuns(columns);
  return columns.t();
}

cv::Mat localGround(const cv::Mat& filledHeights, int window) {
  cv::Mat smooth = filledHeights.clone();
  cv::patchNaNs(smooth, 0.0);
  cv::medianBlur(smooth, smooth, 5);
  // The opening at a reduced scale: a structuring element of about 41 px, whatever the window.
  const int scale = std::max(1, window / 41);
  const cv::Size small((smooth.cols + scale - 1) / scale, (smooth.rows + scale - 1) / scale);
  cv::Mat reduced;
  cv::resize(smooth, reduced, small, 0, 0, cv::INTER_AREA);
  const int side = std::max(3, (window / scale) | 1);
  const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, {side, side});
  cv::morphologyEx(reduced, reduced, cv::MORPH_OPEN, square);
  cv::Mat ground;
  cv::resize(reduced, ground, filledHeights.size(), 0, 0, cv::INTER_LINEAR);
  return ground;
}

double roofLevel(const cv::Mat& aboveGround, const cv::Mat& mask, double minHeight) {
  cv::Mat depth;
  cv::distanceTransform(mask, depth, cv::DIST_L2, 3);
  double maxHeight = -std::numeric_limits<double>::infinity();
  int count = 0;
  for (int y = 0; y < mask.rows; ++y) {
    const float* h = aboveGround.ptr<float>(y);
    const uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (m[x] && h[x] >= minHeight) maxHeight = std::max(maxHeight, double(h[x])), ++count;
    }
  }
  if (count < 20) return std::nan("");
  constexpr double kBin = 0.25;
  const int bins = static_cast<int>((maxHeight - minHeight) / kBin) + 1;
  std::vector<double> histogram(static_cast<size_t>(bins), 0.0);
  for (int y = 0; y < mask.rows; ++y) {
    const float* h = aboveGround.ptr<float>(y);
    const uchar* m = mask.ptr<uchar>(y);
    const float* d = depth.ptr<float>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (!m[x] || !(h[x] >= minHeight)) continue;
      const int b = std::min(bins - 1, static_cast<int>((h[x] - minHeight) / kBin));
      histogram[static_cast<size_t>(b)] += d[x];
    }
  }
  // Smoothed over ±1 m: a gable's slopes or a noisy matcher spread one roof over several bins.
  constexpr int kHalf = 4;
  double best = -1.0;
  int bestBin = 0;
  for (int b = 0; b < bins; ++b) {
    double s = 0.0;
    for (int k = std::max(0, b - kHalf); k <= std::min(bins - 1, b + kHalf); ++k) s += histogram[static_cast<size_t>(k)];
    if (s > best) best = s, bestBin = b;
  }
  return minHeight + (bestBin + 0.5) * kBin;
}

cv::Mat buildingSegment(const cv::Mat& aboveGround, const cv::Mat& initMask, double roofHeight,
                        const BoxFitParams& params) {
  const double low = std::max(params.minHeight, params.thresholdFraction * roofHeight);
  const double high = (1.0 + params.roofBand) * roofHeight + params.minHeight;
  cv::Mat mask = (aboveGround >= low) & (aboveGround <= high);
  if (params.leash > 0) {
    cv::Mat reach;
    cv::dilate(initMask, reach, disk(params.leash));
    mask &= reach;
  } else {
    mask &= initMask;
  }
  fillSmallHoles(mask, params.minArea);
  // A separate buffer: eroding into a header of `mask` would erode `mask` itself, and the
  // grow-back below would then be clipped to the eroded mask.
  cv::Mat eroded;
  if (params.erosionRadius > 0) cv::erode(mask, eroded, disk(params.erosionRadius));
  else eroded = mask.clone();
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(eroded, labels, stats, centroids, 8, CV_32S);
  std::vector<int> overlap(static_cast<size_t>(n), 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const uchar* m = initMask.ptr<uchar>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (l[x] > 0 && m[x]) ++overlap[static_cast<size_t>(l[x])];
    }
  }
  int best = 0;
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) < params.minArea) continue;
    if (overlap[static_cast<size_t>(i)] > (best > 0 ? overlap[static_cast<size_t>(best)] : 0)) best = i;
  }
  cv::Mat segment = cv::Mat::zeros(mask.size(), CV_8U);
  if (best == 0) return segment;
  segment.setTo(255, labels == best);
  if (params.erosionRadius > 0) {
    cv::dilate(segment, segment, disk(params.erosionRadius));
    segment &= mask;
  }
  return segment;
}

std::vector<cv::Mat> candidateRegions(const cv::Mat& aboveGround, const BoxFitParams& params) {
  cv::Mat mask = aboveGround >= params.minHeight;
  // A separate buffer: eroding into a header of `mask` would erode `mask` itself, and the
  // grow-back below would then be clipped to the eroded mask.
  cv::Mat eroded;
  if (params.erosionRadius > 0) cv::erode(mask, eroded, disk(params.erosionRadius));
  else eroded = mask.clone();
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(eroded, labels, stats, centroids, 8, CV_32S);
  std::vector<cv::Mat> regions;
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) < params.minArea) continue;
    cv::Mat region = labels == i;
    if (params.erosionRadius > 0) {
      cv::dilate(region, region, disk(params.erosionRadius));
      region &= mask;
    }
    regions.push_back(region);
  }
  return regions;
}

cv::Mat boxEdges(const cv::Mat& image, const BoxFitParams& params) {
  cv::Mat grey;
  if (image.depth() == CV_8U) {
    grey = image;
  } else {
    cv::Mat f;
    image.convertTo(f, CV_32F);
    cv::patchNaNs(f, 0.0);
    double vmin = 0, vmax = 0;
    cv::minMaxLoc(f, &vmin, &vmax);
    if (vmin >= 0 && vmax <= 255) {
      f.convertTo(grey, CV_8U);  // 8-bit imagery read as float: grey levels as they are
    } else {
      // Other ranges (16-bit, reflectance) mapped from their 1st and 99th percentiles.
      std::vector<float> values(f.begin<float>(), f.end<float>());
      const size_t lo = values.size() / 100, hi = values.size() - 1 - values.size() / 100;
      std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(lo), values.end());
      const float low = values[lo];
      std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(hi), values.end());
      const float high = std::max(values[hi], low + 1e-3f);
      f.convertTo(grey, CV_8U, 255.0 / (high - low), -255.0 * low / (high - low));
    }
  }
  cv::Mat smooth;
  if (params.bilateralSigma > 0) {
    cv::bilateralFilter(grey, smooth, 5, params.bilateralSigma, 2.0);
  } else {
    smooth = grey;
  }
  cv::Mat dx, dy;
  cv::Sobel(smooth, dx, CV_16S, 1, 0, 3);
  cv::Sobel(smooth, dy, CV_16S, 0, 1, 3);
  const double high = std::max(8.0, params.edgeContrast * medianGradient(dx, dy));
  cv::Mat edges;
  cv::Canny(dx, dy, edges, 0.5 * high, high, true);
  return edges;
}

}  // namespace delineo::boxfit
