#pragma once
// The DTM of the ground/above-ground segmentation (after Baillard and Maître): one ground point
// per window (the lowest well-populated elevation of the window's ground pixels, nearest the
// window's centre), a Delaunay triangulation of those points (cv::Subdiv2D) and planar interpolation in
// each triangle. Outside the points' convex hull the surface continues from the nearest hull
// pixel with the slope of the points' least-squares plane, so that a sloped terrain is not
// flattened at the image borders.
#include <vector>

#include <opencv2/core.hpp>

namespace delineo::segmentation {

struct GroundSample {
  cv::Point position;  // pixel (column, row); interpolated at its centre
  float height = 0.0f; // m
};

// One sample per `windowPx` x `windowPx` window (tiled from the top-left corner) of the pixels
// where `ground` is non-zero and `dem` (CV_32F, m) is finite: the pixel nearest the window's
// centre among those whose height falls in the lowest bin of `binWidth` metres that holds at
// least `levelShare` of the most populated bin's pixels (1: the most populated bin). A
// window gives no sample when its ground pixels are fewer than 1 % of its area and fewer than
// its pixels with a height (a speck of ground in a window of roof says little).
std::vector<GroundSample> sampleGround(const cv::Mat& dem, const cv::Mat& ground, int windowPx, double binWidth,
                                       double levelShare = 1.0);

// The DTM (CV_32F, m) of `size` from the samples: planar per Delaunay triangle inside their
// hull, extended outside it (see above). One or two samples, or samples on one line, give their
// least-squares plane everywhere; no sample gives NaN everywhere.
cv::Mat interpolateDtm(const std::vector<GroundSample>& samples, cv::Size size);

}  // namespace delineo::segmentation
