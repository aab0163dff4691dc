#include "delineo/segmentation/roof_levels.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"

namespace delineo::segmentation {

using core::Error;
using core::ErrorCode;

namespace {

constexpr double kValley = 0.5;     // two modes are two levels when the histogram dips below this share of the lower peak
constexpr int kMaxBins = 100000;    // a wider span of heights takes wider bins

// The histogram of `heights` in bins of `bin` m from `low`, smoothed by a Gaussian of `sigma` bins.
std::vector<double> smoothedHistogram(const std::vector<float>& heights, double low, double bin, int bins, double sigma) {
  std::vector<double> counts(static_cast<size_t>(bins), 0.0);
  for (float h : heights) counts[static_cast<size_t>(std::clamp(static_cast<int>((h - low) / bin), 0, bins - 1))] += 1.0;
  const int reach = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<double> kernel;
  for (int k = -reach; k <= reach; ++k) kernel.push_back(std::exp(-0.5 * k * k / (sigma * sigma)));
  std::vector<double> smooth(counts.size(), 0.0);
  for (int i = 0; i < bins; ++i) {
    for (int k = -reach; k <= reach; ++k) {
      if (i + k >= 0 && i + k < bins) smooth[static_cast<size_t>(i)] += kernel[static_cast<size_t>(k + reach)] * counts[static_cast<size_t>(i + k)];
    }
  }
  return smooth;
}

// The modes (bin indices) of `smooth`, most populated first.
std::vector<int> modesOf(const std::vector<double>& smooth) {
  std::vector<int> modes;
  const int n = static_cast<int>(smooth.size());
  for (int i = 0; i < n; ++i) {
    const double left = i > 0 ? smooth[static_cast<size_t>(i - 1)] : -1.0;
    const double right = i + 1 < n ? smooth[static_cast<size_t>(i + 1)] : -1.0;
    if (smooth[static_cast<size_t>(i)] > 0.0 && smooth[static_cast<size_t>(i)] >= left && smooth[static_cast<size_t>(i)] > right) modes.push_back(i);
  }
  std::stable_sort(modes.begin(), modes.end(), [&](int a, int b) { return smooth[static_cast<size_t>(a)] > smooth[static_cast<size_t>(b)]; });
  return modes;
}

// True when modes a and b are separate levels: far enough apart, with a valley between them.
bool separateModes(const std::vector<double>& smooth, int a, int b, int minBins) {
  if (std::abs(a - b) < minBins) return false;
  const auto lo = smooth.begin() + std::min(a, b), hi = smooth.begin() + std::max(a, b) + 1;
  const double valley = *std::min_element(lo, hi);
  return valley <= kValley * std::min(smooth[static_cast<size_t>(a)], smooth[static_cast<size_t>(b)]);
}

// Index of the level nearest `h` within half `minStep`, or -1.
int nearestLevel(float h, const std::vector<double>& levels, double minStep) {
  int best = -1;
  double bestDistance = 0.5 * minStep;
  for (size_t k = 0; k < levels.size(); ++k) {
    const double d = std::abs(h - levels[k]);
    if (d <= bestDistance) best = static_cast<int>(k), bestDistance = d;
  }
  return best;
}

// Drops the level holding fewest heights while it holds fewer than `minPixels`.
void dropSmallLevels(std::vector<double>& levels, const std::vector<float>& heights, double minStep, double minPixels) {
  while (levels.size() > 1) {
    std::vector<int> support(levels.size(), 0);
    for (float h : heights) {
      const int k = nearestLevel(h, levels, minStep);
      if (k >= 0) ++support[static_cast<size_t>(k)];
    }
    const auto smallest = std::min_element(support.begin(), support.end());
    if (*smallest >= minPixels) return;
    levels.erase(levels.begin() + (smallest - support.begin()));
  }
}

// Gives every pixel of `domain` labelled -1 the label of the nearest pixel whose label is in
// `sources` (non-zero mask); pixels stay -1 when there is no source.
void fillFromNearest(cv::Mat& labels, const cv::Mat& domain, const cv::Mat& sources) {
  if (cv::countNonZero(sources) == 0) return;
  cv::Mat distance, nearest;
  cv::distanceTransform(sources == 0, distance, nearest, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  // nearest: the index of the nearest source pixel, numbered from 1 in row-major order.
  std::vector<int> sourceLabel{-1};
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      if (sources.at<uchar>(y, x) != 0) sourceLabel.push_back(labels.at<int>(y, x));
    }
  }
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      int& label = labels.at<int>(y, x);
      if (label < 0 && domain.at<uchar>(y, x) != 0) label = sourceLabel[static_cast<size_t>(nearest.at<int>(y, x))];
    }
  }
}

