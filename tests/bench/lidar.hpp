#pragma once
// The DublinCity tile's LiDAR ground truth as the benchmarks read it: its disparity map, and the
// ground plane of that disparity.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "delineo/core/error.hpp"

namespace delineo::bench {

// The LiDAR-projected disparity (uint16 PNG, d = value / 256) as CV_32F px, NaN where it has none
// (value 0). Throws core::Error naming the file when it cannot be read.
inline cv::Mat readLidarDisparity(const std::string& path) {
  const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (raw.empty() || raw.type() != CV_16UC1) {
    throw core::Error(core::ErrorCode::UnsupportedInput, "not a 16-bit one-band disparity image", path);
  }
  cv::Mat lidar;
  raw.convertTo(lidar, CV_32F, 1.0 / 256.0);
  lidar.setTo(std::nanf(""), raw == 0);
  return lidar;
}

inline double tenthPercentile(std::vector<float> v) {
  const auto k = static_cast<long>(0.1 * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<size_t>(k)];
}

// The LiDAR's ground as a plane of disparity: the 10th percentile of each 128 px window, fitted
// by least squares, windows more than 3 px above the fit dropped and the fit repeated.
inline cv::Mat lidarGround(const cv::Mat& lidar) {
  std::vector<cv::Vec3d> samples;
  const int w = 128;
  for (int y = 0; y + w <= lidar.rows; y += w / 2) {
    for (int x = 0; x + w <= lidar.cols; x += w / 2) {
      std::vector<float> v;
      const cv::Mat win = lidar(cv::Rect(x, y, w, w));
      for (int r = 0; r < w; ++r) {
        for (int c = 0; c < w; ++c) {
          if (std::isfinite(win.at<float>(r, c))) v.push_back(win.at<float>(r, c));
        }
      }
      if (v.size() > 200) samples.push_back({x + w / 2.0, y + w / 2.0, tenthPercentile(v)});
    }
  }
  cv::Vec3d plane(0, 0, 0);  // d = a x + b y + c
  for (int round = 0; round < 5 && samples.size() >= 3; ++round) {
    cv::Mat A(static_cast<int>(samples.size()), 3, CV_64F), b(static_cast<int>(samples.size()), 1, CV_64F);
    for (size_t i = 0; i < samples.size(); ++i) {
      A.at<double>(static_cast<int>(i), 0) = samples[i][0];
      A.at<double>(static_cast<int>(i), 1) = samples[i][1];
      A.at<double>(static_cast<int>(i), 2) = 1.0;
      b.at<double>(static_cast<int>(i)) = samples[i][2];
    }
    cv::Mat p;
    cv::solve(A, b, p, cv::DECOMP_SVD);
    plane = {p.at<double>(0), p.at<double>(1), p.at<double>(2)};
    std::erase_if(samples, [&](const cv::Vec3d& s) { return s[2] > plane[0] * s[0] + plane[1] * s[1] + plane[2] + 3.0; });
  }
  cv::Mat ground(lidar.size(), CV_32F);
  for (int y = 0; y < lidar.rows; ++y) {
    for (int x = 0; x < lidar.cols; ++x) ground.at<float>(y, x) = static_cast<float>(plane[0] * x + plane[1] * y + plane[2]);
  }
  return ground;
}

}  // namespace delineo::bench
