// MainWindow's methods on the DEM: box-fitting on a building, shown beside its outline (the boxes
// and the box-fitting outline in colours of their own, both outlines' attributes under the
// buildings list) until the operator keeps one of the two; and the enhanced DEM (the DEM sharpened
// with the current outlines) in the DEM view and the 3D view.
#include <QAction>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPainter>
#include <QPixmap>
#include <QPointer>
#include <QSignalBlocker>
#include <QStatusBar>
#include <QTableWidget>
#include <QToolButton>
#include <QVBoxLayout>
#include <cmath>
#include <utility>
#include <vector>

#include "buildings_model.hpp"
#include "delineo/core/error.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "main_window.hpp"

namespace delineo::gui {

using project::Building;
using project::BuildingStatus;

namespace {

// Box-fitting's colours (the left view's overlay and the panel's legend): a violet that no
// building status uses for its outline, white dots for its boxes.
const QColor kBoxFitOutlineColour(190, 110, 255);
const QColor kBoxColour(255, 255, 255);

enum BoxFitRow { MethodRow, AreaRow, VerticesRow, EnergyRow, BoxEnergyRow, BoxesRow, RowCount };

int vertexCount(const core::Polygon& polygon) {
  int n = static_cast<int>(polygon.outer.size());
  for (const auto& hole : polygon.holes) n += static_cast<int>(hole.size());
  return n;
}

QString number(double value, int decimals) {
  return std::isfinite(value) ? QString::number(value, 'f', decimals) : QStringLiteral("–");
}

// A short line in `colour` and `style`: the legend of an outline in the panel's header.
QIcon lineSwatch(const QColor& colour, Qt::PenStyle style) {
  QPixmap pixmap(24, 12);
  pixmap.fill(Qt::transparent);
  QPainter painter(&pixmap);
  painter.setPen(QPen(QColor(0, 0, 0, 160), 4.5));
  painter.drawLine(2, 6, 22, 6);
  painter.setPen(QPen(colour, 3.0, style));
  painter.drawLine(2, 6, 22, 6);
  return QIcon(pixmap);
}

// The polygons an enhanced DEM is made from (as project::enhanceHeights takes them).
std::vector<core::Polygon> footprintsOf(const project::Project& project) {
  std::vector<core::Polygon> footprints;
  for (const Building& b : project.buildings) {
    if (b.hasOutline() && b.status != BuildingStatus::Rejected) footprints.push_back(b.outline);
  }
  return footprints;
}

bool sameFootprints(const std::vector<core::Polygon>& a, const std::vector<core::Polygon>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!(a[i].outer == b[i].outer && a[i].holes == b[i].holes)) return false;
  }
  return true;
}

}  // namespace

// ------------------------------------------------------------------------------------------
// box-fitting

widgets::JobId MainWindow::startBoxFitting(int id) {
  if (!document_) return 0;
  const Building* current = document_->project().find(id);
  if (current == nullptr) {
    showMessage(tr("Box-fitting"), tr("Select a building first."));
    return 0;
  }
  if (document_->dem().empty()) {
    showMessage(tr("Box-fitting"), tr("Box-fitting needs heights: compute the disparity and set the height model "
                                      "(File → Project settings)."));
    return 0;
  }
  const project::Project projectCopy = document_->project();
  Building building = *current;
  // The roof interval scores the box-fitting outline with the active polygon's energy F(C).
  if (!building.roofInterval && !document_->disparity().empty()) {
    building.roofInterval = project::suggestRoofInterval(document_->disparity(), building.initial);
  }
  const cv::Mat heights = document_->dem();
  const project::StereoPair pair = document_->pair();
  QPointer<Document> doc(document_.get());
  return jobs_->run<BoxFitProposal>(
      tr("Box-fitting, building %1").arg(id),
      [projectCopy, building, heights, pair](core::Progress& p) {
        BoxFitProposal proposal;
        core::Progress::Range fitting(&p, 0.0, 0.8);
        proposal.outcome = project::fitBuildingBoxes(projectCopy, building, heights, pair.left, &fitting);
        if (!proposal.outcome.hasOutline() || !building.roofInterval) return proposal;
        core::Progress::Range scoring(&p, 0.8, 1.0);
        try {
          proposal.activeEnergy =
              project::outlineEnergy(projectCopy, building, pair, proposal.outcome.outline, &scoring);
        } catch (const core::Error&) {
          // An outline the energy cannot score (degenerate on the pixel grid): shown as unknown.
        }
        return proposal;
      },
      [this, doc, id](BoxFitProposal proposal) {
        if (!doc || doc != document_.get() || doc->project().find(id) == nullptr) return;
        if (proposal.outcome.status != core::RunStatus::Completed) return;
        if (!proposal.outcome.hasOutline()) {
          showMessage(tr("Box-fitting"), tr("Box-fitting found no building in building %1's initial polygon: %2")
                                             .arg(id)
                                             .arg(QString::fromStdString(proposal.outcome.message)));
        } else if (!doc->project().find(id)->hasOutline()) {
          // Nothing to compare with: the building takes the outline (one undoable step).
          doc->setBoxFitResult(id, proposal.outcome, proposal.activeEnergy);
          statusBar()->showMessage(tr("Building %1 outlined by box-fitting.").arg(id), 10000);
        } else {
          const int boxes = static_cast<int>(proposal.outcome.boxes.size());
          boxFitProposals_[id] = std::move(proposal);
          refreshBoxFitProposals();
          statusBar()->showMessage(tr("Box-fitting of building %1: %n box(es). Keep either outline under the buildings list.",
                                      nullptr, boxes)
                                       .arg(id),
                                   10000);
        }
        emit boxFittingFinished(id);
      },
      QStringLiteral("boxfit-%1").arg(id));
}

