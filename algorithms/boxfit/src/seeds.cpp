// Stage 2 of box-fitting: seeds from the segment's skeleton, split at junctions and into pieces.
#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

#include "delineo/boxfit/stages.hpp"

namespace delineo::boxfit {

namespace {

// The 8 neighbours, 4-neighbours first so that a walk along a staircase takes the straight step.
const cv::Point kSteps[8] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}, {1, 1}, {-1, 1}, {-1, -1}, {1, -1}};

bool inside(const cv::Mat& m, cv::Point p) { return p.x >= 0 && p.y >= 0 && p.x < m.cols && p.y < m.rows; }

// Distance of each mask pixel to the nearest pixel outside the mask, the outside of the ROI
// counted as outside: where a building runs past the image's border, its depth there is the
// distance to that border (OpenCV's transform takes the outside of the array as infinitely far,
// and a box grown from a seed on the border would start as a square reaching past the image).
cv::Mat depthInside(const cv::Mat& mask) {
  cv::Mat padded, depth;
  cv::copyMakeBorder(mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::distanceTransform(padded, depth, cv::DIST_L2, 5);
  return depth(cv::Rect(1, 1, mask.cols, mask.rows)).clone();
}

// Zhang-Suen skeleton with the outside of the ROI as background: the thinning leaves the
// array's outer rows and columns alone, so a segment touching the image's border would keep
// that whole border in its skeleton (a line of seeds along it).
cv::Mat skeletonOf(const cv::Mat& mask) {
  cv::Mat padded, skeleton;
  cv::copyMakeBorder(mask, padded, 2, 2, 2, 2, cv::BORDER_CONSTANT, 0);
  cv::ximgproc::thinning(padded, skeleton, cv::ximgproc::THINNING_ZHANGSUEN);
  return skeleton(cv::Rect(2, 2, mask.cols, mask.rows)).clone();
}

// The pixels of one branch (label `id` in `labels`) in walking order, from an end when it has
// one. Pixels a walk cannot reach without going back are appended last. `visited` is shared by
// the branches (they do not overlap).
std::vector<cv::Point> walk(const cv::Mat& labels, int id, const std::vector<cv::Point>& pixels,
                            cv::Mat& visited) {
  auto mine = [&](cv::Point q) {
    return inside(labels, q) && labels.at<int>(q) == id && visited.at<uchar>(q) == 0;
  };
  auto count = [&](cv::Point p) {
    int c = 0;
    for (const auto& s : kSteps) c += mine(p + s);
    return c;
  };
  cv::Point start = pixels.front();
  for (const auto& p : pixels) {
    if (count(p) <= 1) {
      start = p;
      break;
    }
  }
  std::vector<cv::Point> order;
  order.reserve(pixels.size());
  cv::Point p = start;
  for (;;) {
    order.push_back(p);
    visited.at<uchar>(p) = 1;
    bool moved = false;
    for (const auto& s : kSteps) {
      if (mine(p + s)) {
        p += s;
        moved = true;
        break;
      }
    }
    if (!moved) break;
  }
  for (const auto& q : pixels) {
    if (visited.at<uchar>(q) == 0) order.push_back(q), visited.at<uchar>(q) = 1;
  }
  return order;
}

}  // namespace

