// Correlation cost service: quantised Crit planes (one per disparity) plus block minima over d,
// so that c_D(x, y) = min over an arbitrary disparity interval costs a handful of vectorised
// plane minima instead of a pass over every disparity.
#include "delineo/stereo/cost_service.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "radiometry.hpp"

namespace delineo::stereo {

void CostParams::validate() const {
  core::checkDeclaredRanges(*this);
  if (window % 2 == 0) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "cost-window = " + std::to_string(window) + " must be odd");
  }
}

namespace {

using core::Error;
using core::ErrorCode;
using detail::noiseSigma;
using detail::radiometricMap;

// Costs are in [0, 1]; 16-bit quantisation keeps the error below 1e-5, far under the noise of
// any correlation score, at half the memory of float.
constexpr double kQuantScale = 65535.0;
// Disparities per block of the block-minimum planes: a query touches at most 2 partial blocks
// (< 2 * kBlock planes) plus (range / kBlock) block planes.
constexpr int kBlock = 16;

uint16_t quantise(double cost) {
  return static_cast<uint16_t>(std::lround(std::clamp(cost, 0.0, 1.0) * kQuantScale));
}

// Copies `rect` of `src` (float) into a new CV_64F matrix; pixels outside `src` become NaN.
cv::Mat cropWithNaN(const cv::Mat& src, const cv::Rect& rect) {
  cv::Mat out(rect.size(), CV_64F, cv::Scalar(std::numeric_limits<double>::quiet_NaN()));
  const cv::Rect inside = rect & cv::Rect(0, 0, src.cols, src.rows);
  if (inside.area() > 0) {
    src(inside).convertTo(out(cv::Rect(inside.tl() - rect.tl(), inside.size())), CV_64F);
  }
  return out;
}

// Splits an image with NaN into zero-filled values and a validity (1/0) mask.
void splitValid(const cv::Mat& withNaN, cv::Mat& values, cv::Mat& valid) {
  values = withNaN.clone();
  valid = cv::Mat(withNaN.size(), CV_64F);
  for (int y = 0; y < withNaN.rows; ++y) {
    double* v = values.ptr<double>(y);
    double* m = valid.ptr<double>(y);
    for (int x = 0; x < withNaN.cols; ++x) {
      const bool ok = std::isfinite(v[x]);
      m[x] = ok ? 1.0 : 0.0;
      if (!ok) v[x] = 0.0;
    }
  }
}

// Unnormalised box sums of side `window` for every position where the box fits in `src`.
cv::Mat boxSums(const cv::Mat& src, int window) {
  cv::Mat sums;
  cv::boxFilter(src, sums, CV_64F, cv::Size(window, window), cv::Point(-1, -1), false,
                cv::BORDER_CONSTANT);
  const int r = window / 2;
  return sums(cv::Rect(r, r, src.cols - 2 * r, src.rows - 2 * r));
}

class QuantisedCostVolume final : public CorrelationCostService {
 public:
  QuantisedCostVolume(cv::Rect roi, int dmin, int dmax, double unmatched)
      : roi_(roi), dmin_(dmin), dmax_(dmax), unmatched_(quantise(unmatched)) {
    // One table serves cost(), minCost() and bestCost(), so they agree bit for bit; the
    // unmatched level reads back as the exact unmatched cost.
    dequantised_.resize(65536);
    for (size_t q = 0; q < dequantised_.size(); ++q) {
      dequantised_[q] = static_cast<float>(static_cast<double>(q) / kQuantScale);
    }
    dequantised_[unmatched_] = static_cast<float>(unmatched);
    const size_t planes = static_cast<size_t>(dmax - dmin + 1);
    planes_.resize(planes);
    for (auto& p : planes_) p.create(roi.size(), CV_16U);
    blockMin_.resize((planes + kBlock - 1) / kBlock);
  }

  cv::Rect roi() const override { return roi_; }
  int dmin() const override { return dmin_; }
  int dmax() const override { return dmax_; }

  float cost(int x, int y, int d) const override {
    if (!roi_.contains(cv::Point(x, y)) || d < dmin_ || d > dmax_) {
      throw Error(ErrorCode::InvalidParameter, "cost(" + std::to_string(x) + ", " +
                                                   std::to_string(y) + ", " + std::to_string(d) +
                                                   ") is outside the ROI or the disparity range");
    }
    return dequantise(planes_[d - dmin_].at<uint16_t>(y - roi_.y, x - roi_.x));
  }