bool MainWindow::keepBoxFitOutline() {
  const auto it = boxFitProposals_.find(selectedId_);
  if (!document_ || it == boxFitProposals_.end()) return false;
  const BoxFitProposal proposal = std::move(it->second);
  boxFitProposals_.erase(it);
  document_->setBoxFitResult(selectedId_, proposal.outcome, proposal.activeEnergy);
  refreshBoxFitProposals();
  updateActions();
  return true;
}

void MainWindow::discardBoxFitProposal() {
  if (boxFitProposals_.erase(selectedId_) == 0) return;
  refreshBoxFitProposals();
  updateActions();
}

// Under the buildings list: the selected building's outline beside its box-fitting outline,
// with the legend of their colours, and the two choices.
QWidget* MainWindow::createBoxFitPanel() {
  boxFitPanel_ = new QWidget;
  boxFitPanel_->setObjectName(QStringLiteral("boxFitPanel"));
  auto* layout = new QVBoxLayout(boxFitPanel_);
  layout->setContentsMargins(0, 4, 0, 0);
  boxFitTable_ = new QTableWidget(RowCount, 2);
  boxFitTable_->setObjectName(QStringLiteral("boxFitTable"));
  boxFitTable_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  boxFitTable_->setSelectionMode(QAbstractItemView::NoSelection);
  boxFitTable_->setVerticalHeaderLabels({tr("Method"), tr("Area (px²)"), tr("Vertices"), tr("Energy F(C)"),
                                         tr("Box energy (px)"), tr("Boxes")});
  boxFitTable_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  boxFitTable_->verticalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  boxFitTable_->setToolTip(tr("The building's outline beside the outline box-fitting proposes (violet, dashed; "
                              "its boxes dotted white). Energy F(C) is the active polygon's energy of each "
                              "outline (lower explains the images better); box energy is box-fitting's own, the "
                              "mean distance of the boxes' sides to the image's edges."));
  boxFitTable_->setVerticalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  auto* legend = new QLabel(tr("Boxes: dotted white."));
  legend->setObjectName(QStringLiteral("boxFitLegend"));
  auto* buttons = new QHBoxLayout;
  for (const char* name : {"keepBoxFit", "keepCurrentOutline"}) {
    auto* button = new QToolButton;
    button->setObjectName(QString::fromLatin1(name));
    button->setToolButtonStyle(Qt::ToolButtonTextOnly);
    buttons->addWidget(button);  // its action is set with the actions (createBuildingActions)
  }
  buttons->addStretch(1);
  layout->addWidget(boxFitTable_);
  layout->addWidget(legend);
  layout->addLayout(buttons);
  boxFitPanel_->hide();
  return boxFitPanel_;
}

// The proposals' boxes and outlines, drawn on the left view and the DEM view.
std::vector<widgets::OverlayGuide> MainWindow::boxFitGuides() const {
  std::vector<widgets::OverlayGuide> guides;
  for (const auto& [id, proposal] : boxFitProposals_) {
    for (const project::FittedBox& box : proposal.outcome.boxes) {
      core::Polygon corners;
      corners.outer = box.corners;
      guides.push_back({corners, kBoxColour, 1.0, Qt::DotLine});
    }
    guides.push_back({proposal.outcome.outline, kBoxFitOutlineColour, 2.5, Qt::DashLine});
  }
  return guides;
}

