#include "delineo/segmentation/classify.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"

namespace delineo::segmentation {

using core::Error;
using core::ErrorCode;

void ClassifyParams::validate() const { core::checkDeclaredRanges(*this); }

namespace {

void checkInputs(const cv::Mat& image, const cv::Mat& above, const cv::Mat& ndsm, const cv::Mat& regions,
                 double gsd) {
  if (image.empty() || (image.type() != CV_8UC1 && image.type() != CV_8UC3)) {
    throw Error(ErrorCode::UnsupportedInput, "the image must be 8-bit grey or 8-bit BGR colour");
  }
  if (above.empty() || above.type() != CV_8UC1) {
    throw Error(ErrorCode::UnsupportedInput, "the above-ground mask must be one band of 8 bits");
  }
  if (ndsm.empty() || ndsm.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput, "the heights above the DTM (nDSM) must be one band of float32");
  }
  if (!regions.empty() && regions.type() != CV_32SC1) {
    throw Error(ErrorCode::UnsupportedInput, "the region map must be one band of int32");
  }
  if (above.size() != image.size() || ndsm.size() != image.size() ||
      (!regions.empty() && regions.size() != image.size())) {
    throw Error(ErrorCode::MismatchedInputs,
                "the image, the above-ground mask, the nDSM and the region map must have one size");
  }
  if (!std::isfinite(gsd) || gsd <= 0.0) {
    throw Error(ErrorCode::InvalidParameter, "the ground sampling distance must be a positive number of metres");
  }
}

// Sum of `values` over a side x side window (zero outside the image).
cv::Mat windowSum(const cv::Mat& values, int side) {
  cv::Mat out;
  cv::boxFilter(values, out, CV_32F, {side, side}, {-1, -1}, false, cv::BORDER_CONSTANT);
  return out;
}

struct LocalMeasures {
  cv::Mat brightness; // mean grey of the window's above-ground pixels
  cv::Mat variation;  // their standard deviation over their mean
};

// Mean brightness and variation of the above-ground pixels of each window. Only above-ground
// pixels count, so that the ground next to a roof does not blur its measure.
LocalMeasures localMeasures(const cv::Mat& grey, const cv::Mat& above, int side) {
  LocalMeasures m;
  cv::Mat insideF;
  above.convertTo(insideF, CV_32F, 1.0 / 255.0);
  const cv::Mat pixels = cv::max(windowSum(insideF, side), 1.0f);
  m.brightness = windowSum(grey.mul(insideF), side) / pixels;
  const cv::Mat sumSquares = windowSum(grey.mul(grey).mul(insideF), side);
  cv::Mat deviation;
  cv::sqrt(cv::max(sumSquares / pixels - m.brightness.mul(m.brightness), 0.0f), deviation);
  m.variation = deviation / cv::max(m.brightness, 1.0f);
  return m;
}

// Mean of the excess green (2G - R - B) / (R + G + B) over the window's above-ground pixels; empty for a grey image.
cv::Mat greennessOf(const cv::Mat& image, const cv::Mat& above, int side) {
  if (image.channels() != 3) return {};
  cv::Mat bgr[3];
  cv::split(image, bgr);
  cv::Mat b, g, r;
  bgr[0].convertTo(b, CV_32F);
  bgr[1].convertTo(g, CV_32F);
  bgr[2].convertTo(r, CV_32F);
  // Normalised excess green: grey and bluish-grey roofs stay near 0 where (G - R) alone does not.
  const cv::Mat index = (2 * g - r - b) / cv::max(r + g + b, 1.0f);
  cv::Mat insideF;
  const cv::Mat inside = above != 0;
  inside.convertTo(insideF, CV_32F, 1.0 / 255.0);
  const cv::Mat sum = windowSum(index.mul(insideF), side);
  return sum / cv::max(windowSum(insideF, side), 1.0f);
}

// The per-pixel rules: green (colour), or dark and textured, is vegetation.
cv::Mat pixelRules(const cv::Mat& above, const LocalMeasures& m, const cv::Mat& green, const ClassifyParams& p) {
  cv::Mat labels = cv::Mat::zeros(above.size(), CV_8U);
  for (int y = 0; y < above.rows; ++y) {
    for (int x = 0; x < above.cols; ++x) {
      if (above.at<uchar>(y, x) == 0) continue;
      bool vegetation = false;
      if (p.darkLevel > 0 && m.variation.at<float>(y, x) > p.textureVariation &&
          m.brightness.at<float>(y, x) < p.darkLevel) {
        vegetation = true;
      }
      if (!green.empty() && p.greenThreshold < 1.0 && green.at<float>(y, x) > p.greenThreshold) vegetation = true;
      labels.at<uchar>(y, x) = vegetation ? kClassVegetation : kClassBuilding;
    }
  }
  return labels;
}

// One class per region: the majority of its pixels (ties go to building).
cv::Mat regionMajority(const cv::Mat& pixelLabels, const cv::Mat& regions) {
  std::map<int, std::pair<long, long>> counts;  // region -> (building, vegetation)
  for (int y = 0; y < regions.rows; ++y) {
    for (int x = 0; x < regions.cols; ++x) {
      const int r = regions.at<int>(y, x);
      const uchar l = pixelLabels.at<uchar>(y, x);
      if (r < 0 || l == kClassGround) continue;
      (l == kClassBuilding ? counts[r].first : counts[r].second)++;
    }
  }
  cv::Mat labels = cv::Mat::zeros(pixelLabels.size(), CV_8U);
  for (int y = 0; y < regions.rows; ++y) {
    for (int x = 0; x < regions.cols; ++x) {
      const int r = regions.at<int>(y, x);
      const uchar l = pixelLabels.at<uchar>(y, x);
      if (l == kClassGround) continue;
      if (r < 0) {  // above ground but in no region: its own rules decide
        labels.at<uchar>(y, x) = l;
        continue;
      }
      const auto& c = counts[r];
      labels.at<uchar>(y, x) = c.second > c.first ? kClassVegetation : kClassBuilding;
    }
  }
  return labels;
}

// Pieces of one class smaller than `minPixels` take the other class when they touch it (a
// chimney read as vegetation on a roof, a patch of a crown read as a roof).
void absorbSmallPieces(cv::Mat& labels, double minPixels) {
  if (minPixels <= 0) return;
  for (const uchar cls : {kClassVegetation, kClassBuilding}) {
    const uchar other = cls == kClassBuilding ? kClassVegetation : kClassBuilding;
    cv::Mat pieces, stats, centroids;
    const int n = cv::connectedComponentsWithStats(labels == cls, pieces, stats, centroids, 8, CV_32S);
    std::vector<long> border(static_cast<size_t>(n), 0);
    for (int y = 0; y < labels.rows; ++y) {
      for (int x = 0; x < labels.cols; ++x) {
        const int id = pieces.at<int>(y, x);
        if (id == 0 || stats.at<int>(id, cv::CC_STAT_AREA) >= minPixels) continue;
        const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
        for (const cv::Point& s : steps) {
          const cv::Point q(x + s.x, y + s.y);
          if (q.x >= 0 && q.y >= 0 && q.x < labels.cols && q.y < labels.rows && labels.at<uchar>(q) == other) {
            ++border[static_cast<size_t>(id)];
          }
        }
      }
    }
    for (int y = 0; y < labels.rows; ++y) {
      for (int x = 0; x < labels.cols; ++x) {
        const int id = pieces.at<int>(y, x);
        if (id != 0 && border[static_cast<size_t>(id)] > 0 && stats.at<int>(id, cv::CC_STAT_AREA) < minPixels) {
          labels.at<uchar>(y, x) = other;
        }
      }
    }
  }
}

}  // namespace

