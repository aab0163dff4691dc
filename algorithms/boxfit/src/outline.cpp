// Stage 4 of box-fitting: the boxes merged (filled, closed) and the merged border refined into
// straight lines.
#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/boxfit/stages.hpp"

namespace delineo::boxfit {

namespace {

constexpr int kScale = 2;  // the union is drawn at twice the resolution

// Fills the pixels whose centre lies inside the convex ring (continuous coordinates of `mask`).
void fillConvex(cv::Mat& mask, const core::Ring& ring) {
  const cv::Rect2d box = core::boundingBox(ring);
  const int y0 = std::max(0, static_cast<int>(std::floor(box.y))), y1 = std::min(mask.rows, static_cast<int>(std::ceil(box.y + box.height)) + 1);
  for (int y = y0; y < y1; ++y) {
    const double yc = y + 0.5;
    double lo = 1e300, hi = -1e300;
    for (size_t i = 0; i < ring.size(); ++i) {
      const cv::Point2d& a = ring[i];
      const cv::Point2d& b = ring[(i + 1) % ring.size()];
      if ((a.y <= yc) == (b.y <= yc)) continue;
      const double x = a.x + (yc - a.y) * (b.x - a.x) / (b.y - a.y);
      lo = std::min(lo, x), hi = std::max(hi, x);
    }
    if (lo > hi) continue;
    const int x0 = std::max(0, static_cast<int>(std::ceil(lo - 0.5)));
    const int x1 = std::min(mask.cols, static_cast<int>(std::ceil(hi - 0.5)));
    uchar* row = mask.ptr<uchar>(y);
    for (int x = x0; x < x1; ++x) row[x] = 255;
  }
}

double distanceToChord(const cv::Point2d& p, const cv::Point2d& a, const cv::Point2d& b) {
  const cv::Point2d d = b - a;
  const double length = std::hypot(d.x, d.y);
  if (length < 1e-12) return std::hypot(p.x - a.x, p.y - a.y);
  return std::abs(d.x * (p.y - a.y) - d.y * (p.x - a.x)) / length;
}

// Douglas-Peucker breakpoints of the open run pts[first..last] (indices modulo n).
void breakpoints(const std::vector<cv::Point2d>& pts, size_t first, size_t last, double tolerance,
                 std::vector<size_t>& out) {
  const size_t n = pts.size();
  double worst = 0;
  size_t at = first;
  for (size_t i = first + 1; i < last; ++i) {
    const double d = distanceToChord(pts[i % n], pts[first % n], pts[last % n]);
    if (d > worst) worst = d, at = i;
  }
  if (worst <= tolerance) return;
  breakpoints(pts, first, at, tolerance, out);
  out.push_back(at % n);
  breakpoints(pts, at, last, tolerance, out);
}

struct Line {
  cv::Point2d point, direction;  // unit direction
  size_t first = 0, last = 0;    // the contour run it was fitted to (indices, last may exceed n)
};

// Total least squares line through pts[first..last] (modulo n).
Line fitLine(const std::vector<cv::Point2d>& pts, size_t first, size_t last) {
  const size_t n = pts.size();
  cv::Point2d mean(0, 0);
  for (size_t i = first; i <= last; ++i) mean += pts[i % n];
  mean *= 1.0 / static_cast<double>(last - first + 1);
  double sxx = 0, sxy = 0, syy = 0;
  for (size_t i = first; i <= last; ++i) {
    const cv::Point2d d = pts[i % n] - mean;
    sxx += d.x * d.x, sxy += d.x * d.y, syy += d.y * d.y;
  }
  const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);
  Line line{mean, {std::cos(angle), std::sin(angle)}, first, last};
  // Keep the direction along the contour.
  const cv::Point2d run = pts[last % n] - pts[first % n];
  if (run.dot(line.direction) < 0) line.direction = -line.direction;
  return line;
}

double lineDistance(const Line& l, const cv::Point2d& p) {
  const cv::Point2d d = p - l.point;
  return std::abs(l.direction.x * d.y - l.direction.y * d.x);
}

cv::Point2d project(const Line& l, const cv::Point2d& p) { return l.point + l.direction * (p - l.point).dot(l.direction); }

// Corners of the closed contour: Douglas-Peucker from the point farthest from the first, then
// breakpoints that a straight chord would replace within the tolerance are removed (the start is
// arbitrary). Indices into pts, in order.
std::vector<size_t> ringCorners(const std::vector<cv::Point2d>& pts, double tolerance) {
  const size_t n = pts.size();
  size_t far = 0;
  double farthest = -1;
  for (size_t i = 0; i < n; ++i) {
    const double d = cv::norm(pts[i] - pts[0]);
    if (d > farthest) farthest = d, far = i;
  }
  std::vector<size_t> corners{0};
  breakpoints(pts, 0, far, tolerance, corners);
  corners.push_back(far);
  breakpoints(pts, far, n, tolerance, corners);
  for (bool removed = true; removed && corners.size() > 3;) {
    removed = false;
    for (size_t c = 0; c < corners.size() && corners.size() > 3; ++c) {
      const size_t a = corners[(c + corners.size() - 1) % corners.size()], b = corners[(c + 1) % corners.size()];
      const size_t end = b > a ? b : b + n;
      double worst = 0;
      for (size_t i = a + 1; i < end; ++i) worst = std::max(worst, distanceToChord(pts[i % n], pts[a], pts[b]));
      if (worst <= tolerance) {
        corners.erase(corners.begin() + static_cast<std::ptrdiff_t>(c));
        removed = true;
        break;
      }
    }
  }
  return corners;
}

// Pieces of at most refine-length px along each side, one line each; the closing rounds the
// corners, so a few points next to each corner are left out of the fit when the side is long.
std::vector<Line> sideLines(const std::vector<cv::Point2d>& pts, const std::vector<size_t>& corners,
                            const BoxFitParams& params, double pointSpacing) {
  const size_t n = pts.size();
  std::vector<Line> lines;
  const size_t perPiece = std::max<size_t>(3, static_cast<size_t>(params.refineLength / pointSpacing));
  const size_t trim = static_cast<size_t>(std::ceil((params.closingRadius + 0.5) / pointSpacing));
  for (size_t c = 0; c < corners.size(); ++c) {
    const size_t a = corners[c], b = corners[(c + 1) % corners.size()];
    const size_t end = b > a ? b : b + n;
    const size_t count = end - a;
    const size_t pieces = std::max<size_t>(1, (count + perPiece / 2) / perPiece);
    for (size_t k = 0; k < pieces; ++k) {
      size_t first = a + k * count / pieces, last = a + (k + 1) * count / pieces;
      if (k == 0 && last - first > 3 * trim + 3) first += trim;
      if (k + 1 == pieces && last - first > 3 * trim + 3) last -= trim;
      lines.push_back(fitLine(pts, first, last));
    }
  }
  return lines;
}

// The closing rounds concave corners and the slopes of small jogs; such a rounding, cut off as
// a side of its own, would be a short slanted line. A line fitted to no more than the
// rounding's extent is dropped: its neighbours then meet at the corner itself, or, parallel,
// make a jog square to them.
void dropRoundings(std::vector<Line>& lines, int closingRadius, double pointSpacing) {
  const double rounding = 2.0 * closingRadius + 2.0;
  for (bool dropped = true; dropped && lines.size() > 3;) {
    dropped = false;
    for (size_t i = 0; i < lines.size() && lines.size() > 3; ++i) {
      if (static_cast<double>(lines[i].last - lines[i].first) * pointSpacing > rounding) continue;
      lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(i));
      dropped = true;
      break;
    }
  }
}

