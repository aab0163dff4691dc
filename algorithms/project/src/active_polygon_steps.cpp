// The project's steps of the active polygon: a building delineated, an outline scored and an
// outline regularized, each with the building's roof interval and the project's parameters.
#include "delineo/core/error.hpp"
#include "delineo/delineation/delineate.hpp"
#include "delineo/project/pipeline.hpp"

namespace delineo::project {

namespace {

// The active polygon's request for a building of the project.
delineation::DelineationRequest requestFor(const Project& project, const Building& building,
                                           const StereoPair& pair) {
  if (!building.roofInterval) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "building " + std::to_string(building.id) + " has no roof disparity interval");
  }
  delineation::DelineationRequest request;
  request.init = building.initial;
  request.roof = {building.roofInterval->low, building.roofInterval->high};
  if (project.disparityRange) {
    request.searchRange = delineation::DisparityInterval{project.disparityRange->low, project.disparityRange->high};
  }
  request.excludeMask = pair.exclude;
  request.disparity = pair.disparity;
  return request;
}

}  // namespace

DelineationOutcome delineateBuilding(const Project& project, const Building& building,
                                     const StereoPair& pair, core::Progress* progress,
                                     const ContourListener& onContour) {
  const delineation::DelineationRequest request = requestFor(project, building, pair);
  const auto params = parameters<delineation::DelineationParams>(project, "delineation");
  // delineate() reports its contours in left-image pixels already, as the listener wants them.
  delineation::IterationObserver observer;
  if (onContour) {
    observer = [&onContour](const delineation::IterationReport& report) {
      onContour(delineation::toPolygon(report.polygon));
    };
  }
  const delineation::DelineationResult result =
      delineation::delineate(pair.left, pair.right, request, params, observer, progress);
  DelineationOutcome outcome;
  outcome.status = result.status;
  outcome.outline = result.polygon;
  outcome.energy = result.terms.total();
  outcome.terms = result.terms.term;
  outcome.iterations = result.iterations;
  outcome.rawOutline = result.rawPolygon;
  outcome.regularization = delineation::toString(result.regularization.status);
  outcome.regularizationNote = result.regularization.reason;
  return outcome;
}

EnergyOutcome outlineEnergy(const Project& project, const Building& building, const StereoPair& pair,
                            const core::Polygon& outline, core::Progress* progress) {
  const delineation::DelineationRequest request = requestFor(project, building, pair);
  const auto params = parameters<delineation::DelineationParams>(project, "delineation");
  const delineation::OutlineEnergy energy =
      delineation::evaluateOutline(pair.left, pair.right, request, params, outline, progress);
  EnergyOutcome outcome;
  outcome.status = energy.status;
  outcome.energy = energy.terms.total();
  outcome.terms = energy.terms.term;
  return outcome;
}

RegularizationOutcome regularizeOutline(const Project& project, const Building& building,
                                        const StereoPair& pair, const core::Polygon& outline,
                                        core::Progress* progress) {
  const delineation::DelineationRequest request = requestFor(project, building, pair);
  const auto params = parameters<delineation::DelineationParams>(project, "delineation");
  const delineation::RegularizationOutcome r = delineation::regularizeBuildingOutline(
      pair.left, pair.right, request, params, outline, progress);
  RegularizationOutcome outcome;
  outcome.outline = r.polygon;
  outcome.regularization = delineation::toString(r.status);
  outcome.regularizationNote = r.reason;
  outcome.verticesBefore = r.inputVertices;
  outcome.verticesAfter = r.outputVertices;
  outcome.energyChange = r.energyChange;
  return outcome;
}

}  // namespace delineo::project
