#pragma once
// Synthetic stereo data for the stereo tests: smooth random texture and exact sub-pixel shifts.
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace delineo::stereo::testing {

// Band-limited random texture in [0, 255] (Gaussian-blurred uniform noise), float32.
inline cv::Mat texture(cv::Size size, unsigned seed, double blurSigma = 1.5) {
  cv::RNG rng(seed);
  cv::Mat noise(size, CV_32F);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::Mat out;
  cv::GaussianBlur(noise, out, cv::Size(0, 0), blurSigma);
  cv::normalize(out, out, 0, 255, cv::NORM_MINMAX);
  return out;
}

// right(x, y) = left(x + d, y): a left pixel x matches the right pixel x - d (x_r = x_l - d).
inline cv::Mat shiftedRight(const cv::Mat& left, double d) {
  cv::Mat mapX(left.size(), CV_32F), mapY(left.size(), CV_32F);
  for (int y = 0; y < left.rows; ++y) {
    for (int x = 0; x < left.cols; ++x) {
      mapX.at<float>(y, x) = static_cast<float>(x + d);
      mapY.at<float>(y, x) = static_cast<float>(y);
    }
  }
  cv::Mat out;
  cv::remap(left, out, mapX, mapY, cv::INTER_CUBIC, cv::BORDER_REFLECT);
  return out;
}

}  // namespace delineo::stereo::testing
