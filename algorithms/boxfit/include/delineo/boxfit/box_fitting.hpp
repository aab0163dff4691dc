#pragma once
// Box-fitting (Sirmacek, d'Angelo, Reinartz): a building's outline as the merged union of
// rectangles. The DEM gives the building segment (local thresholding), its skeleton gives the
// seeds, each seed grows a box onto the left image's Canny edges over a sweep of orientations
// (energy: mean distance of the box sides to the nearest edge, plus their disagreement with the
// segment), the boxes are merged and the
// merged border is refined into straight lines. docs/boxfit.md explains each stage.
//
// No GUI interaction here: the CLI (`delineo-cli boxfit`) and, through delineo::project, the
// GUI's job runner and `delineo-cli run` call these functions. Coordinates are left-image pixels (x right, y down, pixel (i, j)
// covers [i, i+1) x [j, j+1)).
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/boxfit/params.hpp"
#include "delineo/core/geometry.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::boxfit {

// A fitted box: a rectangle of `length` x `width` px centred at `centre`, its length along
// `angleDeg` (degrees from the x axis, towards y, in [0, 90)).
struct Box {
  cv::Point2d centre;
  double length = 0.0;
  double width = 0.0;
  double angleDeg = 0.0;
  double energy = 0.0;  // px: mean cost of its sides (edge distance capped at edge-cap, plus
                        // segment-weight x edge-cap where the segment disagrees with a side)
  cv::Point2d seed;     // the skeleton seed it grew from
  core::Ring corners() const;  // four corners, counter-clockwise on screen
  // The part of the box inside an image of `size` (a box may reach past the border of an image
  // that cuts the building): its corners clipped to [0, width] x [0, height]; empty when none.
  core::Ring cornersWithin(cv::Size size) const;
  double area() const { return length * width; }
};

// What each stage found, for display and benchmarks.
struct BoxFitDiagnostics {
  // Segment.
  double groundHeight = 0.0;  // median local ground in the ROI (m)
  double roofHeight = 0.0;    // roof height above the local ground used for the threshold (m)
  double threshold = 0.0;     // local threshold above the ground (m)
  cv::Mat aboveGround;        // CV_32F, ROI size: heights above the local ground (m)
  int segmentArea = 0;        // px
  cv::Mat segment;            // CV_8U, ROI size, 255 on the building segment
  // Seeds.
  int skeletonPixels = 0;
  int junctions = 0;
  std::vector<cv::Point2d> seeds;  // pixel centres, left-image coordinates
  // Boxes.
  int seedsFitted = 0;        // seeds that grew a box
  int seedsSkipped = 0;       // seeds inside an earlier box (skip-covered)
  int anglesEvaluated = 0;    // rotated frames built
  double mainOrientationDeg = 0.0;  // the building's main orientation, [0, 90)
  int boxesAtMainOrientation = 0;
  // Outline.
  int mergedArea = 0;         // px, union of the boxes after the closing
  int vertices = 0;           // of the outline, holes included
  // CPU time of each stage, ms.
  double segmentMs = 0.0, seedsMs = 0.0, boxesMs = 0.0, outlineMs = 0.0;
};

struct BoxFitBuilding {
  core::Polygon outline;    // left-image pixels, holes for courtyards
  // The boxes the outline is made of: those another box (or several) covers to within
  // 5 % of their area are left out, as are dropped ones.
  std::vector<Box> boxes;
  double energy = 0.0;      // area-weighted mean energy of the boxes (px)
  cv::Rect roi;             // where it was computed
  BoxFitDiagnostics diagnostics;
};

struct BoxFitRequest {
  // The operator's rough polygon or rectangle around one building (left-image pixels). Empty
  // outer ring: every building segment of the image.
  core::Polygon init;
  // Roof height above the ground (m, e.g. from the operator's roof disparity interval); estimated
  // from the DEM inside the init when unset. Ignored without an init.
  std::optional<double> roofHeight;
};

struct BoxFitResult {
  std::vector<BoxFitBuilding> buildings;  // one at most with an init
  // Why no building came out when `buildings` is empty ("no finite height in the region", "no
  // segment above 2.0 m", ...); empty otherwise.
  std::string message;
  core::RunStatus status = core::RunStatus::Completed;
};

// Box-fitting on `heights` (CV_32F metres in left-image geometry, NaN = no value) and `image`
// (the left image, one channel, CV_8U or CV_32F, same size). Throws core::Error:
// InvalidParameter for empty inputs, an init outside the image or with fewer than 3 vertices,
// or invalid parameters; MismatchedInputs when the sizes differ; UnsupportedInput for
// multi-channel inputs. A DEM without data or without buildings is no error: the result is
// empty with a message. Cancel returns status Canceled with the buildings finished so far.
BoxFitResult fitBoxes(const cv::Mat& heights, const cv::Mat& image, const BoxFitRequest& request,
                      const BoxFitParams& params = {}, core::Progress* progress = nullptr);

// Heights (m) from a disparity map in left-image geometry:
// (d - groundDisparity) * metresPerPixel, NaN kept.
cv::Mat heightsFromDisparity(const cv::Mat& disparity, double groundDisparity,
                             double metresPerPixel);

}  // namespace delineo::boxfit