// Neighbouring lines within 10° whose points lie within the tolerance of one line are merged.
void mergeCollinear(std::vector<Line>& lines, const std::vector<cv::Point2d>& pts, double tolerance) {
  const size_t n = pts.size();
  const double cosMerge = std::cos(10.0 * 3.14159265358979323846 / 180.0);
  for (bool merged = true; merged && lines.size() > 3;) {
    merged = false;
    for (size_t i = 0; i < lines.size() && lines.size() > 3; ++i) {
      const size_t j = (i + 1) % lines.size();
      if (lines[i].direction.dot(lines[j].direction) < cosMerge) continue;
      const size_t first = lines[i].first, last = j > i ? lines[j].last : lines[j].last + n;
      if (last < first || last - first >= n) continue;
      const Line both = fitLine(pts, first, last);
      double worst = 0;
      for (size_t p = first; p <= last; ++p) worst = std::max(worst, lineDistance(both, pts[p % n]));
      if (worst > tolerance) continue;
      lines[i] = both;
      lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(j));
      if (j < i) --i;  // the first line was merged into the last: indices moved
      merged = true;
    }
  }
}

// Shift away from the region. For a ring running clockwise on screen (positive shoelace sum
// with y down) (-dy, dx) points into the ring.
void shiftAway(std::vector<Line>& lines, const std::vector<cv::Point2d>& pts, double shift, bool hole) {
  const size_t n = pts.size();
  double area2 = 0;
  for (size_t i = 0; i < n; ++i) area2 += pts[i].x * pts[(i + 1) % n].y - pts[(i + 1) % n].x * pts[i].y;
  const double intoRing = area2 > 0 ? 1.0 : -1.0;
  const double away = hole ? shift : -shift;
  for (auto& l : lines) l.point += intoRing * away * cv::Point2d(-l.direction.y, l.direction.x);
}

