// MainWindow itself: construction, the window's settings, messages and title; also the 3D view's
// content and the pick of an above-ground object. The rest of the class is in main_window_*.cpp,
// one file per part (listed in main_window.hpp).
#include "main_window.hpp"

#include <QAction>
#include <QCloseEvent>
#include <QComboBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QMessageBox>
#include <QSettings>
#include <QSignalBlocker>
#include <QStatusBar>
#include <algorithm>
#include <cmath>
#include <vector>

#include "delineo/core/error.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/roof_parts.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "delineo/widgets/terrain3d_view.hpp"
#include "document.hpp"
#include "error_text.hpp"

namespace delineo::gui {

using project::Building;
using project::BuildingStatus;

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent) {
  setObjectName(QStringLiteral("MainWindow"));
  setWindowIcon(QIcon(QStringLiteral(":/icons/delineo.svg")));
  jobs_ = new widgets::JobRunner(this);
  createViews();
  createDocks();
  createActions();
  createMenus();
  restoreSettings();
  connect(&autosaveTimer_, &QTimer::timeout, this, &MainWindow::autosaveNow);
  enhanceTimer_.setSingleShot(true);
  enhanceTimer_.setInterval(300);
  connect(&enhanceTimer_, &QTimer::timeout, this, [this] { startDemEnhancement(); });
  QSettings settings;
  autosaveTimer_.start(std::max(5, settings.value(QStringLiteral("autosaveSeconds"), 60).toInt()) * 1000);
  connect(jobs_, &widgets::JobRunner::failed, this,
          [this](widgets::JobId id, core::ErrorCode code, const QString& message) {
            if (id == rangeJob_ && code == core::ErrorCode::ProcessingFailed) return onRangeEstimateFailed(message);
            showMessage(tr("Job failed"), errorSentence(code) + QStringLiteral("\n\n") + message);
          });
  connect(jobs_, &widgets::JobRunner::activeCountChanged, this, [this](int count) {
    if (count == 0) leftView_->polygons().clearEvolvingContour();
    updateActions();
  });
  refreshTitle();
  updateActions();
}

void MainWindow::showActivated() {
  show();
  raise();
  activateWindow();
}

MainWindow::~MainWindow() {
  // Workers hold copies of their inputs, but their results are delivered to this window:
  // stop them before the views go away.
  jobs_->cancelAll();
  jobs_->waitForIdle(30000);
}

void MainWindow::restoreSettings() {
  QSettings settings;
  resize(1400, 900);
  restoreGeometry(settings.value(QStringLiteral("window/geometry")).toByteArray());
  if (!restoreState(settings.value(QStringLiteral("window/state")).toByteArray())) {
    // First start: the right image and the 3D view need room as much as the left image.
    resizeDocks({dock(QStringLiteral("rightDock"))}, {560}, Qt::Horizontal);
  }
}

QDockWidget* MainWindow::dock(const QString& objectName) const {
  return findChild<QDockWidget*>(objectName);
}

QAction* MainWindow::action(const QString& objectName) const {
  return findChild<QAction*>(objectName, Qt::FindDirectChildrenOnly);
}

void MainWindow::showDock(const QString& objectName) {
  if (QDockWidget* d = dock(objectName)) {
    d->show();
    d->raise();
  }
}

// ------------------------------------------------------------------------------------------
// messages

void MainWindow::showMessage(const QString& title, const QString& text) {
  lastMessage_ = text;
  statusBar()->showMessage(text.section(QLatin1Char('\n'), 0, 0), 10000);
  emit messageShown(text);
  if (interactive_) QMessageBox::warning(this, title, text);
}

bool MainWindow::askYesNo(const QString& title, const QString& text, bool defaultAnswer) {
  if (!interactive_) return defaultAnswer;
  return QMessageBox::question(this, title, text, QMessageBox::Yes | QMessageBox::No,
                               defaultAnswer ? QMessageBox::Yes : QMessageBox::No) == QMessageBox::Yes;
}

void MainWindow::closeEvent(QCloseEvent* event) {
  if (!maybeSave()) {
    event->ignore();
    return;
  }
  QSettings settings;
  settings.setValue(QStringLiteral("window/geometry"), saveGeometry());
  settings.setValue(QStringLiteral("window/state"), saveState());
  jobs_->cancelAll();
  event->accept();
}

void MainWindow::refreshTitle() {
  QString title = QStringLiteral("Delineo");
  if (document_) title = document_->displayName() + QStringLiteral("[*] — Delineo");
  setWindowTitle(title);
  setWindowModified(document_ && document_->isModified());
}

// ------------------------------------------------------------------------------------------
// 3D view

// The DEM, its texture and the extruded outlines of the buildings with a roof height: one block
// per roof part (project::roofParts on the DEM shown, as the CityJSON export writes them).
void MainWindow::refresh3D() {
  if (view3D_ == nullptr || !document_) return;
  if (document_->dem().empty()) return;
  // A new DEM of the project (not the enhanced one shown instead of it) is framed again.
  const bool newDem = view3DDem_.data != document_->dem().data;
  if (newDem) {
    view3DDem_ = document_->dem();
    const QSignalBlocker block(view3DExaggeration_);
    view3DExaggeration_->setValue(
        widgets::Terrain3DView::suggestedExaggeration(view3DDem_, document_->project().height.gsd));
    view3D_->setVerticalExaggeration(view3DExaggeration_->value());
  }
  const cv::Mat& dem = shownDem();
  view3D_->setDem(dem, document_->project().height.gsd);
  // Height colours by default: a grey drape is low-contrast and repeats the 2D view.
  view3D_->setTexture(view3DColour_->currentIndex() == 1 ? document_->leftGrey() : cv::Mat());
  view3D_->setBuildings(buildingBlocks_.of(document_->project(), dem));
  if (newDem) frame3D();
}

// ------------------------------------------------------------------------------------------
// picking an above-ground object

void MainWindow::onObjectPicked(QPointF imagePos) {
  if (!document_) return;
  const cv::Mat& disparity = document_->disparity();
  const cv::Mat& dem = document_->dem();
  const cv::Size size = !disparity.empty() ? disparity.size() : dem.size();
  if (imagePos.x() < 0 || imagePos.y() < 0 || imagePos.x() >= size.width || imagePos.y() >= size.height) {
    if (size.area() > 0) showMessage(tr("Pick an object"), tr("No above-ground object under the cursor."));
    else showMessage(tr("Pick an object"), tr("Picking an above-ground object needs a DEM or a disparity map."));
    return;
  }
  // The connected region above the local ground, with the ground estimate of the histogram's
  // line (algorithms: delineation::aboveGroundObjectAt through the project's steps).
  using Outcome = project::ObjectPick::Outcome;
  project::ObjectPick pick;
  try {
    pick = project::pickAboveGroundObject(document_->project(), disparity, dem, {imagePos.x(), imagePos.y()});
  } catch (const core::Error& e) {  // e.g. the project's "pick" parameters are out of their domain
    showMessage(tr("Pick an object"), errorSentence(e.code()) + QStringLiteral("\n\n") + QString::fromStdString(e.what()));
    return;
  }
  switch (pick.outcome) {
    case Outcome::Found: onPicked(pick.outline); return;
    case Outcome::NoHeights:
      showMessage(tr("Pick an object"), tr("Picking an above-ground object needs a DEM or a disparity map."));
      return;
    case Outcome::NoGround:
    case Outcome::NotAboveGround:
      showMessage(tr("Pick an object"), tr("No above-ground object under the cursor."));
      return;
  }
}

}  // namespace delineo::gui
