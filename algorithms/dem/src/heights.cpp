#include "delineo/dem/heights.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"

namespace delineo::dem {

namespace {

using core::Error;
using core::ErrorCode;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kRowsPerPoll = 64;  // rows between two cancel polls

void checkDem(const cv::Mat& dem, const char* what) {
  if (dem.empty()) throw Error(ErrorCode::UnsupportedInput, std::string("the ") + what + " is empty");
  if (dem.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput, std::string("the ") + what + " must be one band of float32");
  }
}

// Fills the NaN pixels of `values` (CV_32F) from its finite ones by pull-push: a pyramid of
// weighted means (pull), then, from the coarsest level down, each pixel with little or no weight
// takes the bilinear interpolation of the level above (push). Smooth, exact on the finite pixels,
// linear in the area. Leaves `values` unchanged when nothing is finite.
void pullPush(cv::Mat& values) {
  std::vector<cv::Mat> v(1), w(1);
  v[0] = values.clone();
  w[0] = cv::Mat(values.size(), CV_32F);
  bool any = false;
  for (int y = 0; y < values.rows; ++y) {
    float* pv = v[0].ptr<float>(y);
    float* pw = w[0].ptr<float>(y);
    for (int x = 0; x < values.cols; ++x) {
      pw[x] = std::isfinite(pv[x]) ? 1.0f : 0.0f;
      if (pw[x] == 0.0f) pv[x] = 0.0f;
      any = any || pw[x] > 0.0f;
    }
  }
  if (!any) return;
  while (v.back().cols > 1 || v.back().rows > 1) {
    const cv::Mat& fv = v.back();
    const cv::Mat& fw = w.back();
    const cv::Size size((fv.cols + 1) / 2, (fv.rows + 1) / 2);
    cv::Mat sums(size, CV_32F, cv::Scalar(0)), weights(size, CV_32F, cv::Scalar(0));
    for (int y = 0; y < fv.rows; ++y) {
      for (int x = 0; x < fv.cols; ++x) {
        const float weight = fw.at<float>(y, x);
        sums.at<float>(y / 2, x / 2) += weight * fv.at<float>(y, x);
        weights.at<float>(y / 2, x / 2) += weight;
      }
    }
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x) {
        float& weight = weights.at<float>(y, x);
        if (weight > 0.0f) sums.at<float>(y, x) /= weight;
        weight = std::min(1.0f, weight);
      }
    }
    v.push_back(sums);
    w.push_back(weights);
  }
  for (size_t l = v.size() - 1; l-- > 0;) {
    cv::Mat coarse;
    cv::resize(v[l + 1], coarse, v[l].size(), 0, 0, cv::INTER_LINEAR);
    for (int y = 0; y < v[l].rows; ++y) {
      float* pv = v[l].ptr<float>(y);
      const float* pw = w[l].ptr<float>(y);
      const float* pc = coarse.ptr<float>(y);
      for (int x = 0; x < v[l].cols; ++x) pv[x] = pw[x] * pv[x] + (1.0f - pw[x]) * pc[x];
    }
  }
  for (int y = 0; y < values.rows; ++y) {
    float* out = values.ptr<float>(y);
    const float* in = v[0].ptr<float>(y);
    for (int x = 0; x < values.cols; ++x) {
      if (!std::isfinite(out[x])) out[x] = in[x];
    }
  }
}

// Writes into `dem` the pull-push interpolation of `anchors` (positions and heights) over the
// pixels of gap `label` (box `box` of `labels`).
void interpolateGap(cv::Mat& dem, const cv::Mat& labels, int label, const cv::Rect& box,
                    const std::vector<cv::Point>& anchors) {
  const cv::Rect local = cv::Rect(box.x - 1, box.y - 1, box.width + 2, box.height + 2) &
                         cv::Rect(0, 0, dem.cols, dem.rows);
  cv::Mat values(local.size(), CV_32F, cv::Scalar(kNaN));
  for (const cv::Point& p : anchors) values.at<float>(p - local.tl()) = dem.at<float>(p);
  pullPush(values);
  for (int y = box.y; y < box.y + box.height; ++y) {
    const int* l = labels.ptr<int>(y);
    float* d = dem.ptr<float>(y);
    const float* v = values.ptr<float>(y - local.y);
    for (int x = box.x; x < box.x + box.width; ++x) {
      if (l[x] == label) d[x] = v[x - local.x];
    }
  }
}