// Consecutive lines intersected: one corner where they cross at 20° or more and near the contour
// point between their runs, else both projected onto that point (a jog: two vertices).
core::Ring intersected(const std::vector<Line>& lines, const std::vector<cv::Point2d>& pts, double refineLength) {
  const size_t n = pts.size();
  core::Ring ring;
  const double sinCorner = std::sin(20.0 * 3.14159265358979323846 / 180.0);
  for (size_t i = 0; i < lines.size(); ++i) {
    const Line& a = lines[i];
    const Line& b = lines[(i + 1) % lines.size()];
    const cv::Point2d junction = pts[(a.last + (b.first >= a.last ? b.first : b.first + n)) / 2 % n];
    const double cross = a.direction.x * b.direction.y - a.direction.y * b.direction.x;
    if (std::abs(cross) >= sinCorner) {
      const cv::Point2d d = b.point - a.point;
      const double t = (d.x * b.direction.y - d.y * b.direction.x) / cross;
      const cv::Point2d corner = a.point + a.direction * t;
      if (cv::norm(corner - junction) <= refineLength) {
        ring.push_back(corner);
        continue;
      }
    }
    ring.push_back(project(a, junction));
    ring.push_back(project(b, junction));
  }
  return ring;
}

// Vertices closer than half a pixel are merged; vertices on a straight line dropped.
core::Ring cleaned(const core::Ring& ring) {
  core::Ring clean;
  for (const auto& v : ring) {
    if (clean.empty() || cv::norm(v - clean.back()) >= 0.5) clean.push_back(v);
  }
  while (clean.size() > 3 && cv::norm(clean.front() - clean.back()) < 0.5) clean.pop_back();
  for (bool removed = true; removed && clean.size() > 3;) {
    removed = false;
    for (size_t i = 0; i < clean.size(); ++i) {
      const cv::Point2d& p = clean[(i + clean.size() - 1) % clean.size()];
      const cv::Point2d& q = clean[(i + 1) % clean.size()];
      if (distanceToChord(clean[i], p, q) < 0.25) {
        clean.erase(clean.begin() + static_cast<std::ptrdiff_t>(i));
        removed = true;
        break;
      }
    }
  }
  return clean;
}

// The border of one region (contour points in image pixels, pixel centres at the union's scale)
// as straight lines: corners by Douglas-Peucker, sides cut into pieces of at most `pieceLength`
// px, one line per piece, collinear neighbours merged, consecutive lines intersected (a jog
// between parallel lines gets two vertices). `shift` moves every line by that many px away from
// the region (the contour runs through the border pixels' centres, half a pixel inside); the
// region is inside the ring, or outside it for a `hole`.
core::Ring refineRing(const std::vector<cv::Point2d>& pts, const BoxFitParams& params, double shift,
                      double pointSpacing, bool hole) {
  if (pts.size() < 8) return pts;
  const std::vector<size_t> corners = ringCorners(pts, params.cornerTolerance);
  std::vector<Line> lines = sideLines(pts, corners, params, pointSpacing);
  dropRoundings(lines, params.closingRadius, pointSpacing);
  mergeCollinear(lines, pts, params.cornerTolerance);
  shiftAway(lines, pts, shift, hole);
  return cleaned(intersected(lines, pts, params.refineLength));
}

// The contour (pixel centres at the union's scale) in image pixels.
std::vector<cv::Point2d> toImage(const std::vector<cv::Point>& contour) {
  std::vector<cv::Point2d> out;
  out.reserve(contour.size());
  for (const auto& p : contour) out.emplace_back((p.x + 0.5) / kScale, (p.y + 0.5) / kScale);
  return out;
}

// A fallback when the refined lines do not make a simple ring: the contour simplified.
core::Ring simplified(const std::vector<cv::Point>& contour, double shiftTolerance) {
  std::vector<cv::Point> approx;
  cv::approxPolyDP(contour, approx, shiftTolerance * kScale, true);
  return toImage(approx);
}

core::Ring clampTo(core::Ring ring, cv::Size size) {
  for (auto& v : ring) {
    v.x = std::clamp(v.x, 0.0, static_cast<double>(size.width));
    v.y = std::clamp(v.y, 0.0, static_cast<double>(size.height));
  }
  return ring;
}

