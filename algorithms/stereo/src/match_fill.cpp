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

// The cluster candidates of a region can be too close in outline error to pass the contrast
// test (a roof of nearly the ground's grey). Scanning every integer disparity of the range then
// confirms `best` when the scan's minimum is within `reach` px of it and at most `agreement` ×
// the lowest error found 3 px or more away: the outline lines up there and nowhere else.
// (`best` is a sub-pixel cluster mean and a large roof's ring error is flat within a pixel of
// its minimum: the integer minimum can lie 1.4 px away.)
template <typename ErrorAt>
bool scanConfirms(const ErrorAt& errorAt, int dmin, int dmax, float best, double agreement,
                  double reach) {
  std::vector<double> errors(static_cast<size_t>(dmax - dmin + 1));
  for (int d = dmin; d <= dmax; ++d)
    errors[static_cast<size_t>(d - dmin)] = errorAt(static_cast<float>(d));
  const auto lowest = std::min_element(errors.begin(), errors.end());
  const int found = dmin + static_cast<int>(lowest - errors.begin());
  if (std::abs(static_cast<double>(found) - best) > reach || *lowest >= 1e29) return false;
  double other = 1e30;
  for (int d = dmin; d <= dmax; ++d) {
    if (std::abs(d - found) > 2) other = std::min(other, errors[static_cast<size_t>(d - dmin)]);
  }
  return *lowest <= agreement * other;
}

// The flat region stops 2 px short of its contour (its 5x5 windows reach across it): grow it
// back, 4-connected and at most `growReach` px, over the pixels that look like the region next to
// them (within growSigmas noise sigmas of the mean of the region pixels in their 7x7
// neighbourhood) and that match at the region's disparity on their own (|left − mapped right|
// within growPhotometric noise sigmas). The contour's mixed pixel fails the first test, the
// surface beyond it both: the fill then ends at the image contour.
void growToContour(const cv::Mat& left, const cv::Mat& right, const cv::Rect& box,
                   const cv::Mat& region, int shift, double gain, double offset, double sigma,
                   const RegionFillSettings& settings, cv::Mat& grown) {
  cv::Mat leftBox = left(box).clone();
  cv::patchNaNs(leftBox, 0.0);
  cv::Mat regionF, sum, count;
  region.convertTo(regionF, CV_32F, 1.0 / 255.0);
  cv::boxFilter(leftBox.mul(regionF), sum, CV_32F, {7, 7}, {-1, -1}, false);
  cv::boxFilter(regionF, count, CV_32F, {7, 7}, {-1, -1}, false);
  const auto like = [&](int x, int y) {
    const float a = left.at<float>(box.y + y, box.x + x);
    const int xr = box.x + x - shift;
    if (!std::isfinite(a) || xr < 0 || xr >= right.cols) return false;
    const float b = right.at<float>(box.y + y, xr);
    const float n = count.at<float>(y, x);
    if (!std::isfinite(b) || n < 1.0F) return false;
    return std::abs(a - sum.at<float>(y, x) / n) <= settings.growSigmas * sigma &&
           std::abs(a - (gain * b + offset)) <= settings.growPhotometric * sigma;
  };
  for (int step = 0; step < settings.growReach; ++step) {
    const cv::Mat before = grown.clone();
    for (int y = 0; y < box.height; ++y) {
      for (int x = 0; x < box.width; ++x) {
        if (before.at<uchar>(y, x)) continue;
        const bool touches = (x > 0 && before.at<uchar>(y, x - 1)) ||
                             (x + 1 < box.width && before.at<uchar>(y, x + 1)) ||
                             (y > 0 && before.at<uchar>(y - 1, x)) ||
                             (y + 1 < box.height && before.at<uchar>(y + 1, x));
        if (touches && like(x, y)) grown.at<uchar>(y, x) = 255;
      }
    }
  }
}