// The heights 8-adjacent to each gap: positions per gap label (index 0 unused).
std::vector<std::vector<cv::Point>> gapBorders(const cv::Mat& dem, const cv::Mat& labels, int count,
                                               core::Progress* progress, bool& canceled) {
  std::vector<std::vector<cv::Point>> borders(static_cast<size_t>(count));
  for (int y = 0; y < dem.rows; ++y) {
    if (y % kRowsPerPoll == 0) {
      if (core::isCanceled(progress)) {
        canceled = true;
        return borders;
      }
      core::report(progress, 0.1 + 0.3 * y / dem.rows);
    }
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < dem.cols; ++x) {
      if (l[x] == 0) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= dem.rows) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= dem.cols || labels.at<int>(yy, xx) != 0) continue;
          borders[static_cast<size_t>(l[x])].emplace_back(xx, yy);
        }
      }
    }
  }
  for (auto& border : borders) {
    std::sort(border.begin(), border.end(),
              [](const cv::Point& a, const cv::Point& b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
    border.erase(std::unique(border.begin(), border.end()), border.end());
  }
  return borders;
}

// The highest value of the lower of two clusters of `values` (the split of the sorted values
// with the least within-cluster variance); the only value when there is one.
float lowerClusterTop(std::vector<float> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  std::vector<double> sum(n + 1, 0.0), sum2(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) {
    sum[i + 1] = sum[i] + values[i];
    sum2[i + 1] = sum2[i] + static_cast<double>(values[i]) * values[i];
  }
  // Within-cluster sum of squares of values[a, b).
  auto scatter = [&](size_t a, size_t b) {
    const double s = sum[b] - sum[a];
    return sum2[b] - sum2[a] - s * s / static_cast<double>(b - a);
  };
  size_t best = n;
  double bestCost = std::numeric_limits<double>::infinity();
  for (size_t k = 1; k < n; ++k) {
    const double cost = scatter(0, k) + scatter(k, n);
    if (cost < bestCost) bestCost = cost, best = k;
  }
  return values[best - 1];
}

}  // namespace

void HeightModel::validate() const {
  core::checkDeclaredRanges(*this);
  if (metresPerPixel == 0.0) {
    throw Error(ErrorCode::InvalidParameter, "metres-per-pixel must not be zero");
  }
}

void GapParams::validate() const { core::checkDeclaredRanges(*this); }

cv::Mat heightsFromDisparity(const cv::Mat& disparity, const HeightModel& model) {
  model.validate();
  checkDem(disparity, "disparity map");
  cv::Mat heights;
  // NaN times anything stays NaN.
  disparity.convertTo(heights, CV_32F, model.metresPerPixel,
                      model.referenceHeight - model.groundDisparity * model.metresPerPixel);
  return heights;
}

cv::Mat disparityFromHeights(const cv::Mat& heights, const HeightModel& model) {
  model.validate();
  checkDem(heights, "DEM");
  cv::Mat disparity;
  heights.convertTo(disparity, CV_32F, 1.0 / model.metresPerPixel,
                    model.groundDisparity - model.referenceHeight / model.metresPerPixel);
  return disparity;
}

