// Disparity search range from sparse feature matches (docs/disparity-range.md).
#include "delineo/stereo/disparity_range.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/core/nan_mask.hpp"
#include "plain_regions.hpp"

namespace delineo::stereo {

using core::Error;
using core::ErrorCode;

namespace {

// One view ready for detection: 8-bit grey (each view stretched on its own, so that a gain or
// offset between the views changes nothing), the mask of its valid pixels, at `scale`.
struct DetectionView {
  cv::Mat grey;  // CV_8U
  cv::Mat mask;  // CV_8U, 255 where keypoints may be detected
};

// Throws ProcessingFailed for a view without any contrast (blank, or all no data).
DetectionView detectionView(const cv::Mat& image, double scale, const char* name) {
  const cv::Mat valid = core::numberMask(image);
  // About 20 000 samples on a regular grid (rows and columns).
  std::vector<float> samples;
  const int step = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(image.total()) / 20000)));
  for (int y = 0; y < image.rows; y += step) {
    const float* row = image.ptr<float>(y);
    for (int x = 0; x < image.cols; x += step) {
      if (std::isfinite(row[x])) samples.push_back(row[x]);
    }
  }
  if (samples.size() < 2) {
    throw Error(ErrorCode::ProcessingFailed,
                std::string("the ") + name + " image has no data: cannot estimate the disparity "
                "range");
  }
  auto at = [&](double q) {
    auto it = samples.begin() + static_cast<std::ptrdiff_t>(q * (samples.size() - 1));
    std::nth_element(samples.begin(), it, samples.end());
    return static_cast<double>(*it);
  };
  double lo = at(0.01), hi = at(0.99);
  if (hi - lo < 1e-6) {
    double mn = 0, mx = 0;
    cv::minMaxLoc(image, &mn, &mx, nullptr, nullptr, valid);
    lo = mn;
    hi = mx;
  }
  if (!(hi - lo > 1e-6)) {
    throw Error(ErrorCode::ProcessingFailed,
                std::string("the ") + name + " image is blank (one grey level): cannot estimate "
                "the disparity range");
  }
  DetectionView v;
  cv::Mat filled = image.clone();
  filled.setTo(0.5 * (lo + hi), ~valid);
  cv::Mat grey;
  filled.convertTo(grey, CV_8U, 255.0 / (hi - lo), -lo * 255.0 / (hi - lo));
  cv::Mat mask = valid;
  if (scale < 1.0) {
    cv::resize(grey, v.grey, cv::Size(), scale, scale, cv::INTER_AREA);
    cv::resize(valid, mask, v.grey.size(), 0, 0, cv::INTER_AREA);
    mask = mask == 255;
  } else {
    v.grey = grey;
  }
  // Keypoints keep clear of no-data borders, whose edges are not in the scene.
  cv::erode(mask, v.mask, cv::getStructuringElement(cv::MORPH_RECT, {9, 9}));
  return v;
}

cv::Ptr<cv::Feature2D> makeDetector(const std::string& name) {
  if (name == "orb") {
    return cv::ORB::create(100000, 1.2f, 4, 15, 0, 2, cv::ORB::HARRIS_SCORE, 31, 10);
  }
  if (name == "akaze") {
    // Threshold 2e-5 instead of 1e-3: Dublin's pair, taken hours apart, needs weak keypoints.
    return cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB_UPRIGHT, 0, 3, 0.00002f, 3, 3);
  }
  // Contrast threshold 0.01 instead of OpenCV's 0.04: keypoints in shadows and on weakly
  // textured roofs and roads (0.04 leaves Dublin 26 matches instead of 419).
  return cv::SIFT::create(0, 3, 0.01, 10.0, 1.6);
}

struct Features {
  std::vector<cv::KeyPoint> keypoints;  // full-resolution coordinates
  cv::Mat descriptors;                  // one row per keypoint
};