// Each footprint pixel's level (step 2); -1 outside the footprint.
cv::Mat levelOfPixels(const cv::Mat& heights, const cv::Mat& footprint, const std::vector<double>& levels, double minStep) {
  cv::Mat labels(heights.size(), CV_32S, cv::Scalar(-1));
  for (int y = 0; y < heights.rows; ++y) {
    for (int x = 0; x < heights.cols; ++x) {
      const float h = heights.at<float>(y, x);
      if (footprint.at<uchar>(y, x) != 0 && std::isfinite(h)) labels.at<int>(y, x) = nearestLevel(h, levels, minStep);
    }
  }
  fillFromNearest(labels, footprint, labels >= 0);
  return labels;
}

// Step 3: each level opened with a disk `radius` px; the freed pixels go to the nearest other level.
void openLevels(cv::Mat& labels, const cv::Mat& footprint, int levelCount, int radius) {
  if (radius < 1 || levelCount < 2) return;
  const cv::Mat disk = cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * radius + 1, 2 * radius + 1});
  for (int k = 0; k < levelCount; ++k) {
    const cv::Mat mine = labels == k;
    cv::Mat opened;
    cv::morphologyEx(mine, opened, cv::MORPH_OPEN, disk, {-1, -1}, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    const cv::Mat freed = mine & ~opened;
    if (cv::countNonZero(freed) == 0) continue;
    const cv::Mat others = (labels >= 0) & ~mine;
    if (cv::countNonZero(others) == 0) continue;
    labels.setTo(-1, freed);
    fillFromNearest(labels, footprint, others);
  }
}

}  // namespace

std::vector<double> roofLevels(const std::vector<float>& heights, double pixelArea, const RoofLevelParams& params) {
  params.validate();
  if (heights.empty()) return {};
  const auto [lowIt, highIt] = std::minmax_element(heights.begin(), heights.end());
  double bin = params.minStep / 10.0;
  const double span = static_cast<double>(*highIt) - *lowIt;
  if (span / bin + 1 > kMaxBins) bin = span / (kMaxBins - 1);
  const int bins = static_cast<int>(span / bin) + 1;
  const std::vector<double> smooth = smoothedHistogram(heights, *lowIt, bin, bins, params.minStep / 4.0 / bin);
  const int minBins = static_cast<int>(std::ceil(params.minStep / bin - 1e-9));
  std::vector<int> kept;
  for (int mode : modesOf(smooth)) {
    const bool separate = std::all_of(kept.begin(), kept.end(), [&](int k) { return separateModes(smooth, mode, k, minBins); });
    if (separate) kept.push_back(mode);
  }
  std::vector<double> levels;
  for (int mode : kept) levels.push_back(*lowIt + (mode + 0.5) * bin);
  std::sort(levels.begin(), levels.end());
  dropSmallLevels(levels, heights, params.minStep, params.minArea / pixelArea);
  return levels;
}