GapResult handleGaps(const cv::Mat& dem, const GapParams& params, core::Progress* progress) {
  params.validate();
  checkDem(dem, "DEM");
  GapResult result;
  result.dem = dem.clone();
  cv::Mat noData(dem.size(), CV_8U);
  for (int y = 0; y < dem.rows; ++y) {
    const float* d = dem.ptr<float>(y);
    uchar* n = noData.ptr<uchar>(y);
    for (int x = 0; x < dem.cols; ++x) {
      if (std::isinf(d[x])) {
        throw Error(ErrorCode::UnsupportedInput, "the DEM holds an infinite height at pixel (" +
                                                     std::to_string(x) + ", " + std::to_string(y) + ")");
      }
      n[x] = std::isnan(d[x]) ? 255 : 0;
    }
  }
  cv::Mat stats, centroids;
  const int count = cv::connectedComponentsWithStats(noData, result.gapLabels, stats, centroids, 8, CV_32S);
  core::report(progress, 0.1);
  bool canceled = false;
  const auto borders = gapBorders(dem, result.gapLabels, count, progress, canceled);
  if (canceled) {
    result.status = core::RunStatus::Canceled;
    result.dem = dem;
    return result;
  }
  result.gaps.resize(static_cast<size_t>(std::max(0, count - 1)));
  for (int label = 1; label < count; ++label) {
    if (core::isCanceled(progress)) {
      result.status = core::RunStatus::Canceled;
      result.dem = dem;
      return result;
    }
    if (label % 64 == 0) core::report(progress, 0.4 + 0.6 * label / count);
    DemGap& gap = result.gaps[static_cast<size_t>(label - 1)];
    gap.pixels = stats.at<int>(label, cv::CC_STAT_AREA);
    gap.box = cv::Rect(stats.at<int>(label, cv::CC_STAT_LEFT), stats.at<int>(label, cv::CC_STAT_TOP),
                       stats.at<int>(label, cv::CC_STAT_WIDTH), stats.at<int>(label, cv::CC_STAT_HEIGHT));
    gap.touchesEdge = gap.box.x == 0 || gap.box.y == 0 || gap.box.br().x == dem.cols || gap.box.br().y == dem.rows;
    const std::vector<cv::Point>& border = borders[static_cast<size_t>(label)];
    gap.borderPixels = static_cast<int>(border.size());
    std::vector<float> heights;
    heights.reserve(border.size());
    for (const cv::Point& p : border) heights.push_back(dem.at<float>(p));
    if (!heights.empty()) {
      double sum = 0.0, sum2 = 0.0;
      for (float h : heights) sum += h, sum2 += static_cast<double>(h) * h;
      const double n = static_cast<double>(heights.size());
      gap.borderMean = sum / n;
      gap.borderSpread = std::sqrt(std::max(0.0, sum2 / n - gap.borderMean * gap.borderMean));
    }
    gap.merged = gap.borderPixels >= params.minBorderPixels && gap.borderSpread <= params.maxBorderSpread;
    if (gap.merged) {
      interpolateGap(result.dem, result.gapLabels, label, gap.box, border);
      result.mergedPixels += gap.pixels;
      continue;
    }
    result.keptPixels += gap.pixels;
  }
  core::report(progress, 1.0);
  return result;
}

void fillKeptGaps(GapResult& result) {
  if (result.dem.empty() || result.gaps.empty()) return;
  bool canceled = false;
  const auto borders = gapBorders(result.dem, result.gapLabels, static_cast<int>(result.gaps.size()) + 1,
                                  nullptr, canceled);
  for (size_t i = 0; i < result.gaps.size(); ++i) {
    DemGap& gap = result.gaps[i];
    const std::vector<cv::Point>& border = borders[i + 1];
    if (gap.merged || gap.filled || border.empty()) continue;
    std::vector<float> heights;
    heights.reserve(border.size());
    for (const cv::Point& p : border) heights.push_back(result.dem.at<float>(p));
    const float split = lowerClusterTop(heights);
    std::vector<cv::Point> lower;
    for (size_t k = 0; k < border.size(); ++k) {
      if (heights[k] <= split) lower.push_back(border[k]);
    }
    interpolateGap(result.dem, result.gapLabels, static_cast<int>(i) + 1, gap.box, lower);
    gap.filled = true;
    result.filledPixels += gap.pixels;
  }
}

GapResult demFromDisparity(const cv::Mat& disparity, const HeightModel& model, const GapParams& params,
                           bool fill, core::Progress* progress) {
  params.validate();
  const cv::Mat heights = heightsFromDisparity(disparity, model);
  GapResult result = handleGaps(heights, params, progress);
  if (fill && result.status == core::RunStatus::Completed) fillKeptGaps(result);
  return result;
}

}  // namespace delineo::dem
