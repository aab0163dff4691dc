#pragma once
// Heights from disparity and the DEM's elevation gaps (docs/dem.md).
//
// Heights follow the linear model of an epipolar pair over a small area:
//   height = referenceHeight + (disparity - groundDisparity) * metresPerPixel
// in left-image geometry (one height per left-image pixel, NaN = no data). The DEM keeps the
// disparity map's grid, so the caller keeps its georeferencing.
//
// Elevation gaps (after Baillard and Maître): each connected no-data area is a gap; the heights
// along its border tell what it is. A low spread means the gap lies inside one surface (a roof
// or the ground the matcher left unmatched): it is merged into that surface, its pixels
// interpolated from the border. A high spread means a hidden part at a height discontinuity (an
// occlusion beside a wall): the gap is kept as no data. An optional fill then interpolates the
// kept gaps too, from the lower side of their border (what an occlusion hides is the ground or
// the lower roof), for display and export. No GUI interaction here: the CLI and the GUI call
// the same functions, and the ground/above-ground segmentation builds on the gap list.
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::dem {

// The linear relation between disparity and height.
struct HeightModel {
  double metresPerPixel = 1.0;   // m of height per px of disparity (non-zero)
  double groundDisparity = 0.0;  // px, disparity at the reference height
  double referenceHeight = 0.0;  // m, height at the ground disparity

  double heightAt(double disparity) const {
    return referenceHeight + (disparity - groundDisparity) * metresPerPixel;
  }
  double disparityAt(double height) const {
    return groundDisparity + (height - referenceHeight) / metresPerPixel;
  }

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"metres-per-pixel", "Metres per pixel", "m/px",
                "Metres of height per pixel of disparity", -1e6, 1e6},
      metresPerPixel);
    v(ParamInfo{"ground-disparity", "Ground disparity", "px",
                "Disparity at the reference height", -1e6, 1e6},
      groundDisparity);
    v(ParamInfo{"reference-height", "Reference height", "m",
                "Height at the ground disparity", -1e6, 1e6},
      referenceHeight);
  }
  // Throws core::Error(InvalidParameter): a field outside its domain or zero metres per pixel.
  void validate() const;
};

struct GapParams {
  double maxBorderSpread = 1.0;  // m, standard deviation of a gap's border heights up to which
                                 // the gap is merged (paper: the region-growing threshold, 1 m)
  int minBorderPixels = 4;       // px, fewer border heights say too little: the gap is kept

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"max-border-spread", "Gap border spread", "m",
                "Standard deviation of a gap's border heights up to which the gap is filled from "
                "its border (paper: 1 m)",
                0, 1000},
      maxBorderSpread);
    v(ParamInfo{"min-border-pixels", "Gap border pixels", "px",
                "Fewest border heights from which a gap may be merged", 1, 1000000},
      minBorderPixels);
  }
  // Throws core::Error(InvalidParameter) for a field outside its domain.
  void validate() const;
};

// What one gap (a connected no-data area, 8-connected) is and what was done with it.
struct DemGap {
  int pixels = 0;
  int borderPixels = 0;  // heights 8-adjacent to the gap
  double borderMean = std::numeric_limits<double>::quiet_NaN();    // m
  double borderSpread = std::numeric_limits<double>::quiet_NaN();  // m, standard deviation
  bool merged = false;   // low spread: interpolated from its border
  bool filled = false;   // a kept gap that fillKeptGaps() interpolated
  bool touchesEdge = false;  // reaches the image border (its border heights are partial)
  cv::Rect box;          // its pixels' bounding box
};

struct GapResult {
  core::RunStatus status = core::RunStatus::Completed;
  cv::Mat dem;        // CV_32F heights, merged (and, with fill, kept) gaps interpolated
  cv::Mat gapLabels;  // CV_32S: 0 where the input had a height, i + 1 on the pixels of gaps[i]
  std::vector<DemGap> gaps;
  int mergedPixels = 0;  // no-data pixels interpolated because their gap was merged
  int keptPixels = 0;    // no-data pixels of kept gaps (still no data unless filled)
  int filledPixels = 0;  // pixels of kept gaps fillKeptGaps() interpolated
};

// Heights (CV_32F, metres) from a disparity map (CV_32F, one channel, px, NaN = no data);
// NaN stays NaN. Throws core::Error: InvalidParameter for a bad model, UnsupportedInput for an
// empty map or another type.
cv::Mat heightsFromDisparity(const cv::Mat& disparity, const HeightModel& model);
// The inverse: disparity (px) from heights (m), for estimates made in disparity on a DEM. Throws
// like heightsFromDisparity().
cv::Mat disparityFromHeights(const cv::Mat& heights, const HeightModel& model);

// Finds the gaps of `dem` (CV_32F, one channel, metres, NaN = no data) and merges or keeps each
// (see the top of this file). Throws core::Error: InvalidParameter for bad parameters,
// UnsupportedInput for an empty DEM, another type or infinite heights. A DEM without any height
// is one kept gap. Polls cancel once per band of rows and per gap; a cancel returns status
// Canceled and the input DEM.
GapResult handleGaps(const cv::Mat& dem, const GapParams& params, core::Progress* progress = nullptr);

// The optional fill for display and export: every kept gap of `result` (from handleGaps())
// interpolated from the lower side of its border (the lower of two clusters of its border
// heights: what an occlusion beside a wall hides is the ground or the lower roof). A gap without
// any border height stays no data.
void fillKeptGaps(GapResult& result);

// heightsFromDisparity(), handleGaps(), then fillKeptGaps() when `fill`: `delineo-cli dem`.
GapResult demFromDisparity(const cv::Mat& disparity, const HeightModel& model, const GapParams& params,
                           bool fill = false, core::Progress* progress = nullptr);

}  // namespace delineo::dem
