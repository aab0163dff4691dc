#pragma once
// Edge map of an image for snapping outline vertices to image edges while an operator edits
// them: thin (one pixel wide) edges from the smoothed gradient with non-maximum suppression and
// hysteresis (Canny). The thresholds are relative to the median gradient, which measures the
// image's texture and noise, so that one setting works on bright and dark, sharp and soft
// images.
#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"

namespace delineo::project {

struct EdgeMapParams {
  double smoothing = 1.2;  // px, sigma of the Gaussian applied before the gradient (texture noise)
  double contrast = 5.0;   // edges start where the gradient exceeds this many times its median

  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"smoothing", "Edge smoothing", "px",
                      "Gaussian sigma applied before the gradient; larger ignores finer texture", 0.0, 10.0},
      smoothing);
    v(core::ParamInfo{"contrast", "Edge contrast", "",
                      "An edge starts where the gradient is this many times the image's median gradient "
                      "(texture and noise level), and continues down to half of that",
                      1.0, 100.0},
      contrast);
  }
  void validate() const { core::checkDeclaredRanges(*this); }
};

// CV_8U map, 255 on edge pixels and 0 elsewhere, same size as `grey` (CV_8U or CV_32F, one
// channel; NaN is treated as 0). Empty input gives an empty map. Throws InvalidParameter.
cv::Mat edgeMap(const cv::Mat& grey, const EdgeMapParams& params = {});

}  // namespace delineo::project
