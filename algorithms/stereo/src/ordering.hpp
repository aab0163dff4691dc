#pragma once
// Matches the right view cannot see, by the order of the matches along a row (internal to
// delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct OrderingSettings {
  double tolerance = 1.0;  // px: how far a match's right-view position may lie beyond a match's
                           //   to its right (sub-pixel noise, slanted surfaces)
  double minJump = 2.0;    // px: the nearer match must be at least this much nearer
  int threads = 1;         // workers over bands of rows (the rows are independent)
};

// Whether a match that lies at `nearMapped` in the right view with disparity `nearDisparity`
// hides one at `farMapped` with `farDisparity` there (the test below; the fill's planes are held
// to it too). T: float or double, as the caller computes the positions.
template <typename T>
bool hides(T nearMapped, T nearDisparity, T farMapped, T farDisparity,
           const OrderingSettings& settings) {
  return nearMapped < farMapped - static_cast<T>(settings.tolerance) &&
         nearDisparity - farDisparity >= static_cast<T>(settings.minJump);
}

// Along a row of the left view, a match at x (disparity d) maps to x − d in the right view. A
// match at x' > x with a larger disparity d' that maps to the left of it (x' − d' < x − d −
// tolerance) hides it: the nearer surface at x' covers, in the right view, the point seen at x.
// The farther match is then occluded and cannot be right; it is rejected (NaN, score NaN). Such
// matches are windows that carried a far surface's disparity into a nearer one that the right
// view sees (a band of the ground's disparity along a roof's outline, matched alike in both
// views, so that the left/right check passes): the order of the two surfaces along the row tells
// what the check cannot. Thin near objects (a pole in front of a wall) can legitimately break the
// order; the simulated and aerial scenes have none narrower than their parallax.
// `disparity` CV_32F, NaN = unmatched; `score` empty or of the same size. Returns the rejected
// matches.
int rejectOrderingViolations(cv::Mat& disparity, cv::Mat& score, const OrderingSettings& settings);

}  // namespace delineo::stereo::detail
