#include "delineo/widgets/stage_text.hpp"

#include <QCoreApplication>

namespace delineo::widgets {
QString stageText(const core::Stage& stage) {
  using core::StageId;
  const int n = stage.number, count = stage.count;
  switch (stage.id) {
    case StageId::Text:
      return QString::fromStdString(stage.text);
    case StageId::PreparingPyramids:
      return QCoreApplication::translate("Stages", "preparing pyramids and edges");
    case StageId::MatchingLevel:
      return QCoreApplication::translate("Stages", "matching level %1/%2").arg(n).arg(count);
    case StageId::MatchingLevelRightView:
      return QCoreApplication::translate("Stages", "matching level %1/%2, right view")
          .arg(n)
          .arg(count);
    case StageId::ValidatingLevel:
      return QCoreApplication::translate("Stages", "validating level %1/%2").arg(n).arg(count);
    case StageId::RefiningDepthSteps:
      return QCoreApplication::translate("Stages", "refining depth steps, level %1/%2")
          .arg(n)
          .arg(count);
    case StageId::FillingFlatRegions:
      return QCoreApplication::translate("Stages", "filling flat regions");
    case StageId::RemovingSpeckles:
      return QCoreApplication::translate("Stages", "removing speckles");
    case StageId::SnappingDepthSteps:
      return QCoreApplication::translate("Stages", "snapping depth steps to contours");
    case StageId::RemovingSnappingSpeckles:
      return QCoreApplication::translate("Stages", "removing speckles left by the snapping");
    case StageId::MatchingSgbm:
      return QCoreApplication::translate("Stages", "matching (SGBM)");
    case StageId::SimulatingLayout:
      return QCoreApplication::translate("Stages", "simulating: layout");
    case StageId::SimulatingRendering:
      return QCoreApplication::translate("Stages", "simulating: rendering");
    case StageId::SimulatingRadiometry:
      return QCoreApplication::translate("Stages", "simulating: radiometry");
    case StageId::CorrelationCosts:
      return QCoreApplication::translate("Stages", "correlation costs");
    case StageId::ActivePolygon:
      return QCoreApplication::translate("Stages", "active polygon");
    case StageId::PolygonMoves:
      return QCoreApplication::translate("Stages", "active polygon: moves");
    case StageId::PolygonDeletions:
      return QCoreApplication::translate("Stages", "active polygon: deletions");
    case StageId::PolygonInsertion:
      return QCoreApplication::translate("Stages", "active polygon: insertion");
    case StageId::PolygonNotch:
      return QCoreApplication::translate("Stages", "active polygon: notch");
    case StageId::PolygonCourtyard:
      return QCoreApplication::translate("Stages", "active polygon: courtyard");
    case StageId::DenseMatching:
      return QCoreApplication::translate("Stages", "dense matching");
    case StageId::DelineatingBuilding:
      return QCoreApplication::translate("Stages", "delineating building %1").arg(n);
  }
  return QString::fromStdString(stage.english());
}

}  // namespace delineo::widgets