// Boxes that do not touch (a wing whose corner no box covers) are joined by the pieces of the
// segment that no box covers and that touch two or more groups of boxes: the outline is one
// polygon, and the segment says the building is continuous there.
void bridgeWithSegment(cv::Mat& mask, const cv::Mat& segment) {
  cv::Mat groups;
  const int n = cv::connectedComponents(mask, groups, 8, CV_32S);
  if (n <= 2) return;
  cv::Mat segmentScaled;
  cv::resize(segment, segmentScaled, mask.size(), 0, 0, cv::INTER_NEAREST);
  const cv::Mat uncovered = segmentScaled & ~mask;
  cv::Mat pieces;
  const int m = cv::connectedComponents(uncovered, pieces, 8, CV_32S);
  std::vector<std::vector<int>> touched(static_cast<size_t>(m));
  for (int y = 0; y < mask.rows; ++y) {
    const int* p = pieces.ptr<int>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (p[x] == 0) continue;
      auto& list = touched[static_cast<size_t>(p[x])];
      for (const cv::Point d : {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
        const cv::Point q(x + d.x, y + d.y);
        if (q.x < 0 || q.y < 0 || q.x >= mask.cols || q.y >= mask.rows) continue;
        const int g = groups.at<int>(q);
        if (g > 0 && std::find(list.begin(), list.end(), g) == list.end()) list.push_back(g);
      }
    }
  }
  std::vector<uchar> bridge(static_cast<size_t>(m), 0);
  for (int i = 1; i < m; ++i) bridge[static_cast<size_t>(i)] = touched[static_cast<size_t>(i)].size() >= 2;
  for (int y = 0; y < mask.rows; ++y) {
    const int* p = pieces.ptr<int>(y);
    uchar* out = mask.ptr<uchar>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (bridge[static_cast<size_t>(p[x])]) out[x] = 255;
    }
  }
}

}  // namespace

core::Polygon mergeBoxes(const std::vector<Box>& boxes, cv::Size roiSize, const BoxFitParams& params,
                         const cv::Mat& segment, int* mergedArea) {
  core::Polygon polygon;
  if (mergedArea) *mergedArea = 0;
  if (boxes.empty()) return polygon;
  cv::Mat mask = cv::Mat::zeros(roiSize * kScale, CV_8U);
  for (const auto& b : boxes) {
    core::Ring corners = b.corners();
    for (auto& c : corners) c *= kScale;
    fillConvex(mask, corners);
  }
  if (!segment.empty()) bridgeWithSegment(mask, segment);
  if (params.closingRadius > 0) {
    // The border replicated: boxes reaching the ROI's side (the image's border, for a building
    // the image cuts) keep reaching it instead of being eroded by the radius there.
    const int r = params.closingRadius * kScale;
    cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1}),
                     {-1, -1}, 1, cv::BORDER_REPLICATE);
  }
  std::vector<std::vector<cv::Point>> contours;
  std::vector<cv::Vec4i> hierarchy;
  cv::findContours(mask, contours, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE);
  int outer = -1;
  double largest = 0;
  for (size_t i = 0; i < contours.size(); ++i) {
    if (hierarchy[i][3] >= 0) continue;
    const double a = cv::contourArea(contours[i]);
    if (a > largest) largest = a, outer = static_cast<int>(i);
  }
  if (outer < 0) return polygon;
  const double shift = 0.5 / kScale, spacing = 1.0 / kScale;
  auto ringOf = [&](const std::vector<cv::Point>& contour, bool hole) {
    core::Ring ring = clampTo(refineRing(toImage(contour), params, shift, spacing, hole), roiSize);
    if (ring.size() < 3 || !core::isSimple(ring)) ring = clampTo(simplified(contour, 0.75), roiSize);
    return ring;
  };
  polygon.outer = ringOf(contours[static_cast<size_t>(outer)], false);
  double area = largest;
  for (int h = hierarchy[static_cast<size_t>(outer)][2]; h >= 0; h = hierarchy[static_cast<size_t>(h)][0]) {
    const double a = cv::contourArea(contours[static_cast<size_t>(h)]);
    if (a / (kScale * kScale) < params.minHoleArea) continue;
    core::Ring ring = ringOf(contours[static_cast<size_t>(h)], true);
    if (ring.size() >= 3) polygon.holes.push_back(std::move(ring)), area -= a;
  }
  if (mergedArea) *mergedArea = static_cast<int>(std::lround(area / (kScale * kScale)));
  return polygon;
}

std::vector<Box> essentialBoxes(const std::vector<Box>& boxes, cv::Size roiSize, double minShare) {
  std::vector<size_t> order(boxes.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return boxes[a].area() > boxes[b].area(); });
  cv::Mat covered = cv::Mat::zeros(roiSize, CV_8U), box = cv::Mat::zeros(roiSize, CV_8U);
  std::vector<bool> keep(boxes.size(), false);
  for (size_t i : order) {
    box.setTo(0);
    fillConvex(box, boxes[i].corners());
    const int own = cv::countNonZero(box);
    const int added = own - cv::countNonZero(box & covered);
    if (own == 0 || added < minShare * own) continue;
    keep[i] = true;
    covered |= box;
  }
  std::vector<Box> kept;
  for (size_t i = 0; i < boxes.size(); ++i) {
    if (keep[i]) kept.push_back(boxes[i]);
  }
  return kept;
}

}  // namespace delineo::boxfit
