#include "weak_matches.hpp"

#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "components.hpp"
#include "neighbourhood_range.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
// Makes unmatched (NaN disparity and score) every matched pixel that does not score exactly
// `fillScore` (the fill's), scores below `minScore` and passes `rejects(y, x)`; by bands of rows
// on `threads` workers. Returns how many.
template <class Rejects>
int rejectWeakWhere(cv::Mat& disparity, cv::Mat& score, float fillScore, float minScore,
                    int threads, const Rejects& rejects) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  std::vector<int> rejectedPerRow(static_cast<size_t>(disparity.rows), 0);
  forRowBands(disparity.rows, threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      float* d = disparity.ptr<float>(y);
      float* s = score.ptr<float>(y);
      int rejected = 0;
      for (int x = 0; x < disparity.cols; ++x) {
        if (d[x] != d[x] || s[x] == fillScore || !(s[x] < minScore) || !rejects(y, x)) continue;
        d[x] = kNaN;
        s[x] = kNaN;
        ++rejected;
      }
      rejectedPerRow[static_cast<size_t>(y)] = rejected;
    }
  });
  int total = 0;
  for (const int r : rejectedPerRow) total += r;
  return total;
}
}  // namespace

int rejectWeakMatchesBesideSteps(const WeakMatchSettings& settings, float fillScore,
                                 cv::Mat& disparity, cv::Mat& score, const cv::Mat& candidates) {
  CV_Assert(disparity.type() == CV_32F && score.type() == CV_32F &&
            disparity.size() == score.size());
  CV_Assert(candidates.empty() ||
            (candidates.type() == CV_8U && candidates.size() == disparity.size()));
  if (!(settings.minScore > 0) || disparity.empty()) return 0;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  // Neighbourhood min and max of the valid disparities (unmatched pixels ignored).
  cv::Mat forMin, forMax, lowest, highest;
  rangeFilterInputs(disparity, kInf, -kInf, settings.threads, forMin, forMax);
  const int side = 2 * settings.radius + 1;
  rangeFilters(forMin, forMax, cv::Mat::ones(side, side, CV_8U), kInf, -kInf, settings.threads,
               lowest, highest);
  const float minStep = static_cast<float>(settings.minStep);
  return rejectWeakWhere(disparity, score, fillScore, static_cast<float>(settings.minScore),
                         settings.threads, [&](int y, int x) {
                           if (!candidates.empty() && candidates.ptr<uchar>(y)[x] == 0)
                             return false;
                           // Beside a step, and on its far side (nearer the lowest disparity than
                           // the highest).
                           const float lo = lowest.ptr<float>(y)[x], hi = highest.ptr<float>(y)[x];
                           const float d = disparity.ptr<float>(y)[x];
                           return hi - lo >= minStep && d - lo < hi - d;
                         });
}

int rejectWeakMatchesBesideUnmatchedPlain(const UnmatchedPlainSettings& settings, float fillScore,
                                          const cv::Mat& plain, cv::Mat& disparity,
                                          cv::Mat& score) {
  CV_Assert(disparity.type() == CV_32F && score.type() == CV_32F &&
            disparity.size() == score.size());
  CV_Assert(plain.type() == CV_8U && plain.size() == disparity.size());
  if (!(settings.minScore > 0) || disparity.empty()) return 0;
  // The unmatched plain pixels, their 4-connected regions, and the large ones grown by the radius.
  cv::Mat unmatched(disparity.size(), CV_8U);
  forRowBands(disparity.rows, settings.threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const float* d = disparity.ptr<float>(y);
      const uchar* p = plain.ptr<uchar>(y);
      uchar* u = unmatched.ptr<uchar>(y);
      for (int x = 0; x < disparity.cols; ++x) u[x] = d[x] != d[x] && p[x] != 0 ? 255 : 0;
    }
  });
  cv::Mat labels, stats, centroids;
  componentsWithStats(unmatched, labels, stats, centroids, 4, settings.threads);
  cv::Mat large(disparity.size(), CV_8U);
  forRowBands(disparity.rows, settings.threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      const int* l = labels.ptr<int>(y);
      uchar* out = large.ptr<uchar>(y);
      for (int x = 0; x < disparity.cols; ++x) {
        out[x] = l[x] > 0 && stats.at<int>(l[x], cv::CC_STAT_AREA) >= settings.minArea ? 255 : 0;
      }
    }
  });
  cv::Mat beside;
  const int side = 2 * settings.radius + 1;
  cv::dilate(large, beside, cv::Mat::ones(side, side, CV_8U));
  return rejectWeakWhere(
      disparity, score, fillScore, static_cast<float>(settings.minScore), settings.threads,
      [&](int y, int x) { return plain.ptr<uchar>(y)[x] != 0 && beside.ptr<uchar>(y)[x] != 0; });
}

}  // namespace delineo::stereo::detail
