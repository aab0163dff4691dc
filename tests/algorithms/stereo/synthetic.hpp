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

// A textureless roof (flat `roofGrey` plus noise `noise`, 50x40 px at (60, 40), disparity 20)
// on textured ground (disparity 4), 180x120. `rightShowsIt` false: the right view shows
// textured ground where the roof should be (a flat patch only the left image has, e.g. a
// reflection). `groundSeed` / `noiseSeed` pick the texture and the noise.
struct FlatRoofPair {
  cv::Mat left, right;
  cv::Rect roof{60, 40, 50, 40};
};

inline FlatRoofPair flatRoofPair(bool rightShowsIt, float roofGrey, double noise,
                                 unsigned groundSeed, unsigned noiseSeed) {
  FlatRoofPair s;
  const cv::Size size(180, 120);
  const cv::Mat ground = texture(cv::Size(size.width + 64, size.height), groundSeed) * 0.6 + 20.0;
  s.left.create(size, CV_32F);
  s.right.create(size, CV_32F);
  cv::RNG rng(noiseSeed);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const bool onRoof = s.roof.contains({x, y});
      s.left.at<float>(y, x) = (onRoof ? roofGrey : ground.at<float>(y, x + 32)) +
                               static_cast<float>(rng.gaussian(noise));
      const bool seesRoof = rightShowsIt && s.roof.contains({x + 20, y});
      s.right.at<float>(y, x) = (seesRoof ? roofGrey : ground.at<float>(y, x + 4 + 32)) +
                                static_cast<float>(rng.gaussian(noise));
    }
  }
  return s;
}

// Independent Gaussian sensor noise of `sigma` grey levels added to each view.
inline void addSensorNoise(cv::Mat& left, cv::Mat& right, double sigma, cv::RNG& rng) {
  cv::Mat noise(left.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  left += noise;
  noise.create(right.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  right += noise;
}

}  // namespace delineo::stereo::testing

namespace delineo::stereo::testing {

// A textured background at disparity `background` and a brighter textured square at disparity
// `foreground` (larger: closer). Left-image truth in `truth`; `occluded` marks left pixels whose
// scene point is hidden in the right image.
struct SquareScene {
  cv::Mat left, right, truth, occluded;
  cv::Rect square;  // in the left image
};

// `squareLevel` is the square's mean grey level (140: brighter than the background's 30, so its
// outline is a contour; 30: no contour at all); `noiseSigma` > 0 adds Gaussian noise to both
// views (one seeded draw per pixel, left then right).
inline SquareScene squareScene(cv::Size size, cv::Rect square, int background, int foreground,
                               unsigned seed = 11, double squareLevel = 140.0,
                               double noiseSigma = 0.0) {
  // Moderate texture on both surfaces and a brighter square: its outline is the strongest
  // contour, as a roof edge is in aerial images.
  const cv::Mat back = texture(cv::Size(size.width + 64, size.height), seed) * 0.35 + 30.0;
  const cv::Mat front =
      texture(cv::Size(size.width + 64, size.height), seed + 1) * 0.35 + squareLevel;
  SquareScene s;
  s.square = square;
  s.left.create(size, CV_32F);
  s.right.create(size, CV_32F);
  s.truth.create(size, CV_32F);
  s.occluded = cv::Mat::zeros(size, CV_8U);
  cv::RNG rng(5);
  const auto noise = [&] {
    return noiseSigma > 0 ? static_cast<float>(rng.gaussian(noiseSigma)) : 0.0f;
  };
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const bool inSquare = square.contains(cv::Point(x, y));
      // Textures are indexed by left-image x so both views see the same surface point.
      s.left.at<float>(y, x) =
          (inSquare ? front.at<float>(y, x + 32) : back.at<float>(y, x + 32)) + noise();
      s.truth.at<float>(y, x) = static_cast<float>(inSquare ? foreground : background);
      // Right pixel xr sees the square if xr + foreground is inside it, else the background.
      const int xf = x + foreground;
      const bool seesSquare =
          y >= square.y && y < square.br().y && xf >= square.x && xf < square.br().x;
      s.right.at<float>(y, x) =
          (seesSquare ? front.at<float>(y, xf + 32) : back.at<float>(y, x + background + 32)) +
          noise();
      const int xr = x - background;
      const bool hidden = !inSquare && y >= square.y && y < square.br().y &&
                          xr + foreground >= square.x && xr + foreground < square.br().x;
      s.occluded.at<uchar>(y, x) = hidden ? 1 : 0;
    }
  }
  return s;
}

}  // namespace delineo::stereo::testing