// The 2 px on both sides of a region's outline (CV_8U 0/255 mask in, same size out).
cv::Mat outlineRing(const cv::Mat& region) {
  cv::Mat outer, inner;
  cv::dilate(region, outer, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
  cv::erode(region, inner, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}), {-1, -1}, 1,
            cv::BORDER_CONSTANT, 0);
  return outer & ~inner;
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
  // The regions without their thin parts (see RegionFillSettings::coreOpening).
  cv::Mat flatCores;
  if (settings.coreOpening > 1) {
    cv::morphologyEx(
        flat, flatCores, cv::MORPH_OPEN,
        cv::getStructuringElement(cv::MORPH_RECT, {settings.coreOpening, settings.coreOpening}));
  }
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
    cv::Mat region = labels(box) == r;
    cv::Mat near;
    cv::dilate(region, near, cv::getStructuringElement(cv::MORPH_RECT, {7, 7}));
    cv::Mat ring = outlineRing(region);
    std::vector<float> matches;
    for (int y = 0; y < box.height; ++y) {
      const uchar* n = near.ptr<uchar>(y);
      const float* d = disparity.ptr<float>(box.y + y) + box.x;
      for (int x = 0; x < box.width; ++x) {
        if (n[x] && std::isfinite(d[x])) matches.push_back(d[x]);
      }
    }
    if (static_cast<int>(matches.size()) < settings.minMatched) continue;
    // Mean |left − mapped right| over the ring at disparity `value`, the right view read with
    // linear interpolation (the candidates are sub-pixel means).
    auto ringError = [&](float value) {
      const int whole = static_cast<int>(std::floor(value));
      const float t = value - static_cast<float>(whole);
      double sum = 0, n = 0;
      for (int y = 0; y < box.height; ++y) {
        const uchar* m = ring.ptr<uchar>(y);
        const float* a = left.ptr<float>(box.y + y) + box.x;
        const float* b = right.ptr<float>(box.y + y);
        for (int x = 0; x < box.width; ++x) {
          if (!m[x]) continue;
          const int xr = box.x + x - whole;                 // x − value lies in [xr − 1, xr]
          if (xr - 1 < 0 || xr >= right.cols) return 1e30;  // the outline leaves the right image
          const float bv = (1 - t) * b[xr] + t * b[xr - 1];
          if (!std::isfinite(a[x]) || !std::isfinite(bv)) continue;
          sum += std::abs(a[x] - (gain * bv + offset));
          n += 1;
        }
      }
      return n > 0 ? sum / n : 1e30;
    };
    // The cluster candidates ranked by their error on the current ring.
    const std::vector<int> centres =
        twoLargestClusters(matches, dmin, dmax, settings.minMatched / 2);
    struct Ranking {
      float best = 0;
      double bestError = 1e30, otherError = 1e30;
    };
    const auto rankCandidates = [&] {
      Ranking k;
      for (const int centre : centres) {
        const float value = clusterMean(matches, static_cast<float>(centre));
        const double e = ringError(value);
        if (e < k.bestError) {
          k.otherError = k.bestError;
          k.bestError = e;
          k.best = value;
        } else {
          k.otherError = std::min(k.otherError, e);
        }
      }
      return k;
    };
    Ranking ranked = rankCandidates();
    if (!flatCores.empty() && ranked.bestError < 1e29) {
      // Thin flat parts joined to the region (a facade's plain bands between its window rows,
      // joined to the roof above) put their own outline, which does not line up at the roof's
      // disparity, into the ring. When the region's core (without them) lines up clearly better,
      // the core is the region.
      const int area = stats.at<int>(r, cv::CC_STAT_AREA);
      const cv::Mat core = flatCores(box) & region;
      const int coreArea = cv::countNonZero(core);
      if (coreArea < area && coreArea >= settings.coreMinShare * area) {
        const cv::Mat wholeRing = ring;
        ring = outlineRing(core);
        const Ranking onCore = rankCandidates();
        if (onCore.bestError < settings.coreErrorRatio * ranked.bestError) {
          region = core;
          ranked = onCore;
        } else {
          ring = wholeRing;
        }
      }
    }
    const auto [best, bestError, otherError] = ranked;
    if (bestError > settings.photometric * sigma) continue;
    if (bestError > settings.contrast * otherError &&
        !(settings.scanAgreement > 0 &&
          scanConfirms(ringError, dmin, dmax, best, settings.scanAgreement, settings.scanReach))) {
      continue;
    }
    const int shift = static_cast<int>(std::lround(best));
    cv::Mat grown = region.clone();
    if (settings.growReach > 0) {
      growToContour(left, right, box, region, shift, gain, offset, sigma, settings, grown);
    }
    for (int y = 0; y < box.height; ++y) {
      const uchar* m = grown.ptr<uchar>(y);
      const uchar* inRegion = region.ptr<uchar>(y);
      const float* a = left.ptr<float>(box.y + y) + box.x;
      float* d = disparity.ptr<float>(box.y + y) + box.x;
      float* s = score.ptr<float>(box.y + y) + box.x;
      const float* b = right.ptr<float>(box.y + y);
      for (int x = 0; x < box.width; ++x) {
        const int xr = box.x + x - shift;
        if (!m[x] || xr < 0 || xr >= right.cols || !std::isfinite(b[xr])) continue;
        if (std::isfinite(d[x])) {
          // A grown pixel matched elsewhere (the far side's disparity carried over the outline
          // by a window that reached across it) is taken when the region's disparity explains
          // its grey level better than its own.
          if (inRegion[x] || std::abs(d[x] - best) < 2.0F) continue;
          const int xo = box.x + x - static_cast<int>(std::lround(d[x]));
          if (xo < 0 || xo >= right.cols || !std::isfinite(b[xo])) continue;
          if (!(std::abs(a[x] - (gain * b[xo] + offset)) >
                std::abs(a[x] - (gain * b[xr] + offset)))) {
            continue;
          }
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
