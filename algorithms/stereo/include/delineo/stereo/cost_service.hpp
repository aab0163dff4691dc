#pragma once
// Correlation cost service for delineation (the contract between stereo and delineation).
//
// For a region of interest of the left image and an integer disparity range [dmin, dmax], holds
// Crit(x, y, d): a correlation cost in [0, 1] with 0 a perfect match, for every ROI pixel and d,
// where x_right = x - d. Answers c_D(x, y) = min over d in D of Crit(x, y, d) for arbitrary
// intervals D fast enough for interactive dragging (300x300 ROI, 256 disparities: well under
// 20 ms per query), without a full-image float cost volume.
#include <memory>

#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::stereo {

struct CostParams {
  int window = 5;              // px, odd side of the correlation window for Crit
  double unmatchedCost = 1.0;  // cost where the match falls outside the right image or on NaN
  // Mean grey level term for windows with little texture, where NCC is noise: 0 = NCC only.
  // Else a window whose left variance exceeds the noise's by t gets weight t / (t + sigma^2) on NCC
  // and the rest on |mean_left - mean_right| / (brightnessScale * sigma), capped at 1, after a
  // global gain/offset match of the right view to the left (sigma: image noise estimated from the
  // left ROI).
  double brightnessScale = 0.0;  // × noise sigma: mean difference that costs 1 (0 = off)
  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"cost-window", "Cost window", "px",
                      "Side of the square window of the per-pixel correlation cost", 3, 31},
      window);
    v(core::ParamInfo{"brightness-scale", "Brightness scale", "× noise",
                      "Windows with little texture are also compared by mean grey level (after a "
                      "global gain/offset match of the views): a mean difference of this many "
                      "noise sigmas costs 1 (0 = NCC only)",
                      0, 100},
      brightnessScale);
    v(core::ParamInfo{"unmatched-cost", "Unmatched cost", "",
                      "Cost given where the matching window leaves the right image", 0, 1},
      unmatchedCost);
  }
  void validate() const;
};

class CorrelationCostService {
 public:
  // left/right: single-channel float32 (NaN = nodata), same size. roi inside the left image.
  // Throws core::Error: InvalidParameter (empty range, dmin > dmax, ROI outside the image),
  // MismatchedInputs (sizes). Returns nullptr when `progress` was canceled.
  static std::unique_ptr<CorrelationCostService> compute(const cv::Mat& left, const cv::Mat& right,
                                                         cv::Rect roi, int dmin, int dmax,
                                                         const CostParams& params = {},
                                                         core::Progress* progress = nullptr);
  virtual ~CorrelationCostService() = default;

  virtual cv::Rect roi() const = 0;  // in left-image pixel coordinates
  virtual int dmin() const = 0;
  virtual int dmax() const = 0;
  // Crit at left-image pixel (x, y) inside roi() and d in [dmin, dmax].
  virtual float cost(int x, int y, int d) const = 0;
  // c_D for D = [a, b] clipped to [dmin, dmax]: CV_32F of roi().size(); unmatchedCost where the
  // clipped interval is empty.
  virtual cv::Mat minCost(int a, int b) const = 0;
  // Argmin disparity over the full range (CV_32S, roi size) and its cost (CV_32F).
  virtual cv::Mat bestDisparity() const = 0;
  virtual cv::Mat bestCost() const = 0;
};

}  // namespace delineo::stereo
