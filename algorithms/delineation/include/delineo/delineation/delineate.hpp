#pragma once
// Building delineation on an epipolar pair: builds the energy images from the correlation cost
// service and runs the statistical active polygon. Coordinates are left-image pixels.
#include <optional>
#include <utility>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/progress.hpp"
#include "delineo/delineation/active_polygon.hpp"
#include "delineo/delineation/params.hpp"
#include "delineo/delineation/regularize.hpp"

namespace delineo::stereo {
class CorrelationCostService;
}

namespace delineo::delineation {

struct DisparityInterval {
  int min = 0;
  int max = 0;  // inclusive
};

struct DelineationRequest {
  // Initial contour: the operator's polygon or rectangle. Ignored when `initMask` is set.
  core::Polygon init;
  // Alternative init: CV_8U mask of the left image, non-zero on an above-ground region; its
  // largest connected component is used.
  cv::Mat initMask;
  DisparityInterval roof;                     // Δd_b, required
  std::optional<DisparityInterval> ground;    // Δd_g; estimated around the init when unset
  std::optional<DisparityInterval> searchRange;  // full search range, when the caller knows it
  // Optional CV_8U mask of the left image's size, non-zero where a pixel is known not to belong
  // to the roof (vegetation from a classification or a near-infrared band, a neighbour's roof
  // painted by the operator). Such pixels cost as much as possible inside the outline and no
  // more than the occlusion band outside it: trees at roof height match the roof interval as
  // well as a roof does, and the correlation costs alone cannot keep them out.
  cv::Mat excludeMask;
  // Optional CV_32F of the left image's size: the matcher's disparity map (NaN = unmatched). Where
  // it has a value, c_roof and c_ground come from it (`map-cost`), and the ground interval, when
  // not given, is estimateGroundLevel() on it; empty = the correlation costs alone.
  cv::Mat disparity;
};

// The energy inputs of one building, in ROI coordinates, plus what was derived on the way.
struct PreparedEnergy {
  cv::Rect roi;
  EnergyImages images;
  IntPolygon init;              // ROI coordinates (the region-stage outline when regionInit)
  bool regionInit = false;      // the region stage's outline had the lower energy
  DisparityInterval ground;     // given or estimated
  double groundDisparity = 0;   // representative ground level used for the occlusion band
  double roofDisparity = 0;     // median roof disparity near the initial contour
  // Intervals the costs c_roof and c_ground were taken over (balanced, see balanceIntervals).
  DisparityInterval roofSearched, groundSearched;
  // CV_8U, ROI size: pixels kept out of the roof (the request's exclusion mask and the pixels
  // seen at an intermediate height, see intermediateMargin); 255 = excluded.
  cv::Mat excluded;
};

// The intervals over which c_roof and c_ground are computed. With `balance`, the narrower one is
// extended, on the side away from the other, to as many disparities as the wider one: the minimum
// of Crit over more disparities is lower on textureless pixels (noise), which would otherwise
// make a textureless roof look like ground (or the reverse).
std::pair<DisparityInterval, DisparityInterval> costIntervals(const DisparityInterval& roof,
                                                              const DisparityInterval& ground,
                                                              bool balance);

struct DelineationResult {
  core::Polygon polygon;  // left-image coordinates: the regularized outline when it passed the gate
  EnergyTerms terms;      // of `polygon` (vertices rounded to the pixel grid when regularized)
  int iterations = 0;
  int vertexCount = 0;    // of `polygon`
  core::Polygon rawPolygon;  // the active polygon's own outline, before regularization
  // The last stage: regularized, kept raw (and why) or off. Its polygon is `polygon`.
  RegularizationOutcome regularization;
  core::RunStatus status = core::RunStatus::Completed;
  cv::Rect roi;
  DisparityInterval roof, ground;
  double noMatchCost = 0;
};

// Checks the request against the images; throws core::Error(InvalidParameter) for an empty or
// inverted interval, a roof interval outside the search range, an init outside the image or a
// degenerate init, and MismatchedInputs for images of different sizes.
cv::Rect regionOfInterest(const cv::Mat& left, const cv::Mat& right,
                          const DelineationRequest& request, const DelineationParams& params);

// Builds c_roof, c_ground, NoMatchCost, the occlusion widths and the gradient images from a
// cost service covering `roi` (left and right: single-channel images of one size).
PreparedEnergy prepareEnergy(const stereo::CorrelationCostService& costs, const cv::Mat& left,
                             const cv::Mat& right, const DelineationRequest& request,
                             const DelineationParams& params);

// The whole pipeline for one building. Cancel returns the best polygon so far (status Canceled).
DelineationResult delineate(const cv::Mat& left, const cv::Mat& right,
                            const DelineationRequest& request, const DelineationParams& params,
                            const IterationObserver& observer = {},
                            core::Progress* progress = nullptr);

// The energy F(C) of a given outline (left-image pixels: an operator's edit, an imported or a
// regularised outline) with the same costs, weights and region of interest as delineate() would
// use for `request`; vertices are rounded to the pixel grid. Throws InvalidParameter when the
// rounded outline is not a valid polygon. Cancel returns status Canceled and no terms.
struct OutlineEnergy {
  EnergyTerms terms;
  core::RunStatus status = core::RunStatus::Completed;
};
OutlineEnergy evaluateOutline(const cv::Mat& left, const cv::Mat& right, const DelineationRequest& request,
                              const DelineationParams& params, const core::Polygon& outline,
                              core::Progress* progress = nullptr);

// The regularization stage of delineate() on any outline of the building of `request` (an
// operator's edit, a box-fitting outline): regularizeOutline() with params.regularization, then
// the energy gate: the regularized outline's F(C), on the same costs as delineate() would use,
// may exceed the input's by at most regularize-energy-margin per px of the input's length. The
// tolerance is tried whole, then halved twice; the first result that passes both gates is kept,
// else the input (status KeptRaw, with the reason the whole tolerance failed). Throws like
// evaluateOutline(); cancel returns the input with status Off.
RegularizationOutcome regularizeBuildingOutline(const cv::Mat& left, const cv::Mat& right,
                                                const DelineationRequest& request, const DelineationParams& params,
                                                const core::Polygon& outline, core::Progress* progress = nullptr);

}  // namespace delineo::delineation
