#pragma once
// Small gaps of the contour map closed (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

// Canny breaks a roof outline where its contrast dips against the ground's texture, and the
// adaptive shape, a 4-connected flood fill, leaks through the gap: the windows of a plain roof's
// pixels behind it reach the ground and can carry its disparity into the roof (sim seed 15
// 1000²: a 5 x 4 px patch 40 px off behind a 2 px gap, 91 % of the roof's squared error). Each
// chain end (a contour pixel with exactly one contour neighbour) is joined by a straight
// 8-connected segment to the nearest contour pixel across at most `maxGap` missing pixels
// (Chebyshev distance 2 .. maxGap + 1), ahead of it (within 60° of the direction the chain runs
// out in) and not already joined to it by contour pixels within maxGap + 3 px: the gap is closed,
// the chain's own bends are not. The segments are drawn once all ends are found, so a segment
// does not make new ends. `edges`: CV_8U, contour pixels non-zero (Canny's 255); maxGap < 1:
// no-op. Returns the number of segments drawn (both ends of a gap draw one).
int bridgeContourGaps(cv::Mat& edges, int maxGap);

}  // namespace delineo::stereo::detail
