#include "delineo/core/progress.hpp"

#include <algorithm>

namespace delineo::core {

void Progress::report(double fraction) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  double prev = fraction_.load();
  while (fraction > prev && !fraction_.compare_exchange_weak(prev, fraction)) {
  }
  const int n = reports_.fetch_add(1) + 1;
  const int limit = cancelAfter_.load();
  if (limit >= 0 && n >= limit) cancel();
  if (listener_) listener_(fraction_.load(), stage());
}

std::string Stage::english() const {
  const std::string level = "level " + std::to_string(number) + "/" + std::to_string(count);
  switch (id) {
    case StageId::Text: return text;
    case StageId::PreparingPyramids: return "preparing pyramids and edges";
    case StageId::MatchingLevel: return "matching " + level;
    case StageId::MatchingLevelRightView: return "matching " + level + ", right view";
    case StageId::ValidatingLevel: return "validating " + level;
    case StageId::RefiningDepthSteps: return "refining depth steps, " + level;
    case StageId::FillingFlatRegions: return "filling flat regions";
    case StageId::RemovingSpeckles: return "removing speckles";
    case StageId::SnappingDepthSteps: return "snapping depth steps to contours";
    case StageId::RemovingSnappingSpeckles: return "removing speckles left by the snapping";
    case StageId::FittingRoofPlanes: return "fitting roof planes";
    case StageId::MatchingSgbm: return "matching (SGBM)";
    case StageId::SimulatingLayout: return "simulate: layout";
    case StageId::SimulatingRendering: return "simulate: rendering";
    case StageId::SimulatingRadiometry: return "simulate: radiometry";
    case StageId::CorrelationCosts: return "correlation costs";
    case StageId::ActivePolygon: return "active polygon";
    case StageId::PolygonMoves: return "moves";
    case StageId::PolygonDeletions: return "deletions";
    case StageId::PolygonInsertion: return "insertion";
    case StageId::PolygonNotch: return "notch";
    case StageId::PolygonCourtyard: return "courtyard";
    case StageId::DenseMatching: return "matching";
    case StageId::DelineatingBuilding: return "building " + std::to_string(number);
    case StageId::BoxFitSegment: return "box-fitting: building segment";
    case StageId::BoxFitBoxes: return "box-fitting: boxes";
    case StageId::BoxFitOutline: return "box-fitting: outline";
    case StageId::BoxFittingBuilding: return "box-fitting building " + std::to_string(number);
    case StageId::EnhancingDem: return "enhancing the DEM";
    case StageId::SegmentingGround: return "ground and terrain model";
    case StageId::DetectingObjects: return "buildings, vegetation and objects";
  }
  return text;
}

void Progress::setStage(const Stage& stage) {
  std::lock_guard lock(stageMutex_);
  stage_ = stage;
}

Stage Progress::stageInfo() const {
  std::lock_guard lock(stageMutex_);
  return stage_;
}

Progress::Range::Range(Progress* parent, double begin, double end)
    : parent_(parent), begin_(std::clamp(begin, 0.0, 1.0)), end_(std::clamp(end, begin, 1.0)) {}

void Progress::Range::report(double fraction) {
  Progress::report(fraction);
  if (parent_ != nullptr) parent_->report(begin_ + (end_ - begin_) * std::clamp(fraction, 0.0, 1.0));
}

void Progress::Range::setStage(const Stage& stage) {
  Progress::setStage(stage);
  if (parent_ != nullptr) parent_->setStage(stage);
}

void Progress::Range::cancel() noexcept {
  Progress::cancel();
  if (parent_ != nullptr) parent_->cancel();
}

bool Progress::Range::canceled() const noexcept {
  return Progress::canceled() || (parent_ != nullptr && parent_->canceled());
}

}  // namespace delineo::core