  cv::Mat minCost(int a, int b) const override {
    const int lo = std::max(a, dmin_) - dmin_;
    const int hi = std::min(b, dmax_) - dmin_;
    if (lo > hi) return cv::Mat(roi_.size(), CV_32F, cv::Scalar(dequantise(unmatched_)));
    cv::Mat acc = planes_[lo].clone();
    int d = lo + 1;
    // Head: single planes up to the next block boundary.
    for (; d <= hi && d % kBlock != 0; ++d) cv::min(acc, planes_[d], acc);
    // Whole blocks.
    for (; d + kBlock - 1 <= hi; d += kBlock) cv::min(acc, blockMin_[d / kBlock], acc);
    // Tail.
    for (; d <= hi; ++d) cv::min(acc, planes_[d], acc);
    return dequantiseAll(acc);
  }

  cv::Mat bestDisparity() const override { return bestDisparity_.clone(); }
  cv::Mat bestCost() const override { return dequantiseAll(bestCost_); }

  cv::Mat& plane(int index) { return planes_[index]; }
  uint16_t unmatchedQuantised() const { return unmatched_; }

  // Block minima and the full-range argmin, once every plane is filled.
  void finish() {
    for (size_t blockIndex = 0; blockIndex < blockMin_.size(); ++blockIndex) {
      const size_t first = blockIndex * kBlock;
      const size_t last = std::min(planes_.size(), first + kBlock) - 1;
      cv::Mat m = planes_[first].clone();
      for (size_t d = first + 1; d <= last; ++d) cv::min(m, planes_[d], m);
      blockMin_[blockIndex] = m;
    }
    bestCost_ = planes_[0].clone();
    bestDisparity_ = cv::Mat(roi_.size(), CV_32S, cv::Scalar(dmin_));
    for (size_t d = 1; d < planes_.size(); ++d) {
      for (int y = 0; y < roi_.height; ++y) {
        const uint16_t* c = planes_[d].ptr<uint16_t>(y);
        uint16_t* best = bestCost_.ptr<uint16_t>(y);
        int* bestD = bestDisparity_.ptr<int>(y);
        for (int x = 0; x < roi_.width; ++x) {
          if (c[x] < best[x]) {
            best[x] = c[x];
            bestD[x] = dmin_ + static_cast<int>(d);
          }
        }
      }
    }
  }

 private:
  float dequantise(uint16_t q) const { return dequantised_[q]; }
  cv::Mat dequantiseAll(const cv::Mat& quantised) const {
    cv::Mat out(quantised.size(), CV_32F);
    for (int y = 0; y < quantised.rows; ++y) {
      const uint16_t* q = quantised.ptr<uint16_t>(y);
      float* o = out.ptr<float>(y);
      for (int x = 0; x < quantised.cols; ++x) o[x] = dequantised_[q[x]];
    }
    return out;
  }

  cv::Rect roi_;
  int dmin_, dmax_;
  uint16_t unmatched_;
  std::vector<float> dequantised_;  // quantised level -> cost
  std::vector<cv::Mat> planes_;     // CV_16U, one per disparity, index d - dmin
  std::vector<cv::Mat> blockMin_;   // CV_16U, min over disparities [k*kBlock, (k+1)*kBlock)
  cv::Mat bestDisparity_;           // CV_32S
  cv::Mat bestCost_;                // CV_16U
};

// Blends a mean grey level term into the NCC planes of `volume` for windows with little texture:
// cost = w * ncc_cost + (1 - w) * min(1, |mean_left - (gain * mean_right + offset)| / (scale *
// sigma)), w = t / (t + sigma^2) with t the left window's variance above the noise's (sigma^2) and
// sigma the left ROI's noise (radiometricMap gives gain and offset). On a textureless roof NCC is
// noise at every disparity while the mean grey level still tells the roof's match from the
// ground's. sums*: box sums of the left (A, ROI positions) and right (B, ROI positions shifted by
// the plane's offset) windows, as in the NCC pass.
void addBrightnessTerm(QuantisedCostVolume& volume, const cv::Mat& sumA, const cv::Mat& sumAA,
                       const cv::Mat& sumB, const cv::Mat& leftRoi, int window, double scale,
                       double gain, double shift) {
  const cv::Rect roi = volume.roi();
  const int dmin = volume.dmin(), dmax = volume.dmax();
  const int planes = dmax - dmin + 1;
  const double n = static_cast<double>(window) * window;
  const double sigma = std::max(1e-3, noiseSigma(leftRoi));
  const double flatVariance = sigma * sigma;
  const uint16_t unmatched = volume.unmatchedQuantised();
  // NCC counts as much as the left window's variance stands above the noise's. Per pixel:
  // cost = nccWeight * ncc_cost + min(brightnessWeight, |sa - gain * sb - n * shift| * slope).
  const double meanScale = scale * sigma;
  cv::Mat nccWeight(roi.size(), CV_32F), brightnessWeight(roi.size(), CV_32F),
      slope(roi.size(), CV_32F);
  for (int y = 0; y < roi.height; ++y) {
    for (int x = 0; x < roi.width; ++x) {
      const double m = sumA.at<double>(y, x) / n;
      const double variance = std::max(0.0, sumAA.at<double>(y, x) / n - m * m);
      // Texture is the variance above the noise's: a flat window's NCC is noise and weighs 0.
      const double texture = std::max(0.0, variance - flatVariance);
      const double w = texture / (texture + flatVariance);
      nccWeight.at<float>(y, x) = static_cast<float>(w / kQuantScale);
      brightnessWeight.at<float>(y, x) = static_cast<float>(1.0 - w);
      slope.at<float>(y, x) = static_cast<float>((1.0 - w) / (meanScale * n));
    }
  }
  const float gainF = static_cast<float>(gain), shiftF = static_cast<float>(n * shift);
  cv::parallel_for_(cv::Range(0, planes), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k) {
      const int offset = dmax - (dmin + k);
      cv::Mat& plane = volume.plane(k);
      for (int y = 0; y < roi.height; ++y) {
        uint16_t* o = plane.ptr<uint16_t>(y);
        const double* sa = sumA.ptr<double>(y);
        const double* sb = sumB.ptr<double>(y) + offset;
        const float* wn = nccWeight.ptr<float>(y);
        const float* wb = brightnessWeight.ptr<float>(y);
        const float* sl = slope.ptr<float>(y);
        for (int x = 0; x < roi.width; ++x) {
          if (o[x] == unmatched) continue;
          const float difference =
              static_cast<float>(sa[x]) - gainF * static_cast<float>(sb[x]) - shiftF;
          const float cost = wn[x] * o[x] + std::min(wb[x], std::abs(difference) * sl[x]);
          o[x] = static_cast<uint16_t>(std::min(65535.f, cost * 65535.f + 0.5f));
        }
      }
    }
  });
}

