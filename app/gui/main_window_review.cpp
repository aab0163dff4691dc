// MainWindow's review of the outlined buildings: the next building to review (an outline awaiting
// a decision, else a pending building), framed in the left view, and the count of what is left to
// review in the status bar.
#include <QAction>
#include <QLabel>
#include <QStatusBar>
#include <QStringList>
#include <algorithm>
#include <map>

#include "buildings_model.hpp"
#include "delineo/widgets/image_view.hpp"
#include "document.hpp"
#include "main_window.hpp"

namespace delineo::gui {

using project::Building;
using project::BuildingStatus;

namespace {

bool outlineAwaitsDecision(BuildingStatus s) {
  return s == BuildingStatus::Automatic || s == BuildingStatus::Corrected;
}
bool isPending(BuildingStatus s) { return s == BuildingStatus::Pending; }

// A building fits when its outline, vertex handles included, stays this far (widget px) inside
// the view; one that does not is zoomed out to take 1 / kFrameScale of the view's width or height.
constexpr double kFitInset = 16.0;
constexpr double kFrameScale = 1.3;

}  // namespace

// The rows are visited from the selected one's neighbour (the first or last row without a
// selection) round to the selected row itself, first for an outline awaiting a decision, then for
// a pending building.
int MainWindow::nextToReview(int step) const {
  const int rows = buildingsModel_->rowCount();
  if (rows == 0) return -1;
  const int selectedRow = buildingsModel_->rowOf(selectedId_);
  const int start = selectedRow >= 0 ? selectedRow : (step > 0 ? -1 : rows);
  for (const auto wanted : {outlineAwaitsDecision, isPending}) {
    for (int k = 1; k <= rows; ++k) {
      const int id = buildingsModel_->idAt(((start + step * k) % rows + rows) % rows);
      const Building* b = document_->project().find(id);
      if (b != nullptr && wanted(b->status)) return id;
    }
  }
  return -1;
}

int MainWindow::selectNextToReview(int step) {
  if (!document_) return -1;
  const int id = nextToReview(step);
  if (id <= 0) {
    statusBar()->showMessage(tr("Review complete: no building is left to review."), 10000);
    return -1;
  }
  selectBuilding(id);
  frameInLeftView(id);
  return id;
}

// selectBuilding() has centred the view on the building: the view zooms out when the building is
// larger than it at the operator's zoom, and keeps that zoom when the building fits.
void MainWindow::frameInLeftView(int id) {
  const Building* b = document_->project().find(id);
  if (b == nullptr || b->currentPolygon().outer.empty()) return;
  const cv::Rect2d box = core::boundingBox(b->currentPolygon().outer);
  const double width = leftView_->width(), height = leftView_->height();
  const double zoom = leftView_->zoom();
  if (width <= 2 * kFitInset || height <= 2 * kFitInset) return;
  if (box.width * zoom <= width - 2 * kFitInset && box.height * zoom <= height - 2 * kFitInset) return;
  const double framed = std::min(width / (std::max(box.width, 1.0) * kFrameScale),
                                 height / (std::max(box.height, 1.0) * kFrameScale));
  leftView_->setView(QPointF(box.x + box.width / 2, box.y + box.height / 2), std::min(framed, zoom));
}

void MainWindow::advanceAfterDecision() {
  if (action(QStringLiteral("actionNextAfterDecision"))->isChecked()) selectNextToReview(1);
}

// "To review: 5 outlined, 3 pending · 12 accepted · 2 rejected", the parts that are not zero.
QString MainWindow::reviewProgressText() const {
  if (!document_) return {};
  std::map<BuildingStatus, int> count;
  for (const Building& b : document_->project().buildings) ++count[b.status];
  const int outlined = count[BuildingStatus::Automatic] + count[BuildingStatus::Corrected];
  const int pending = count[BuildingStatus::Pending];
  const int accepted = count[BuildingStatus::Accepted];
  const int rejected = count[BuildingStatus::Rejected];
  QStringList toReview;
  if (outlined > 0) toReview << tr("%n outlined", nullptr, outlined);
  if (pending > 0) toReview << tr("%n pending", nullptr, pending);
  QStringList parts;
  if (!toReview.isEmpty()) parts << tr("To review: %1").arg(toReview.join(QStringLiteral(", ")));
  if (accepted > 0) parts << tr("%n accepted", nullptr, accepted);
  if (rejected > 0) parts << tr("%n rejected", nullptr, rejected);
  return parts.join(QStringLiteral(" · "));
}

void MainWindow::refreshReviewProgress() { reviewProgress_->setText(reviewProgressText()); }

}  // namespace delineo::gui
