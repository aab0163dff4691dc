// The project's steps that work on heights: box-fitting of one building and the enhancement of
// the DEM with the buildings' outlines.
#include <cstdio>
#include <string>
#include <vector>

#include "delineo/boxfit/box_fitting.hpp"
#include "delineo/core/error.hpp"
#include "delineo/dem/enhance.hpp"
#include "delineo/project/pipeline.hpp"

namespace delineo::project {

using core::Error;
using core::ErrorCode;

cv::Mat projectHeights(const Project& project, const cv::Mat& disparity) {
  if (!project.dem.empty()) {
    io::ReadOptions options;
    options.type = io::PixelType::Float32;
    options.toGrey = true;
    return io::readRaster(project.dem, options).data;
  }
  if (disparity.empty() || !project.height.known()) return {};
  return (disparity - project.height.groundDisparity) * project.height.metresPerPixel;
}

BoxFitOutcome fitBuildingBoxes(const Project& project, const Building& building, const cv::Mat& heights,
                               const cv::Mat& left, core::Progress* progress) {
  if (heights.empty()) {
    throw Error(ErrorCode::InvalidParameter,
                "box-fitting needs heights: a DEM, or the disparity and the height model");
  }
  const auto params = parameters<boxfit::BoxFitParams>(project, "boxfit");
  params.validate();
  boxfit::BoxFitRequest request;
  request.init = building.initial;
  const boxfit::BoxFitResult result = boxfit::fitBoxes(heights, left, request, params, progress);
  BoxFitOutcome outcome;
  outcome.status = result.status;
  outcome.message = result.message;
  if (!result.buildings.empty()) {
    const boxfit::BoxFitBuilding& fitted = result.buildings.front();
    outcome.outline = fitted.outline;
    outcome.energy = fitted.energy;
    for (const boxfit::Box& box : fitted.boxes) {
      core::Ring corners = box.cornersWithin(heights.size());
      if (!corners.empty()) outcome.boxes.push_back({std::move(corners), box.energy});
    }
  }
  return outcome;
}

Building withBoxFitOutline(const Project& project, const Building& building, const BoxFitOutcome& outcome,
                           const cv::Mat& disparity, const std::string& origin) {
  Building after = building;
  after.outline = outcome.outline;
  after.status = BuildingStatus::Automatic;
  after.method = kBoxFitting;
  after.energy = std::nan("");
  after.energyTerms.reset();
  after.roofHeight = roofHeight(project, disparity, after.outline);
  size_t vertices = after.outline.outer.size();
  for (const auto& hole : after.outline.holes) vertices += hole.size();
  char energy[32];
  std::snprintf(energy, sizeof energy, "%.2f", outcome.energy);
  std::string detail = origin.empty() ? std::string() : origin + ", ";
  detail += std::string(kBoxFitting) + ", " + std::to_string(outcome.boxes.size()) + " boxes, energy " + energy +
            " px, " + std::to_string(vertices) + " vertices";
  after.addHistory("delineated", detail);
  return after;
}

EnhancedDemOutcome enhanceHeights(const Project& project, const cv::Mat& heights, core::Progress* progress) {
  std::vector<core::Polygon> footprints;
  for (const Building& b : project.buildings) {
    if (b.hasOutline() && b.status != BuildingStatus::Rejected) footprints.push_back(b.outline);
  }
  EnhancedDemOutcome outcome;
  outcome.footprints = static_cast<int>(footprints.size());
  if (footprints.empty()) {
    outcome.dem = heights;
    return outcome;
  }
  const auto params = parameters<dem::EnhanceParams>(project, "enhance");
  params.validate();
  if (progress != nullptr) progress->setStage(core::StageId::EnhancingDem);
  dem::EnhanceResult result = dem::enhanceDem(heights, footprints, params, progress);
  outcome.dem = result.dem;
  outcome.status = result.status;
  return outcome;
}

}  // namespace delineo::project