// The inputs compute() takes: two float32 images of one size, a disparity range and an ROI
// within the image; throws core::Error otherwise.
void checkInputs(const cv::Mat& left, const cv::Mat& right, cv::Rect roi, int dmin, int dmax) {
  if (left.empty() || right.empty() || left.type() != CV_32FC1 || right.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput,
                "cost service: left and right must be non-empty single-channel float32 images");
  }
  if (left.size() != right.size()) {
    throw Error(ErrorCode::MismatchedInputs,
                "cost service: left image is " + std::to_string(left.cols) + "x" +
                    std::to_string(left.rows) + " but right image is " +
                    std::to_string(right.cols) + "x" + std::to_string(right.rows));
  }
  if (dmin > dmax) {
    throw Error(ErrorCode::InvalidParameter,
                "cost service: empty disparity range dmin = " + std::to_string(dmin) +
                    " > dmax = " + std::to_string(dmax));
  }
  if (roi.area() <= 0 || (roi & cv::Rect(0, 0, left.cols, left.rows)) != roi) {
    throw Error(ErrorCode::InvalidParameter, "cost service: ROI is empty or outside the image");
  }
}

// What the NCC of every window reads: the grey levels around the ROI (NaN as 0) and the box
// sums of the left windows (A, at ROI positions) and of the right windows (B, at ROI positions
// shifted by dmax − d for disparity d), with their counts of valid pixels.
struct WindowSums {
  int window = 0;
  double n = 0;       // pixels in a window
  cv::Rect leftRect;  // the ROI grown by the window's radius
  cv::Mat leftVals, rightVals;
  cv::Mat sumA, sumAA, countA, sumB, sumBB, countB;
};

WindowSums windowSums(const cv::Mat& left, const cv::Mat& right, cv::Rect roi, int dmin, int dmax,
                      int window) {
  WindowSums s;
  s.window = window;
  const int r = window / 2;
  s.n = static_cast<double>(window) * window;
  // Left windows: ROI grown by the window radius; pixels outside the image count as NaN, so
  // windows leaving the image get the unmatched cost.
  s.leftRect = cv::Rect(roi.x - r, roi.y - r, roi.width + 2 * r, roi.height + 2 * r);
  cv::Mat leftValid;
  splitValid(cropWithNaN(left, s.leftRect), s.leftVals, leftValid);
  // Right windows for every d: columns x - d for x in the grown ROI and d in [dmin, dmax].
  const cv::Rect rightRect(roi.x - r - dmax, roi.y - r, roi.width + 2 * r + (dmax - dmin),
                           roi.height + 2 * r);
  cv::Mat rightValid;
  splitValid(cropWithNaN(right, rightRect), s.rightVals, rightValid);

  s.sumA = boxSums(s.leftVals, window);
  s.sumAA = boxSums(s.leftVals.mul(s.leftVals), window);
  s.countA = boxSums(leftValid, window);
  s.sumB = boxSums(s.rightVals, window);
  s.sumBB = boxSums(s.rightVals.mul(s.rightVals), window);
  s.countB = boxSums(rightValid, window);
  return s;
}

