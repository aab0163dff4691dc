#include "delineo/segmentation/dtm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace delineo::segmentation {

namespace {

constexpr int kMaxBins = 4096;  // bins of one window's height histogram at most

struct Point3 {
  float x, y, z;  // pixel centre, height
};

// One window's sample, if any (see sampleGround()).
bool sampleWindow(const cv::Mat& dem, const cv::Mat& ground, const cv::Rect& window, double binWidth,
                  double levelShare, std::vector<Point3>& points, GroundSample& sample) {
  points.clear();
  int withHeight = 0;
  for (int y = window.y; y < window.br().y; ++y) {
    const float* h = dem.ptr<float>(y);
    const unsigned char* g = ground.ptr<unsigned char>(y);
    for (int x = window.x; x < window.br().x; ++x) {
      if (!std::isfinite(h[x])) continue;
      ++withHeight;
      if (g[x]) points.push_back({x + 0.5f, y + 0.5f, h[x]});
    }
  }
  if (points.empty()) return false;
  if (points.size() < 0.01 * window.area() && static_cast<int>(points.size()) < withHeight) return false;
  auto [lo, hi] = std::minmax_element(points.begin(), points.end(),
                                       [](const Point3& a, const Point3& b) { return a.z < b.z; });
  const double low = lo->z, range = hi->z - low;
  const double width = std::max(binWidth, range / kMaxBins);
  const int bins = static_cast<int>(range / width) + 1;
  std::vector<int> histogram(static_cast<size_t>(bins), 0);
  auto binOf = [&](float z) { return std::min(bins - 1, static_cast<int>((z - low) / width)); };
  for (const Point3& p : points) ++histogram[static_cast<size_t>(binOf(p.z))];
  // The lowest bin holding at least `levelShare` of the most populated one: in a window mostly
  // covered by a roof (the street beside it in shadow, without heights) the most frequent
  // "ground" height of the first round is the roof's, and the roof would stay ground.
  const int peak = static_cast<int>(std::max_element(histogram.begin(), histogram.end()) - histogram.begin());
  int mode = peak;
  for (int b = 0; b < peak; ++b) {
    if (histogram[static_cast<size_t>(b)] >= levelShare * histogram[static_cast<size_t>(peak)]) {
      mode = b;
      break;
    }
  }
  const float cx = window.x + 0.5f * window.width, cy = window.y + 0.5f * window.height;
  float best = std::numeric_limits<float>::infinity();
  for (const Point3& p : points) {
    if (binOf(p.z) != mode) continue;
    const float d = (p.x - cx) * (p.x - cx) + (p.y - cy) * (p.y - cy);
    if (d < best) {
      best = d;
      sample.position = cv::Point(static_cast<int>(p.x), static_cast<int>(p.y));
      sample.height = p.z;
    }
  }
  return true;
}

// Least-squares plane z = c0 + c1 (x - mx) + c2 (y - my) through the samples (minimum norm when
// they do not fix it: one sample gives a level plane, two a plane level across their line).
struct Plane {
  double mx = 0, my = 0, c0 = 0, c1 = 0, c2 = 0;
  double at(double x, double y) const { return c0 + c1 * (x - mx) + c2 * (y - my); }
};

Plane fitPlane(const std::vector<GroundSample>& samples) {
  Plane plane;
  for (const GroundSample& s : samples) plane.mx += s.position.x + 0.5, plane.my += s.position.y + 0.5;
  plane.mx /= static_cast<double>(samples.size());
  plane.my /= static_cast<double>(samples.size());
  // Normal equations; the SVD solve zeroes the directions the samples do not fix.
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0, 0, 0);
  for (const GroundSample& s : samples) {
    const cv::Vec3d row(1.0, s.position.x + 0.5 - plane.mx, s.position.y + 0.5 - plane.my);
    normal += row * row.t();
    rhs += row * static_cast<double>(s.height);
  }
  cv::Vec3d c;
  cv::solve(normal, rhs, c, cv::DECOMP_SVD);
  plane.c0 = c[0];
  plane.c1 = c[1];
  plane.c2 = c[2];
  return plane;
}