// Keeps the strongest keypoints of each grid cell, `perCell` at most, so that textured parts of
// the image do not take every keypoint (roofs and ground both matter).
std::vector<int> spreadOverGrid(const std::vector<cv::KeyPoint>& keypoints, cv::Size size,
                                int grid, int perCell) {
  std::vector<std::vector<int>> cells(static_cast<size_t>(grid) * grid);
  for (int i = 0; i < static_cast<int>(keypoints.size()); ++i) {
    const cv::Point2f& pt = keypoints[i].pt;
    const int cx = std::clamp(static_cast<int>(pt.x * grid / size.width), 0, grid - 1);
    const int cy = std::clamp(static_cast<int>(pt.y * grid / size.height), 0, grid - 1);
    cells[static_cast<size_t>(cy) * grid + cx].push_back(i);
  }
  std::vector<int> kept;
  for (auto& cell : cells) {
    std::stable_sort(cell.begin(), cell.end(), [&](int a, int b) {
      return keypoints[a].response > keypoints[b].response;
    });
    if (static_cast<int>(cell.size()) > perCell) cell.resize(perCell);
    kept.insert(kept.end(), cell.begin(), cell.end());
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

// SIFT keypoints made upright, one per location: the pair shares its orientation (epipolar
// rows), and SIFT repeats a location for each dominant orientation, twins that would fail each
// other's ratio test. Descriptors are then computed for the kept keypoints only.
void uprightSift(cv::Feature2D& sift, const DetectionView& view, int grid, int perCell,
                 std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors) {
  std::vector<cv::KeyPoint> all;
  sift.detect(view.grey, all, view.mask);
  for (cv::KeyPoint& kp : all) kp.angle = 0;
  std::sort(all.begin(), all.end(), [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
    if (a.pt.y != b.pt.y) return a.pt.y < b.pt.y;
    if (a.pt.x != b.pt.x) return a.pt.x < b.pt.x;
    return a.size < b.size;
  });
  all.erase(std::unique(all.begin(), all.end(),
                        [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
                          return a.pt == b.pt && a.size == b.size;
                        }),
            all.end());
  keypoints.clear();
  for (int k : spreadOverGrid(all, view.grey.size(), grid, perCell)) keypoints.push_back(all[k]);
  sift.compute(view.grey, keypoints, descriptors);
}

// Keypoints and descriptors of one view, coordinates in full-resolution pixels.
Features detectFeatures(const DetectionView& view, const RangeEstimateParams& params,
                        double scale) {
  const cv::Ptr<cv::Feature2D> detector = makeDetector(params.detector);
  const int cells = params.grid * params.grid;
  const int perCell = std::max(1, (params.features + cells - 1) / cells);
  Features f;
  if (params.detector == "sift") {
    uprightSift(*detector, view, params.grid, perCell, f.keypoints, f.descriptors);
  } else {
    std::vector<cv::KeyPoint> all;
    cv::Mat descriptors;
    detector->detectAndCompute(view.grey, view.mask, all, descriptors);
    const std::vector<int> kept = spreadOverGrid(all, view.grey.size(), params.grid, perCell);
    f.descriptors.create(static_cast<int>(kept.size()), descriptors.cols, descriptors.type());
    for (int k = 0; k < static_cast<int>(kept.size()); ++k) {
      f.keypoints.push_back(all[kept[k]]);
      descriptors.row(kept[k]).copyTo(f.descriptors.row(k));
    }
  }
  for (cv::KeyPoint& kp : f.keypoints) {
    kp.pt = {static_cast<float>((kp.pt.x + 0.5) / scale - 0.5),
             static_cast<float>((kp.pt.y + 0.5) / scale - 0.5)};
  }
  return f;
}

// The checks' distances in full-resolution pixels. The tolerances are at least one pixel of the
// detection copy (its keypoints are no more precise); the support radius follows the image's
// size, as the keypoints' spacing does (their number does not depend on it).
struct Geometry {
  double rowTolerance, supportRadius, supportTolerance;
};

Geometry geometry(const RangeEstimateParams& params, cv::Size size, double scale) {
  const double diagonal = std::hypot(size.width, size.height);
  return {std::max(params.rowTolerance, 1.0 / scale), params.supportRadius / 100.0 * diagonal,
          std::max(params.supportTolerance, 1.0 / scale)};
}

struct Match {
  float x = 0, y = 0;  // left keypoint, full-resolution pixels
  float d = 0;         // x_left - x_right
  double weight = 1;
};

// Descriptor distance: L2 for float descriptors (SIFT), Hamming for binary ones.
double distance(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  if (a.type() == CV_8U) {
    return cv::norm(a.row(i), b.row(j), cv::NORM_HAMMING);
  }
  const float* pa = a.ptr<float>(i);
  const float* pb = b.ptr<float>(j);
  double s = 0;
  for (int k = 0; k < a.cols; ++k) {
    const double e = pa[k] - pb[k];
    s += e * e;
  }
  return std::sqrt(s);
}

// For each keypoint of `from`, the keypoint of `to` on the same rows (within `tolerance`) with
// the nearest descriptor when it passes the ratio test, else -1.
std::vector<int> bestOnRows(const Features& from, const Features& to, double tolerance,
                            double ratio) {
  std::vector<int> order(to.keypoints.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return to.keypoints[a].pt.y < to.keypoints[b].pt.y; });
  std::vector<float> ys(order.size());
  for (size_t k = 0; k < order.size(); ++k) ys[k] = to.keypoints[order[k]].pt.y;
  std::vector<int> best(from.keypoints.size(), -1);
  cv::parallel_for_(cv::Range(0, static_cast<int>(from.keypoints.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const float y = from.keypoints[i].pt.y;
      const auto first = std::lower_bound(ys.begin(), ys.end(), y - tolerance);
      const auto last = std::upper_bound(ys.begin(), ys.end(), y + tolerance);
      double d1 = std::numeric_limits<double>::infinity(), d2 = d1;
      int j1 = -1;
      for (auto it = first; it != last; ++it) {
        const int j = order[static_cast<size_t>(it - ys.begin())];
        const double dist = distance(from.descriptors, i, to.descriptors, j);
        if (dist < d1) {
          d2 = d1;
          d1 = dist;
          j1 = j;
        } else if (dist < d2) {
          d2 = dist;
        }
      }
      // A lone candidate passes: the row band already rules most false matches out.
      if (j1 >= 0 && d1 < ratio * d2) best[i] = j1;
    }
  });
  return best;
}

std::vector<Match> matchOnRows(const Features& left, const Features& right,
                               const RangeEstimateParams& params, const Geometry& g) {
  const std::vector<int> forward = bestOnRows(left, right, g.rowTolerance, params.ratio);
  std::vector<int> backward;
  if (params.mutualCheck) backward = bestOnRows(right, left, g.rowTolerance, params.ratio);
  std::vector<Match> matches;
  for (int i = 0; i < static_cast<int>(forward.size()); ++i) {
    const int j = forward[i];
    if (j < 0 || (params.mutualCheck && backward[j] != i)) continue;
    const cv::Point2f& pl = left.keypoints[i].pt;
    const cv::Point2f& pr = right.keypoints[j].pt;
    matches.push_back({pl.x, pl.y, pl.x - pr.x, 1.0});
  }
  return matches;
}

// Drops matches with fewer than `support` other matches within the support radius at a
// disparity within the support tolerance: a false match is alone at its disparity (or with one
// other, on a repeated pattern), a surface has several.
std::vector<Match> supported(const std::vector<Match>& matches, const RangeEstimateParams& params,
                             const Geometry& g) {
  if (params.support <= 0) return matches;
  std::vector<int> order(matches.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return matches[a].y < matches[b].y; });
  std::vector<float> ys(order.size());
  for (size_t k = 0; k < order.size(); ++k) ys[k] = matches[order[k]].y;
  const double r2 = g.supportRadius * g.supportRadius;
  std::vector<Match> out;
  for (const Match& m : matches) {
    const auto first = std::lower_bound(ys.begin(), ys.end(), m.y - g.supportRadius);
    const auto last = std::upper_bound(ys.begin(), ys.end(), m.y + g.supportRadius);
    int count = -1;  // m itself is in the window
    for (auto it = first; it != last && count < params.support; ++it) {
      const Match& o = matches[order[static_cast<size_t>(it - ys.begin())]];
      const double dx = o.x - m.x, dy = o.y - m.y;
      if (dx * dx + dy * dy <= r2 && std::abs(o.d - m.d) <= g.supportTolerance) ++count;
    }
    if (count >= params.support) out.push_back(m);
  }
  return out;
}