// The quantised cost (1 − NCC)/2 of every ROI pixel at the disparity whose right windows start
// `offset` columns into the right sums (dmax − d), into `out`; `product`: scratch.
void nccCostPlane(const WindowSums& s, int offset, uint16_t unmatched, cv::Mat& product,
                  cv::Mat& out) {
  const double n = s.n;
  const cv::Rect& leftRect = s.leftRect;
  cv::multiply(s.leftVals, s.rightVals(cv::Rect(offset, 0, leftRect.width, leftRect.height)),
               product);
  const cv::Mat sumAB = boxSums(product, s.window);
  for (int y = 0; y < out.rows; ++y) {
    const double* sa = s.sumA.ptr<double>(y);
    const double* saa = s.sumAA.ptr<double>(y);
    const double* ca = s.countA.ptr<double>(y);
    const double* sb = s.sumB.ptr<double>(y) + offset;
    const double* sbb = s.sumBB.ptr<double>(y) + offset;
    const double* cb = s.countB.ptr<double>(y) + offset;
    const double* sab = sumAB.ptr<double>(y);
    uint16_t* o = out.ptr<uint16_t>(y);
    for (int x = 0; x < out.cols; ++x) {
      if (ca[x] < n - 0.5 || cb[x] < n - 0.5) {
        o[x] = unmatched;
        continue;
      }
      const double varA = saa[x] - sa[x] * sa[x] / n;
      const double varB = sbb[x] - sb[x] * sb[x] / n;
      const double scaleA = 1e-10 * (1.0 + saa[x]);
      const double scaleB = 1e-10 * (1.0 + sbb[x]);
      // A flat window carries no information: NCC 0, cost 0.5.
      double ncc = 0.0;
      if (varA > scaleA && varB > scaleB) {
        ncc = (sab[x] - sa[x] * sb[x] / n) / std::sqrt(varA * varB);
      }
      o[x] = quantise((1.0 - std::clamp(ncc, -1.0, 1.0)) * 0.5);
    }
  }
}

// Every NCC cost plane of `volume`, in parallel, reporting progress up to 0.95; false when
// canceled.
bool nccCostPlanes(QuantisedCostVolume& volume, const WindowSums& sums, core::Progress* progress) {
  const int dmin = volume.dmin(), dmax = volume.dmax();
  const int planes = dmax - dmin + 1;
  std::atomic<int> done{0};
  std::atomic<bool> canceled{false};
  const uint16_t unmatched = volume.unmatchedQuantised();
  cv::parallel_for_(cv::Range(0, planes), [&](const cv::Range& range) {
    cv::Mat product;
    for (int k = range.start; k < range.end; ++k) {
      if (canceled.load() || core::isCanceled(progress)) {
        canceled.store(true);
        return;
      }
      const int d = dmin + k;
      const int offset = dmax - d;  // column of x - d in the right sums for x = leftRect.x
      nccCostPlane(sums, offset, unmatched, product, volume.plane(k));
      const int finished = ++done;
      if (progress != nullptr && (finished % 8 == 0 || finished == planes)) {
        progress->report(0.95 * finished / planes);
      }
    }
  });
  return !(canceled.load() || core::isCanceled(progress));
}

}  // namespace

std::unique_ptr<CorrelationCostService> CorrelationCostService::compute(
    const cv::Mat& left, const cv::Mat& right, cv::Rect roi, int dmin, int dmax,
    const CostParams& params, core::Progress* progress) {
  params.validate();
  checkInputs(left, right, roi, dmin, dmax);
  auto volume = std::make_unique<QuantisedCostVolume>(roi, dmin, dmax, params.unmatchedCost);
  const WindowSums sums = windowSums(left, right, roi, dmin, dmax, params.window);
  if (!nccCostPlanes(*volume, sums, progress)) return nullptr;
  if (params.brightnessScale > 0) {
    const int r = params.window / 2;
    const auto [gain, shift] = radiometricMap(left, right, dmin, dmax);
    addBrightnessTerm(*volume, sums.sumA, sums.sumAA, sums.sumB,
                      sums.leftVals(cv::Rect(r, r, roi.width, roi.height)), params.window,
                      params.brightnessScale, gain, shift);
  }
  volume->finish();
  core::report(progress, 1.0);
  return volume;
}

}  // namespace delineo::stereo
