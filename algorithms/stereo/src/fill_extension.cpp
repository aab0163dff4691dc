// The fill extended from each filled region over the unmatched pixels beside it that match at
// its disparity on their own (see RegionFillSettings::extendReach).
#include "fill_internal.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <vector>

namespace delineo::stereo::detail {

namespace {

// The surface's own brightness offset between the views (a facet lit or seen differently): the
// mean difference over the filled pixels (`grown`, over `box`), the right view at `plane` and
// mapped by the images' grey map (`gain`, `offset`).
double surfaceBias(const cv::Mat& left, const cv::Mat& right, const cv::Rect& box,
                   const cv::Mat& grown, const FillPlane& plane, double gain, double offset) {
  double bias = 0, biasCount = 0;
  for (int y = 0; y < box.height; ++y) {
    const uchar* m = grown.ptr<uchar>(y);
    for (int x = 0; x < box.width; ++x) {
      const int u = box.x + x, v = box.y + y;
      const int xr = u - static_cast<int>(std::lround(plane.at(u, v)));
      if (!m[x] || xr < 0 || xr >= right.cols) continue;
      const float a = left.at<float>(v, u), b = right.at<float>(v, xr);
      if (!std::isfinite(a) || !std::isfinite(b)) continue;
      bias += a - (gain * b + offset);
      biasCount += 1;
    }
  }
  if (biasCount > 0) bias /= biasCount;
  return bias;
}

// The extension of one filled region over the unmatched pixels around it (see
// extendOverUnmatched), in its steps: whether a pixel's window matches at the fill's disparity
// and at no other (matchesAt, with errorAtTheFill, clearerThanAt and clearInAWiderWindow), and
// the walks from the filled pixels that fill the pixels it holds for (walk).
struct Extension {
  // What a pixel is to the extension, decided on its first visit (kept for the second walk).
  enum Kind : uchar {
    kUnseen,
    kPassedOver,
    kRestarts,
    kUnmatched,
    kDisagrees,
    kMatchesHere,
    kExtended,
    kStops
  };

  bool errorAtTheFill(int x, int y, int w, double value, double pixelLimit, double& sum) const;
  bool clearerThanAt(int x, int y, int w, double sum, int other) const;
  bool clearInAWiderWindow(int x, int y, double value, int first) const;
  bool matchesAt(int x, int y) const;
  bool agreesWithMatchesBeside(int x, int y) const;
  void walk(bool restarts);
  void startWalk(cv::Mat& distance, std::deque<cv::Point>& queue);
  uchar firstVisit(int x, int y) const;
  bool goesThrough(int x, int y, uchar& k, bool restarts);

