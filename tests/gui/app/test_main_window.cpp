// Drives the real main window on a generated sample project: open, match (with an event-loop
// latency measurement), pick a building with the mouse, set the roof interval, run the active
// polygon, drag a vertex, undo, redo, accept, save, reload, export; plus bad inputs, autosave
// recovery and the French translation.
#include <QAbstractSpinBox>
#include <QAction>
#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QFile>
#include <QLabel>
#include <QMenu>
#include <QScrollArea>
#include <QSettings>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTabWidget>
#include <QTableView>
#include <QTableWidget>
#include <QComboBox>
#include <QTemporaryDir>
#include <QTest>
#include <QToolBar>
#include <QToolButton>
#include <QTranslator>
#include <QUndoStack>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "buildings_model.hpp"
#include "delineo/boxfit/params.hpp"
#include "delineo/delineation/above_ground.hpp"
#include "delineo/delineation/params.hpp"
#include "delineo/dem/enhance.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/segmentation/classify.hpp"
#include "delineo/segmentation/detect.hpp"
#include "delineo/segmentation/ground.hpp"
#include "delineo/segmentation/roof_levels.hpp"
#include "delineo/segmentation/objects.hpp"
#include "delineo/stereo/match.hpp"
#include "delineo/widgets/disparity_histogram.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/parameter_form.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "delineo/widgets/stage_text.hpp"
#include "document.hpp"
#include "main_window.hpp"
#include "sample_window.hpp"

using namespace delineo;
using gui::MainWindow;
using project::BuildingStatus;

namespace {

// Statuses compared as their names, so a failure prints them.
QString st(BuildingStatus status) { return QString::fromStdString(project::toString(status)); }

// Bounding rectangle of the largest building label component (the sample's ground truth).
cv::Rect largestBuilding(const cv::Mat& labels) {
  cv::Mat components, stats, centroids;
  const int n = cv::connectedComponentsWithStats(labels == 1, components, stats, centroids, 4);
  int best = 1;
  for (int i = 2; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = i;
  }
  return {stats.at<int>(best, cv::CC_STAT_LEFT), stats.at<int>(best, cv::CC_STAT_TOP),
          stats.at<int>(best, cv::CC_STAT_WIDTH), stats.at<int>(best, cv::CC_STAT_HEIGHT)};
}

double percentile99(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[static_cast<size_t>(0.99 * static_cast<double>(v.size() - 1))];
}

}  // namespace

class MainWindowTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir dir_;
  QString projectPath_;
  std::unique_ptr<MainWindow> window_;
  int buildingId_ = -1;

  // Runs the event loop while `job` is active, recording how late a 5 ms timer fires.
  std::vector<double> measureLatencyWhileRunning(widgets::JobId job) {
    std::vector<double> lateness;
    QElapsedTimer clock;
    QTimer timer;
    timer.setTimerType(Qt::PreciseTimer);
    qint64 last = 0;
    clock.start();
    connect(&timer, &QTimer::timeout, [&] {
      const qint64 now = clock.nsecsElapsed();
      if (last != 0) lateness.push_back(std::max(0.0, (now - last) / 1e6 - 5.0));
      last = now;
    });
    timer.start(5);
    [&] { QTRY_VERIFY_WITH_TIMEOUT(!window_->jobs()->isActive(job), 240000); }();
    timer.stop();
    return lateness;
  }

  // Shows `editor` on the Matching tab, scrolled to (DELINEO_SCREENSHOT_DIR keeps a rendering,
  // named `shot`). Returns the tab widget, left on that tab, or nullptr when it is not shown.
  QTabWidget* showOnMatchingTab(QWidget* editor, const QString& shot) {
    auto* tabs = window_->findChild<QTabWidget*>();
    if (!tabs) return nullptr;
    tabs->setCurrentIndex(1);
    auto* scroll = qobject_cast<QScrollArea*>(tabs->currentWidget());
    if (!scroll) return nullptr;
    scroll->ensureWidgetVisible(editor);
    if (!editor->isVisible()) return nullptr;
    const QString dir = qEnvironmentVariable("DELINEO_SCREENSHOT_DIR");
    if (!dir.isEmpty()) window_->grab().save(dir + QLatin1Char('/') + shot);
    return tabs;
  }

  // Each pair the edit tests below open: a bright roof [100, 180) x [60, 120) on a noisy
  // ground, the right image shifted by 12 px. `colour` writes it as an RGB image (a reddish roof).
  bool openSyntheticPair(const QString& name, bool colour) {
    cv::Mat grey(200, 260, CV_8U);
    cv::RNG rng(11);
    rng.fill(grey, cv::RNG::NORMAL, 90, 5);
    grey(cv::Rect(100, 60, 80, 60)) += cv::Scalar(60);
    cv::Mat left = grey;
    if (colour) {
      cv::Mat rgb[3] = {grey.clone(), grey * 0.6, grey * 0.4};  // file band order: R, G, B
      cv::merge(rgb, 3, left);
    }
    cv::Mat right = cv::Mat::zeros(left.size(), left.type());
    left(cv::Rect(12, 0, left.cols - 12, left.rows))
        .copyTo(right(cv::Rect(0, 0, left.cols - 12, left.rows)));
    const QString l = dir_.filePath(name + QStringLiteral("_left.tif"));
    const QString r = dir_.filePath(name + QStringLiteral("_right.tif"));
    io::writeGeoTiff(l.toStdString(), left);
    io::writeGeoTiff(r.toStdString(), right);
    return window_->openPair(l, r);
  }

  // Picks a pending building on the open pair, selects it and enters Edit outline mode, the
  // window active (another test's window may have taken the focus) and the left view focused.
  int editBuilding(const core::Polygon& polygon) {
    window_->activateWindow();
    if (!QTest::qWaitForWindowActive(window_.get())) return -1;
    const int id = window_->document()->addBuilding(polygon);
    window_->selectBuilding(id);
    window_->action(QStringLiteral("actionEdit"))->trigger();
    window_->action(QStringLiteral("actionSnapRightAngles"))->setChecked(false);
    window_->action(QStringLiteral("actionSnapEdges"))->setChecked(false);
    window_->leftView()->setView(QPointF(140, 90), 4.0);
    window_->leftView()->setFocus();
    return id;
  }

  void restoreEditDefaults() {
    window_->action(QStringLiteral("actionSnapRightAngles"))->setChecked(true);
    window_->action(QStringLiteral("actionSnapEdges"))->setChecked(true);
    window_->action(QStringLiteral("actionNavigate"))->trigger();
  }

 private slots:
  void initTestCase() {
    // Each step is driven by the test (the automatic run on pick is tested on its own).
    guitest::isolateSettings(QStringLiteral("DelineoTest"), false);
    QVERIFY(dir_.isValid());
    projectPath_ = guitest::makeSampleProject(dir_);
    window_ = guitest::showMainWindow();
    QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
  }

  void opensProjectAndMatchesWithResponsiveUi() {
    QSignalSpy opened(window_.get(), &MainWindow::documentOpened);
    QVERIFY(window_->openProject(projectPath_));
    QCOMPARE(opened.count(), 1);
    QVERIFY(window_->document()->disparity().empty());
    QVERIFY(window_->leftView()->hasImage());
    // Every tick is taken while a matching job runs; the sample's matching now takes about
    // 0.1 s, so it is run again until the ticks are enough for a 99th percentile.
    std::vector<double> lateness;
    for (int run = 0; run < 20 && lateness.size() <= 40; ++run) {
      const widgets::JobId job = window_->startMatching();
      QVERIFY(job != 0);
      const std::vector<double> ticks = measureLatencyWhileRunning(job);
      lateness.insert(lateness.end(), ticks.begin(), ticks.end());
      QVERIFY(!window_->document()->disparity().empty());
    }
    QVERIFY(lateness.size() > 40);
    const double p99 = percentile99(lateness);
    qInfo("event-loop lateness during matching: %zu ticks, p99 %.2f ms, max %.2f ms", lateness.size(), p99,
          *std::max_element(lateness.begin(), lateness.end()));
    QVERIFY2(p99 < 50.0, qPrintable(QStringLiteral("p99 lateness %1 ms").arg(p99)));
    QVERIFY(window_->disparityView()->hasImage());
    // Matching is an undoable result.
    QVERIFY(window_->document()->undoStack()->canUndo());
  }

  void labelsOverlayIsOffByDefaultAndRemembered() {
    // The sample has a label raster (simulated ground truth): available, but not shown.
    QAction* labels = window_->action(QStringLiteral("actionShowLabels"));
    QVERIFY(labels->isEnabled());
    QVERIFY(!labels->isChecked());
    QVERIFY(!window_->leftView()->overlayVisible());
    labels->trigger();
    QVERIFY(window_->leftView()->overlayVisible());
    QVERIFY(QSettings().value(QStringLiteral("view/showLabels")).toBool());
    labels->trigger();
    QVERIFY(!window_->leftView()->overlayVisible());
    QVERIFY(!QSettings().value(QStringLiteral("view/showLabels")).toBool());
  }

  void picksABuildingWithARectangleDrag() {
    gui::Document* doc = window_->document();
    QVERIFY(doc);
    const cv::Rect truth = largestBuilding(doc->labels());
    widgets::ImageView* view = window_->leftView();
    view->setView(QPointF(truth.x + truth.width / 2.0, truth.y + truth.height / 2.0), 1.5);
    // Nothing selected yet: the histogram asks for a building instead of showing an interval.
    QVERIFY(window_->selectedBuilding() <= 0);
    QVERIFY(!window_->histogram()->placeholder().isEmpty());
    window_->action(QStringLiteral("actionPickRectangle"))->trigger();
    QCOMPARE(view->interactionMode(), widgets::InteractionMode::PickRectangle);
    const QPoint a = view->imageToWidget(QPointF(truth.x - 6, truth.y - 6)).toPoint();
    const QPoint b = view->imageToWidget(QPointF(truth.br().x + 6, truth.br().y + 6)).toPoint();
    QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, a);
    QTest::mouseMove(view, (a + b) / 2);
    QTest::mouseMove(view, b);
    QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, b);
    QCOMPARE(window_->buildingsModel()->rowCount(), 1);
    buildingId_ = window_->selectedBuilding();
    QVERIFY(buildingId_ > 0);
    const project::Building* building = doc->project().find(buildingId_);
    QCOMPARE(st(building->status), st(BuildingStatus::Pending));
    QCOMPARE(building->initial.outer.size(), size_t(4));
    QVERIFY(std::abs(building->initial.outer[0].x - (truth.x - 6)) < 1.5);
    // The table shows it selected, the histogram is filled and has a roof interval.
    QCOMPARE(window_->buildingsTable()->selectionModel()->selectedRows().size(), 1);
    QVERIFY(window_->histogram()->sampleCount() > 100);
    QVERIFY(window_->histogram()->placeholder().isEmpty());
    QVERIFY(building->roofInterval.has_value());
    QVERIFY(window_->histogram()->groundLevel().has_value());
    QVERIFY(building->roofInterval->low > *window_->histogram()->groundLevel());
  }

  void setsTheRoofIntervalOnTheHistogram() {
    gui::Document* doc = window_->document();
    const auto before = *doc->project().find(buildingId_)->roofInterval;
    widgets::DisparityHistogramWidget* histogram = window_->histogram();
    histogram->setFocus();
    QTest::keyClick(histogram, Qt::Key_Left, Qt::ShiftModifier);  // upper bound - 1
    auto after = *doc->project().find(buildingId_)->roofInterval;
    QCOMPARE(after.high, before.high - 1);
    QCOMPARE(after.low, before.low);
    QTest::keyClick(histogram, Qt::Key_Right, Qt::ShiftModifier);  // back
    QCOMPARE(doc->project().find(buildingId_)->roofInterval->high, before.high);
    // Interval steps merge into one undo entry.
    QVERIFY(doc->undoStack()->undoText().contains(QStringLiteral("Roof interval")));
  }

  void runsTheActivePolygonInTheBackground() {
    gui::Document* doc = window_->document();
    QSignalSpy finished(window_.get(), &MainWindow::delineationFinished);
    const widgets::JobId job = window_->startDelineation(buildingId_);
    QVERIFY(job != 0);
    // A second run on the same building cancels the first one.
    QSignalSpy canceled(window_->jobs(), &widgets::JobRunner::canceled);
    const widgets::JobId second = window_->startDelineation(buildingId_);
    QVERIFY(second != job);
    const std::vector<double> lateness = measureLatencyWhileRunning(second);
    QTRY_COMPARE_WITH_TIMEOUT(canceled.count(), 1, 10000);
    QCOMPARE(canceled.first().first().value<widgets::JobId>(), job);
    QCOMPARE(finished.count(), 1);
    if (!lateness.empty()) qInfo("event-loop lateness during delineation: p99 %.2f ms", percentile99(lateness));
    QVERIFY(percentile99(lateness) < 50.0);
    const project::Building* b = doc->project().find(buildingId_);
    QCOMPARE(st(b->status), st(BuildingStatus::Automatic));
    QVERIFY(b->outline.outer.size() >= 4);
    QVERIFY(std::isfinite(b->energy));
    QVERIFY(std::isfinite(b->roofHeight));
    QVERIFY(b->roofHeight > 2.0);
    // The outline covers most of the true roof.
    const cv::Mat outline = core::rasterize(b->outline, doc->labels().size());
    const cv::Rect truth = largestBuilding(doc->labels());
    cv::Mat truthMask = (doc->labels() == 1);
    const double overlap = cv::countNonZero(outline(truth) & truthMask(truth));
    const double truthArea = cv::countNonZero(truthMask(truth));
    QVERIFY2(overlap / truthArea > 0.6, qPrintable(QString::number(overlap / truthArea)));
    // The overlay shows the result; the evolving contour is gone.
    QTRY_VERIFY(window_->leftView()->polygons().evolvingContour().isEmpty());
    const auto* shown = window_->leftView()->polygons().selectedPolygon();
    QVERIFY(shown != nullptr);
    QCOMPARE(shown->polygon.outer.size(), b->outline.outer.size());
    // Undo of the algorithm result restores the pending building; redo brings it back.
    doc->undoStack()->undo();
    QCOMPARE(st(doc->project().find(buildingId_)->status), st(BuildingStatus::Pending));
    doc->undoStack()->redo();
    QCOMPARE(st(doc->project().find(buildingId_)->status), st(BuildingStatus::Automatic));
  }

  void rightViewShowsOutlinesShiftedByTheRoofDisparity() {
    gui::Document* doc = window_->document();
    const project::Building* b = doc->project().find(buildingId_);
    if (!b->hasOutline() || !b->roofInterval) QSKIP("needs the delineation result");
    window_->selectBuilding(buildingId_);
    const double d = 0.5 * (b->roofInterval->low + b->roofInterval->high);
    QCOMPARE(*window_->roofDisparity(buildingId_), d);
    QCOMPARE(window_->rightViewShift(), d);
    const auto& shown = window_->rightView()->polygons().polygons();
    QCOMPARE(shown.size(), size_t(1));
    QCOMPARE(shown[0].id, buildingId_);
    QCOMPARE(shown[0].polygon.outer.size(), b->outline.outer.size());
    for (size_t i = 0; i < b->outline.outer.size(); ++i) {
      QCOMPARE(shown[0].polygon.outer[i].x, b->outline.outer[i].x - d);
      QCOMPARE(shown[0].polygon.outer[i].y, b->outline.outer[i].y);
    }
    // The outline really sits on the roof in the right image: the right image under the
    // shifted roof matches the left image under the outline better than unshifted.
    const cv::Mat roof = core::rasterize(b->outline, doc->leftGrey().size());
    cv::Mat leftF, rightF;
    doc->leftGrey().convertTo(leftF, CV_32F);
    doc->rightGrey().convertTo(rightF, CV_32F);
    auto meanAbsDifference = [&](int shift) {
      double sum = 0;
      int n = 0;
      for (int y = 0; y < roof.rows; ++y) {
        for (int x = 0; x < roof.cols; ++x) {
          if (roof.at<uchar>(y, x) == 0 || x - shift < 0) continue;
          sum += std::abs(leftF.at<float>(y, x) - rightF.at<float>(y, x - shift));
          ++n;
        }
      }
      return n > 0 ? sum / n : 1e9;
    };
    const double shifted = meanAbsDifference(static_cast<int>(std::lround(d)));
    const double unshifted = meanAbsDifference(0);
    qInfo("right view: roof disparity %.1f px, mean |L - R| on the roof %.1f shifted, %.1f unshifted", d, shifted,
          unshifted);
    QVERIFY(shifted < 0.6 * unshifted);
    // Linked views keep the same roof point at both centres, in both directions.
    widgets::ImageView* left = window_->leftView();
    widgets::ImageView* right = window_->rightView();
    left->setView(QPointF(200, 150), 2.0);
    QCOMPARE(right->viewCenter(), QPointF(200 - d, 150));
    QCOMPARE(right->zoom(), 2.0);
    right->setViewCenter(QPointF(100, 120));
    QCOMPARE(left->viewCenter(), QPointF(100 + d, 120));
    // Without a selection the ground disparity is the offset.
    window_->selectBuilding(-1);
    QCOMPARE(window_->rightViewShift(), doc->project().height.groundDisparity);
    window_->selectBuilding(buildingId_);
  }

  void dragsAVertexThenUndoesAndRedoes() {
    gui::Document* doc = window_->document();
    const project::Building* b = doc->project().find(buildingId_);
    if (b->status == BuildingStatus::Pending) QSKIP("needs the delineation result");
    const core::Ring original = b->outline.outer;
    widgets::ImageView* view = window_->leftView();
    window_->selectBuilding(buildingId_);
    window_->action(QStringLiteral("actionEdit"))->trigger();
    // A free move: both snaps off (their menu toggles drive the overlay).
    window_->action(QStringLiteral("actionSnapRightAngles"))->setChecked(false);
    window_->action(QStringLiteral("actionSnapEdges"))->setChecked(false);
    QVERIFY(!view->polygons().snapToRightAngles());
    QVERIFY(!view->polygons().snapToEdges());
    const QPointF vertex(original[0].x, original[0].y);
    const QPoint from = view->imageToWidget(vertex).toPoint();
    const QPoint to = from + QPoint(9, 6);
    QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, from);
    QTest::mouseMove(view, from + QPoint(3, 2));
    QTest::mouseMove(view, to);
    QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, to);
    b = doc->project().find(buildingId_);
    QCOMPARE(st(b->status), st(BuildingStatus::Corrected));
    QVERIFY(b->outline.outer != original);
    QVERIFY(b->history.back().action == "edited");
    // Ctrl+Z / Ctrl+Y through the window's shortcuts.
    QTest::keyClick(window_.get(), Qt::Key_Z, Qt::ControlModifier);
    QVERIFY(doc->project().find(buildingId_)->outline.outer == original);
    QCOMPARE(st(doc->project().find(buildingId_)->status), st(BuildingStatus::Automatic));
    QVERIFY(view->polygons().selectedPolygon()->polygon.outer == original);
    QTest::keyClick(window_.get(), Qt::Key_Y, Qt::ControlModifier);
    QCOMPARE(st(doc->project().find(buildingId_)->status), st(BuildingStatus::Corrected));
    QVERIFY(view->polygons().selectedPolygon()->polygon.outer != original);
    window_->action(QStringLiteral("actionSnapRightAngles"))->setChecked(true);
    window_->action(QStringLiteral("actionSnapEdges"))->setChecked(true);
  }

  void regularizesAnEditedOutlineAsOneStep() {
    gui::Document* doc = window_->document();
    window_->selectBuilding(buildingId_);
    // A hand-drawn outline of the building that zigzags by a pixel along its sides.
    const cv::Rect truth = largestBuilding(doc->labels());
    core::Ring jagged;
    const double x0 = truth.x, y0 = truth.y, x1 = truth.br().x, y1 = truth.br().y;
    for (int k = 0; k < 6; ++k) jagged.emplace_back(x0 + (x1 - x0) * k / 6.0, y0 + (k % 2));
    for (int k = 0; k < 6; ++k) jagged.emplace_back(x1 - (k % 2), y0 + (y1 - y0) * k / 6.0);
    for (int k = 0; k < 6; ++k) jagged.emplace_back(x1 - (x1 - x0) * k / 6.0, y1 - (k % 2));
    for (int k = 0; k < 6; ++k) jagged.emplace_back(x0 + (k % 2), y1 - (y1 - y0) * k / 6.0);
    doc->editRing(buildingId_, 0, jagged, QStringLiteral("Draw outline"));
    QUndoStack* undo = doc->undoStack();
    const int steps = undo->count();
    QSignalSpy done(window_.get(), &MainWindow::regularizationFinished);
    QAction* regularize = window_->action(QStringLiteral("actionRegularize"));
    QVERIFY(regularize->isEnabled());
    regularize->trigger();
    QTRY_COMPARE_WITH_TIMEOUT(done.count(), 1, 60000);
    const core::Ring squared = doc->project().find(buildingId_)->outline.outer;
    QVERIFY2(squared.size() <= 6, qPrintable(QString::number(squared.size())));
    QCOMPARE(undo->count(), steps + 1);
    QVERIFY(undo->undoText().startsWith(QStringLiteral("Regularize building")));
    undo->undo();
    QVERIFY(doc->project().find(buildingId_)->outline.outer == jagged);
    undo->redo();
    QVERIFY(doc->project().find(buildingId_)->outline.outer == squared);
  }

  void boxFittingIsShownBesideTheOutlineAndKeptAsOneStep() {
    gui::Document* doc = window_->document();
    window_->selectBuilding(buildingId_);
    const project::Building before = *doc->project().find(buildingId_);
    QVERIFY(before.hasOutline());
    QUndoStack* undo = doc->undoStack();
    const int steps = undo->count();
    QAction* boxFit = window_->action(QStringLiteral("actionBoxFit"));
    QAction* keep = window_->action(QStringLiteral("actionKeepBoxFit"));
    QVERIFY(boxFit->isEnabled());
    QVERIFY(!keep->isEnabled());
    QVERIFY(!window_->boxFitPanel()->isVisible());
    QSignalSpy done(window_.get(), &MainWindow::boxFittingFinished);
    boxFit->trigger();
    QTRY_COMPARE_WITH_TIMEOUT(done.count(), 1, 60000);
    QVERIFY2(window_->hasBoxFitProposal(buildingId_), qPrintable(window_->lastMessage()));
    // A proposal only: the building is as it was, nothing on the undo stack.
    QCOMPARE(undo->count(), steps);
    QVERIFY(doc->project().find(buildingId_)->outline.outer == before.outline.outer);
    // Drawn beside the building's outline: one dotted guide per box, then the dashed outline,
    // which lies on the true roof.
    const auto& guides = window_->leftView()->polygons().guides();
    QVERIFY(guides.size() >= 2);
    const widgets::OverlayGuide outline = guides.back();
    QCOMPARE(outline.style, Qt::DashLine);
    for (size_t i = 0; i + 1 < guides.size(); ++i) {
      QCOMPARE(guides[i].style, Qt::DotLine);
      QCOMPARE(guides[i].polygon.outer.size(), size_t(4));
    }
    QVERIFY(outline.colour != window_->leftView()->polygons().selectedPolygon()->colour);
    const cv::Mat truth = (doc->labels() == 1);
    const cv::Mat fitted = core::rasterize(outline.polygon, truth.size());
    const cv::Rect roof = largestBuilding(doc->labels());
    const double inter = cv::countNonZero(fitted(roof) & truth(roof));
    const double uni = cv::countNonZero(fitted) + cv::countNonZero(truth(roof)) - inter;
    qInfo("box-fitting: %zu boxes, IoU %.3f with the true roof", guides.size() - 1, inter / uni);
    QVERIFY2(inter / uni > 0.7, qPrintable(QString::number(inter / uni)));
    // Both outlines' attributes side by side.
    QVERIFY(window_->boxFitPanel()->isVisible());
    QTableWidget* table = window_->boxFitTable();
    QCOMPARE(table->item(5, 1)->text().toInt(), static_cast<int>(guides.size() - 1));  // boxes
    int fittedVertices = static_cast<int>(outline.polygon.outer.size());
    for (const auto& hole : outline.polygon.holes) fittedVertices += static_cast<int>(hole.size());
    QCOMPARE(table->item(2, 1)->text().toInt(), fittedVertices);
    int currentVertices = static_cast<int>(before.outline.outer.size());
    for (const auto& hole : before.outline.holes) currentVertices += static_cast<int>(hole.size());
    QCOMPARE(table->item(2, 0)->text().toInt(), currentVertices);
    QVERIFY(table->item(4, 1)->text().toDouble() > 0.0);  // box energy, px
    if (const QString dir = qEnvironmentVariable("DELINEO_SCREENSHOT_DIR"); !dir.isEmpty()) {
      window_->leftView()->setView(QPointF(roof.x + roof.width / 2.0, roof.y + roof.height / 2.0), 2.0);
      QTest::qWait(200);
      window_->grab().save(dir + QStringLiteral("/sample-box-fitting.png"));
    }
    // Keeping it is one undoable step that records the method.
    QVERIFY(keep->isEnabled());
    keep->trigger();
    const project::Building* b = doc->project().find(buildingId_);
    QCOMPARE(undo->count(), steps + 1);
    QVERIFY(undo->undoText().startsWith(QStringLiteral("Box-fitting outline")));
    QCOMPARE(QString::fromStdString(b->method), QStringLiteral("box-fitting"));
    QCOMPARE(st(b->status), st(BuildingStatus::Automatic));
    const int row = window_->buildingsModel()->rowOf(buildingId_);
    QCOMPARE(window_->buildingsModel()->data(window_->buildingsModel()->index(row, gui::BuildingsModel::Method),
                                             Qt::DisplayRole).toString(),
             QStringLiteral("box-fitting"));
    QVERIFY(b->outline.outer == outline.polygon.outer);
    QCOMPARE(QString::fromStdString(b->history.back().action), QStringLiteral("delineated"));
    QVERIFY(QString::fromStdString(b->history.back().detail).startsWith(QStringLiteral("box-fitting, ")));
    QVERIFY(!window_->hasBoxFitProposal(buildingId_));
    QVERIFY(window_->leftView()->polygons().guides().empty());
    QVERIFY(!window_->boxFitPanel()->isVisible());
    QVERIFY(window_->leftView()->polygons().selectedPolygon()->polygon.outer == outline.polygon.outer);
    undo->undo();
    b = doc->project().find(buildingId_);
    QVERIFY(b->outline.outer == before.outline.outer);
    QCOMPARE(st(b->status), st(before.status));
    QCOMPARE(b->method, before.method);
    undo->redo();
    QCOMPARE(QString::fromStdString(doc->project().find(buildingId_)->method), QStringLiteral("box-fitting"));
    undo->undo();  // the tests after this one work on the active polygon's outline
  }

  void canceledBoxFittingKeepsTheOutline() {
    gui::Document* doc = window_->document();
    window_->selectBuilding(buildingId_);
    window_->discardBoxFitProposal();  // one a test before may have left
    const project::Building before = *doc->project().find(buildingId_);
    QUndoStack* undo = doc->undoStack();
    const int steps = undo->count();
    QSignalSpy canceled(window_->jobs(), &widgets::JobRunner::canceled);
    QSignalSpy done(window_.get(), &MainWindow::boxFittingFinished);
    const widgets::JobId job = window_->startBoxFitting(buildingId_);
    QVERIFY(job != 0);
    window_->action(QStringLiteral("actionCancelJobs"))->trigger();
    QVERIFY(window_->jobs()->waitForIdle(30000));
    QCOMPARE(canceled.count(), 1);
    QCOMPARE(done.count(), 0);
    QVERIFY(!window_->hasBoxFitProposal(buildingId_));
    QVERIFY(window_->leftView()->polygons().guides().empty());
    QCOMPARE(undo->count(), steps);
    QVERIFY(doc->project().find(buildingId_)->outline.outer == before.outline.outer);
    QCOMPARE(st(doc->project().find(buildingId_)->status), st(before.status));
    // "Keep the current outline" drops a proposal and changes nothing either.
    window_->action(QStringLiteral("actionBoxFit"))->trigger();
    QTRY_COMPARE_WITH_TIMEOUT(done.count(), 1, 60000);
    QVERIFY(window_->hasBoxFitProposal(buildingId_));
    QAction* keepCurrent = window_->action(QStringLiteral("actionDiscardBoxFit"));
    QVERIFY(keepCurrent->isEnabled());
    keepCurrent->trigger();
    QVERIFY(!window_->hasBoxFitProposal(buildingId_));
    QVERIFY(window_->leftView()->polygons().guides().empty());
    QCOMPARE(undo->count(), steps);
    QVERIFY(doc->project().find(buildingId_)->outline.outer == before.outline.outer);
  }

  void enhancedDemToggleChangesTheDemView() {
    gui::Document* doc = window_->document();
    QVERIFY(doc->project().find(buildingId_)->hasOutline());
    window_->showDock(QStringLiteral("demDock"));
    window_->findChild<QComboBox*>(QStringLiteral("demMode"))->setCurrentIndex(1);  // heights
    QVERIFY(window_->demView()->hasImage());
    const auto finite = [](const cv::Mat& m) {
      cv::Mat copy = m.clone();
      cv::patchNaNs(copy, -9999.0);
      return copy;
    };
    const cv::Mat plain = finite(window_->demView()->image());
    QCOMPARE(plain.type(), CV_32F);
    const cv::Mat projectDem = doc->dem().clone();
    QAction* toggle = window_->action(QStringLiteral("actionEnhancedDem"));
    QVERIFY(toggle->isEnabled());
    QSignalSpy enhanced(window_.get(), &MainWindow::demEnhanced);
    toggle->trigger();
    QTRY_COMPARE_WITH_TIMEOUT(enhanced.count(), 1, 60000);
    QVERIFY(toggle->isChecked());
    const cv::Mat shown = finite(window_->demView()->image());
    QCOMPARE(shown.size(), plain.size());
    // The DEM view now shows other heights near the outline, the same ones far from it.
    const cv::Mat changed = shown != plain;
    cv::Mat near = core::rasterize(doc->project().find(buildingId_)->outline, plain.size());
    cv::dilate(near, near, cv::getStructuringElement(cv::MORPH_RECT, {41, 41}));
    qInfo("enhanced DEM: %d pixels changed near the outline, %d elsewhere", cv::countNonZero(changed & near),
          cv::countNonZero(changed & ~near));
    QVERIFY(cv::countNonZero(changed & near) > 50);
    QCOMPARE(cv::countNonZero(changed & ~near), 0);
    QVERIFY(window_->shownDem().data != doc->dem().data);
    // The project's DEM is not touched.
    QCOMPARE(cv::norm(finite(doc->dem()), finite(projectDem), cv::NORM_INF), 0.0);
    // Back to the plain DEM.
    toggle->trigger();
    QVERIFY(!toggle->isChecked());
    QCOMPARE(cv::norm(finite(window_->demView()->image()), plain, cv::NORM_INF), 0.0);
    window_->findChild<QComboBox*>(QStringLiteral("demMode"))->setCurrentIndex(0);
  }

  void acceptsSavesReloadsAndExports() {
    gui::Document* doc = window_->document();
    window_->selectBuilding(buildingId_);
    if (!doc->project().find(buildingId_)->hasOutline()) QSKIP("needs the delineation result");
    window_->acceptSelected();
    QCOMPARE(st(doc->project().find(buildingId_)->status), st(BuildingStatus::Accepted));
    QCOMPARE(window_->buildingsModel()->data(window_->buildingsModel()->index(0, gui::BuildingsModel::Status),
                                             Qt::DisplayRole).toString(), QStringLiteral("accepted"));
    QVERIFY(doc->isModified());
    const QString saved = dir_.filePath(QStringLiteral("sample/saved.delineo.json"));
    QVERIFY(window_->saveAs(saved));
    QVERIFY(!doc->isModified());
    const project::Project inMemory = doc->project();

    MainWindow reopened;
    reopened.setInteractive(false);
    QVERIFY(reopened.openProject(saved));
    const project::Project& loaded = reopened.document()->project();
    QCOMPARE(loaded.buildings.size(), inMemory.buildings.size());
    QVERIFY(loaded.buildings[0].outline.outer == inMemory.buildings[0].outline.outer);
    QCOMPARE(st(loaded.buildings[0].status), st(BuildingStatus::Accepted));
    QVERIFY(!reopened.document()->disparity().empty());  // written next to the outputs at save
    QCOMPARE(reopened.buildingsModel()->rowCount(), 1);

    const QString exported = dir_.filePath(QStringLiteral("sample/accepted.geojson"));
    QCOMPARE(reopened.exportOutlines(exported), 1);
    const auto features = io::readFeatures(exported.toStdString());
    QCOMPARE(features.size(), size_t(1));
    QCOMPARE(std::get<long long>(features[0].attributes.at("id")), static_cast<long long>(buildingId_));
    // The same building as a CityJSON LoD1 block, up to its roof height.
    QVERIFY(std::isfinite(loaded.buildings[0].roofHeight));
    const QString blocks = dir_.filePath(QStringLiteral("sample/accepted.city.json"));
    QSignalSpy cityExported(&reopened, &MainWindow::cityModelExported);
    reopened.exportAccepted(blocks);  // in the background
    QVERIFY(cityExported.wait(60000));
    QCOMPARE(cityExported.first().at(1).toInt(), 1);
    QFile blocksFile(blocks);
    QVERIFY(blocksFile.open(QIODevice::ReadOnly));
    const QByteArray blocksText = blocksFile.readAll();
    QVERIFY(blocksText.contains("\"type\":\"CityJSON\""));
    // Its base is the ground the 3D view draws it from (on the document's DEM).
    const std::optional<double> base =
        project::groundHeightNextTo(loaded, reopened.document()->dem(), loaded.buildings[0].outline);
    QVERIFY(base.has_value());
    const QByteArray expectedBase = "\"ground_height_m\":" + QByteArray::fromStdString(nlohmann::json(*base).dump());
    QVERIFY2(blocksText.contains(expectedBase), expectedBase.constData());
  }

  void badInputsShowAMessageAndChangeNothing() {
    gui::Document* before = window_->document();
    QSignalSpy messages(window_.get(), &MainWindow::messageShown);
    // Corrupt project file.
    const QString corrupt = dir_.filePath(QStringLiteral("corrupt.json"));
    std::ofstream(corrupt.toStdString()) << "{\"format\": \"delineo-project\", \"version\": 1, \"images\": ";
    QVERIFY(!window_->openProject(corrupt));
    QCOMPARE(window_->document(), before);
    QCOMPARE(messages.count(), 1);
    QVERIFY(window_->lastMessage().contains(QStringLiteral("corrupt.json")));
    // Unreadable image.
    const QString fake = dir_.filePath(QStringLiteral("fake.tif"));
    std::ofstream(fake.toStdString()) << "not an image";
    QVERIFY(!window_->openPair(fake, fake));
    QCOMPARE(window_->document(), before);
    QCOMPARE(messages.count(), 2);
    // Left and right of different heights.
    const QString small = dir_.filePath(QStringLiteral("small.tif"));
    io::writeGeoTiff(small.toStdString(), cv::Mat(100, 512, CV_8U, cv::Scalar(90)));
    QVERIFY(!window_->openPair(QString::fromStdString(before->project().left), small));
    QCOMPARE(window_->document(), before);
    QCOMPARE(messages.count(), 3);
    QVERIFY(window_->lastMessage().contains(QStringLiteral("do not match")));
  }

  void missingImageCanBeRelocated() {
    namespace fs = std::filesystem;
    const fs::path folder = dir_.filePath(QStringLiteral("moved")).toStdString();
    fs::create_directories(folder);
    const project::Project original = window_->document()->project();
    project::Project p = original;
    p.buildings.clear();
    p.right = (folder / "right-renamed.tif").string();  // does not exist yet
    p.dem.clear();
    p.labels.clear();
    p.disparity.clear();
    const std::string path = (folder / "p.json").string();
    project::saveProject(p, path);
    gui::Document* before = window_->document();
    window_->setRelocateHandler([](const QString&) { return QString(); });  // operator gives up
    QVERIFY(!window_->openProject(QString::fromStdString(path)));
    QCOMPARE(window_->document(), before);
    QVERIFY(window_->lastMessage().contains(QStringLiteral("right-renamed.tif")));
    QString asked;
    window_->setRelocateHandler([&](const QString& missing) {
      asked = missing;
      return QString::fromStdString(original.right);
    });
    QVERIFY(window_->openProject(QString::fromStdString(path)));
    QVERIFY(asked.endsWith(QStringLiteral("right-renamed.tif")));
    QCOMPARE(window_->document()->project().right, original.right);
    // No label raster: nothing to show, the toggle is disabled.
    QVERIFY(!window_->action(QStringLiteral("actionShowLabels"))->isEnabled());
    window_->setRelocateHandler({});
  }

  void autosaveIsOfferedAfterACrash() {
    namespace fs = std::filesystem;
    const QString path = dir_.filePath(QStringLiteral("sample/saved.delineo.json"));
    QVERIFY(window_->openProject(path));
    gui::Document* doc = window_->document();
    core::Polygon extra;
    extra.outer = {{20, 20}, {60, 20}, {60, 50}, {20, 50}};
    doc->addBuilding(extra);
    window_->autosaveNow();
    const std::string autosave = project::autosavePath(path.toStdString());
    QVERIFY(fs::exists(autosave));
    // The "crash": the autosave is newer than the project file, which was never saved again.
    fs::last_write_time(autosave, fs::last_write_time(path.toStdString()) + std::chrono::seconds(10));
    MainWindow restored;
    restored.setInteractive(false);
    restored.setRestoreAutosavePolicy(true);
    QVERIFY(restored.openProject(path));
    QCOMPARE(restored.document()->project().buildings.size(), size_t(2));
    MainWindow declined;
    declined.setInteractive(false);
    declined.setRestoreAutosavePolicy(false);
    QVERIFY(declined.openProject(path));
    QCOMPARE(declined.document()->project().buildings.size(), size_t(1));
    doc->undoStack()->undo();
  }

  void draggedVertexSnapsOntoAnImageEdge() {
    // A pair whose left image has one bright roof [100, 180) x [60, 120) on a noisy ground.
    cv::Mat left(200, 260, CV_8U);
    cv::RNG rng(11);
    rng.fill(left, cv::RNG::NORMAL, 90, 5);
    left(cv::Rect(100, 60, 80, 60)) += cv::Scalar(60);
    cv::Mat right = cv::Mat::zeros(left.size(), CV_8U);
    left(cv::Rect(12, 0, left.cols - 12, left.rows)).copyTo(right(cv::Rect(0, 0, left.cols - 12, left.rows)));
    const QString leftPath = dir_.filePath(QStringLiteral("edges_left.tif"));
    const QString rightPath = dir_.filePath(QStringLiteral("edges_right.tif"));
    io::writeGeoTiff(leftPath.toStdString(), left);
    io::writeGeoTiff(rightPath.toStdString(), right);
    QVERIFY(window_->openPair(leftPath, rightPath));
    // Both snaps are on by default; the edge map is computed in the background.
    QVERIFY(window_->action(QStringLiteral("actionSnapEdges"))->isChecked());
    QVERIFY(window_->action(QStringLiteral("actionSnapRightAngles"))->isChecked());
    QTRY_VERIFY_WITH_TIMEOUT(!window_->edgeMap().empty(), 10000);
    const cv::Mat& edges = window_->edgeMap();
    QCOMPARE(edges.size(), left.size());

    gui::Document* doc = window_->document();
    core::Polygon rough;
    rough.outer = {{94, 54}, {186, 54}, {186, 126}, {94, 126}};
    const int id = doc->addBuilding(rough);
    window_->selectBuilding(id);
    window_->action(QStringLiteral("actionEdit"))->trigger();
    widgets::ImageView* view = window_->leftView();
    view->setView(QPointF(180, 80), 4.0);
    auto drag = [&](QPointF fromImage, QPointF toImage) {
      const QPoint from = view->imageToWidget(fromImage).toPoint();
      const QPoint to = view->imageToWidget(toImage).toPoint();
      QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, from);
      QTest::mouseMove(view, from + (to - from) / 2);
      QTest::mouseMove(view, to);
      QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, to);
      return view->widgetToImage(to);
    };
    // Vertex 1 dropped 2 px right of the roof's right wall (x = 180): it lands on the wall.
    const QPointF dropped = drag(QPointF(186, 54), QPointF(182.1, 75.3));
    const cv::Point2d moved = doc->project().find(id)->initial.outer[1];
    qInfo("edge snap: dropped at (%.2f, %.2f), vertex at (%.2f, %.2f)", dropped.x(), dropped.y(), moved.x, moved.y);
    QVERIFY2(std::abs(moved.x - 180.0) <= 1.0, qPrintable(QString::number(moved.x)));
    QVERIFY(std::abs(moved.y - dropped.y()) <= 3.0);
    QCOMPARE(edges.at<uchar>(static_cast<int>(moved.y), static_cast<int>(moved.x)), uchar(255));
    // With edge snapping off, the same kind of drop stays where the mouse left it.
    window_->action(QStringLiteral("actionSnapEdges"))->trigger();
    window_->action(QStringLiteral("actionSnapRightAngles"))->trigger();
    QVERIFY(!QSettings().value(QStringLiteral("edit/snapEdges")).toBool());
    const QPointF free = drag(QPointF(186, 126), QPointF(182.1, 104.3));
    const cv::Point2d unsnapped = doc->project().find(id)->initial.outer[2];
    QVERIFY(std::abs(unsnapped.x - free.x()) < 1e-6 && std::abs(unsnapped.y - free.y()) < 1e-6);
    window_->action(QStringLiteral("actionSnapEdges"))->trigger();
    window_->action(QStringLiteral("actionSnapRightAngles"))->trigger();
    window_->action(QStringLiteral("actionNavigate"))->trigger();
  }

  void languageChoicePersistsAndAsksForARestart() {
    QAction* french = window_->findChild<QAction*>(QStringLiteral("actionLanguage_fr"));
    QAction* system = window_->findChild<QAction*>(QStringLiteral("actionLanguage_system"));
    QVERIFY(french && system && window_->findChild<QAction*>(QStringLiteral("actionLanguage_en")));
    QVERIFY(system->isChecked());
    QSignalSpy messages(window_.get(), &MainWindow::messageShown);
    french->trigger();
    QCOMPARE(QSettings().value(QStringLiteral("language")).toString(), QStringLiteral("fr"));
    QCOMPARE(messages.count(), 1);
    QVERIFY(window_->lastMessage().contains(QStringLiteral("next time")));
    // A new window (the next start) shows the stored choice.
    MainWindow next;
    QVERIFY(next.findChild<QAction*>(QStringLiteral("actionLanguage_fr"))->isChecked());
    system->trigger();
    QCOMPARE(QSettings().value(QStringLiteral("language")).toString(), QString());
  }

  void frenchTranslationIsComplete() {
    QTranslator translator;
    QVERIFY(translator.load(QStringLiteral(":/i18n/delineo_fr.qm")));
    QCOMPARE(translator.translate("delineo::gui::MainWindow", "Buildings"), QStringLiteral("Bâtiments"));
    QCOMPARE(translator.translate("delineo::gui::BuildingsModel", "accepted"), QStringLiteral("accepté"));
    QCOMPARE(translator.translate("delineo::gui::MainWindow", "Bo&x-fitting"), QStringLiteral("Ajustement de &boîtes"));
    QCOMPARE(translator.translate("delineo::gui::MainWindow", "En&hanced DEM"), QStringLiteral("MNE a&mélioré"));
    QCOMPARE(translator.translate("delineo::gui::MainWindow", "Select a building to see the disparities around it."),
             QStringLiteral("Sélectionnez un bâtiment pour voir les disparités autour de lui."));
    QCOMPARE(translator.translate("ErrorText", "The input files do not match each other."),
             QStringLiteral("Les fichiers d’entrée ne correspondent pas entre eux."));
    // Every label of the parameter forms (their strings come from the structs' visit(),
    // which lupdate cannot see: app/gui/parameter_labels.cpp must list each new one).
    QStringList untranslated;
    const auto check = [&](const delineo::core::ParamInfo& info, auto&) {
      const std::string label(info.label);
      if (translator.translate("Parameters", label.c_str()).isEmpty()) {
        untranslated << QString::fromStdString(label);
      }
    };
    delineo::delineation::DelineationParams delineation;
    delineation.visit(check);
    delineo::stereo::MatchParams matching;
    matching.visit(check);
    delineo::delineation::AboveGroundParams pick;
    pick.visit(check);
    delineo::dem::EnhanceParams enhance;
    enhance.visit(check);
    delineo::boxfit::BoxFitParams boxFit;
    boxFit.visit(check);
    delineo::segmentation::GroundParams ground;
    ground.visit(check);
    delineo::segmentation::ClassifyParams classify;
    classify.visit(check);
    delineo::segmentation::ObjectParams objects;
    objects.visit(check);
    delineo::segmentation::DetectParams detect;
    detect.visit(check);
    delineo::segmentation::RoofLevelParams roofLevels;
    roofLevels.visit(check);
    QCOMPARE(translator.translate("delineo::gui::MainWindow", "De&tect buildings"), QStringLiteral("Dé&tecter les bâtiments"));
    QVERIFY2(untranslated.isEmpty(), qPrintable(untranslated.join(QStringLiteral(", "))));
    // The reusable widgets' strings are in the same translation.
    QCOMPARE(translator.translate("delineo::widgets::JobProgressWidget", "Idle"), QStringLiteral("Inactif"));
    QCOMPARE(translator.translate("delineo::widgets::PolygonOverlay", "Move vertex"),
             QStringLiteral("Déplacer le sommet"));
    // Every progress stage an algorithm names is worded in French in the status bar.
    QStringList english;
    for (int id = static_cast<int>(delineo::core::StageId::PreparingPyramids);
         id <= static_cast<int>(delineo::core::kLastStageId); ++id) {
      english << delineo::widgets::stageText(delineo::core::Stage::of(static_cast<delineo::core::StageId>(id), 2, 3));
    }
    QCoreApplication::installTranslator(&translator);
    QStringList stillEnglish;
    for (int id = static_cast<int>(delineo::core::StageId::PreparingPyramids);
         id <= static_cast<int>(delineo::core::kLastStageId); ++id) {
      const QString text = delineo::widgets::stageText(delineo::core::Stage::of(static_cast<delineo::core::StageId>(id), 2, 3));
      if (english.contains(text)) stillEnglish << text;
    }
    QCoreApplication::removeTranslator(&translator);
    QVERIFY2(stillEnglish.isEmpty(), qPrintable(stillEnglish.join(QStringLiteral(", "))));
  }

  void orderingCheckIsAMatchingParameterOfTheProject() {
    if (!window_->document()) QVERIFY(window_->openProject(projectPath_));
    auto* box = window_->matchingForm()->findChild<QCheckBox*>(QStringLiteral("ordering-check"));
    QVERIFY(box);
    QVERIFY(box->isChecked());
    QVERIFY(!box->toolTip().isEmpty());
    const auto stored = [&] {
      return project::parameters<stereo::MatchParams>(window_->document()->project(), "matching").orderingCheck;
    };
    QVERIFY(stored());
    // One click, one undo entry (the stored delineation group of the sample lacks fields the form
    // has: it was written too, as a second entry).
    QUndoStack* undo = window_->document()->undoStack();
    const int entries = undo->count();
    box->click();
    QVERIFY(!stored());
    QCOMPARE(undo->count(), entries + 1);
    QCOMPARE(undo->undoText(), QStringLiteral("Change matching parameters"));
    // The toolbar button keeps its short label; its tooltip names the command.
    auto* toolbar = window_->findChild<QToolBar*>();
    QVERIFY(toolbar);
    auto* undoButton = qobject_cast<QToolButton*>(
        toolbar->widgetForAction(window_->findChild<QAction*>(QStringLiteral("actionUndo"))));
    QVERIFY(undoButton);
    QCOMPARE(undoButton->text(), QStringLiteral("Undo"));
    QCOMPARE(undoButton->toolTip(), QStringLiteral("Undo Change matching parameters"));
    undo->undo();
    QVERIFY(stored());
    QVERIFY(box->isChecked());
    undo->redo();
    QVERIFY(!stored());
    QVERIFY(!box->isChecked());
    // Shown on the Matching tab, scrolled to.
    QTabWidget* tabs = showOnMatchingTab(box, QStringLiteral("matching-tab.png"));
    QVERIFY(tabs);
    box->click();
    QVERIFY(stored());
    tabs->setCurrentIndex(0);
  }

  void roofPlanesAreMatchingParametersOfTheProject() {
    if (!window_->document()) QVERIFY(window_->openProject(projectPath_));
    auto* residual = window_->matchingForm()->findChild<QDoubleSpinBox*>(QStringLiteral("plane-residual"));
    auto* area = window_->matchingForm()->findChild<QSpinBox*>(QStringLiteral("plane-min-area"));
    QVERIFY(residual);
    QVERIFY(area);
    QCOMPARE(residual->value(), 0.4);
    QCOMPARE(area->value(), 300);
    QVERIFY(!residual->toolTip().isEmpty());
    const auto stored = [&] {
      return project::parameters<stereo::MatchParams>(window_->document()->project(), "matching").planeResidual;
    };
    // Off (0) from the form, stored in the project, and back by undo.
    residual->setValue(0.0);
    QCOMPARE(stored(), 0.0);
    window_->document()->undoStack()->undo();
    QCOMPARE(stored(), 0.4);
    QCOMPARE(residual->value(), 0.4);
    QTabWidget* tabs = showOnMatchingTab(area, QStringLiteral("matching-tab-planes.png"));
    QVERIFY(tabs);
    tabs->setCurrentIndex(0);
  }

  void squareWindowsOnOneSurfaceIsAMatchingParameterOfTheProject() {
    if (!window_->document()) QVERIFY(window_->openProject(projectPath_));
    auto* box =
        window_->matchingForm()->findChild<QCheckBox*>(QStringLiteral("square-on-one-surface"));
    QVERIFY(box);
    QVERIFY(box->isChecked());
    QVERIFY(!box->toolTip().isEmpty());
    const auto stored = [&] {
      return project::parameters<stereo::MatchParams>(window_->document()->project(), "matching")
          .squareOnOneSurface;
    };
    QVERIFY(stored());
    box->click();
    QVERIFY(!stored());
    window_->document()->undoStack()->undo();
    QVERIFY(stored());
    QVERIFY(box->isChecked());
    QTabWidget* tabs = showOnMatchingTab(box, QStringLiteral("matching-tab-one-surface.png"));
    QVERIFY(tabs);
    tabs->setCurrentIndex(0);
  }

  void aPairWithoutFeaturesAsksForTheRangeOnTheMatchingTab() {
    // Two flat images: no feature to match, so no range can be read from them.
    const cv::Mat flat(120, 160, CV_8U, cv::Scalar(100));
    const QString left = dir_.filePath(QStringLiteral("flat_left.tif"));
    const QString right = dir_.filePath(QStringLiteral("flat_right.tif"));
    io::writeGeoTiff(left.toStdString(), flat);
    io::writeGeoTiff(right.toStdString(), flat);
    QVERIFY(window_->openPair(left, right));
    auto* tabs = window_->findChild<QTabWidget*>(QStringLiteral("parameterTabs"));
    QVERIFY(tabs != nullptr);
    tabs->setCurrentIndex(0);
    QVERIFY(window_->startMatching() != 0);
    QVERIFY(window_->jobs()->waitForIdle(30000));
    const QString message = window_->lastMessage();
    QVERIFY2(message.contains(QStringLiteral("could not be estimated from the images: the left image is blank")),
             qPrintable(message));
    QVERIFY2(message.contains(QStringLiteral("Matching tab")), qPrintable(message));
    QVERIFY2(!message.contains(QStringLiteral("processing failed")), qPrintable(message));
    QVERIFY(window_->rangeNote()->text().startsWith(QStringLiteral("Not estimated: the left image is blank")));
    QCOMPARE(tabs->tabText(tabs->currentIndex()), QStringLiteral("Matching"));
    QVERIFY(!window_->document()->project().disparityRange);
    QVERIFY(window_->document()->disparity().empty());
    tabs->setCurrentIndex(0);
  }

  void colourPairIsShownInColourAndMatchedInGrey() {
    QVERIFY(openSyntheticPair(QStringLiteral("colour"), true));
    gui::Document* doc = window_->document();
    QCOMPARE(doc->leftGrey().type(), CV_8UC1);
    QCOMPARE(doc->pair().left.channels(), 1);
    QCOMPARE(doc->leftDisplay().type(), CV_8UC3);
    QCOMPARE(doc->rightDisplay().type(), CV_8UC3);
    QCOMPARE(window_->leftView()->image().type(), CV_8UC3);
    QCOMPARE(window_->rightView()->image().type(), CV_8UC3);
    // The roof is reddish on screen: red > green > blue (OpenCV's BGR order handled).
    widgets::ImageView* view = window_->leftView();
    view->setView(QPointF(140, 90), 2.0);
    const QImage shot = view->grab().toImage().convertToFormat(QImage::Format_RGB32);
    const QColor roof(shot.pixel(view->imageToWidget(QPointF(140.5, 90.5)).toPoint()));
    QVERIFY2(roof.red() > roof.green() + 30 && roof.green() > roof.blue() + 15,
             qPrintable(roof.name()));
    // The read-out gives the grey value matching works on.
    QTest::mouseMove(view, view->imageToWidget(QPointF(140.5, 90.5)).toPoint());
    QTRY_VERIFY(window_->readout()->text().contains(
        QStringLiteral("grey %1").arg(doc->leftGrey().at<uchar>(90, 140))));
    // A grey pair is shown grey (the grey image itself).
    QVERIFY(openSyntheticPair(QStringLiteral("grey"), false));
    QCOMPARE(window_->leftView()->image().type(), CV_8UC1);
    QCOMPARE(window_->document()->leftDisplay().data, window_->document()->leftGrey().data);
  }

  void imageFillsTheViewWhenItOpens() {
    // As delineo starts: the window is shown and the pair opened before the first layout.
    const project::Project sample = project::loadProject(projectPath_.toStdString());
    const QString left = QString::fromStdString(sample.left);
    const QString right = QString::fromStdString(sample.right);
    auto fills = [](widgets::ImageView* view) {
      const cv::Size size = view->imageSize();
      const QRectF shown(view->imageToWidget(QPointF(0, 0)),
                         view->imageToWidget(QPointF(size.width, size.height)));
      return std::abs(shown.width() - view->width()) < 1.0 ||
             std::abs(shown.height() - view->height()) < 1.0;
    };
    for (const bool asProject : {false, true}) {
      MainWindow fresh;
      fresh.setInteractive(false);
      fresh.resize(1300, 850);
      fresh.showActivated();
      QVERIFY(asProject ? fresh.openProject(projectPath_) : fresh.openPair(left, right));
      QVERIFY(QTest::qWaitForWindowExposed(&fresh));
      QTRY_VERIFY_WITH_TIMEOUT(fresh.jobs()->activeCount() == 0, 20000);
      widgets::ImageView* view = fresh.leftView();
      QVERIFY(view->width() > 300);
      QVERIFY2(fills(view), qPrintable(QStringLiteral("zoom %1 in a %2x%3 view")
                                           .arg(view->zoom())
                                           .arg(view->width())
                                           .arg(view->height())));
      QVERIFY(view->isFitted());
      // A disparity arriving later (its dock's view gets its first image) leaves it fitted.
      if (asProject) {
        const widgets::JobId job = fresh.startMatching();
        QTRY_VERIFY_WITH_TIMEOUT(!fresh.jobs()->isActive(job), 60000);
        QVERIFY(fresh.disparityView()->hasImage());
        QVERIFY(fills(view));
      }
      // Until the operator zooms: then a resize keeps the operator's view.
      view->zoomAround(2.0, QPointF(view->width() / 2.0, view->height() / 2.0));
      const double zoom = view->zoom();
      fresh.resize(1200, 800);
      QTRY_COMPARE(view->zoom(), zoom);
    }
  }

  void deletesAHoleAsOneUndoableStep() {
    QVERIFY(openSyntheticPair(QStringLiteral("hole"), false));
    gui::Document* doc = window_->document();
    core::Polygon courtyard;
    courtyard.outer = {{100, 60}, {180, 60}, {180, 120}, {100, 120}};
    courtyard.holes = {{{130, 80}, {150, 80}, {150, 100}, {130, 100}}};
    const int id = editBuilding(courtyard);
    QVERIFY(id > 0);
    QUndoStack* undo = doc->undoStack();
    const int steps = undo->count();
    // The hole's context menu, as a right-click on its ring opens it.
    widgets::ImageView* view = window_->leftView();
    QMenu menu;
    QVERIFY(view->polygons().fillContextMenu(menu, view->imageToWidget(QPointF(140, 80))));
    QAction* deleteHole = nullptr;
    for (QAction* a : menu.actions()) {
      if (a->text() == QStringLiteral("Delete hole")) deleteHole = a;
    }
    QVERIFY(deleteHole);
    deleteHole->trigger();
    QVERIFY(doc->project().find(id)->currentPolygon().holes.empty());
    QVERIFY(doc->project().find(id)->currentPolygon().outer == courtyard.outer);
    QVERIFY(view->polygons().selectedPolygon()->polygon.holes.empty());
    QCOMPARE(undo->count(), steps + 1);
    QCOMPARE(undo->undoText(), QStringLiteral("Delete hole"));
    QTest::keyClick(view, Qt::Key_Z, Qt::ControlModifier);
    QCOMPARE(doc->project().find(id)->currentPolygon().holes.size(), size_t(1));
    QVERIFY(doc->project().find(id)->currentPolygon().holes[0] == courtyard.holes[0]);
    QCOMPARE(view->polygons().selectedPolygon()->polygon.holes.size(), size_t(1));
    QTest::keyClick(view, Qt::Key_Y, Qt::ControlModifier);
    QVERIFY(doc->project().find(id)->currentPolygon().holes.empty());
    restoreEditDefaults();
  }

  void rubberBandDeletesVerticesAsOneUndoableStep() {
    QVERIFY(openSyntheticPair(QStringLiteral("band"), false));
    gui::Document* doc = window_->document();
    core::Polygon rough;
    rough.outer = {{100, 60}, {120, 58}, {140, 62}, {180, 60}, {180, 120}, {100, 120}};
    const int id = editBuilding(rough);
    QVERIFY(id > 0);
    widgets::ImageView* view = window_->leftView();
    auto at = [&](double x, double y) { return view->imageToWidget(QPointF(x, y)).toPoint(); };
    QTest::mousePress(view, Qt::LeftButton, Qt::ControlModifier, at(112, 50));
    QTest::mouseMove(view, at(130, 60));
    QTest::mouseMove(view, at(150, 66));
    QTest::mouseRelease(view, Qt::LeftButton, Qt::ControlModifier, at(150, 66));
    QCOMPARE(view->polygons().selectedVertices().size(), size_t(2));
    QUndoStack* undo = doc->undoStack();
    const int steps = undo->count();
    // Delete is also the window's "Remove building" shortcut: the view claims it here.
    QTest::keyClick(view, Qt::Key_Delete);
    QVERIFY(doc->project().find(id) != nullptr);
    const core::Ring expected{{100, 60}, {180, 60}, {180, 120}, {100, 120}};
    QVERIFY(doc->project().find(id)->currentPolygon().outer == expected);
    QCOMPARE(undo->count(), steps + 1);
    QCOMPARE(undo->undoText(), QStringLiteral("Delete 2 vertices"));
    undo->undo();
    QVERIFY(doc->project().find(id)->currentPolygon().outer == rough.outer);
    undo->redo();
    // A deletion that would leave 2 vertices is refused with a message; nothing changes.
    QSignalSpy messages(window_.get(), &MainWindow::messageShown);
    view->polygons().selectVerticesIn(QRectF(90, 50, 100, 20));
    QTest::keyClick(view, Qt::Key_Backspace);
    QCOMPARE(messages.count(), 1);
    QVERIFY(window_->lastMessage().contains(QStringLiteral("fewer than 3")));
    QVERIFY(doc->project().find(id)->currentPolygon().outer == expected);
    QCOMPARE(undo->count(), steps + 1);
    restoreEditDefaults();
  }

  void deleteOnAHoveredVertexDeletesTheVertexNotTheBuilding() {
    QVERIFY(openSyntheticPair(QStringLiteral("hover"), false));
    gui::Document* doc = window_->document();
    core::Polygon rough;
    rough.outer = {{100, 60}, {140, 58}, {180, 60}, {180, 120}, {100, 120}};
    const int id = editBuilding(rough);
    QVERIFY(id > 0);
    widgets::ImageView* view = window_->leftView();
    QTest::mouseMove(view, view->imageToWidget(QPointF(140, 58)).toPoint());
    QTest::keyClick(view, Qt::Key_Delete);
    QVERIFY2(doc->project().find(id) != nullptr, "the building was removed");
    QCOMPARE(doc->project().find(id)->currentPolygon().outer.size(), size_t(4));
    // Away from any vertex, Delete is the window's again: it removes the selected building.
    QTest::mouseMove(view, view->imageToWidget(QPointF(20, 20)).toPoint());
    QTest::keyClick(view, Qt::Key_Delete);
    QVERIFY(doc->project().find(id) == nullptr);
    restoreEditDefaults();
  }

  void everyMenuShortcutWorksWhateverWidgetHasFocus() {
    // A window of its own, started as delineo starts it: its actions are cut from their effects
    // (dialogs, quitting, jobs) so that only "the shortcut reached the action" is measured.
    MainWindow window;
    window.setInteractive(false);
    window.resize(1300, 850);
    window.showActivated();
    QVERIFY(QTest::qWaitForWindowActive(&window));
    QVERIFY(window.openProject(projectPath_));
    QTRY_VERIFY_WITH_TIMEOUT(window.jobs()->activeCount() == 0, 20000);
    struct Shortcut {
      QAction* action;
      QKeySequence keys;
    };
    std::vector<Shortcut> shortcuts;
    std::map<QAction*, int> fired;
    for (QAction* a : window.findChildren<QAction*>(QString(), Qt::FindDirectChildrenOnly)) {
      if (a->shortcuts().isEmpty()) continue;
      QObject::disconnect(a, &QAction::triggered, nullptr, nullptr);
      connect(a, &QAction::triggered, &window, [&fired, a] { ++fired[a]; });
      for (const QKeySequence& k : a->shortcuts()) shortcuts.push_back({a, k});
    }
    QVERIFY(shortcuts.size() >= 20);
    // A text field keeps what it types and edits with (letters, Delete, Ctrl+Z, Ctrl+E = end of
    // line on X11...): there, the commands of the File and Processing menus must still work.
    const QList<QKeySequence> commands{QKeySequence::New,         QKeySequence::Open,
                                       QKeySequence::Save,        QKeySequence::SaveAs,
                                       QKeySequence::Quit,        QKeySequence(tr("Ctrl+M")),
                                       QKeySequence(tr("Ctrl+R"))};
    auto* field = window.delineationForm()->findChild<QAbstractSpinBox*>();
    QVERIFY(field);
    window.showDock(QStringLiteral("rightDock"));
    const std::vector<QWidget*> targets{window.leftView(), window.rightView(), window.histogram(),
                                        window.buildingsTable(), field};
    QStringList missed;
    for (QWidget* target : targets) {
      target->setFocus(Qt::OtherFocusReason);
      QTRY_VERIFY2(target->hasFocus(), qPrintable(target->objectName()));
      for (const Shortcut& s : shortcuts) {
        if (target == field && !commands.contains(s.keys)) continue;
        s.action->setEnabled(true);
        const int before = fired[s.action];
        QTest::keySequence(target, s.keys);
        if (fired[s.action] != before + 1) {
          missed << QStringLiteral("%1 in %2").arg(s.keys.toString(), target->objectName());
        }
      }
    }
    QVERIFY2(missed.isEmpty(), qPrintable(missed.join(QStringLiteral(", "))));
  }

  void cleanupTestCase() { window_.reset(); }
};

QTEST_MAIN(MainWindowTest)
#include "test_main_window.moc"