// The proposals on the views, and the panel for the selected building.
void MainWindow::refreshBoxFitProposals() {
  refreshGuides();

  const auto it = boxFitProposals_.find(selectedId_);
  const Building* b = document_ ? document_->project().find(selectedId_) : nullptr;
  boxFitPanel_->setVisible(it != boxFitProposals_.end() && b != nullptr);
  if (it == boxFitProposals_.end() || b == nullptr) return;
  const BoxFitProposal& proposal = it->second;
  // The current outline's colour, as the left view draws it.
  QColor current = widgets::statusColour(widgets::PolygonStatus::Candidate);
  for (const widgets::OverlayPolygon& p : leftView_->polygons().polygons()) {
    if (p.id == b->id) current = p.colour.isValid() ? p.colour : widgets::statusColour(p.status);
  }
  auto* currentHeader = new QTableWidgetItem(lineSwatch(current, Qt::SolidLine), tr("Building %1").arg(b->id));
  auto* boxFitHeader = new QTableWidgetItem(lineSwatch(kBoxFitOutlineColour, Qt::DashLine), tr("Box-fitting"));
  boxFitTable_->setHorizontalHeaderItem(0, currentHeader);
  boxFitTable_->setHorizontalHeaderItem(1, boxFitHeader);
  const core::Polygon& outline = b->currentPolygon();
  const QString method = b->hasOutline() ? BuildingsModel::methodText(*b) : tr("initial polygon");
  const project::BoxFitOutcome& fitted = proposal.outcome;
  const QStringList left = {method, number(core::area(outline), 0), QString::number(vertexCount(outline)),
                            number(b->energy, 1), QStringLiteral("–"), QStringLiteral("–")};
  const QStringList right = {tr("box-fitting"), number(core::area(fitted.outline), 0),
                             QString::number(vertexCount(fitted.outline)),
                             proposal.activeEnergy ? number(proposal.activeEnergy->energy, 1) : QStringLiteral("–"),
                             number(fitted.energy, 2), QString::number(fitted.boxes.size())};
  for (int row = 0; row < RowCount; ++row) {
    boxFitTable_->setItem(row, 0, new QTableWidgetItem(left[row]));
    boxFitTable_->setItem(row, 1, new QTableWidgetItem(right[row]));
    for (int column = 0; column < 2; ++column) {
      if (row != MethodRow) boxFitTable_->item(row, column)->setTextAlignment(Qt::AlignRight | Qt::AlignVCenter);
    }
  }
  // Every row shown, without a scroll bar: the table is as high as its rows.
  boxFitTable_->resizeRowsToContents();
  boxFitTable_->setFixedHeight(boxFitTable_->horizontalHeader()->sizeHint().height() +
                               boxFitTable_->verticalHeader()->length() + 2 * boxFitTable_->frameWidth());
}

// ------------------------------------------------------------------------------------------
// enhanced DEM

const cv::Mat& MainWindow::shownDem() const {
  static const cv::Mat none;
  if (!document_) return none;
  const QAction* toggle = action(QStringLiteral("actionEnhancedDem"));
  if (toggle != nullptr && toggle->isChecked() && !enhancedDem_.empty()) return enhancedDem_;
  return document_->dem();
}

void MainWindow::onEnhancedDemToggled(bool on) {
  if (on) {
    startDemEnhancement();
  } else {
    enhanceTimer_.stop();
    enhancedDem_ = cv::Mat();
    enhancedFrom_.clear();
  }
  refreshRasters();
  refresh3D();
}

widgets::JobId MainWindow::startDemEnhancement() {
  QAction* toggle = action(QStringLiteral("actionEnhancedDem"));
  if (!document_) return 0;
  const auto refuse = [&](const QString& reason) -> widgets::JobId {
    const QSignalBlocker block(toggle);
    toggle->setChecked(false);
    enhancedDem_ = cv::Mat();
    enhancedFrom_.clear();
    refreshRasters();
    refresh3D();
    showMessage(tr("Enhanced DEM"), reason);
    return 0;
  };
  if (document_->dem().empty()) {
    return refuse(tr("The enhanced DEM needs a DEM: compute the disparity and set the height model "
                     "(File → Project settings)."));
  }
  std::vector<core::Polygon> footprints = footprintsOf(document_->project());
  if (footprints.empty()) {
    return refuse(tr("The enhanced DEM sharpens the DEM along the buildings' outlines: delineate a building first."));
  }
  const project::Project projectCopy = document_->project();
  const cv::Mat heights = document_->dem();
  QPointer<Document> doc(document_.get());
  return jobs_->run<project::EnhancedDemOutcome>(
      tr("Enhanced DEM"),
      [projectCopy, heights](core::Progress& p) { return project::enhanceHeights(projectCopy, heights, &p); },
      [this, doc, heights, footprints = std::move(footprints)](project::EnhancedDemOutcome outcome) mutable {
        if (!doc || doc != document_.get() || outcome.status != core::RunStatus::Completed) return;
        // Turned off meanwhile, or the DEM itself changed: this result is about another DEM.
        if (!action(QStringLiteral("actionEnhancedDem"))->isChecked() || heights.data != document_->dem().data) return;
        enhancedDem_ = outcome.dem;
        enhancedFrom_ = std::move(footprints);
        refreshRasters();
        refresh3D();
        statusBar()->showMessage(tr("Enhanced DEM from %n outline(s).", nullptr, outcome.footprints), 5000);
        emit demEnhanced();
      },
      QStringLiteral("enhance"));
}

// Outlines or the DEM changed while the enhanced DEM is shown: it is computed again shortly
// (edits come in bursts), unless the outlines it was made from are still the same.
void MainWindow::scheduleDemEnhancement() {
  const QAction* toggle = action(QStringLiteral("actionEnhancedDem"));
  if (toggle == nullptr || !toggle->isChecked() || !document_) return;
  if (!enhancedDem_.empty() && sameFootprints(enhancedFrom_, footprintsOf(document_->project()))) return;
  enhanceTimer_.start();
}

}  // namespace delineo::gui
