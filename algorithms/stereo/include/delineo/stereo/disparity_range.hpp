#pragma once
// Automatic disparity search range of an epipolar pair, for operators and batches that do not
// know it. docs/disparity-range.md describes each stage and its measured results.
//
// Method: keypoints and descriptors in both views (upright SIFT by default) on copies reduced
// to about max-pixels, spread over a grid; each left keypoint matched to the right keypoints on
// the same rows (within row-tolerance) with a ratio test and a mutual check; matches without
// `support` neighbours at a similar disparity dropped; plain regions (roofs without texture,
// which give no keypoint) paired by their shape on the same rows; then the low/high
// percentiles of d = x_left - x_right, each match weighted so that every grid cell counts
// alike, widened by a margin (more above: the tall structures are the rarer ones).
//
// Use: the result's [dmin, dmax] is the range to give matchStereo (MatchParams::dmin/dmax) or
// delineation (DelineationRequest::searchRange) when the operator does not know it.
//
//   stereo::RangeEstimate r = stereo::estimateDisparityRange(left, right, {}, &progress);
//   if (r.status == core::RunStatus::Completed) { params.dmin = r.dmin; params.dmax = r.dmax; }
//
// It throws core::Error(ProcessingFailed) when it cannot tell (blank views, too few matches):
// the range must then be given by hand. Conventions as in match.hpp: left = reference,
// x_right = x_left - d, NaN = no data. No Qt; about 0.5 s of CPU for a 1 Mpx pair.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::stereo {

struct RangeEstimateParams {
  std::string detector = "sift";  // sift | akaze | orb
  int maxPixels = 300000;         // px, images larger than this are detected on a copy reduced
                                  // to about this many pixels
  int features = 6000;            // keypoints kept per view, spread over a grid of cells
  int grid = 16;                  // cells per image side (keypoint spreading and weighting)
  double ratio = 0.8;             // Lowe's ratio: best / second-best descriptor distance
  bool mutualCheck = true;        // keep a match only when it is also the right keypoint's best
  double rowTolerance = 2.0;      // px, largest |y_left - y_right| (at least one pixel of the
                                  // detection copy)
  double supportRadius = 5.7;     // % of the image diagonal, neighbourhood of the support check
  double supportTolerance = 2.0;  // px, disparity difference of a supporting neighbour (at
                                  // least one pixel of the detection copy)
  int support = 2;                // other matches needed in that neighbourhood (0 = off)
  double lowPercentile = 0.5;     // %, of the weighted match disparities: the range's low end
  double highPercentile = 99.5;   // %, its high end
  double margin = 2.0;            // px, added below the low end and above the high end
  double lowMarginFraction = 0.05;  // of (high - low), also added below the low end
  double highMarginFraction = 0.2;  // of (high - low), also added above the high end
  bool plainRegions = true;       // also pair plain regions (textureless roofs) by their shape
  double plainRegionArea = 0.2;   // %, of the image: smallest plain region paired
  int minMatches = 20;            // fewer matches (after the checks) is an error

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"detector", "Detector", "", "Keypoints and descriptors: SIFT, AKAZE or ORB", 0,
                0, "sift|akaze|orb"},
      detector);
    v(ParamInfo{"max-pixels", "Detection size", "px",
                "Larger images are detected on a reduced copy of about this many pixels", 10000,
                100000000},
      maxPixels);
    v(ParamInfo{"features", "Keypoints", "", "Keypoints kept per view, spread over the grid",
                50, 1000000},
      features);
    v(ParamInfo{"grid", "Grid", "", "Cells per image side over which keypoints are spread", 1,
                256},
      grid);
    v(ParamInfo{"ratio", "Ratio test", "",
                "A match is kept when its descriptor distance is below this times the "
                "second-best one on the same rows",
                0.1, 1},
      ratio);
    v(ParamInfo{"mutual-check", "Mutual check", "",
                "Keep a match only when the left keypoint is also the right keypoint's best"},
      mutualCheck);
    v(ParamInfo{"row-tolerance", "Row tolerance", "px",
                "Largest row difference between matched keypoints (epipolar pair)", 0, 100},
      rowTolerance);
    v(ParamInfo{"support-radius", "Support radius", "%",
                "Neighbourhood in which a match needs support from others, in % of the image "
                "diagonal",
                0.1, 100},
      supportRadius);
    v(ParamInfo{"support-tolerance", "Support tolerance", "px",
                "Largest disparity difference of a supporting match", 0, 1000},
      supportTolerance);
    v(ParamInfo{"support", "Support", "",
                "Other matches at a similar disparity needed nearby, 0 = off", 0, 100},
      support);
    v(ParamInfo{"low-percentile", "Low percentile", "%",
                "Percentile of the match disparities taken as the range's low end", 0, 50},
      lowPercentile);
    v(ParamInfo{"high-percentile", "High percentile", "%",
                "Percentile of the match disparities taken as the range's high end", 50, 100},
      highPercentile);
    v(ParamInfo{"margin", "Margin", "px", "Added below the low end and above the high end", 0,
                10000},
      margin);
    v(ParamInfo{"low-margin-fraction", "Relative margin below", "",
                "Fraction of the percentiles' span also added below the low end", 0, 10},
      lowMarginFraction);
    v(ParamInfo{"high-margin-fraction", "Relative margin above", "",
                "Fraction of the percentiles' span also added above the high end", 0, 10},
      highMarginFraction);
    v(ParamInfo{"plain-regions", "Plain regions", "",
                "Also pair regions without texture (plain roofs, which give no keypoint) between "
                "the views by their shape on the same rows"},
      plainRegions);
    v(ParamInfo{"plain-region-area", "Plain region area", "%",
                "Smallest plain region paired, in % of the image", 0.01, 100},
      plainRegionArea);
    v(ParamInfo{"min-matches", "Minimal matches", "",
                "Fewer matches after the checks is an error", 1, 1000000},
      minMatches);
  }
  void validate() const;
};

struct RangeEstimate {
  int dmin = 0;             // px, low end of the range to search (x_right = x_left - d)
  int dmax = 0;             // px, high end (inclusive)
  int matches = 0;          // matches the percentiles were taken over (with the samples of
                            // paired plain regions)
  int plainRegionSamples = 0;  // of those, samples of paired plain regions (one per grid cell)
  int keypointsLeft = 0;    // keypoints kept in each view
  int keypointsRight = 0;
  double low = 0;           // px, the low-percentile disparity of the matches (before margin)
  double high = 0;          // px, the high-percentile disparity
  double median = 0;        // px, the weighted median disparity
  double scale = 1;         // detection image size / full size (1 = full resolution)
  std::vector<cv::Point3f> points;  // the matches used: (x_left, y_left, d), full-resolution px
  core::RunStatus status = core::RunStatus::Completed;  // Canceled: the fields above are unset
};

// left/right: single-channel float32 of the same size, NaN = no data (as io::readGreyFloat
// gives them). Throws core::Error: InvalidParameter (bad parameters), UnsupportedInput (empty or
// not float32), MismatchedInputs (sizes), ProcessingFailed (blank images, or fewer than
// min-matches matches: the range must then be given by hand). Returns status Canceled when
// `progress` is canceled. Deterministic: the same inputs give the same range.
RangeEstimate estimateDisparityRange(const cv::Mat& left, const cv::Mat& right,
                                     const RangeEstimateParams& params = {},
                                     core::Progress* progress = nullptr);

}  // namespace delineo::stereo
