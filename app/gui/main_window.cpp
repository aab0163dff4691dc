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
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "delineo/widgets/terrain3d_view.hpp"
#include "document.hpp"
#include "error_text.hpp"

namespace delineo::gui {

using project::Building;
using project::BuildingStatus;

namespace {

// Median of the finite values of `values` in a band of `width` px around the polygon (outside
// it): the local ground level next to a building.
std::optional<double> ringMedian(const cv::Mat& values, const core::Polygon& polygon, int width) {
  if (values.empty() || polygon.outer.size() < 3) return std::nullopt;
  const cv::Rect2d box = core::boundingBox(polygon.outer);
  cv::Rect roi(static_cast<int>(box.x) - width - 2, static_cast<int>(box.y) - width - 2,
               static_cast<int>(box.width) + 2 * width + 4, static_cast<int>(box.height) + 2 * width + 4);
  roi &= cv::Rect(0, 0, values.cols, values.rows);
  if (roi.empty()) return std::nullopt;
  core::Polygon local = polygon;
  for (auto& p : local.outer) p -= cv::Point2d(roi.x, roi.y);
  local.holes.clear();
  const cv::Mat inside = core::rasterize(local, roi.size());
  cv::Mat grown;
  cv::dilate(inside, grown, cv::getStructuringElement(cv::MORPH_RECT, {2 * width + 1, 2 * width + 1}));
  std::vector<float> samples;
  const cv::Mat patch = values(roi);
  for (int y = 0; y < roi.height; ++y) {
    for (int x = 0; x < roi.width; ++x) {
      const float v = patch.at<float>(y, x);
      if (grown.at<uchar>(y, x) != 0 && inside.at<uchar>(y, x) == 0 && std::isfinite(v)) samples.push_back(v);
    }
  }
  if (samples.empty()) return std::nullopt;
  std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(samples.size() / 2), samples.end());
  return samples[samples.size() / 2];
}

}  // namespace

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
          [this](widgets::JobId, core::ErrorCode code, const QString& message) {
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

// The DEM, its texture and the extruded outlines of the buildings with a roof height.
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
  std::vector<widgets::BuildingOutline> outlines;
  for (const Building& b : document_->project().buildings) {
    if (!b.hasOutline() || b.status == BuildingStatus::Rejected || !std::isfinite(b.roofHeight)) continue;
    const double base = ringMedian(dem, b.outline, 6).value_or(0.0);
    outlines.push_back({b.outline, base, b.roofHeight});
  }
  view3D_->setBuildings(outlines);
  if (newDem) frame3D();
}

// ------------------------------------------------------------------------------------------
// picking an above-ground object

void MainWindow::onObjectPicked(QPointF imagePos) {
  if (!document_) return;
  const cv::Mat& dem = document_->dem();
  const int x = static_cast<int>(imagePos.x());
  const int y = static_cast<int>(imagePos.y());
  if (dem.empty() || x < 0 || y < 0 || x >= dem.cols || y >= dem.rows) {
    showMessage(tr("Pick an object"), tr("Picking an above-ground object needs a DEM or a disparity map."));
    return;
  }
  // Above-ground region: pixels at least 2.5 m above the local ground (the low quantile of the
  // heights in a window around the click), connected to the clicked pixel.
  const cv::Rect window = cv::Rect(x - 60, y - 60, 121, 121) & cv::Rect(0, 0, dem.cols, dem.rows);
  std::vector<float> heights;
  for (int yy = window.y; yy < window.y + window.height; ++yy) {
    for (int xx = window.x; xx < window.x + window.width; ++xx) {
      const float h = dem.at<float>(yy, xx);
      if (std::isfinite(h)) heights.push_back(h);
    }
  }
  if (heights.empty()) return;
  std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 10), heights.end());
  const float ground = heights[heights.size() / 10];
  cv::Mat above = (dem > ground + 2.5f);
  cv::morphologyEx(above, above, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  if (above.at<uchar>(y, x) == 0) {
    showMessage(tr("Pick an object"), tr("No above-ground object under the cursor."));
    return;
  }
  cv::Mat mask = cv::Mat::zeros(dem.rows + 2, dem.cols + 2, CV_8U);
  cv::floodFill(above, mask, cv::Point(x, y), 128, nullptr, 0, 0, 4 | cv::FLOODFILL_MASK_ONLY | (255 << 8));
  cv::Mat region = mask(cv::Rect(1, 1, dem.cols, dem.rows));
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(region, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  if (contours.empty()) return;
  std::vector<cv::Point> simplified;
  cv::approxPolyDP(contours.front(), simplified, 2.0, true);
  core::Polygon p;
  for (const auto& q : simplified) p.outer.emplace_back(q.x + 0.5, q.y + 0.5);
  onPicked(p);
}

}  // namespace delineo::gui
