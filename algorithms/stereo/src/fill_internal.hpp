#pragma once
// The flat-region fill's parts, shared by its files (internal to delineo_stereo; see
// fillFlatRegions in match_fill.hpp). match_fill.cpp runs the stage: the flat regions
// (fill_regions.cpp), the decision on each and its fill (fill_region_decision.cpp, with
// fill_own_light.cpp, fill_edge_disparity.cpp and fill_sloped_facet.cpp), then the extension over
// the unmatched pixels (fill_extension.cpp) in the order fill_extension_footprints.cpp allows.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "match_fill.hpp"

namespace delineo::stereo::detail {

// Half-width of the flat test's window (5x5).
inline constexpr int kFlatReach = 2;

// Appends to `cells` the ids base + ty·tilesX + tx of the tile × tile squares that `rect`
// (non-empty) meets: a task's cells for RowOrderedTasks.
inline void addTileCells(const cv::Rect& rect, int tile, int tilesX, int base,
                         std::vector<int>& cells) {
  for (int ty = rect.y / tile; ty <= (rect.br().y - 1) / tile; ++ty) {
    for (int tx = rect.x / tile; tx <= (rect.br().x - 1) / tile; ++tx) {
      cells.push_back(base + ty * tilesX + tx);
    }
  }
}

// The flat regions of both views (fill_regions.cpp).

// Pixels of `image` whose 5x5 standard deviation is below flatSigmas noise sigmas (CV_8U
// 0/255); the image's noise sigma in `sigmaOut`.
cv::Mat flatMask(const cv::Mat& image, const RegionFillSettings& settings,
                 double* sigmaOut = nullptr, const LocalMoments* known = nullptr);

// The flat regions of the right view, labelled as the left ones, with their mean grey levels.
struct RightFlatRegions {
  cv::Mat labels;  // CV_32S, 0 off the flat regions
  std::vector<double> meanGrey;
};
RightFlatRegions rightFlatRegions(const cv::Mat& flat, const cv::Mat& right);

// The left view's flat regions (flatMask, 4-connected) and which of them the fill decides on.
struct LeftFlatRegions {
  double sigma = 0;   // the left view's noise sigma
  cv::Mat flatCores;  // the regions without their thin parts (empty without coreOpening)
  cv::Mat labels, stats, centroids;
  // By label: a region the fill decides on itself (the extension does not enter them).
  std::vector<uchar> ownFill;
};
LeftFlatRegions leftFlatRegions(const cv::Mat& left, const cv::Mat& disparity,
                                const RegionFillSettings& settings,
                                const LocalMoments* leftMoments);

// The error of a region's outline ring at a plane's disparity.

// Calls visit(residual) for each pixel of `ring` (over `box`) with data in both views, residual =
// left − (gain · right + offset) with the right view read at the plane's disparity by linear
// interpolation (the candidates are sub-pixel); `stopAtRow()` is asked before each row. False
// when the outline leaves the right image or stopAtRow() said stop.
template <typename Visit, typename StopAtRow>
bool visitRingResiduals(const cv::Mat& left, const cv::Mat& right, const cv::Mat& ring,
                        const cv::Rect& box, const FillPlane& plane,
                        const std::pair<double, double>& map, Visit&& visit,
                        StopAtRow&& stopAtRow) {
  const auto [mapGain, mapOffset] = map;
  for (int y = 0; y < box.height; ++y) {
    if (stopAtRow()) return false;
    const uchar* m = ring.ptr<uchar>(y);
    const float* a = left.ptr<float>(box.y + y) + box.x;
    const float* b = right.ptr<float>(box.y + y);
    for (int x = 0; x < box.width; ++x) {
      if (!m[x]) continue;
      const double value = plane.at(box.x + x, box.y + y);
      const int whole = static_cast<int>(std::floor(value));
      const float t = static_cast<float>(value - whole);
      const int xr = box.x + x - whole;  // x − value lies in [xr − 1, xr]
      if (xr - 1 < 0 || xr >= right.cols) return false;
      const float bv = (1 - t) * b[xr] + t * b[xr - 1];
      if (!std::isfinite(a[x]) || !std::isfinite(bv)) continue;
      visit(a[x] - (mapGain * bv + mapOffset));
    }
  }
  return true;
}

// The ring's error in the region's own light (see RegionFillSettings::shadowOwnLight): mean
// |residual − median residual|; 1e30 when the outline leaves the right image or has no data
// (fill_own_light.cpp).
double ringErrorInOwnLight(const cv::Mat& left, const cv::Mat& right, const cv::Mat& ring,
                           const cv::Rect& box, const FillPlane& plane,
                           const std::pair<double, double>& map);

// The median grey of the valid pixels of `image`, from about 10 000 of them (fill_own_light.cpp).
double medianGrey(const cv::Mat& image);

// A region's row ends, read by its sloped facet's plane and by its edges' disparity
// (regionRowEnds: fill_sloped_facet.cpp).

// A region's first and last pixel on each of its rows (image coordinates), for the rows it
// spans 3 px or more (`region` is the mask of `box`).
struct RowEnds {
  int y, l0, l1;
};
// The rows of `region` (over `box`) whose ends lie at least `minSpan` px apart (a sloped facet's
// row ends need 2: a tip's rows tell nothing of its slope).
std::vector<RowEnds> regionRowEnds(const cv::Mat& region, const cv::Rect& box, int minSpan = 2);

// The lowest and highest value of `plane` over the rows `rows` (a plane's extremes on a row are
// at its ends).
inline std::pair<double, double> planeRange(const FillPlane& plane,
                                            const std::vector<RowEnds>& rows) {
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  for (const RowEnds& r : rows) {
    for (const int x : {r.l0, r.l1}) {
      lowest = std::min(lowest, plane.at(x, r.y));
      highest = std::max(highest, plane.at(x, r.y));
    }
  }
  return {lowest, highest};
}

// A row's search band in the right view (`cols` px wide): the columns its ends can map to.
inline std::pair<int, int> searchBand(const RowEnds& r, int dmin, int dmax, int cols) {
  return {std::max(0, r.l0 - dmax), std::min(cols - 1, r.l1 - dmin)};
}

// The first and last pixel of `label` (in `labels`, CV_32S) on the row's search band; -1 when
// absent.
inline std::pair<int, int> labelEndsInBand(const cv::Mat& labels, const RowEnds& r, int label,
                                           int dmin, int dmax) {
  const int* l = labels.ptr<int>(r.y);
  const auto [x0, x1] = searchBand(r, dmin, dmax, labels.cols);
  int first = -1, last = -1;
  for (int x = x0; x <= x1; ++x) {
    if (l[x] != label) continue;
    if (first < 0) first = x;
    last = x;
  }
  return {first, last};
}

// A plain region's disparity read from its edges in both views (fill_edge_disparity.cpp).

// Sub-pixel position of a flat region's edge on a row of `row` (`cols` px), walking from its end
// pixel `start` outwards (`step` −1 or +1); nothing where the edge is not sharp.
std::optional<double> subpixelEdge(const float* row, int cols, int start, int step, double roof,
                                   double sigma);

// The constant disparity of a plain region read from its edges in both views (see
// RegionFillSettings::edgeMinSamples): the row ends within `reach` of `candidate`, the right
// view's counterpart being the flat region of the region's grey (within 3 sigma, through the
// matches' grey map) whose row ends agree with `candidate` on most rows. The mean of the
// row-end disparities within 0.75 px of their median (samples 0: none).
struct EdgeReading {
  double value = 0;
  int samples = 0;       // row ends within 0.75 px of the median
  int read = 0;          // row ends read (sharp in both views, within `reach` of the candidate)
  int fromLeftEnds = 0;  // of `samples`, those at the rows' left ends
};
EdgeReading edgeDisparity(const cv::Mat& left, const cv::Mat& right, const cv::Mat& region,
                          const cv::Rect& box, const RightFlatRegions& rightFlat, double gain,
                          double offset, double sigma, int dmin, int dmax, float candidate,
                          double reach);

// The plane of a sloped facet (fill_sloped_facet.cpp).

// The two views, when a plane's row ends are read to a fraction of a pixel from their edges.
struct EdgeViews {
  const cv::Mat& left;
  const cv::Mat& right;
};

// The plane of `region` (the mask of `box`) as a sloped facet (see oneSideAgrees in
// fill_sloped_facet.cpp), in `plane`; false when no counterpart's plane passes or `constant` wins
// over it. `oneSided`: only one side's row ends agree with it; `rowSpans`: the span of each row it
// fills (over `box`); `edgeViews`: the row ends read from the edges (all optional).
bool slopedFacetPlane(const cv::Mat& region, const cv::Rect& box, const RightFlatRegions& right,
                      double leftMean, double gain, double offset, double sigma, int dmin, int dmax,
                      const RegionFillSettings& settings, const std::optional<float>& constant,
                      FillPlane& plane, bool* oneSided = nullptr,
                      std::vector<cv::Vec2i>* rowSpans = nullptr,
                      const EdgeViews* edgeViews = nullptr);

// The decision on each flat region and its fill (fill_region_decision.cpp).

// A region filled by the fill, which it extends over the unmatched pixels beside it.
struct FilledRegion {
  cv::Rect box;
  cv::Mat grown;
  FillPlane plane;
};

// What the decisions on the flat regions share (see fillRegions in match_fill.cpp): the views and
// settings, the maps they write, the left view's flat regions and the grey maps of the right view
// to the left.
struct RegionFillShared {
  const cv::Mat& left;
  const cv::Mat& right;
  const RegionFillSettings& settings;
  int dmin, dmax;
  float fillScore;
  cv::Mat& disparity;
  cv::Mat& score;
  const std::function<const RightFlatRegions&()>& rightFlatRegionsOf;  // (see fillRegions)
  double sigma;  // the left view's noise sigma (flatMask)
  // The flat regions (componentsWithStats), and the same without their thin parts (empty
  // without coreOpening).
  const cv::Mat& labels;
  const cv::Mat& stats;
  const cv::Mat& centroids;
  const cv::Mat& flatCores;
  double leftMedian;                  // the left view's median grey (0 without shadowOwnLight)
  double gain, offset;                // the images' grey map
  double matchedGain, matchedOffset;  // the matched pairs' grey map
  std::pair<double, double> imagesMap, matchesMap;
};

// The decision on flat region `label` (`box`: its bounding box grown by 4 px, within the image)
// and its fill (see RegionDecision): the region filled, none when it is left alone; `filled`
// counts the pixels written.
std::optional<FilledRegion> decideAndFillRegion(const RegionFillShared& shared, int label,
                                                const cv::Rect& box, int& filled);

// The fill extended over the unmatched pixels beside a filled region (fill_extension.cpp): from
// its filled pixels (`grown`, over `box`), over those whose window matches at `plane` on its
// own; the pixels filled.
int extendOverUnmatched(const cv::Mat& left, const cv::Mat& right, const cv::Rect& box,
                        const cv::Mat& grown, const FillPlane& plane, double gain, double offset,
                        double sigma, int dmin, int dmax, const RegionFillSettings& settings,
                        float fillScore, const cv::Mat& labels, const std::vector<uchar>& ownFill,
                        cv::Mat& disparity, cv::Mat& score);

}  // namespace delineo::stereo::detail