SkeletonSeeds skeletonSeeds(const cv::Mat& segment, const BoxFitParams& params) {
  SkeletonSeeds out;
  const cv::Mat depth = depthInside(segment);
  out.skeleton = skeletonOf(segment);

  // Junctions: skeleton pixels with more than two skeleton neighbours.
  cv::Mat skeleton01 = out.skeleton / 255, count;
  cv::filter2D(skeleton01, count, CV_8U, cv::Mat::ones(3, 3, CV_32F), {-1, -1}, 0, cv::BORDER_CONSTANT);
  cv::Mat junction = (count > 3) & out.skeleton;  // the count includes the pixel itself
  cv::Mat junctionLabels;
  out.junctions = cv::connectedComponents(junction, junctionLabels, 8) - 1;
  // Branches: the skeleton without its junctions (and their 8-neighbours, which would otherwise
  // keep branches touching each other diagonally).
  cv::Mat cut;
  cv::dilate(junction, cut, cv::Mat::ones(3, 3, CV_8U));
  const cv::Mat branches = out.skeleton & ~cut;
  cv::Mat labels;
  const int n = cv::connectedComponents(branches, labels, 8, CV_32S);
  std::vector<std::vector<cv::Point>> pixels(static_cast<size_t>(n));
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (l[x] > 0) pixels[static_cast<size_t>(l[x])].emplace_back(x, y);
    }
  }
  cv::Mat nearJunction;
  cv::dilate(cut, nearJunction, cv::Mat::ones(3, 3, CV_8U));
  cv::Mat visited = cv::Mat::zeros(labels.size(), CV_8U);
  for (int id = 1; id < n; ++id) {
    const std::vector<cv::Point> order = walk(labels, id, pixels[static_cast<size_t>(id)], visited);
    // The branch's depth: its deepest pixel, or the junction it starts from.
    double branchDepth = 0.0;
    int ends = 0;  // ends at a junction
    for (const auto& p : order) branchDepth = std::max(branchDepth, double(depth.at<float>(p)));
    for (const cv::Point& e : {order.front(), order.back()}) {
      if (nearJunction.at<uchar>(e) == 0) continue;
      ++ends;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          const cv::Point q = e + cv::Point(dx, dy);
          if (inside(junction, q) && junction.at<uchar>(q)) branchDepth = std::max(branchDepth, double(depth.at<float>(q)));
        }
      }
    }
    // A spur (one end free, the other at a junction: branches are cut at junctions only) shorter
    // than half the depth there is a ripple of the segment's border, not a wing of the building.
    if (ends == 1 && static_cast<double>(order.size()) < 0.5 * branchDepth) continue;
    const double window = std::max(2.0 * params.pieceLength, params.windowFactor * 2.0 * branchDepth);
    // Pieces of piece-length px; a short remainder joins the last piece.
    const size_t length = static_cast<size_t>(params.pieceLength);
    size_t pieces = std::max<size_t>(1, order.size() / length);
    if (order.size() - pieces * length >= length / 2 && order.size() >= length) ++pieces;
    for (size_t k = 0; k < pieces; ++k) {
      const size_t begin = k * order.size() / pieces, end = (k + 1) * order.size() / pieces;
      cv::Point2d centre(0, 0);
      for (size_t i = begin; i < end; ++i) centre += cv::Point2d(order[i]);
      centre *= 1.0 / static_cast<double>(end - begin);
      cv::Point nearest = order[begin];
      double best = 1e300;
      for (size_t i = begin; i < end; ++i) {
        const double d = cv::norm(cv::Point2d(order[i]) - centre);
        if (d < best) best = d, nearest = order[i];
      }
      const double seedDepth = depth.at<float>(nearest);
      if (seedDepth >= 1.5) out.seeds.push_back({nearest, seedDepth, window});
    }
  }
  if (out.seeds.empty()) {
    double maxDepth = 0;
    cv::Point deepest;
    cv::minMaxLoc(depth, nullptr, &maxDepth, nullptr, &deepest);
    if (maxDepth >= 1.0) {
      out.seeds.push_back({deepest, maxDepth, std::max(2.0 * params.pieceLength, params.windowFactor * 2.0 * maxDepth)});
    }
  }
  std::stable_sort(out.seeds.begin(), out.seeds.end(), [](const Seed& a, const Seed& b) { return a.depth > b.depth; });
  return out;
}

std::vector<Seed> uncoveredSeeds(const cv::Mat& segment, const std::vector<Box>& boxes, const BoxFitParams& params) {
  cv::Mat covered = cv::Mat::zeros(segment.size(), CV_8U);
  for (const auto& b : boxes) {
    std::vector<cv::Point> corners;
    for (const auto& c : b.corners()) corners.emplace_back(static_cast<int>(std::lround(c.x)), static_cast<int>(std::lround(c.y)));
    cv::fillConvexPoly(covered, corners, 255);
  }
  // Slivers along the boxes' sides are no wing: an opening removes them.
  cv::Mat residual = segment & ~covered;
  const int r = std::max(1, params.erosionRadius);
  cv::morphologyEx(residual, residual, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1}));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(residual, labels, stats, centroids, 8, CV_32S);
  if (n <= 1) return {};
  const cv::Mat depth = depthInside(residual), segmentDepth = depthInside(segment);
  const int minArea = std::max(1, params.minArea / 5);
  std::vector<Seed> seeds;
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) < minArea) continue;
    double deepest = 0;
    cv::Point at;
    cv::minMaxLoc(depth, nullptr, &deepest, nullptr, &at, labels == i);
    if (deepest < 3.0) continue;
    const double local = segmentDepth.at<float>(at);
    seeds.push_back({at, deepest, std::max(2.0 * params.pieceLength, params.windowFactor * 2.0 * local)});
  }
  return seeds;
}

}  // namespace delineo::boxfit
