#pragma once
// Sub-pixel noise averaged out on smooth surfaces (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

// Each matched pixel whose whole `window` x `window` neighbourhood is matched and within
// `tolerance` px of it takes the neighbourhood's mean disparity. The peaks' sub-pixel offsets are
// noisy from pixel to pixel (the neighbouring windows share most of their pixels but not the
// parabola's rounding), and a plane is its own mean over a symmetric window; a depth step larger
// than `tolerance` blocks the mean on both of its sides, so outlines do not move. Reads the map
// as it was (not the pixels already averaged): the result does not depend on `threads`. Returns
// the number of pixels averaged. window < 3: nothing done.
int smoothSurfaces(cv::Mat& disparity, int window, double tolerance, int threads = 1);

}  // namespace delineo::stereo::detail
