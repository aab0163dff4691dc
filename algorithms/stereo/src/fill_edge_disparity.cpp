// A plain region's disparity read from its edges, located to a fraction of a pixel in both views
// (see RegionFillSettings::edgeMinSamples).
#include "fill_internal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <tuple>
#include <vector>

#include "radiometry.hpp"

namespace delineo::stereo::detail {

// Sub-pixel position of a flat region's edge on a row of `row` (`cols` px), from the region's end
// pixel `start` walking outwards (`step` −1 or +1) over at most 5 pixels of the roof's grey
// (within 3 `sigma` of `roof`): the first other pixel q is the mixed one, the next lies beyond.
// The edge is where the roof's share of q, (grey − beyond) / (roof − beyond), ends. Pixel x
// covers [x − 0.5, x + 0.5]. Nothing when the walk leaves the row or the edge's contrast is below
// 6 sigma (its share is then mostly noise).
std::optional<double> subpixelEdge(const float* row, int cols, int start, int step, double roof,
                                   double sigma) {
  int p = start;
  for (int k = 0; k < 5; ++k) {
    const int next = p + step;
    if (next - step < 0 || next - step >= cols || next + 2 * step < 0 || next + 2 * step >= cols) {
      return std::nullopt;
    }
    if (std::abs(row[next] - roof) > 3 * sigma) break;
    p = next;
  }
  const int q = p + step;
  if (q + step < 0 || q + step >= cols) return std::nullopt;
  const double beyond = row[q + step];
  if (!std::isfinite(beyond) || !std::isfinite(row[q]) || std::abs(roof - beyond) < 6 * sigma) {
    return std::nullopt;
  }
  const double share = std::clamp((row[q] - beyond) / (roof - beyond), 0.0, 1.0);
  return step < 0 ? q + 0.5 - share : q - 0.5 + share;
}

EdgeReading edgeDisparity(const cv::Mat& left, const cv::Mat& right, const cv::Mat& region,
                          const cv::Rect& box, const RightFlatRegions& rightFlat, double gain,
                          double offset, double sigma, int dmin, int dmax, float candidate,
                          double reach) {
  const double leftMean = cv::mean(left(box), region)[0];
  const std::vector<RowEnds> rows = regionRowEnds(region, box);
  std::map<int, int> agreeing;  // right label -> rows with an end that agrees with `candidate`
  for (const RowEnds& r : rows) {
    const int* l = rightFlat.labels.ptr<int>(r.y);
    const auto [x0, x1] = searchBand(r, dmin, dmax, rightFlat.labels.cols);
    std::map<int, std::pair<int, int>> ends;
    for (int x = x0; x <= x1; ++x) {
      if (l[x] == 0) continue;
      const auto [it, inserted] = ends.try_emplace(l[x], x, x);
      if (!inserted) it->second.second = x;
    }
    for (const auto& [label, e] : ends) {
      const double mapped = gain * rightFlat.meanGrey[static_cast<size_t>(label)] + offset;
      if (std::abs(mapped - leftMean) > 3 * sigma) continue;
      if (std::abs(r.l0 - e.first - candidate) <= reach ||
          std::abs(r.l1 - e.second - candidate) <= reach) {
        ++agreeing[label];
      }
    }
  }
  int label = 0, most = 0;
  for (const auto& [k, n] : agreeing) {
    if (n > most) {
      most = n;
      label = k;
    }
  }
  if (label == 0) return {};
  const double rightMean = rightFlat.meanGrey[static_cast<size_t>(label)];
  const double rightSigma = sigma / gain;
  std::vector<double> values;
  std::vector<std::uint8_t> atLeftEnd;
  for (const RowEnds& r : rows) {
    const auto [r0, r1] = labelEndsInBand(rightFlat.labels, r, label, dmin, dmax);
    if (r0 < 0) continue;
    const float* a = left.ptr<float>(r.y);
    const float* b = right.ptr<float>(r.y);
    for (const auto& [l, rr, step] : {std::tuple{r.l0, r0, -1}, std::tuple{r.l1, r1, +1}}) {
      if (std::abs(l - rr - candidate) > reach) continue;
      const auto inLeft = subpixelEdge(a, left.cols, l, step, leftMean, sigma);
      const auto inRight = subpixelEdge(b, right.cols, rr, step, rightMean, rightSigma);
      if (inLeft && inRight) {
        values.push_back(*inLeft - *inRight);
        atLeftEnd.push_back(step < 0 ? 1 : 0);
      }
    }
  }
  if (values.empty()) return {};
  const double median = middleValue(values);
  EdgeReading reading;
  reading.read = static_cast<int>(values.size());
  double sum = 0;
  for (size_t k = 0; k < values.size(); ++k) {
    if (std::abs(values[k] - median) <= 0.75) {
      sum += values[k];
      ++reading.samples;
      reading.fromLeftEnds += atLeftEnd[k];
    }
  }
  reading.value = sum / reading.samples;
  return reading;
}

}  // namespace delineo::stereo::detail
