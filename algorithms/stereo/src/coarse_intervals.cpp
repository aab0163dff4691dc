#include "coarse_intervals.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "cpu_features.hpp"
#include "neighbourhood_range.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
// The wider neighbourhood's radius, and the extra margin its intervals get (see the header).
constexpr int kWideRadius = 4;
constexpr int kWideExtraMargin = 7;  // px, at the finer level
// The widest neighbourhood's radius, above the finest level and at it (see the header).
constexpr int kWidestRadiusAbove = 12;
constexpr int kWidestRadiusFinest = 16;

// One coarse row of intervalsFromCoarse(): from the 3x3 min/max (n0, n1) or, where the 3x3
// neighbourhood holds no valid disparity, the wide one (w0, w1); from the widest one (f0, f1)
// where `beside` (may be null) is non-zero or both are empty; the full range where that is
// empty too. Also built for AVX2 (floor and ceil in one instruction each).
DELINEO_TARGET_CLONES("avx2", "default") void coarseIntervalRow(
    const float* n0, const float* n1, const float* w0, const float* w1, const float* f0,
    const float* f1, const uchar* beside, int cw, int dmin, int dmax, int margin, int* l, int* h) {
  for (int x = 0; x < cw; ++x) {
    const bool isNear = n0[x] <= n1[x];
    const bool widest = (beside != nullptr && beside[x] != 0) || !(isNear || w0[x] <= w1[x]);
    if (widest && !(f0[x] <= f1[x])) {
      l[x] = dmin;
      h[x] = dmax;
      continue;
    }
    const float mn = widest ? f0[x] : isNear ? n0[x] : w0[x];
    const float mx = widest ? f1[x] : isNear ? n1[x] : w1[x];
    const int m = isNear && !widest ? margin : margin + kWideExtraMargin;
    l[x] = std::max(dmin, static_cast<int>(std::floor(2.0F * mn)) - m);
    h[x] = std::min(dmax, static_cast<int>(std::ceil(2.0F * mx)) + m);
  }
}
}  // namespace

void intervalsFromCoarse(const cv::Mat& coarse, cv::Size size, int dmin, int dmax, int margin,
                         bool widenNearRejected, int threads, cv::Mat& lo, cv::Mat& hi) {
  const int cw = coarse.cols, ch = coarse.rows;
  // Neighbourhood minima and maxima of the valid coarse disparities (rejected pixels ignored;
  // the border does not extend the neighbourhood).
  constexpr float kInf = std::numeric_limits<float>::infinity();
  cv::Mat forMin, forMax, rejected;
  rangeFilterInputs(coarse, kInf, -kInf, threads, forMin, forMax);
  if (widenNearRejected) cv::compare(forMin, kInf, rejected, cv::CMP_EQ);  // 255 where rejected
  cv::Mat mn1, mx1, mnWide, mxWide, mnWidest, mxWidest, nearRejected;
  const auto square = [](int radius) {
    return cv::Mat::ones(2 * radius + 1, 2 * radius + 1, CV_8U);
  };
  const int widestRadius = widenNearRejected ? kWidestRadiusAbove : kWidestRadiusFinest;
  // The six filters and the rejected pixels' dilation as seven tasks, the widest (the longest)
  // first, so that the workers share them evenly.
  const auto minFilter = [&](int radius, cv::Mat& out) {
    cv::erode(forMin, out, square(radius), {-1, -1}, 1, cv::BORDER_CONSTANT, kInf);
  };
  const auto maxFilter = [&](int radius, cv::Mat& out) {
    cv::dilate(forMax, out, square(radius), {-1, -1}, 1, cv::BORDER_CONSTANT, -kInf);
  };
  runTasks({[&] { minFilter(widestRadius, mnWidest); }, [&] { maxFilter(widestRadius, mxWidest); },
            [&] { minFilter(kWideRadius, mnWide); }, [&] { maxFilter(kWideRadius, mxWide); },
            [&] { minFilter(1, mn1); }, [&] { maxFilter(1, mx1); },
            [&] {
              if (widenNearRejected) cv::dilate(rejected, nearRejected, square(1));
            }},
           threads);
  cv::Mat clo(coarse.size(), CV_32S), chi(coarse.size(), CV_32S);
  // By bands of rows on the level's threads (serial, ~0.3 % of the run's instructions).
  forRowBands(ch, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      coarseIntervalRow(mn1.ptr<float>(y), mx1.ptr<float>(y), mnWide.ptr<float>(y),
                        mxWide.ptr<float>(y), mnWidest.ptr<float>(y), mxWidest.ptr<float>(y),
                        widenNearRejected ? nearRejected.ptr<uchar>(y) : nullptr, cw, dmin, dmax,
                        margin, clo.ptr<int>(y), chi.ptr<int>(y));
    }
  });
  lo.create(size, CV_32S);
  hi.create(size, CV_32S);
  forRowBands(size.height, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const int cy = std::min(ch - 1, y / 2);
      const int *cl = clo.ptr<int>(cy), *chh = chi.ptr<int>(cy);
      int *l = lo.ptr<int>(y), *h = hi.ptr<int>(y);
      for (int x = 0; x < size.width; ++x) {
        const int cx = std::min(cw - 1, x / 2);
        l[x] = cl[cx];
        h[x] = chh[cx];
      }
    }
  });
}

cv::Mat oneSurfacePixels(const cv::Mat& coarse, cv::Size size, int radius, float spread,
                         int threads) {
  CV_Assert(coarse.type() == CV_32F && radius >= 0);
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // A rejected pixel makes the neighbourhood's spread infinite: -inf for the minimum, +inf for
  // the maximum, and so does the border.
  cv::Mat forMin, forMax, lowest, highest;
  rangeFilterInputs(coarse, -kInf, kInf, threads, forMin, forMax);
  rangeFilters(forMin, forMax, cv::Mat::ones(2 * radius + 1, 2 * radius + 1, CV_8U), -kInf, kInf,
               threads, lowest, highest);
  const int cw = coarse.cols, ch = coarse.rows;
  cv::Mat out(size, CV_8U);
  forRowBands(size.height, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const int cy = std::min(ch - 1, y / 2);
      const float* lo = lowest.ptr<float>(cy);
      const float* hi = highest.ptr<float>(cy);
      uchar* o = out.ptr<uchar>(y);
      for (int x = 0; x < size.width; ++x) {
        const int cx = std::min(cw - 1, x / 2);
        o[x] = hi[cx] - lo[cx] <= spread ? 1 : 0;  // (inf − (−inf) never is)
      }
    }
  });
  return out;
}

}  // namespace delineo::stereo::detail