cv::Mat heightRegions(const cv::Mat& aboveGround, const cv::Mat& ndsm, double maxStep) {
  if (aboveGround.empty() || aboveGround.type() != CV_8UC1 || ndsm.type() != CV_32FC1 ||
      ndsm.size() != aboveGround.size()) {
    throw Error(ErrorCode::UnsupportedInput, "heightRegions needs an 8-bit mask and a float32 nDSM of one size");
  }
  cv::Mat regions(aboveGround.size(), CV_32S, cv::Scalar(-1));
  std::vector<cv::Point> stack;
  const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  int next = 0;
  // Seeds on valid heights first, so that no-data pixels join a region rather than link two.
  for (const bool validSeeds : {true, false}) {
    for (int y = 0; y < regions.rows; ++y) {
      for (int x = 0; x < regions.cols; ++x) {
        if (aboveGround.at<uchar>(y, x) == 0 || regions.at<int>(y, x) >= 0) continue;
        if (std::isfinite(ndsm.at<float>(y, x)) != validSeeds) continue;
        const int id = next++;
        regions.at<int>(y, x) = id;
        stack.assign(1, {x, y});
        while (!stack.empty()) {
          const cv::Point p = stack.back();
          stack.pop_back();
          const float here = ndsm.at<float>(p);
          if (validSeeds && !std::isfinite(here)) continue;  // no-data pixels join, never spread
          for (const cv::Point& s : steps) {
            const cv::Point q = p + s;
            if (q.x < 0 || q.y < 0 || q.x >= regions.cols || q.y >= regions.rows) continue;
            if (aboveGround.at<uchar>(q) == 0 || regions.at<int>(q) >= 0) continue;
            const float there = ndsm.at<float>(q);
            if (std::isfinite(here) && std::isfinite(there) && std::abs(there - here) > maxStep) continue;
            regions.at<int>(q) = id;
            stack.push_back(q);
          }
        }
      }
    }
  }
  return regions;
}

Classification classify(const cv::Mat& image, const cv::Mat& aboveGround, const cv::Mat& ndsm, double gsd,
                        const ClassifyParams& params, const cv::Mat& regions, core::Progress* progress) {
  params.validate();
  checkInputs(image, aboveGround, ndsm, regions, gsd);
  Classification out;
  const int side = std::max(3, static_cast<int>(std::lround(params.window / gsd)) | 1);
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    grey.convertTo(grey, CV_32F);
  } else {
    image.convertTo(grey, CV_32F);
  }
  core::report(progress, 0.05);
  const cv::Mat above = aboveGround != 0;
  const LocalMeasures m = localMeasures(grey, above, side);
  if (core::isCanceled(progress)) {
    out.status = core::RunStatus::Canceled;
    return out;
  }
  out.greenness = greennessOf(image, aboveGround, side);
  out.pixelLabels = pixelRules(aboveGround, m, out.greenness, params);
  core::report(progress, 0.8);
  if (core::isCanceled(progress)) {
    out.status = core::RunStatus::Canceled;
    out.pixelLabels.release();
    return out;
  }
  out.regions = regions.empty() ? heightRegions(aboveGround, ndsm, params.regionStep) : regions.clone();
  out.labels = regionMajority(out.pixelLabels, out.regions);
  absorbSmallPieces(out.labels, params.minObjectArea / (gsd * gsd));
  core::report(progress, 1.0);
  return out;
}

}  // namespace delineo::segmentation
