// MainWindow's commands on buildings: selecting one (from a view's outline or the list), adding
// one from a pick, editing its outline, accepting, rejecting, reopening and removing it.
#include <QAction>
#include <QItemSelectionModel>
#include <QTableView>

#include "buildings_model.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "main_window.hpp"

namespace delineo::gui {

using project::Building;
using project::BuildingStatus;
using widgets::ImageView;
using widgets::InteractionMode;

void MainWindow::selectBuilding(int id) {
  if (document_ && id > 0 && document_->project().find(id) == nullptr) id = -1;
  const bool changed = id != selectedId_;
  selectedId_ = id;
  updatingSelection_ = true;
  for (ImageView* v : {leftView_, rightView_, disparityView_, demView_}) v->polygons().setSelectedId(id);
  rightShift_ = roofDisparity(id).value_or(document_ ? document_->project().height.groundDisparity : 0.0);
  const int row = buildingsModel_->rowOf(id);
  if (row >= 0) buildingsTable_->selectRow(row);
  else buildingsTable_->clearSelection();
  updatingSelection_ = false;
  if (id > 0) {
    const cv::Rect2d box = core::boundingBox(document_->project().find(id)->currentPolygon().outer);
    leftView_->setViewCenter(QPointF(box.x + box.width / 2, box.y + box.height / 2));
  }
  syncRightView();
  if (changed) frame3D();
  refreshHistogram();
  refreshBoxFitProposals();
  updateActions();
  if (changed) emit selectedBuildingChanged(id);
}

void MainWindow::onSelectionFromOverlay(int id) {
  if (updatingSelection_ || id == selectedId_) return;
  selectBuilding(id);
}

void MainWindow::onSelectionFromTable() {
  if (updatingSelection_) return;
  const auto rows = buildingsTable_->selectionModel()->selectedRows();
  const int id = rows.isEmpty() ? -1 : buildingsModel_->idAt(rows.first().row());
  if (id != selectedId_) selectBuilding(id);
}

void MainWindow::onPicked(const core::Polygon& polygon) {
  if (!document_) return;
  if (polygon.outer.size() < 3 || core::area(polygon) < 16.0 || !core::isSimple(polygon.outer)) {
    showMessage(tr("Pick a building"), tr("The picked shape is too small or crosses itself; draw it again."));
    return;
  }
  const int id = document_->addBuilding(polygon);
  selectBuilding(id);
  leftView_->setInteractionMode(InteractionMode::Navigate);
  // The pick is the request: the project's method starts at once (the active polygon with the
  // proposed interval), or as soon as the disparity is there.
  if (action(QStringLiteral("actionDelineateOnPick"))->isChecked()) {
    if (document_->disparity().empty()) awaitingDisparity_ = id;
    else outlineBuilding(id);
  }
}

widgets::JobId MainWindow::outlineBuilding(int id) {
  if (!document_) return 0;
  const Building* b = document_->project().find(id);
  if (b != nullptr && document_->project().methodOf(*b) == project::kBoxFitting) return startBoxFitting(id);
  return startDelineation(id);
}

void MainWindow::onEditRequested(int id, int ringIndex, const QPolygonF& ring, const QString& description) {
  if (!document_) return;
  const core::Ring newRing = widgets::toRing(ring);
  if (!core::isSimple(newRing)) {
    showMessage(tr("Edit outline"), tr("That change would make the outline cross itself; it was not applied."));
    refreshOverlays();
    return;
  }
  document_->editRing(id, ringIndex, newRing, description);
}

void MainWindow::acceptSelected() {
  if (!document_ || selectedId_ <= 0) return;
  const Building* b = document_->project().find(selectedId_);
  if (b == nullptr || !b->hasOutline()) return;
  document_->setStatus(selectedId_, BuildingStatus::Accepted);
  advanceAfterDecision();
}

void MainWindow::rejectSelected() {
  if (!document_ || document_->project().find(selectedId_) == nullptr) return;
  document_->setStatus(selectedId_, BuildingStatus::Rejected);
  advanceAfterDecision();
}

void MainWindow::reopenSelected() {
  if (document_ && selectedId_ > 0) {
    const Building* b = document_->project().find(selectedId_);
    if (b) document_->setStatus(selectedId_, b->hasOutline() ? BuildingStatus::Corrected : BuildingStatus::Pending);
  }
}

void MainWindow::removeSelected() {
  if (document_ && selectedId_ > 0) {
    const int id = selectedId_;
    selectBuilding(-1);
    document_->removeBuilding(id);
  }
}

}  // namespace delineo::gui
