#pragma once
// The active polygon's request for one building proposal of segmentation::detectBuildings (its
// polygon, roof interval and ground disparity), as `delineate --init` builds it, for the
// benchmarks that run the automatic chain.
#include <cmath>
#include <optional>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/delineation/delineate.hpp"

namespace delineo::bench {

// A numeric attribute of `f`, NaN when absent or not a number.
inline double numberAttribute(const core::Feature& f, const char* key) {
  const auto it = f.attributes.find(key);
  if (it == f.attributes.end()) return std::nan("");
  if (const auto* i = std::get_if<long long>(&it->second)) return static_cast<double>(*i);
  if (const auto* d = std::get_if<double>(&it->second)) return *d;
  return std::nan("");
}

// Nullopt for a proposal without a roof interval. `map`: the matcher's disparity map given with
// the request; `searchRange`: the pair's disparity range.
inline std::optional<delineation::DelineationRequest> proposalRequest(const core::Feature& f, const cv::Mat& map,
                                                                      delineation::DisparityInterval searchRange,
                                                                      int groundTolerance) {
  const double low = numberAttribute(f, "roof_disparity_min"), high = numberAttribute(f, "roof_disparity_max");
  if (!std::isfinite(low) || !std::isfinite(high)) return std::nullopt;
  delineation::DelineationRequest req;
  req.init = f.polygon;
  req.init.holes.clear();
  req.roof = {static_cast<int>(std::floor(low)), static_cast<int>(std::ceil(high))};
  const double g = numberAttribute(f, "ground_disparity");
  if (std::isfinite(g)) {
    const int c = static_cast<int>(std::lround(g));
    req.ground = delineation::DisparityInterval{c - groundTolerance, c + groundTolerance};
  }
  req.disparity = map;
  req.searchRange = searchRange;
  return req;
}

}  // namespace delineo::bench
