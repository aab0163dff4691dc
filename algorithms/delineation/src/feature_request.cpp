#include "delineo/delineation/feature_request.hpp"

#include <cmath>

#include "delineo/core/error.hpp"

namespace delineo::delineation {

FeatureIntervals readFeatureIntervals(const core::Feature& feature) {
  FeatureIntervals out;
  const auto low = core::numberProperty(feature, "roof_disparity_min", kMaxFeatureDisparity);
  const auto high = core::numberProperty(feature, "roof_disparity_max", kMaxFeatureDisparity);
  if (low && high) {
    out.roof = DisparityInterval{static_cast<int>(std::floor(*low)), static_cast<int>(std::ceil(*high))};
    if (out.roof->min > out.roof->max) {
      throw core::Error(core::ErrorCode::InvalidParameter, "roof_disparity_min is above roof_disparity_max");
    }
  }
  if (const auto g = core::numberProperty(feature, "ground_disparity", kMaxFeatureDisparity)) {
    out.groundDisparity = static_cast<int>(std::lround(*g));
  }
  return out;
}

std::optional<DelineationRequest> featureRequest(const core::Feature& feature, int groundTolerance) {
  const FeatureIntervals intervals = readFeatureIntervals(feature);
  if (!intervals.roof) return std::nullopt;
  DelineationRequest req;
  req.init.outer = feature.polygon.outer;
  req.roof = *intervals.roof;
  if (intervals.groundDisparity) {
    const int c = *intervals.groundDisparity;
    req.ground = DisparityInterval{c - groundTolerance, c + groundTolerance};
  }
  return req;
}

}  // namespace delineo::delineation
