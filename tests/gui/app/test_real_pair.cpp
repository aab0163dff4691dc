// The operator's whole job on a real aerial pair (Toulouse 0051 from the shared data folder,
// skipped when it is absent), driven through the real main window with mouse and keys: open the
// pair (the range is estimated, the disparity computed), pick the big roof with a rectangle (the
// active polygon runs at once, its live contour stays on the building), accept, set the height
// model, look at the DEM and the 3D view, save, export; then a second building, and the big roof
// again with "Pick an above-ground object" (a click in its middle). Checks the range
// against the roof, the outline against a hand-drawn one (tests/bench/data/real_roofs.json),
// that nothing is written beside the images, and counts the operator's actions; then box-fitting
// beside the active polygon and the enhanced DEM; then the scene analysis's layers, Detect
// buildings on the whole tile and Outline the pending buildings; last, Split building on the top
// roof's outline and Import outlines of an outdated map of the tile (each outline scored against
// the hand-drawn roofs), and the review (Next building to review, Accept).
//
// DELINEO_DATA_DIR overrides the data folder; DELINEO_SCREENSHOT_DIR keeps a screenshot of each
// step (the user guide's images: scripts/screenshots.sh).
#include <QAction>
#include <QComboBox>
#include <QDir>
#include <QDirIterator>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QImage>
#include <QLabel>
#include <QPainter>
#include <QPixmap>
#include <QFile>
#include <QPushButton>
#include <algorithm>
#include <QSettings>
#include <QSignalSpy>
#include <QStandardPaths>
#include <QStatusBar>
#include <QTableView>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>
#include <QUndoStack>
#include <fstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/eval/polygon_measures.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/disparity_histogram.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "delineo/widgets/terrain3d_view.hpp"
#include "buildings_model.hpp"
#include "document.hpp"
#include "main_window.hpp"
#include "project_settings_dialog.hpp"

using namespace delineo;
using gui::MainWindow;

namespace {

QString dataDirectory() {
  const QString fromEnv = qEnvironmentVariable("DELINEO_DATA_DIR");
  return fromEnv.isEmpty() ? QStringLiteral(DELINEO_DEFAULT_DATA_DIR) : fromEnv;
}

// A hand-drawn roof outline of the labelled set.
core::Polygon handOutline(const std::string& name) {
  std::ifstream in(DELINEO_REAL_ROOFS);
  const nlohmann::json labelled = nlohmann::json::parse(in);
  core::Polygon outline;
  for (const auto& roof : labelled["roofs"]) {
    if (roof["name"] != name) continue;
    for (const auto& v : roof["outline"]) outline.outer.emplace_back(v[0].get<double>(), v[1].get<double>());
  }
  return outline;
}

// Median of the finite disparities inside the outline shrunk by `inset` px (the roof's level).
double roofLevel(const cv::Mat& disparity, const core::Polygon& outline, int inset) {
  cv::Mat mask = core::rasterize(outline, disparity.size());
  cv::erode(mask, mask, cv::getStructuringElement(cv::MORPH_RECT, {2 * inset + 1, 2 * inset + 1}));
  std::vector<float> values;
  for (int y = 0; y < disparity.rows; ++y) {
    for (int x = 0; x < disparity.cols; ++x) {
      const float d = disparity.at<float>(y, x);
      if (mask.at<uchar>(y, x) != 0 && std::isfinite(d)) values.push_back(d);
    }
  }
  if (values.empty()) return std::nan("");
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
  return values[values.size() / 2];
}

QStringList filesUnder(const QString& dir) {
  QStringList files;
  QDirIterator it(dir, QDir::Files | QDir::Hidden, QDirIterator::Subdirectories);
  while (it.hasNext()) files << it.next();
  files.sort();
  return files;
}

}  // namespace

class RealPairTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir dir_;
  QString imagesDir_, projectPath_;
  QStringList imagesBefore_;
  std::unique_ptr<MainWindow> window_;
  int actions_ = 0;  // operator actions after opening the pair
  int bigRoof_ = -1;
  int middle_ = -1;

  void shot(const QString& name) {
    const QString out = qEnvironmentVariable("DELINEO_SCREENSHOT_DIR");
    if (out.isEmpty()) return;
    QTest::qWait(300);  // docks laid out, tiles rendered
    QDir().mkpath(out);
    QVERIFY(window_->grab().save(QDir(out).filePath(name + QStringLiteral(".png"))));
  }

  // The DEM dock floating and large, on the nDSM in height colours (13-ndsm), then back.
  void showNdsm() {
    window_->showDock(QStringLiteral("demDock"));
    window_->findChild<QComboBox*>(QStringLiteral("demMode"))->setCurrentIndex(1);
    window_->action(QStringLiteral("actionDemLayerNdsm"))->trigger();
    QVERIFY(window_->demView()->image().data == window_->sceneAnalysis()->ndsm.data);
    QDockWidget* demDock = window_->dock(QStringLiteral("demDock"));
    demDock->setFloating(true);
    demDock->resize(760, 700);
    QTest::qWait(200);
    window_->demView()->fitToWindow();
    if (const QString out = qEnvironmentVariable("DELINEO_SCREENSHOT_DIR"); !out.isEmpty()) {
      QTest::qWait(300);
      QVERIFY(demDock->grab().save(QDir(out).filePath(QStringLiteral("13-ndsm.png"))));
    }
    demDock->setFloating(false);
    window_->action(QStringLiteral("actionDemLayerDem"))->trigger();
  }

  // Shows `region` (image pixels) whole in the left view; framing is navigation, not an action.
  void frame(const QRectF& region) {
    widgets::ImageView* view = window_->leftView();
    const double zoom = 0.85 * std::min(view->width() / region.width(), view->height() / region.height());
    view->setView(region.center(), zoom);
  }

  // The operator's pick: the rectangle tool (B), then a drag around the building.
  void pickWithRectangle(const QRectF& rect) {
    widgets::ImageView* view = window_->leftView();
    QTest::keyClick(view, Qt::Key_B);
    QCOMPARE(view->interactionMode(), widgets::InteractionMode::PickRectangle);
    drag(rect.topLeft(), rect.bottomRight());
    ++actions_;
  }

  // A left-button drag through the left view between two image points.
  void drag(QPointF fromPixel, QPointF toPixel) {
    widgets::ImageView* view = window_->leftView();
    const QPoint from = view->imageToWidget(fromPixel).toPoint();
    const QPoint to = view->imageToWidget(toPixel).toPoint();
    QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, from);
    QTest::mouseMove(view, (from + to) / 2);
    QTest::mouseMove(view, to);
    QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, to);
  }

  // The building whose outline overlaps `hand` most (-1 when none does), and their IoU.
  std::pair<int, double> closestOutline(const core::Polygon& hand) const {
    std::pair<int, double> best{-1, 0.0};
    for (const project::Building& b : window_->document()->project().buildings) {
      if (!b.hasOutline()) continue;
      const double iou = eval::intersectionOverUnion(b.outline, hand);
      if (iou > best.second) best = {b.id, iou};
    }
    return best;
  }

  // Runs the active polygon (Ctrl+R) on building `id`, selected, and waits for its outline.
  void runActivePolygon(int id) {
    window_->selectBuilding(id);
    QSignalSpy finished(window_.get(), &MainWindow::delineationFinished);
    QTest::keyClick(window_->leftView(), Qt::Key_R, Qt::ControlModifier);
    QTRY_VERIFY_WITH_TIMEOUT(!finished.isEmpty(), 300000);
    QCOMPARE(finished.first().at(0).toInt(), id);
  }

  // Split building (S) on building `id`, selected, with a line dragged from `from` to `to`: one
  // undoable step leaving two corrected pieces, the larger one keeping the id. Returns the other's id.
  int splitAlong(int id, QPointF from, QPointF to) {
    gui::Document* doc = window_->document();
    window_->activateWindow();
    if (!QTest::qWaitFor([&] { return window_->isActiveWindow(); })) return -1;
    window_->selectBuilding(id);
    QTest::keyClick(window_->leftView(), Qt::Key_S);
    if (window_->leftView()->interactionMode() != widgets::InteractionMode::PickLine) return -1;
    const size_t before = doc->project().buildings.size();
    const int undoIndex = doc->undoStack()->index();
    drag(from, to);
    qInfo("split: %s", qPrintable(window_->statusBar()->currentMessage()));
    if (doc->project().buildings.size() != before + 1) return -1;
    if (doc->undoStack()->index() != undoIndex + 1) return -1;
    const int piece = doc->project().buildings.back().id;
    for (int p : {id, piece}) {
      if (doc->project().find(p)->status != project::BuildingStatus::Corrected) return -1;
    }
    return window_->selectedBuilding() == id ? piece : -1;
  }

  // The hand-drawn roofs of 0051 moved by `shift` px, each with its name as "ref", written as
  // GeoJSON in the temporary folder (an outdated map of the tile).
  QString writeShiftedRoofs(const QString& name, cv::Point2d shift) {
    std::ifstream in(DELINEO_REAL_ROOFS);
    const nlohmann::json labelled = nlohmann::json::parse(in);
    std::vector<core::Feature> map;
    for (const auto& roof : labelled["roofs"]) {
      if (roof["pair"] != "toulouse_0051") continue;
      core::Feature f;
      f.polygon = handOutline(roof["name"].get<std::string>());
      for (cv::Point2d& v : f.polygon.outer) v += shift;
      f.attributes["ref"] = roof["name"].get<std::string>();
      map.push_back(f);
    }
    const QString path = dir_.filePath(name);
    io::writeFeatures(path.toStdString(), map, window_->document()->pair().geo);
    return path;
  }

  // Outline the pending buildings, which are `id` alone, and waits for it.
  void outlinePending(int id) {
    QCOMPARE(window_->document()->project().pendingBuildings(), std::vector<int>{id});
    QSignalSpy outlined(window_.get(), &MainWindow::pendingOutlined);
    window_->action(QStringLiteral("actionOutlinePending"))->trigger();
    QTRY_VERIFY_WITH_TIMEOUT(!outlined.isEmpty(), 300000);
    QCOMPARE(outlined.first().at(0).toInt(), 1);
  }

  // Waits for the building's active polygon while checking every live contour drawn meanwhile
  // against `region` (the picked rectangle grown by the search margin).
  void waitForOutline(int id, const QRectF& region, int* contoursSeen) {
    QSignalSpy finished(window_.get(), &MainWindow::delineationFinished);
    double worst = 0;
    QTimer probe;
    connect(&probe, &QTimer::timeout, [&] {
      const QPolygonF live = window_->leftView()->polygons().evolvingContour();
      if (live.isEmpty()) return;
      ++*contoursSeen;
      for (const QPointF& p : live) {
        const double dx = std::max({region.left() - p.x(), p.x() - region.right(), 0.0});
        const double dy = std::max({region.top() - p.y(), p.y() - region.bottom(), 0.0});
        worst = std::max(worst, std::hypot(dx, dy));
      }
    });
    probe.start(15);
    QTRY_VERIFY_WITH_TIMEOUT(!finished.isEmpty(), 300000);
    probe.stop();
    QCOMPARE(finished.first().at(0).toInt(), id);
    QVERIFY2(worst == 0.0, qPrintable(QStringLiteral("a live contour vertex was %1 px off the picked region").arg(worst)));
  }

 private slots:
  void initTestCase() {
    const QString data = dataDirectory();
    const QString left = data + QStringLiteral("/aerial-toulouse/31_15083_31_15084_0051_left.png");
    const QString right = data + QStringLiteral("/aerial-toulouse/31_15083_31_15084_0051_right.png");
    if (!QFile::exists(left) || !QFile::exists(right)) QSKIP("the real Toulouse pair is not here (../shared/data)");
    QStandardPaths::setTestModeEnabled(true);
    QCoreApplication::setOrganizationName(QStringLiteral("DelineoRealPairTest"));
    QSettings().clear();  // defaults: automatic range and matching, delineate on pick
    QVERIFY(dir_.isValid());
    // The operator's copy of the pair in a folder of its own, to see what gets written there.
    imagesDir_ = dir_.filePath(QStringLiteral("images"));
    QVERIFY(QDir().mkpath(imagesDir_));
    QVERIFY(QFile::copy(left, imagesDir_ + QStringLiteral("/left.png")));
    QVERIFY(QFile::copy(right, imagesDir_ + QStringLiteral("/right.png")));
    imagesBefore_ = filesUnder(imagesDir_);
    projectPath_ = dir_.filePath(QStringLiteral("project/toulouse-0051.delineo.json"));
    window_ = std::make_unique<MainWindow>();
    window_->setInteractive(false);
    window_->resize(1500, 950);
    window_->showActivated();
    QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
  }

  void opensThePairWithARangeThatHoldsTheRoofs() {
    QSignalSpy matched(window_.get(), &MainWindow::matchingFinished);
    QVERIFY(window_->openPair(imagesDir_ + QStringLiteral("/left.png"), imagesDir_ + QStringLiteral("/right.png")));
    QTRY_VERIFY_WITH_TIMEOUT(!matched.isEmpty(), 300000);
    const gui::Document* doc = window_->document();
    const auto range = doc->project().disparityRange;
    QVERIFY(range.has_value());
    const double roof = roofLevel(doc->disparity(), handOutline("t51_right_big"), 8);
    qInfo("estimated range %d..%d px; the big roof at %.1f px", range->low, range->high, roof);
    QVERIFY2(roof > range->low + 1 && roof < range->high - 1, "the big roof lies outside the estimated range");
    QVERIFY(doc->leftDisplay().channels() == 3);  // shown in colour
    shot(QStringLiteral("01-pair-opened"));
  }

  void delineatesTheBigRoofWithOnePick() {
    const core::Polygon hand = handOutline("t51_right_big");
    QVERIFY(hand.outer.size() >= 4);
    const cv::Rect2d box = core::boundingBox(hand.outer);
    // An operator's rough rectangle: 15 px around the roof, inside the image.
    const QRectF pick = QRectF(box.x - 15, box.y - 15, box.width + 30, box.height + 30) & QRectF(0, 0, 1024, 1024);
    frame(pick.adjusted(-40, -40, 40, 40));
    pickWithRectangle(pick);
    bigRoof_ = window_->selectedBuilding();
    QVERIFY(bigRoof_ > 0);
    shot(QStringLiteral("02-building-picked"));
    int contours = 0;
    waitForOutline(bigRoof_, pick.adjusted(-40, -40, 40, 40), &contours);
    QVERIFY(contours > 0);
    const project::Building* b = window_->document()->project().find(bigRoof_);
    QVERIFY(b->hasOutline());
    const double iou = eval::intersectionOverUnion(b->outline, hand);
    qInfo("big roof: IoU %.3f against the hand outline, %zu vertices, %d live contours seen", iou,
          b->outline.outer.size(), contours);
    QVERIFY2(iou >= 0.9, qPrintable(QStringLiteral("IoU %1").arg(iou)));
    shot(QStringLiteral("03-delineated"));
  }

  void acceptsAndShowsHeightsIn2DAnd3D() {
    QTest::keyClick(window_->leftView(), Qt::Key_A);
    ++actions_;
    gui::Document* doc = window_->document();
    QVERIFY(doc->project().find(bigRoof_)->status == project::BuildingStatus::Accepted);
    QVERIFY(!window_->heightModelNotice()->isHidden());
    // The pair's height model, set once per project: ground from the disparity map, 0.25 m of
    // height per pixel of disparity (a 5 cm image with a base of a fifth of the flying height).
    window_->setProjectSettingsHandler([](gui::ProjectSettingsDialog& dialog) {
      auto* fromMap = dialog.findChild<QPushButton*>(QStringLiteral("groundFromMap"));
      if (fromMap == nullptr) return false;
      fromMap->click();
      dialog.findChild<QDoubleSpinBox*>(QStringLiteral("metresPerPixel"))->setValue(0.25);
      dialog.findChild<QDoubleSpinBox*>(QStringLiteral("gsd"))->setValue(0.05);
      return true;
    });
    window_->openProjectSettings();
    QVERIFY(doc->project().height.known());
    QVERIFY(std::abs(doc->project().height.groundDisparity - 8.0) < 2.5);
    const double height = doc->project().find(bigRoof_)->roofHeight;
    qInfo("big roof: %.1f m above the ground", height);
    QVERIFY(height > 10.0 && height < 25.0);
    QVERIFY(window_->heightModelNotice()->isHidden());
    QVERIFY(!doc->dem().empty());
    window_->showDock(QStringLiteral("demDock"));
    window_->findChild<QComboBox*>(QStringLiteral("demMode"))->setCurrentIndex(1);
    QVERIFY(window_->demView()->hasImage());
    shot(QStringLiteral("05-accepted-dem"));
    window_->showDock(QStringLiteral("view3DDock"));
    if (qEnvironmentVariableIsEmpty("DISPLAY")) return;  // the 3D view needs an X server
    QTRY_VERIFY_WITH_TIMEOUT(window_->view3D() != nullptr, 10000);
    QVERIFY(window_->view3D()->displayedGridSize().width > 0);
    shot(QStringLiteral("06-3d-view"));
  }

  void savesAndExportsIntoTheProjectFolderOnly() {
    QVERIFY(window_->saveAs(projectPath_));
    ++actions_;
    const QString exported = window_->document()->outputDirectory() + QStringLiteral("/buildings.geojson");
    QCOMPARE(window_->exportOutlines(exported), 1);
    ++actions_;
    QCOMPARE(QFileInfo(exported).absolutePath(), dir_.filePath(QStringLiteral("project/output")));
    QVERIFY(QFile::exists(dir_.filePath(QStringLiteral("project/output/disparity.tif"))));
    QCOMPARE(filesUnder(imagesDir_), imagesBefore_);
    qInfo("big roof: %d operator actions after opening the pair", actions_);
    QVERIFY(actions_ <= 4);
  }

  void delineatesASecondBuilding() {
    const core::Polygon hand = handOutline("t51_middle_main");
    QVERIFY(hand.outer.size() >= 4);
    const cv::Rect2d box = core::boundingBox(hand.outer);
    actions_ = 0;
    // The operator clicks back into the main window after the 3D view; the window manager then
    // gives it the keyboard again (Xvfb has none, so the test does it).
    window_->activateWindow();
    QTRY_VERIFY(window_->isActiveWindow());
    const QRectF pick(box.x - 15, box.y - 15, box.width + 30, box.height + 30);
    frame(pick.adjusted(-40, -40, 40, 40));
    pickWithRectangle(pick);
    const int id = window_->selectedBuilding();
    int contours = 0;
    waitForOutline(id, pick.adjusted(-40, -40, 40, 40), &contours);
    const project::Building* b = window_->document()->project().find(id);
    const double iou = eval::intersectionOverUnion(b->outline, hand);
    qInfo("middle building: IoU %.3f, %zu vertices with the proposed interval %d..%d px", iou,
          b->outline.outer.size(), b->roofInterval->low, b->roofInterval->high);
    // Its lower inner roof (about 72 px) inside the raised ring (80-83 px) is part of the
    // building: the proposed interval reaches down to it.
    QVERIFY(b->roofInterval->low <= 71 && b->roofInterval->high >= 82);
    shot(QStringLiteral("04-second-building"));
    QTest::keyClick(window_->leftView(), Qt::Key_A);
    ++actions_;
    QVERIFY(window_->document()->project().find(id)->status == project::BuildingStatus::Accepted);
    qInfo("middle building: %d operator actions", actions_);
    QVERIFY(iou >= 0.85);
    middle_ = id;
  }

  // The middle building's lower inner roof (about 72 px, 16 m) inside its raised ring (80-83 px,
  // 18 m): the 3D view draws one block per roof level, at their heights.
  void showsTheMiddleBuildingsRoofLevelsIn3D() {
    if (qEnvironmentVariableIsEmpty("DISPLAY")) QSKIP("the 3D view needs an X server");
    QVERIFY(middle_ > 0);
    window_->selectBuilding(middle_);
    window_->showDock(QStringLiteral("view3DDock"));
    QTRY_VERIFY_WITH_TIMEOUT(window_->view3D() != nullptr, 10000);
    const core::Polygon outline = window_->document()->project().find(middle_)->outline;
    const cv::Rect2d box = core::boundingBox(outline.outer);
    std::vector<double> tops;
    for (const widgets::BuildingOutline& block : window_->view3D()->buildings()) {
      const cv::Rect2d blockBox = core::boundingBox(block.polygon.outer);
      if ((blockBox & box).area() > 0.9 * blockBox.area()) tops.push_back(block.topHeight);
    }
    std::sort(tops.begin(), tops.end());
    QString list;
    for (double top : tops) list += QString::number(top, 'f', 1) + QStringLiteral(" m ");
    qInfo("middle building: %zu blocks in the 3D view: %s", tops.size(), qPrintable(list));
    QVERIFY2(tops.size() >= 2, qPrintable(list));
    QVERIFY2(tops.front() > 14.5 && tops.front() < 17.0 && tops.back() > 17.0 && tops.back() < 19.5, qPrintable(list));
    window_->findChild<QPushButton*>(QStringLiteral("view3DFrame"))->click();  // on the selected building
    shot(QStringLiteral("16-3d-roof-levels"));
  }

  // Box-fitting beside the active polygon on the big roof (accepted above), then the choice to keep
  // the active polygon's outline; the enhanced DEM from the two outlines.
  void boxFittingBesideTheActivePolygon() {
    const core::Polygon hand = handOutline("t51_right_big");
    window_->selectBuilding(bigRoof_);
    const project::Building before = *window_->document()->project().find(bigRoof_);
    QSignalSpy done(window_.get(), &MainWindow::boxFittingFinished);
    window_->action(QStringLiteral("actionBoxFit"))->trigger();
    QTRY_VERIFY_WITH_TIMEOUT(!done.isEmpty(), 120000);
    QVERIFY2(window_->hasBoxFitProposal(bigRoof_), qPrintable(window_->lastMessage()));
    const widgets::OverlayGuide fitted = window_->leftView()->polygons().guides().back();
    qInfo("big roof: box-fitting IoU %.3f (%zu vertices, %zu boxes), active polygon IoU %.3f",
          eval::intersectionOverUnion(fitted.polygon, hand), fitted.polygon.outer.size(),
          window_->leftView()->polygons().guides().size() - 1, eval::intersectionOverUnion(before.outline, hand));
    // The left view wide, the right image beside it.
    window_->showDock(QStringLiteral("rightDock"));
    window_->resizeDocks({window_->dock(QStringLiteral("rightDock"))}, {420}, Qt::Horizontal);
    QTest::qWait(100);
    const cv::Rect2d box = core::boundingBox(hand.outer);
    frame(QRectF(box.x - 30, box.y - 30, box.width + 60, box.height + 60));
    shot(QStringLiteral("07-box-fitting"));
    window_->action(QStringLiteral("actionDiscardBoxFit"))->trigger();
    QVERIFY(window_->document()->project().find(bigRoof_)->outline.outer == before.outline.outer);
  }

  void enhancedDemFromTheOutlines() {
    window_->selectBuilding(-1);
    window_->showDock(QStringLiteral("demDock"));
    window_->findChild<QComboBox*>(QStringLiteral("demMode"))->setCurrentIndex(0);  // hillshade
    // The DEM view large enough to read (a floating dock), on the two delineated buildings.
    QDockWidget* demDock = window_->dock(QStringLiteral("demDock"));
    demDock->setFloating(true);
    demDock->resize(820, 520);
    QTest::qWait(200);
    const QRectF both(240, 170, 784, 420);
    widgets::ImageView* demView = window_->demView();
    demView->setView(both.center(), 0.98 * std::min(demView->width() / both.width(), demView->height() / both.height()));
    const QPixmap plain = window_->demView()->grab();
    QSignalSpy enhanced(window_.get(), &MainWindow::demEnhanced);
    window_->action(QStringLiteral("actionEnhancedDem"))->trigger();
    QTRY_VERIFY_WITH_TIMEOUT(!enhanced.isEmpty(), 120000);
    QVERIFY(window_->shownDem().data != window_->document()->dem().data);
    QTest::qWait(300);
    // The DEM view before and after, side by side.
    if (const QString out = qEnvironmentVariable("DELINEO_SCREENSHOT_DIR"); !out.isEmpty()) {
      const QPixmap after = window_->demView()->grab();
      QImage pair(plain.width() + after.width() + 8, plain.height(), QImage::Format_RGB32);
      pair.fill(Qt::white);
      QPainter painter(&pair);
      painter.drawPixmap(0, 0, plain);
      painter.drawPixmap(plain.width() + 8, 0, after);
      painter.end();
      QVERIFY(pair.save(QDir(out).filePath(QStringLiteral("08-enhanced-dem.png"))));
    }
    demDock->setFloating(false);
    // Off again: the project's DEM.
    window_->action(QStringLiteral("actionEnhancedDem"))->trigger();
    QVERIFY(window_->shownDem().data == window_->document()->dem().data);
  }

  // "Pick an above-ground object" (O, then a click) in the middle of the big roof: the roof,
  // whose 350 px extent the former pick's 121 px window could not see past, becomes the initial
  // polygon, and the histogram's ground line is the ground that cut it out.
  void picksTheBigRoofAsAnAboveGroundObject() {
    const core::Polygon hand = handOutline("t51_right_big");
    window_->activateWindow();
    QTRY_VERIFY(window_->isActiveWindow());
    frame(QRectF(560, 140, 464, 460));
    widgets::ImageView* view = window_->leftView();
    QTest::keyClick(view, Qt::Key_O);
    QCOMPARE(view->interactionMode(), widgets::InteractionMode::PickPoint);
    const int before = window_->selectedBuilding();
    QSignalSpy finished(window_.get(), &MainWindow::delineationFinished);
    const QPointF click(760.5, 380.5);
    QTest::mouseClick(view, Qt::LeftButton, Qt::NoModifier, view->imageToWidget(click).toPoint());
    const int id = window_->selectedBuilding();
    QVERIFY2(id > 0 && id != before, qPrintable(QStringLiteral("no object picked: %1").arg(window_->lastMessage())));
    const gui::Document* doc = window_->document();
    const core::Polygon initial = doc->project().find(id)->initial;
    const double iou = eval::intersectionOverUnion(initial, hand);
    const project::ObjectPick pick =
        project::pickAboveGroundObject(doc->project(), doc->disparity(), doc->dem(), {click.x(), click.y()});
    qInfo("picked object: IoU %.3f against the hand outline, %zu vertices, ground %.2f px (%.2f m)", iou,
          initial.outer.size(), pick.groundLevel, pick.groundHeight);
    QVERIFY2(iou >= 0.85, qPrintable(QStringLiteral("IoU %1").arg(iou)));
    const auto line = window_->histogram()->groundLevel();
    QVERIFY(line.has_value());
    QCOMPARE(*line, pick.groundLevel);
    shot(QStringLiteral("09-object-picked"));
    QTRY_VERIFY_WITH_TIMEOUT(!finished.isEmpty(), 300000);
    qInfo("picked object after the active polygon: IoU %.3f",
          eval::intersectionOverUnion(doc->project().find(id)->outline, hand));
    shot(QStringLiteral("10-object-delineated"));
  }

  // The whole tile at once: Analyse the scene (its classes, objects and nDSM as layers), then
  // Detect buildings adds the building objects that are not buildings yet as pending buildings, in
  // one undoable step; the buildings delineated above are not proposed again.
  void detectsTheTilesBuildings() {
    window_->selectBuilding(-1);
    window_->activateWindow();
    window_->leftView()->fitToWindow();
    QSignalSpy analysed(window_.get(), &MainWindow::sceneAnalysed);
    window_->action(QStringLiteral("actionShowClasses"))->trigger();  // runs the analysis
    QTRY_VERIFY_WITH_TIMEOUT(!analysed.isEmpty(), 300000);
    const project::SceneAnalysisOutcome* scene = window_->sceneAnalysis();
    QVERIFY(scene != nullptr && window_->leftView()->overlayVisible());
    const cv::Mat roof = core::rasterize(handOutline("t51_right_big"), scene->classes.size());
    const double roofBuilding =
        static_cast<double>(cv::countNonZero(roof & (scene->classes == 1))) / cv::countNonZero(roof);
    qInfo("scene: %zu objects, %zu proposals; %.1f %% of the big roof classified building", scene->objects.size(),
          scene->proposals.size(), 100 * roofBuilding);
    // The classes are the command line's (delineo-cli segment on the same DEM: 3 building and 2
    // vegetation objects); on this pair the big roof's gravel reads as vegetation.
    QVERIFY(scene->objects.size() >= 3);
    shot(QStringLiteral("11-classes"));
    window_->action(QStringLiteral("actionShowClasses"))->trigger();
    window_->action(QStringLiteral("actionShowObjects"))->trigger();
    QCOMPARE(window_->leftView()->polygons().guides().size(), scene->objects.size());
    shot(QStringLiteral("12-objects"));
    window_->action(QStringLiteral("actionShowObjects"))->trigger();
    showNdsm();
    const int undoIndex = window_->document()->undoStack()->index();
    const size_t before = window_->document()->project().buildings.size();
    QSignalSpy detected(window_.get(), &MainWindow::buildingsDetected);
    window_->action(QStringLiteral("actionDetectBuildings"))->trigger();
    QCOMPARE(detected.count(), 1);  // the analysis is there: at once
    const int added = detected.first().at(0).toInt(), present = detected.first().at(1).toInt();
    qInfo("detect buildings: %d proposed, %d already present", added, present);
    QVERIFY(added >= 1);
    QCOMPARE(window_->document()->project().buildings.size(), before + static_cast<size_t>(added));
    QCOMPARE(window_->document()->undoStack()->index(), undoIndex + 1);
    shot(QStringLiteral("14-detected"));
  }

  // Outline the pending buildings: the detected proposals outlined in turn by the active polygon,
  // as `delineo-cli run --detect` does, then scored against the hand-drawn roofs they cover.
  void outlinesTheProposals() {
    gui::Document* doc = window_->document();
    const std::vector<int> pending = doc->project().pendingBuildings();
    QVERIFY(!pending.empty());
    QSignalSpy outlined(window_.get(), &MainWindow::pendingOutlined);
    window_->action(QStringLiteral("actionOutlinePending"))->trigger();
    QTRY_VERIFY_WITH_TIMEOUT(!outlined.isEmpty(), 600000);
    QCOMPARE(outlined.first().at(0).toInt(), static_cast<int>(pending.size()));
    QVERIFY(doc->project().pendingBuildings().empty());
    // Each hand-drawn roof whose most overlapping outline is one of these.
    std::ifstream in(DELINEO_REAL_ROOFS);
    const nlohmann::json labelled = nlohmann::json::parse(in);
    double sum = 0;
    int reached = 0;
    for (const auto& roof : labelled["roofs"]) {
      if (roof["pair"] != "toulouse_0051") continue;
      const auto [bestId, best] = closestOutline(handOutline(roof["name"].get<std::string>()));
      if (std::find(pending.begin(), pending.end(), bestId) == pending.end() || best < 0.5) continue;
      qInfo("%s: IoU %.3f (building %d)", roof["name"].get<std::string>().c_str(), best, bestId);
      sum += best;
      ++reached;
    }
    QVERIFY(reached >= 2);
    qInfo("outlined proposals: %d roofs reached, mean IoU %.3f", reached, sum / reached);
    QVERIFY(sum / reached > 0.8);
    shot(QStringLiteral("15-proposals-outlined"));
  }

  // Split building (S) on the top roof's outline, which took in the annex north of the raised
  // block (t51_top, 59-60 px; t51_middle_annex, 51 px): a line dragged through the left view along
  // the wall between them, from outside the outline to outside it, cuts it in two, each piece
  // with the roof interval of its own disparities; the active polygon then outlines each piece
  // again (Ctrl+R).
  void splitsTheTopRoofFromItsAnnex() {
    const core::Polygon top = handOutline("t51_top"), annex = handOutline("t51_middle_annex");
    const auto [id, topBefore] = closestOutline(top);
    QVERIFY(id > 0);
    const gui::Document* doc = window_->document();
    const double annexTaken =
        eval::intersectionArea(doc->project().find(id)->outline, annex) / core::area(annex);
    qInfo("top roof: building %d, IoU %.3f, holding %.0f %% of the annex", id, topBefore, 100 * annexTaken);
    QVERIFY(annexTaken > 0.8);
    frame(QRectF(200, 0, 500, 340));
    const int piece = splitAlong(id, {240, 185}, {595, 185});
    QVERIFY(piece > 0);
    for (int p : {id, piece}) runActivePolygon(p);
    const double topIou = eval::intersectionOverUnion(doc->project().find(id)->outline, top);
    const double annexIou = eval::intersectionOverUnion(doc->project().find(piece)->outline, annex);
    qInfo("split: the top roof (building %d) IoU %.3f, the annex (building %d) IoU %.3f", id, topIou, piece,
          annexIou);
    // The annex's piece keeps the raised block's north facade, which the hand outline leaves out.
    QVERIFY2(topIou >= 0.96 && annexIou >= 0.75,
             qPrintable(QStringLiteral("IoU %1, %2").arg(topIou).arg(annexIou)));
    frame(QRectF(230, 0, 470, 560));
    shot(QStringLiteral("17-split"));
  }

  // File → Import outlines with an outdated map of the tile: the hand-drawn roofs of 0051 shifted
  // by (6, −5) px, each with its "ref". The roofs that are buildings already stay out; the one that
  // is not (the small one-storey roof on the left border) comes in as a pending building with its
  // source id, and Outline the pending buildings outlines it from the map's polygon.
  void importsAMapOfTheTile() {
    const QString path = writeShiftedRoofs(QStringLiteral("map.geojson"), {6, -5});
    QString asked;
    window_->setIdFieldHandler([&asked](const QStringList&, const QString& preselected) {
      asked = preselected;
      return std::optional<QString>(preselected);
    });
    gui::Document* doc = window_->document();
    const size_t before = doc->project().buildings.size();
    QSignalSpy imported(window_.get(), &MainWindow::outlinesImported);
    const int added = window_->importOutlines(path);
    qInfo("import: %s", qPrintable(window_->lastMessage()));
    QCOMPARE(asked, QStringLiteral("ref"));
    QCOMPARE(added, 1);
    QCOMPARE(imported.first().at(1).toInt(), 8);  // read
    QVERIFY(window_->lastMessage().contains(QStringLiteral("7 already in the project")));
    QCOMPARE(doc->project().buildings.size(), before + 1);
    const project::Building& left = doc->project().buildings.back();
    QCOMPARE(left.sourceId, std::string("t51_left_low"));
    QVERIFY(!window_->buildingsTable()->isColumnHidden(gui::BuildingsModel::SourceId));
    const int id = left.id;
    outlinePending(id);
    const core::Polygon hand = handOutline("t51_left_low"), outline = doc->project().find(id)->outline;
    const double iou = eval::intersectionOverUnion(outline, hand);
    qInfo("imported t51_left_low (building %d): IoU %.3f as imported, %.3f outlined", id,
          eval::intersectionOverUnion(doc->project().find(id)->initial, hand), iou);
    // The outline leaves the map's shift on the east and south edges, which the matcher sees; the
    // roof's west part, unmatched next to the image border, stays out of it.
    const cv::Rect2d got = core::boundingBox(outline.outer), drawn = core::boundingBox(hand.outer);
    qInfo("  east edge at %.1f px, south edge at %.1f px (hand-drawn: %.1f, %.1f)", got.br().x, got.br().y,
          drawn.br().x, drawn.br().y);
    QVERIFY(std::abs(got.br().x - drawn.br().x) <= 2.0 && std::abs(got.br().y - drawn.br().y) <= 2.0);
    QVERIFY2(iou >= 0.6, qPrintable(QStringLiteral("IoU %1").arg(iou)));
    frame(QRectF(0, 180, 260, 180));
    QTableView* table = window_->buildingsTable();
    const int lastRow = table->model()->rowCount() - 1;
    table->scrollTo(table->model()->index(lastRow, gui::BuildingsModel::SourceId));
    shot(QStringLiteral("18-imported"));
  }

  // Review: Next building to review (N) from no selection goes to the first outline awaiting a
  // decision in the list, then to the next, the top roof; Accept (A) there goes on to the one after
  // by itself; the status bar's count follows.
  void reviewsTheOutlines() {
    window_->activateWindow();
    QTRY_VERIFY(window_->isActiveWindow());
    window_->selectBuilding(-1);
    frame(QRectF(200, 0, 824, 700));
    const gui::Document* doc = window_->document();
    std::vector<int> awaiting;
    for (const project::Building& b : doc->project().buildings) {
      using project::BuildingStatus;
      if (b.status == BuildingStatus::Automatic || b.status == BuildingStatus::Corrected) awaiting.push_back(b.id);
    }
    QCOMPARE(window_->reviewProgress()->text(),
             QStringLiteral("To review: %1 outlined · 2 accepted").arg(awaiting.size()));
    widgets::ImageView* view = window_->leftView();
    for (size_t k = 0; k < 2; ++k) {
      QTest::keyClick(view, Qt::Key_N);
      QCOMPARE(window_->selectedBuilding(), awaiting[k]);
    }
    QCOMPARE(awaiting[1], closestOutline(handOutline("t51_top")).first);
    QTest::keyClick(view, Qt::Key_A);
    QVERIFY(doc->project().find(awaiting[1])->status == project::BuildingStatus::Accepted);
    QCOMPARE(window_->selectedBuilding(), awaiting[2]);
    const QString progress = window_->reviewProgress()->text();
    qInfo("review: %s", qPrintable(progress));
    QCOMPARE(progress, QStringLiteral("To review: %1 outlined · 3 accepted").arg(awaiting.size() - 1));
    shot(QStringLiteral("19-review"));
  }

  void cleanupTestCase() { window_.reset(); }
};

QTEST_MAIN(RealPairTest)
#include "test_real_pair.moc"
