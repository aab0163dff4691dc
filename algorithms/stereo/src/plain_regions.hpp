#pragma once
// Plain regions matched by their shape, for the disparity range estimate (internal to
// delineo_stereo; docs/disparity-range.md).
//
// A roof without texture gives no keypoint, yet it is the same shape in both views of an
// epipolar pair, on the same rows, shifted by its disparity. Regions of plain pixels (local
// standard deviation within a few noise sigmas) are found in both detection copies and paired
// when they span the same rows, have about the same area and grey level, and overlap well once
// shifted; a pairing is kept only when it is the only good one for both regions (identical
// roofs in a row are left out).
#include <vector>

#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct PlainRegionSettings {
  double minAreaShare = 0.002;  // smallest region, share of the detection image's pixels
  double minOverlap = 0.7;      // intersection over union of the shifted shapes
  int grid = 16;                // one sample per grid cell the region covers
  double scale = 1.0;           // detection copy / full resolution
};

struct RegionSample {
  float x = 0, y = 0;  // full-resolution pixels, left image
  float d = 0;         // x_left - x_right, full-resolution pixels
};

// grey: CV_8U detection copies; mask: CV_8U, non-zero where pixels are valid. Returns samples
// of every paired region: one per grid cell it covers a tenth of, at least one per region.
std::vector<RegionSample> matchPlainRegions(const cv::Mat& leftGrey, const cv::Mat& leftMask,
                                            const cv::Mat& rightGrey, const cv::Mat& rightMask,
                                            const PlainRegionSettings& settings);

}  // namespace delineo::stereo::detail
