#pragma once
// Connected components with their statistics (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

// cv::connectedComponentsWithStats(mask, labels, stats, centroids, connectivity, CV_32S): the
// same labels, statistics and centroids, bit for bit (but for a label without pixels, the
// background of an all-foreground mask: area 0, box (0, 0, 0, 0), centroid NaN). OpenCV's version
// accumulates the statistics pixel by pixel over the whole image, background included (~6 ms at 1
// Mpx on one thread, three times its labelling); here they are summed over runs of one label, on
// `threads` workers, and the background's follow from the image's totals.
int componentsWithStats(const cv::Mat& mask, cv::Mat& labels, cv::Mat& stats, cv::Mat& centroids,
                        int connectivity, int threads);

}  // namespace delineo::stereo::detail
