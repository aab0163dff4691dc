// The flat regions of both views, which the flat-region fill decides on (see fill_internal.hpp).
#include "fill_internal.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "components.hpp"
#include "radiometry.hpp"

namespace delineo::stereo::detail {

LocalMoments localMoments(const cv::Mat& image, double noise) {
  // Nodata as 0, and the squares, in one pass; then the two 5x5 means.
  cv::Mat finite(image.size(), CV_32F), squares(image.size(), CV_32F);
  for (int y = 0; y < image.rows; ++y) {
    const float* in = image.ptr<float>(y);
    float* f = finite.ptr<float>(y);
    float* q = squares.ptr<float>(y);
    for (int x = 0; x < image.cols; ++x) {
      f[x] = std::isfinite(in[x]) ? in[x] : 0.0F;
      q[x] = f[x] * f[x];
    }
  }
  LocalMoments out;
  out.noise = noise >= 0 ? noise : noiseSigma(finite);
  const cv::Size window(2 * kFlatReach + 1, 2 * kFlatReach + 1);
  cv::blur(finite, out.mean, window);
  cv::blur(squares, out.meanSquare, window);
  return out;
}

cv::Mat flatMask(const cv::Mat& image, const RegionFillSettings& settings, double* sigmaOut,
                 const LocalMoments* known) {
  const LocalMoments made = known != nullptr ? LocalMoments{} : localMoments(image);
  const LocalMoments& moments = known != nullptr ? *known : made;
  const double sigma = std::max(1e-3, moments.noise);
  if (sigmaOut != nullptr) *sigmaOut = sigma;
  const auto flatVariance =
      static_cast<float>(settings.flatSigmas * settings.flatSigmas * sigma * sigma);
  cv::Mat flat(image.size(), CV_8U);
  for (int y = 0; y < image.rows; ++y) {
    const float* in = image.ptr<float>(y);
    const float* m = moments.mean.ptr<float>(y);
    const float* mm = moments.meanSquare.ptr<float>(y);
    uchar* out = flat.ptr<uchar>(y);
    for (int x = 0; x < image.cols; ++x) {
      out[x] = mm[x] - m[x] * m[x] < flatVariance && std::isfinite(in[x]) ? 255 : 0;
    }
  }
  return flat;
}

cv::Mat plainPixels(const cv::Mat& image, double sigmas, const LocalMoments* moments) {
  RegionFillSettings settings;
  settings.flatSigmas = sigmas;
  return flatMask(image, settings, nullptr, moments);
}

RightFlatRegions rightFlatRegions(const cv::Mat& flat, const cv::Mat& right) {
  RightFlatRegions out;
  const int count = cv::connectedComponents(flat, out.labels, 4, CV_32S);
  // Each region's grey levels summed in raster order, run by run of its label; the pixels off the
  // regions (label 0, whose mean nothing reads) are skipped.
  std::vector<double> sum(static_cast<size_t>(count), 0.0), n(static_cast<size_t>(count), 0.0);
  for (int y = 0; y < right.rows; ++y) {
    const int* l = out.labels.ptr<int>(y);
    const float* g = right.ptr<float>(y);
    for (int x = 0; x < right.cols;) {
      const int label = l[x];
      if (label == 0) {
        ++x;
        continue;
      }
      double total = sum[static_cast<size_t>(label)];
      const int start = x;
      for (; x < right.cols && l[x] == label; ++x) total += g[x];
      sum[static_cast<size_t>(label)] = total;
      n[static_cast<size_t>(label)] += x - start;
    }
  }
  out.meanGrey.resize(static_cast<size_t>(count));
  for (size_t k = 0; k < sum.size(); ++k) out.meanGrey[k] = n[k] > 0 ? sum[k] / n[k] : 0.0;
  return out;
}

LeftFlatRegions leftFlatRegions(const cv::Mat& left, const cv::Mat& disparity,
                                const RegionFillSettings& settings,
                                const LocalMoments* leftMoments) {
  LeftFlatRegions regions;
  const cv::Mat flat = flatMask(left, settings, &regions.sigma, leftMoments);
  // The regions without their thin parts (see RegionFillSettings::coreOpening).
  if (settings.coreOpening > 1) {
    cv::morphologyEx(
        flat, regions.flatCores, cv::MORPH_OPEN,
        cv::getStructuringElement(cv::MORPH_RECT, {settings.coreOpening, settings.coreOpening}));
  }
  // (On this worker alone: the other prepares the grey maps and the right view's flat regions.)
  const int count =
      componentsWithStats(flat, regions.labels, regions.stats, regions.centroids, 4, 1);
  std::vector<int> unmatched(static_cast<size_t>(count), 0);
  for (int y = 0; y < regions.labels.rows; ++y) {
    const int* l = regions.labels.ptr<int>(y);
    const float* d = disparity.ptr<float>(y);
    for (int x = 0; x < regions.labels.cols; ++x) {
      if (l[x] != 0 && !std::isfinite(d[x])) ++unmatched[static_cast<size_t>(l[x])];
    }
  }
  const double pixels =
      settings.wholePixels > 0 ? settings.wholePixels : static_cast<double>(left.total());
  const double maxArea = settings.maxShare * pixels;
  regions.ownFill.assign(static_cast<size_t>(count), 0);
  for (int r = 1; r < count; ++r) {
    regions.ownFill[static_cast<size_t>(r)] =
        unmatched[static_cast<size_t>(r)] >= settings.minUnmatched &&
        regions.stats.at<int>(r, cv::CC_STAT_AREA) <= maxArea;
  }
  return regions;
}

}  // namespace delineo::stereo::detail
