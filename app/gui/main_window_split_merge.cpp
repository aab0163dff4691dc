// MainWindow's edits of the buildings themselves: Split building (a line drawn across the selected
// building in the left view), Merge with… (the next building clicked is merged into the selected
// one) and Merge buildings of the two rows selected in the Buildings list. Each is one undoable
// step (Document::splitBuilding, mergeBuildings); a refusal is said in the status bar.
#include <QAction>
#include <QStatusBar>

#include "delineo/widgets/image_view.hpp"
#include "document.hpp"
#include "main_window.hpp"

namespace delineo::gui {

using widgets::ImageView;
using widgets::InteractionMode;

namespace {
constexpr int kMessageMs = 10000;

// Why a split or a merge changed nothing, in the interface's language.
QString refusalText(const project::BuildingEdit& edit) {
  switch (edit.why) {
    case project::EditRefusal::NotCutInTwo:
      return MainWindow::tr("the line does not cut the building in two: draw it across, from outside to outside");
    case project::EditRefusal::SameBuilding: return MainWindow::tr("a building cannot be merged with itself");
    case project::EditRefusal::TooFarApart:
      return MainWindow::tr("they are more than %1 px apart").arg(static_cast<int>(project::kMergeGap));
    case project::EditRefusal::NoSuchBuilding: return MainWindow::tr("the building is no longer there");
    case project::EditRefusal::None: break;
  }
  return QString::fromStdString(edit.refusal);
}
}  // namespace

void MainWindow::onSplitLine(QPointF from, QPointF to) {
  if (!document_ || document_->project().find(selectedId_) == nullptr) return;
  const int id = selectedId_;
  const project::BuildingEdit edit = document_->splitBuilding(id, {from.x(), from.y()}, {to.x(), to.y()});
  if (!edit.done()) {
    statusBar()->showMessage(
        tr("Building %1 was not split: %2").arg(id).arg(refusalText(edit)), kMessageMs);
    return;
  }
  leftView_->setInteractionMode(InteractionMode::Navigate);
  showEditedBuildings(edit.ids);
  statusBar()->showMessage(tr("Building %1 split into %n buildings.", nullptr, static_cast<int>(edit.ids.size())).arg(id),
                           kMessageMs);
}

void MainWindow::beginMergeWith() {
  leftView_->setFocus(Qt::ShortcutFocusReason);  // Esc reaches the view, which leaves the mode
  statusBar()->showMessage(tr("Click the building to merge into building %1 (Esc: cancel).").arg(selectedId_),
                           kMessageMs);
}

void MainWindow::onMergeClick(int other) {
  if (!document_ || selectedId_ <= 0) return;
  if (other < 0 || other == selectedId_) {
    statusBar()->showMessage(tr("Click another building to merge into building %1 (Esc: cancel).").arg(selectedId_),
                             kMessageMs);
    return;
  }
  leftView_->setInteractionMode(InteractionMode::Navigate);  // one merge per Merge with…
  mergeInto(selectedId_, other);
}

void MainWindow::mergeSelectedRows() {
  const std::vector<int> ids = selectedRowIds();
  if (ids.size() != 2 || selectedId_ <= 0) return;
  mergeInto(selectedId_, ids[0] == selectedId_ ? ids[1] : ids[0]);
}

void MainWindow::mergeInto(int id, int other) {
  if (!document_) return;
  const project::BuildingEdit edit = document_->mergeBuildings(id, other);
  if (!edit.done()) {
    statusBar()->showMessage(tr("Buildings %1 and %2 were not merged: %3")
                                 .arg(id)
                                 .arg(other)
                                 .arg(refusalText(edit)),
                             kMessageMs);
    return;
  }
  showEditedBuildings(edit.ids);
  statusBar()->showMessage(tr("Building %1 merged into building %2.").arg(other).arg(id), kMessageMs);
}

// The first building of an edit is selected; the outlines it left with an unknown energy (the
// pieces of an outlined building, a merged outline) are scored in the background like an edit.
void MainWindow::showEditedBuildings(const std::vector<int>& ids) {
  selectBuilding(ids.front());
  for (int id : ids) startEnergyUpdate(id);
}

// Split needs a selected building, Merge with… another building too, Merge buildings two rows
// of the list. A tool that no longer applies (its building removed, the selection cleared) gives
// the left view back to Navigate.
void MainWindow::updateSplitMergeActions(bool hasSelection) {
  const size_t buildings = document_ ? document_->project().buildings.size() : 0;
  QAction* split = action(QStringLiteral("actionSplit"));
  QAction* mergeWith = action(QStringLiteral("actionMergeWith"));
  split->setEnabled(hasSelection);
  mergeWith->setEnabled(hasSelection && buildings >= 2);
  action(QStringLiteral("actionMergeSelected"))->setEnabled(hasSelection && selectedRowIds().size() == 2);
  const InteractionMode mode = leftView_->interactionMode();
  if ((mode == InteractionMode::PickLine && !split->isEnabled()) ||
      (mode == InteractionMode::PickOutline && !mergeWith->isEnabled())) {
    leftView_->setInteractionMode(InteractionMode::Navigate);
  }
}

}  // namespace delineo::gui
