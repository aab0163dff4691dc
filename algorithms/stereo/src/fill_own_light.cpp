// The own light of a shaded region (see RegionFillSettings::shadowOwnLight): its outline ring's
// error with the views' brightness difference there removed, and the left view's median grey
// that tells a shaded region.
#include "fill_internal.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "radiometry.hpp"

namespace delineo::stereo::detail {

double ringErrorInOwnLight(const cv::Mat& left, const cv::Mat& right, const cv::Mat& ring,
                           const cv::Rect& box, const FillPlane& plane,
                           const std::pair<double, double>& map) {
  std::vector<double> residuals;
  const bool inside = visitRingResiduals(
      left, right, ring, box, plane, map, [&](double r) { residuals.push_back(r); },
      [] { return false; });
  if (!inside || residuals.empty()) return 1e30;
  const double own = middleValue(residuals);
  double sum = 0;
  for (const double r : residuals) sum += std::abs(r - own);
  return sum / static_cast<double>(residuals.size());
}

double medianGrey(const cv::Mat& image) {
  std::vector<double> sample;
  const size_t step = std::max<size_t>(1, image.total() / 10000);
  const float* p = image.ptr<float>();
  for (size_t i = 0; i < image.total(); i += step) {
    if (std::isfinite(p[i])) sample.push_back(p[i]);
  }
  return sample.empty() ? 0 : middleValue(sample);
}

}  // namespace delineo::stereo::detail
