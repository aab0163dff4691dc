#include "delineation_bridge.hpp"

#include "delineo/core/error.hpp"
#include "delineo/delineation/delineate.hpp"

namespace delineo::project {

DelineationOutcome runActivePolygon(const Project& project, const Building& building,
                                    const StereoPair& pair, core::Progress* progress,
                                    const ContourListener& onContour) {
  if (!building.roofInterval) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "building " + std::to_string(building.id) + " has no roof disparity interval");
  }
  const auto params = parameters<delineation::DelineationParams>(project, "delineation");
  delineation::DelineationRequest request;
  request.init = building.initial;
  request.roof = {building.roofInterval->low, building.roofInterval->high};
  request.searchRange = delineation::DisparityInterval{project.disparityMin, project.disparityMax};
  request.excludeMask = pair.exclude;
  // The optimiser reports ROI coordinates; the listener wants left-image pixels.
  const cv::Rect roi = delineation::regionOfInterest(pair.left, pair.right, request, params);
  delineation::IterationObserver observer;
  if (onContour) {
    observer = [&onContour, roi](const delineation::IterationReport& report) {
      onContour(delineation::toPolygon(report.polygon, cv::Point2d(roi.x, roi.y)));
    };
  }
  const delineation::DelineationResult result =
      delineation::delineate(pair.left, pair.right, request, params, observer, progress);
  DelineationOutcome outcome;
  outcome.status = result.status;
  outcome.outline = result.polygon;
  outcome.energy = result.terms.total();
  outcome.iterations = result.iterations;
  return outcome;
}

}  // namespace delineo::project