// Each match weighs 1 / (matches in its grid cell): every sampled part of the image counts
// alike, however many keypoints its texture gives.
void weightByCell(std::vector<Match>& matches, cv::Size size, int grid) {
  std::vector<int> count(static_cast<size_t>(grid) * grid, 0);
  auto cell = [&](const Match& m) {
    const int cx = std::clamp(static_cast<int>(m.x * grid / size.width), 0, grid - 1);
    const int cy = std::clamp(static_cast<int>(m.y * grid / size.height), 0, grid - 1);
    return static_cast<size_t>(cy) * grid + cx;
  };
  for (const Match& m : matches) ++count[cell(m)];
  for (Match& m : matches) m.weight = 1.0 / count[cell(m)];
}

// Weighted percentile (q in [0, 1]) of the match disparities, matches sorted by d.
double weightedPercentile(const std::vector<Match>& sorted, double q) {
  double total = 0;
  for (const Match& m : sorted) total += m.weight;
  const double target = q * total;
  double cumulative = 0;
  for (const Match& m : sorted) {
    cumulative += m.weight;
    if (cumulative >= target) return m.d;
  }
  return sorted.back().d;
}

}  // namespace

void RangeEstimateParams::validate() const {
  core::checkDeclaredRanges(*this);
  if (lowPercentile >= highPercentile) {
    throw Error(ErrorCode::InvalidParameter, "low-percentile must be below high-percentile");
  }
}

