// MainWindow's commands on buildings: selecting one (from a view's outline or the list), adding
// one from a pick, editing its outline, accepting, rejecting, reopening and removing it.
#include <QAction>
#include <QItemSelectionModel>
#include <QTableView>
#include <algorithm>

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
  selectListRow(buildingsModel_->rowOf(id));
  listSelection_.clear();
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

// A row added to the list's selection (Ctrl+click) leaves the selected building as it is: Merge
// buildings merges the other one into it.
void MainWindow::onSelectionFromTable() {
  if (updatingSelection_) return;
  const std::vector<int> ids = selectedRowIds();
  const bool kept = std::find(ids.begin(), ids.end(), selectedId_) != ids.end();
  const int id = kept ? selectedId_ : ids.empty() ? -1 : ids.front();
  if (id != selectedId_) {
    selectBuilding(id);
    return;
  }
  listSelection_ = ids;
  updateActions();
}

void MainWindow::selectListRow(int row) {
  if (row < 0) {
    buildingsTable_->clearSelection();
    return;
  }
  // Not QTableView::selectRow: with extended selection it extends from the last row while Shift
  // is down (Shift+N).
  buildingsTable_->selectionModel()->setCurrentIndex(buildingsModel_->index(row, 0),
                                                     QItemSelectionModel::ClearAndSelect | QItemSelectionModel::Rows);
}

// After a model reset: the selected building's row, and the rows selected with it that remain.
void MainWindow::restoreListSelection() {
  updatingSelection_ = true;
  selectListRow(buildingsModel_->rowOf(selectedId_));
  for (int id : listSelection_) {
    const int row = buildingsModel_->rowOf(id);
    if (selectedId_ <= 0 || id == selectedId_ || row < 0) continue;
    buildingsTable_->selectionModel()->select(buildingsModel_->index(row, 0),
                                              QItemSelectionModel::Select | QItemSelectionModel::Rows);
  }
  updatingSelection_ = false;
}

std::vector<int> MainWindow::selectedRowIds() const {
  std::vector<int> ids;
  for (const QModelIndex& row : buildingsTable_->selectionModel()->selectedRows()) {
    ids.push_back(buildingsModel_->idAt(row.row()));
  }
  std::sort(ids.begin(), ids.end(), [this](int a, int b) { return buildingsModel_->rowOf(a) < buildingsModel_->rowOf(b); });
  return ids;
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