namespace {

// Step 4's pieces: the 4-connected components of each level inside the footprint, numbered
// 0..n-1 (-1 outside); `regionLevel` receives each one's level.
cv::Mat piecesOfLevels(const cv::Mat& levels, int levelCount, std::vector<int>& regionLevel) {
  cv::Mat regions(levels.size(), CV_32S, cv::Scalar(-1));
  for (int k = 0; k < levelCount; ++k) {
    cv::Mat components;
    const int count = cv::connectedComponents(levels == k, components, 4, CV_32S);
    const int first = static_cast<int>(regionLevel.size());
    for (int c = 1; c < count; ++c) regionLevel.push_back(k);
    for (int y = 0; y < levels.rows; ++y) {
      for (int x = 0; x < levels.cols; ++x) {
        const int c = components.at<int>(y, x);
        if (c > 0) regions.at<int>(y, x) = first + c - 1;
      }
    }
  }
  return regions;
}

// Border lengths (4-neighbour pixel pairs) between regions: borders[{a, b}] with a < b.
std::map<std::pair<int, int>, int> regionBorders(const cv::Mat& regions) {
  std::map<std::pair<int, int>, int> borders;
  auto count = [&](int a, int b) {
    if (a >= 0 && b >= 0 && a != b) ++borders[{std::min(a, b), std::max(a, b)}];
  };
  for (int y = 0; y < regions.rows; ++y) {
    for (int x = 0; x < regions.cols; ++x) {
      if (x + 1 < regions.cols) count(regions.at<int>(y, x), regions.at<int>(y, x + 1));
      if (y + 1 < regions.rows) count(regions.at<int>(y, x), regions.at<int>(y + 1, x));
    }
  }
  return borders;
}

// The region sharing most border with `region`, or -1.
int mostBorderWith(const std::map<std::pair<int, int>, int>& borders, int region) {
  int best = -1, bestLength = 0;
  for (const auto& [pair, length] : borders) {
    const int other = pair.first == region ? pair.second : pair.second == region ? pair.first : -1;
    if (other >= 0 && length > bestLength) best = other, bestLength = length;
  }
  return best;
}

std::vector<int> pixelCounts(const cv::Mat& regions, int count) {
  std::vector<int> pixels(static_cast<size_t>(count), 0);
  for (int y = 0; y < regions.rows; ++y) {
    for (const int* row = regions.ptr<int>(y); row != regions.ptr<int>(y) + regions.cols; ++row) {
      if (*row >= 0) ++pixels[static_cast<size_t>(*row)];
    }
  }
  return pixels;
}

// Step 4's merging: the smallest region under `minPixels` joins the region it shares most border
// with, until none is left (a region without neighbours stays). Renumbers the regions 0..n-1.
void mergeSmallRegions(cv::Mat& regions, std::vector<int>& regionLevel, double minPixels) {
  for (;;) {
    const std::vector<int> pixels = pixelCounts(regions, static_cast<int>(regionLevel.size()));
    const auto borders = regionBorders(regions);
    int smallest = -1;
    for (size_t r = 0; r < pixels.size(); ++r) {
      if (pixels[r] == 0 || pixels[r] >= minPixels || mostBorderWith(borders, static_cast<int>(r)) < 0) continue;
      if (smallest < 0 || pixels[r] < pixels[static_cast<size_t>(smallest)]) smallest = static_cast<int>(r);
    }
    if (smallest < 0) break;
    regions.setTo(mostBorderWith(borders, smallest), regions == smallest);
  }
  const std::vector<int> pixels = pixelCounts(regions, static_cast<int>(regionLevel.size()));
  std::vector<int> renumber(pixels.size(), -1), levels;
  for (size_t r = 0; r < pixels.size(); ++r) {
    if (pixels[r] > 0) renumber[r] = static_cast<int>(levels.size()), levels.push_back(regionLevel[r]);
  }
  regions.forEach<int>([&](int& r, const int*) {
    if (r >= 0) r = renumber[static_cast<size_t>(r)];
  });
  regionLevel = levels;
}

void checkInputs(const cv::Mat& heights, const cv::Mat& footprint, double gsd) {
  if (heights.type() != CV_32FC1 || footprint.type() != CV_8UC1 || heights.size() != footprint.size()) {
    throw Error(ErrorCode::InvalidParameter, "roof levels need float32 heights and an 8-bit footprint of one size");
  }
  if (!(gsd > 0.0) || !std::isfinite(gsd)) throw Error(ErrorCode::InvalidParameter, "roof levels need a positive gsd");
}

}  // namespace

RoofLevelRegions roofLevelRegions(const cv::Mat& heights, const cv::Mat& footprint, double gsd,
                                  const RoofLevelParams& params) {
  params.validate();
  checkInputs(heights, footprint, gsd);
  RoofLevelRegions out;
  const cv::Mat inside = footprint != 0;
  if (cv::countNonZero(inside) == 0) return out;
  std::vector<float> values;
  for (int y = 0; y < heights.rows; ++y) {
    for (int x = 0; x < heights.cols; ++x) {
      const float h = heights.at<float>(y, x);
      if (inside.at<uchar>(y, x) != 0 && std::isfinite(h)) values.push_back(h);
    }
  }
  const double pixelArea = gsd * gsd;
  out.levels = roofLevels(values, pixelArea, params);
  if (out.levels.size() < 2) {
    out.labels = cv::Mat(heights.size(), CV_32S, cv::Scalar(0));
    out.regionLevel = {0};
    out.regionPixels = {cv::countNonZero(inside)};
    if (out.levels.empty()) out.levels = {std::nan("")};
    return out;
  }
  cv::Mat levels = levelOfPixels(heights, inside, out.levels, params.minStep);
  openLevels(levels, inside, static_cast<int>(out.levels.size()), static_cast<int>(std::lround(0.5 * params.cleanWidth / gsd)));
  out.labels = piecesOfLevels(levels, static_cast<int>(out.levels.size()), out.regionLevel);
  mergeSmallRegions(out.labels, out.regionLevel, params.minArea / pixelArea);
  out.regionPixels = pixelCounts(out.labels, static_cast<int>(out.regionLevel.size()));
  fillFromNearest(out.labels, cv::Mat(heights.size(), CV_8U, cv::Scalar(255)), out.labels >= 0);
  return out;
}

}  // namespace delineo::segmentation