RangeEstimate estimateDisparityRange(const cv::Mat& left, const cv::Mat& right,
                                     const RangeEstimateParams& params,
                                     core::Progress* progress) {
  params.validate();
  if (left.empty() || right.empty() || left.type() != CV_32FC1 || right.type() != CV_32FC1) {
    throw Error(ErrorCode::UnsupportedInput,
                "disparity range estimation needs non-empty single-channel float32 images");
  }
  if (left.size() != right.size()) {
    throw Error(ErrorCode::MismatchedInputs,
                "left image is " + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
                    " but right image is " + std::to_string(right.cols) + "x" +
                    std::to_string(right.rows));
  }
  RangeEstimate result;
  result.scale = std::min(1.0, std::sqrt(params.maxPixels / static_cast<double>(left.total())));
  const DetectionView views[2] = {detectionView(left, result.scale, "left"),
                                  detectionView(right, result.scale, "right")};
  core::report(progress, 0.1);
  Features features[2];
  cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& r) {
    for (int k = r.start; k < r.end; ++k) features[k] = detectFeatures(views[k], params, result.scale);
  });
  if (core::isCanceled(progress)) {
    result.status = core::RunStatus::Canceled;
    return result;
  }
  core::report(progress, 0.9);
  result.keypointsLeft = static_cast<int>(features[0].keypoints.size());
  result.keypointsRight = static_cast<int>(features[1].keypoints.size());

  const Geometry g = geometry(params, left.size(), result.scale);
  std::vector<Match> matches = supported(matchOnRows(features[0], features[1], params, g), params, g);
  if (params.plainRegions) {
    // Shape-checked already, so not subject to the support check.
    detail::PlainRegionSettings settings;
    settings.minAreaShare = params.plainRegionArea / 100.0;
    settings.grid = params.grid;
    settings.scale = result.scale;
    const auto samples = detail::matchPlainRegions(views[0].grey, views[0].mask, views[1].grey,
                                                   views[1].mask, settings);
    for (const auto& s : samples) matches.push_back({s.x, s.y, s.d, 1.0});
    result.plainRegionSamples = static_cast<int>(samples.size());
  }
  if (static_cast<int>(matches.size()) < params.minMatches) {
    throw Error(ErrorCode::ProcessingFailed,
                "only " + std::to_string(matches.size()) + " feature matches between the views (" +
                    std::to_string(params.minMatches) +
                    " needed): cannot estimate the disparity range");
  }
  weightByCell(matches, left.size(), params.grid);
  std::sort(matches.begin(), matches.end(), [](const Match& a, const Match& b) { return a.d < b.d; });
  result.matches = static_cast<int>(matches.size());
  result.points.reserve(matches.size());
  for (const Match& m : matches) result.points.emplace_back(m.x, m.y, m.d);
  result.low = weightedPercentile(matches, params.lowPercentile / 100.0);
  result.high = weightedPercentile(matches, params.highPercentile / 100.0);
  result.median = weightedPercentile(matches, 0.5);
  const double span = result.high - result.low;
  result.dmin = static_cast<int>(std::floor(result.low - params.margin - params.lowMarginFraction * span));
  result.dmax = static_cast<int>(std::ceil(result.high + params.margin + params.highMarginFraction * span));
  core::report(progress, 1.0);
  return result;
}

}  // namespace delineo::stereo