  const cv::Mat& left;
  const cv::Mat& right;
  const cv::Rect& box;   // the filled region's box
  const cv::Mat& grown;  // over `box`: its filled pixels
  const FillPlane& plane;
  double gain, offset;  // the images' grey map
  double sigma;         // the left view's noise sigma
  int dmin, dmax;
  const RegionFillSettings& settings;
  float fillScore;
  const cv::Mat& labels;              // the flat regions
  const std::vector<uchar>& ownFill;  // by label: the fill decides on the region itself
  cv::Mat& disparity;
  cv::Mat& score;
  const int reach = settings.extendReach;
  // The walks' frame: `box` grown by `reach`, within the image.
  const cv::Rect outer =
      cv::Rect(box.x - reach, box.y - reach, box.width + 2 * reach, box.height + 2 * reach) &
      cv::Rect(0, 0, left.cols, left.rows);
  const double bias = surfaceBias(left, right, box, grown, plane, gain, offset);
  cv::Mat kind = cv::Mat(outer.size(), CV_8U, cv::Scalar(kUnseen));  // over `outer`: Kind
  int extended = 0;                                                  // the pixels filled
};

// The summed error of the window of half-side w at (x, y) at the fill's disparity `value` (the
// right view interpolated, the surface's offset added); false where it leaves either view or a
// pixel's error exceeds `pixelLimit`.
bool Extension::errorAtTheFill(int x, int y, int w, double value, double pixelLimit,
                               double& sum) const {
  const int whole = static_cast<int>(std::floor(value));
  const auto t = static_cast<float>(value - whole);
  sum = 0;
  for (int v = y - w; v <= y + w; ++v) {
    for (int u = x - w; u <= x + w; ++u) {
      const int xr = u - whole;  // u − value lies in [xr − 1, xr]
      if (xr - 1 < 0 || xr >= right.cols) return false;
      const float a = left.at<float>(v, u);
      const float b = (1 - t) * right.at<float>(v, xr) + t * right.at<float>(v, xr - 1);
      if (!std::isfinite(a) || !std::isfinite(b)) return false;
      const double error = std::abs(a - (gain * b + offset + bias));
      if (error > pixelLimit) return false;
      sum += error;
    }
  }
  return true;
}

// Whether that window, of error `sum` at the fill's disparity, matches there clearly better
// than at the integer disparity `other`: sum below extendContrast × its error there. That error
// only grows row by row: once a part of it clears `sum`, the rest of the window is not read.
bool Extension::clearerThanAt(int x, int y, int w, double sum, int other) const {
  double e = 0;
  for (int v = y - w; v <= y + w; ++v) {
    const float* l = left.ptr<float>(v);
    const float* rr = right.ptr<float>(v);
    for (int u = x - w; u <= x + w; ++u) {
      const int xr = u - other;
      if (xr < 0 || xr >= right.cols || !std::isfinite(rr[xr])) return true;
      e += std::abs(l[u] - (gain * rr[xr] + offset));
    }
    if (!(sum > settings.extendContrast * e)) return true;
  }
  return false;
}

// A weakly textured surface's small window can match about as well a few px along the row (on
// the same surface): the wider window (extendWideWindow, holding more of its texture) decides
// then, by the same test: its mean error at the fill's disparity below extendContrast × the one
// at any disparity 2 px or more away. Across the contour it meets another surface in the right
// view, and fails.
// `first`: the disparity the small window failed at, tried first (most wide windows fail there
// too, and the rest is not read).
bool Extension::clearInAWiderWindow(int x, int y, double value, int first) const {
  const int w = settings.extendWideWindow / 2;
  double sum = 0;
  if (w <= settings.extendWindow / 2 || x < w || y < w || x + w >= left.cols ||
      y + w >= left.rows ||
      !errorAtTheFill(x, y, w, value, std::numeric_limits<double>::infinity(), sum)) {
    return false;
  }
  for (int k = dmin - 1; k <= dmax; ++k) {
    const int other = k < dmin ? first : k;
    if (std::abs(other - value) < 2.0 || (k >= dmin && other == first)) continue;
    if (!clearerThanAt(x, y, w, sum, other)) return false;
  }
  return true;
}

bool Extension::matchesAt(int x, int y) const {
  const double value = plane.at(x, y);
  const int w = settings.extendWindow / 2;
  if (value < dmin || value > dmax || x < w || y < w || x + w >= left.cols || y + w >= left.rows) {
    return false;
  }
  // Every pixel of the window within extendPixelSigmas noise sigmas of its counterpart (the
  // right view interpolated, the surface's offset added), and their mean within
  // extendPhotometric.
  double sum = 0;
  if (!errorAtTheFill(x, y, w, value, settings.extendPixelSigmas * sigma, sum)) return false;
  const double error = sum / ((2 * w + 1) * (2 * w + 1));
  if (error > settings.extendPhotometric * sigma) return false;
  // The right pixel it maps to must not be another left pixel's match: there the right view
  // shows that pixel's surface (an occluded ground pixel's window can match the ground nearby).
  const double target = x - value;
  const float* row = disparity.ptr<float>(y);
  for (int u = std::max(0, static_cast<int>(target) + dmin - 1);
       u <= std::min(left.cols - 1, static_cast<int>(target) + dmax + 1); ++u) {
    if (u != x && std::isfinite(row[u]) && std::abs(row[u] - value) >= 1.0 &&
        std::abs(u - row[u] - target) < 0.5) {
      return false;
    }
  }
  // And the window matches there clearly better than at any disparity 2 px or more away (a
  // ground pixel's window matches at the ground's disparity as well).
  if (settings.extendContrast <= 0) return true;
  for (int other = dmin; other <= dmax; ++other) {
    if (std::abs(other - value) < 2.0) continue;
    if (!clearerThanAt(x, y, w, sum, other)) return clearInAWiderWindow(x, y, value, other);
  }
  return true;
}

// Reached through the matches, beyond extendReach from the filled pixels, the fill must still
// be the surface there: no match of the surface beside the pixel (3x3, within extendAgree) off
// it by more than extendRestartAgree (a constant carried along a gently sloped facet reaches
// where it is off by more: 600² edge 92.0 -> 91.7 % without this test).
bool Extension::agreesWithMatchesBeside(int x, int y) const {
  for (int v = std::max(0, y - 1); v <= std::min(left.rows - 1, y + 1); ++v) {
    for (int u = std::max(0, x - 1); u <= std::min(left.cols - 1, x + 1); ++u) {
      const float e = disparity.at<float>(v, u);
      const double off = std::abs(e - plane.at(u, v));
      if (off > settings.extendRestartAgree && off <= settings.extendAgree) {
        return false;
      }
    }
  }
  return true;
}

// One walk from the filled pixels, `outer` coordinates, 4-connected (see extendOverUnmatched):
// `restarts`, the second walk's.
void Extension::walk(bool restarts) {
  cv::Mat distance(outer.size(), CV_32S, cv::Scalar(std::numeric_limits<int>::max()));
  std::deque<cv::Point> queue;
  startWalk(distance, queue);
  // Shortest distances: a pixel is relaxed again whenever a shorter path turns up.
  while (!queue.empty()) {
    const cv::Point p = queue.front();
    queue.pop_front();
    const int step = distance.at<int>(p) + 1;
    for (const cv::Point& q :
         {p + cv::Point(1, 0), p - cv::Point(1, 0), p + cv::Point(0, 1), p - cv::Point(0, 1)}) {
      if (q.x < 0 || q.y < 0 || q.x >= outer.width || q.y >= outer.height) continue;
      const int x = outer.x + q.x, y = outer.y + q.y;
      uchar& k = kind.at<uchar>(q);
      if (k == kUnseen) k = firstVisit(x, y);
      if (k == kStops) continue;
      const int reached = restarts && k == kRestarts ? 0 : step;
      if (reached > reach || reached >= distance.at<int>(q)) continue;
      if (!goesThrough(x, y, k, restarts)) continue;
      distance.at<int>(q) = reached;
      if (reached == 0) {
        queue.push_front(q);
      } else {
        queue.push_back(q);
      }
    }
  }
}

// The walk starts at the filled pixels (matched), at distance 0.
void Extension::startWalk(cv::Mat& distance, std::deque<cv::Point>& queue) {
  for (int y = 0; y < box.height; ++y) {
    const uchar* m = grown.ptr<uchar>(y);
    const float* d = disparity.ptr<float>(box.y + y) + box.x;
    for (int x = 0; x < box.width; ++x) {
      if (m[x] && std::isfinite(d[x])) {
        const cv::Point p(box.x + x - outer.x, box.y + y - outer.y);
        distance.at<int>(p) = 0;
        if (kind.at<uchar>(p) == kUnseen) kind.at<uchar>(p) = kPassedOver;
        queue.push_back(p);
      }
    }
  }
}

// What the image pixel (x, y) is to the extension, by its match and its flat region.
uchar Extension::firstVisit(int x, int y) const {
  const float d = disparity.at<float>(y, x);
  // Matches that agree with the fill are passed over (a weakly textured roof's matched
  // patches between the filled region and the unmatched pixels beyond).
  const bool ownRegion = ownFill[static_cast<size_t>(labels.at<int>(y, x))] != 0;
  const double off = std::abs(d - plane.at(x, y));
  if (!std::isfinite(d)) return ownRegion ? kStops : kUnmatched;
  if (off <= std::min(settings.extendAgree, settings.extendRestartAgree)) return kRestarts;
  if (off <= settings.extendAgree) return kPassedOver;
  if (settings.extendReplaceOff > 0 && off >= settings.extendReplaceOff && !ownRegion) {
    // Far off the fill: a window that met another surface as plain as the roof (the
    // facade the right view sees beside it, the ground beyond the outline). Tested as an
    // unmatched pixel, where the fill's window must also beat the match's own disparity.
    return kDisagrees;
  }
  return kStops;
}

// Whether the walk goes on through the image pixel (x, y) of kind `k`, reached within
// extendReach: an unmatched one only where its window matches at the fill (then filled, and `k`
// updated).
bool Extension::goesThrough(int x, int y, uchar& k, bool restarts) {
  if (k == kUnmatched || k == kDisagrees) {
    if (!matchesAt(x, y)) {
      k = kStops;
      return false;
    }
    k = kMatchesHere;
  }
  if (k == kMatchesHere) {
    // (Only the second walk leaves a pixel that matches here unfilled.)
    if (restarts && !agreesWithMatchesBeside(x, y)) return false;
    disparity.at<float>(y, x) = static_cast<float>(plane.at(x, y));
    score.at<float>(y, x) = fillScore;
    ++extended;
    k = kExtended;
  }
  return true;
}

}  // namespace

// A filled region ends where the flat test ends, but a weakly textured roof is flat only in
// patches (its tiles between their joints): the pixels between the patches and up to the
// contour, not flat enough for the fill and not textured enough for NCC, stay unmatched. From
// the filled pixels (`grown`), the fill goes on over unmatched pixels, 4-connected and at most
// `extendReach` px, while the window around each matches at the region's disparity and at no
// other (see matchesAt), passing over the matches within `extendAgree` px of it. The flat
// regions the fill decides on itself (`ownFill`) are not entered. A window that reaches across the
// contour meets, in the right view, another part of the surface beyond it: the fill stops 1 px
// short of the contour (the snapping's work).
int extendOverUnmatched(const cv::Mat& left, const cv::Mat& right, const cv::Rect& box,
                        const cv::Mat& grown, const FillPlane& plane, double gain, double offset,
                        double sigma, int dmin, int dmax, const RegionFillSettings& settings,
                        float fillScore, const cv::Mat& labels, const std::vector<uchar>& ownFill,
                        cv::Mat& disparity, cv::Mat& score) {
  Extension extension{left, right, box,      grown,     plane,  gain,    offset,    sigma,
                      dmin, dmax,  settings, fillScore, labels, ownFill, disparity, score};
  // Two walks from the filled pixels, `outer` coordinates, 4-connected. The first reaches
  // extendReach steps from them. The second (extendRestartAgree ≥ 0) counts the steps from the
  // nearest match within extendRestartAgree of the fill too (the surface itself: a weakly
  // textured roof's matched patches, which can hold the filled pixels far from its unmatched
  // strips), and the pixels it adds must agree with the surface's matches beside them.
  extension.walk(false);
  if (settings.extendRestartAgree >= 0) extension.walk(true);
  return extension.extended;
}

}  // namespace delineo::stereo::detail
