// Disparity of flat regions from the matches along their outline (see match_fill.hpp).
#include "match_fill.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "radiometry.hpp"

namespace delineo::stereo::detail {

namespace {

// Mean value of the matches within 1.5 px of `centre`.
float clusterMean(const std::vector<float>& values, float centre) {
  double sum = 0, n = 0;
  for (const float v : values) {
    if (std::abs(v - centre) <= 1.5F) {
      sum += v;
      n += 1;
    }
  }
  return static_cast<float>(n > 0 ? sum / n : centre);
}

// Centres (integer disparities) of the two largest clusters of ±1 px among `values`; the second
// is at least 3 px from the first and holds at least `minCount` values, else absent.
std::vector<int> twoLargestClusters(const std::vector<float>& values, int dmin, int dmax,
                                    int minCount) {
  const int bins = dmax - dmin + 1;
  std::vector<int> histogram(static_cast<size_t>(bins), 0);
  for (const float v : values) {
    const int k = std::clamp(static_cast<int>(std::lround(v)) - dmin, 0, bins - 1);
    ++histogram[static_cast<size_t>(k)];
  }
  auto clusterAt = [&](int k) {
    int c = 0;
    for (int j = std::max(0, k - 1); j <= std::min(bins - 1, k + 1); ++j) {
      c += histogram[static_cast<size_t>(j)];
    }
    return c;
  };
  int first = 0;
  for (int k = 1; k < bins; ++k) {
    if (clusterAt(k) > clusterAt(first)) first = k;
  }
  int second = -1;
  for (int k = 0; k < bins; ++k) {
    if (std::abs(k - first) > 2 && (second < 0 || clusterAt(k) > clusterAt(second))) second = k;
  }
  std::vector<int> centres{first + dmin};
  if (second >= 0 && clusterAt(second) >= minCount) centres.push_back(second + dmin);
  return centres;
}

}  // namespace

int fillFlatRegions(const cv::Mat& left, const cv::Mat& right, const RegionFillSettings& settings,
                    int dmin, int dmax, float fillScore, cv::Mat& disparity, cv::Mat& score) {
  cv::Mat leftFinite = left.clone();
  cv::patchNaNs(leftFinite, 0.0);
  const double sigma = std::max(1e-3, noiseSigma(leftFinite));
  cv::Mat mean, meanSquare;
  cv::blur(leftFinite, mean, {5, 5});
  cv::blur(leftFinite.mul(leftFinite), meanSquare, {5, 5});
  const double flatVariance = settings.flatSigmas * settings.flatSigmas * sigma * sigma;
  const cv::Mat flat = (meanSquare - mean.mul(mean) < flatVariance) & (left == left);
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(flat, labels, stats, centroids, 4, CV_32S);
  std::vector<int> unmatched(static_cast<size_t>(count), 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const float* d = disparity.ptr<float>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (l[x] != 0 && !std::isfinite(d[x])) ++unmatched[static_cast<size_t>(l[x])];
    }
  }
  const auto [gain, offset] = radiometricMap(left, right, dmin, dmax);
  const double maxArea = settings.maxShare * static_cast<double>(left.total());
  const cv::Rect image(0, 0, left.cols, left.rows);
  int filled = 0;
  for (int r = 1; r < count; ++r) {
    if (unmatched[static_cast<size_t>(r)] < settings.minUnmatched ||
        stats.at<int>(r, cv::CC_STAT_AREA) > maxArea) {
      continue;
    }
    // Work in the region's bounding box grown by 4 px.
    const cv::Rect box =
        cv::Rect(stats.at<int>(r, cv::CC_STAT_LEFT) - 4, stats.at<int>(r, cv::CC_STAT_TOP) - 4,
                 stats.at<int>(r, cv::CC_STAT_WIDTH) + 8,
                 stats.at<int>(r, cv::CC_STAT_HEIGHT) + 8) &
        image;
    const cv::Mat region = labels(box) == r;
    cv::Mat near, outer, inner;
    cv::dilate(region, near, cv::getStructuringElement(cv::MORPH_RECT, {7, 7}));
    cv::dilate(region, outer, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
    cv::erode(region, inner, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}), {-1, -1}, 1,
              cv::BORDER_CONSTANT, 0);
    const cv::Mat ring = outer & ~inner;
    std::vector<float> matches;
    for (int y = 0; y < box.height; ++y) {
      const uchar* n = near.ptr<uchar>(y);
      const float* d = disparity.ptr<float>(box.y + y) + box.x;
      for (int x = 0; x < box.width; ++x) {
        if (n[x] && std::isfinite(d[x])) matches.push_back(d[x]);
      }
    }
    if (static_cast<int>(matches.size()) < settings.minMatched) continue;
    auto ringError = [&](float value) {
      const int shift = static_cast<int>(std::lround(value));
      double sum = 0, n = 0;
      for (int y = 0; y < box.height; ++y) {
        const uchar* m = ring.ptr<uchar>(y);
        const float* a = left.ptr<float>(box.y + y) + box.x;
        const float* b = right.ptr<float>(box.y + y);
        for (int x = 0; x < box.width; ++x) {
          if (!m[x]) continue;
          const int xr = box.x + x - shift;
          if (xr < 0 || xr >= right.cols) return 1e30;  // the outline leaves the right image
          if (!std::isfinite(a[x]) || !std::isfinite(b[xr])) continue;
          sum += std::abs(a[x] - (gain * b[xr] + offset));
          n += 1;
        }
      }
      return n > 0 ? sum / n : 1e30;
    };
    float best = 0;
    double bestError = 1e30, otherError = 1e30;
    for (const int centre : twoLargestClusters(matches, dmin, dmax, settings.minMatched / 2)) {
      const float value = clusterMean(matches, static_cast<float>(centre));
      const double e = ringError(value);
      if (e < bestError) {
        otherError = bestError;
        bestError = e;
        best = value;
      } else {
        otherError = std::min(otherError, e);
      }
    }
    if (bestError > settings.photometric * sigma || bestError > settings.contrast * otherError) {
      continue;
    }
    const int shift = static_cast<int>(std::lround(best));
    for (int y = 0; y < box.height; ++y) {
      const uchar* m = region.ptr<uchar>(y);
      float* d = disparity.ptr<float>(box.y + y) + box.x;
      float* s = score.ptr<float>(box.y + y) + box.x;
      const float* b = right.ptr<float>(box.y + y);
      for (int x = 0; x < box.width; ++x) {
        const int xr = box.x + x - shift;
        if (!m[x] || std::isfinite(d[x]) || xr < 0 || xr >= right.cols || !std::isfinite(b[xr])) {
          continue;
        }
        d[x] = best;
        s[x] = fillScore;
        ++filled;
      }
    }
  }
  return filled;
}

}  // namespace delineo::stereo::detail
