#pragma once
// A building's start read from a feature: the initial polygon of a `delineate --init` file or a
// building proposal (segmentation::detectBuildings), with the properties roof_disparity_min/max
// and ground_disparity that `delineo-cli detect` writes. The CLI, the project's proposals and the
// benchmarks read them here, one way.
#include <optional>

#include "delineo/core/geometry.hpp"
#include "delineo/delineation/delineate.hpp"

namespace delineo::delineation {

// Disparities beyond this many pixels are no disparity of a real pair: a sign of a bad value.
inline constexpr double kMaxFeatureDisparity = 100000;

// The intervals a feature carries; an absent property leaves its member empty.
struct FeatureIntervals {
  std::optional<DisparityInterval> roof;  // floor(min) .. ceil(max); needs both properties
  std::optional<int> groundDisparity;     // ground_disparity rounded to the nearest integer
};

// Throws core::Error(InvalidParameter) naming the property when one is present but is not a
// finite number within +-kMaxFeatureDisparity, or when roof_disparity_min is above _max.
FeatureIntervals readFeatureIntervals(const core::Feature& feature);

// The feature as a request: its outer ring (the active polygon starts from one ring), its roof
// interval and, when it has one, its ground disparity +- `groundTolerance`. Nullopt without a
// roof interval. Throws as readFeatureIntervals.
std::optional<DelineationRequest> featureRequest(const core::Feature& feature, int groundTolerance);

}  // namespace delineo::delineation