// Planar interpolation of one triangle (vertex centres p, heights z) on the pixels of `dtm` whose
// centre is inside it and that `done` does not mark yet.
void rasterizeTriangle(const cv::Point2f p[3], const float z[3], cv::Mat& dtm, cv::Mat& done) {
  const double det = (p[1].y - p[2].y) * (p[0].x - p[2].x) + (p[2].x - p[1].x) * (p[0].y - p[2].y);
  if (std::abs(det) < 1e-9) return;
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].x, p[1].x, p[2].x}) - 0.5f)));
  const int x1 = std::min(dtm.cols - 1, static_cast<int>(std::ceil(std::max({p[0].x, p[1].x, p[2].x}))));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].y, p[1].y, p[2].y}) - 0.5f)));
  const int y1 = std::min(dtm.rows - 1, static_cast<int>(std::ceil(std::max({p[0].y, p[1].y, p[2].y}))));
  constexpr double kEdge = -1e-6;  // pixels on a shared edge belong to the first triangle drawn
  for (int y = y0; y <= y1; ++y) {
    float* out = dtm.ptr<float>(y);
    unsigned char* mark = done.ptr<unsigned char>(y);
    const double py = y + 0.5;
    for (int x = x0; x <= x1; ++x) {
      if (mark[x]) continue;
      const double px = x + 0.5;
      const double l0 = ((p[1].y - p[2].y) * (px - p[2].x) + (p[2].x - p[1].x) * (py - p[2].y)) / det;
      const double l1 = ((p[2].y - p[0].y) * (px - p[2].x) + (p[0].x - p[2].x) * (py - p[2].y)) / det;
      const double l2 = 1.0 - l0 - l1;
      if (l0 < kEdge || l1 < kEdge || l2 < kEdge) continue;
      out[x] = static_cast<float>(l0 * z[0] + l1 * z[1] + l2 * z[2]);
      mark[x] = 1;
    }
  }
}

// Pixels `done` does not mark take the value of the nearest marked pixel plus the plane's rise
// between the two.
void extendOutsideHull(cv::Mat& dtm, const cv::Mat& done, const Plane& plane) {
  cv::Mat outside = done == 0;
  if (cv::countNonZero(outside) == 0) return;
  cv::Mat distance, nearest;
  cv::distanceTransform(outside, distance, nearest, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  std::vector<cv::Point> byLabel(static_cast<size_t>(dtm.total()) + 1);
  for (int y = 0; y < dtm.rows; ++y) {
    const unsigned char* o = outside.ptr<unsigned char>(y);
    const int* n = nearest.ptr<int>(y);
    for (int x = 0; x < dtm.cols; ++x) {
      if (!o[x]) byLabel[static_cast<size_t>(n[x])] = cv::Point(x, y);
    }
  }
  for (int y = 0; y < dtm.rows; ++y) {
    const unsigned char* o = outside.ptr<unsigned char>(y);
    const int* n = nearest.ptr<int>(y);
    float* out = dtm.ptr<float>(y);
    for (int x = 0; x < dtm.cols; ++x) {
      if (!o[x]) continue;
      const cv::Point q = byLabel[static_cast<size_t>(n[x])];
      out[x] = dtm.at<float>(q) + static_cast<float>(plane.at(x + 0.5, y + 0.5) - plane.at(q.x + 0.5, q.y + 0.5));
    }
  }
}

}  // namespace

std::vector<GroundSample> sampleGround(const cv::Mat& dem, const cv::Mat& ground, int windowPx, double binWidth,
                                       double levelShare) {
  std::vector<GroundSample> samples;
  std::vector<Point3> points;
  const int w = std::max(1, windowPx);
  for (int y = 0; y < dem.rows; y += w) {
    for (int x = 0; x < dem.cols; x += w) {
      const cv::Rect window = cv::Rect(x, y, w, w) & cv::Rect(0, 0, dem.cols, dem.rows);
      GroundSample sample;
      if (sampleWindow(dem, ground, window, binWidth, levelShare, points, sample)) samples.push_back(sample);
    }
  }
  return samples;
}

cv::Mat interpolateDtm(const std::vector<GroundSample>& samples, cv::Size size) {
  cv::Mat dtm(size, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  if (samples.empty()) return dtm;
  const Plane plane = fitPlane(samples);
  cv::Mat done(size, CV_8U, cv::Scalar(0));
  std::vector<cv::Vec6f> triangles;
  if (samples.size() >= 3) {
    cv::Subdiv2D subdivision(cv::Rect(0, 0, size.width, size.height));
    cv::Mat heightAt(size, CV_32F, cv::Scalar(0));
    for (const GroundSample& s : samples) {
      subdivision.insert(cv::Point2f(s.position.x + 0.5f, s.position.y + 0.5f));
      heightAt.at<float>(s.position) = s.height;
    }
    subdivision.getTriangleList(triangles);  // only triangles with all vertices in the rectangle
    for (const cv::Vec6f& t : triangles) {
      const cv::Point2f p[3] = {{t[0], t[1]}, {t[2], t[3]}, {t[4], t[5]}};
      float z[3];
      for (int k = 0; k < 3; ++k) z[k] = heightAt.at<float>(cv::Point(static_cast<int>(p[k].x), static_cast<int>(p[k].y)));
      rasterizeTriangle(p, z, dtm, done);
    }
  }
  if (cv::countNonZero(done) == 0) {  // fewer than three samples, or all on one line
    for (int y = 0; y < size.height; ++y) {
      float* out = dtm.ptr<float>(y);
      for (int x = 0; x < size.width; ++x) out[x] = static_cast<float>(plane.at(x + 0.5, y + 0.5));
    }
    return dtm;
  }
  extendOutsideHull(dtm, done, plane);
  return dtm;
}

}  // namespace delineo::segmentation
