// Split building and Merge with… in the real main window: a line dragged (or clicked end to end)
// across the selected building cuts it in two as one undoable step, its pieces scored in the
// background; a line that does not cross it is refused with nothing changed; the next building
// clicked after Merge with… is merged into the selected one, undo bringing both back with their
// ids and outlines; Esc leaves that mode; Merge buildings of two rows of the Buildings list; the
// actions disabled when they cannot apply; the French strings.
#include <QAction>
#include <QItemSelectionModel>
#include <QStatusBar>
#include <QTableView>
#include <QTemporaryDir>
#include <QTest>
#include <QTranslator>
#include <QUndoStack>
#include <cmath>

#include <opencv2/core.hpp>

#include "buildings_model.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/image_view.hpp"
#include "document.hpp"
#include "main_window.hpp"
#include "sample_window.hpp"

using namespace delineo;
using gui::MainWindow;
using project::BuildingStatus;
using widgets::InteractionMode;

namespace {

core::Polygon rectangle(double x, double y, double w, double h) {
  core::Polygon p;
  p.outer = {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}};
  return p;
}

// The street at 8 px, the roofs at 30 px: the split building and the two merged ones.
cv::Mat roofDisparity(cv::Size size) {
  cv::Mat d(size, CV_32F, cv::Scalar(8.0f));
  d(cv::Rect(100, 100, 200, 100)).setTo(30.0f);
  d(cv::Rect(100, 300, 200, 80)).setTo(30.0f);
  return d;
}

// Statuses compared as their names, so a failure prints them.
QString st(BuildingStatus status) { return QString::fromStdString(project::toString(status)); }

bool samePolygon(const core::Polygon& a, const core::Polygon& b) { return a.outer == b.outer && a.holes == b.holes; }

}  // namespace

class SplitMergeTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir dir_;
  std::unique_ptr<MainWindow> window_;
  // The building to split; two buildings side by side (a wall between them); one far from them.
  int wide_ = -1, left_ = -1, right_ = -1, far_ = -1;
  int baseIndex_ = 0;  // the undo stack's index once they are made

  gui::Document* doc() const { return window_->document(); }
  QAction* act(const char* name) const { return window_->action(QString::fromLatin1(name)); }
  int count() const { return static_cast<int>(doc()->project().buildings.size()); }
  const project::Building* building(int id) const { return doc()->project().find(id); }
  QPoint at(double x, double y) const { return window_->leftView()->imageToWidget(QPointF(x, y)).toPoint(); }
  QString message() const { return window_->statusBar()->currentMessage(); }
  // Selects the building with the whole image in the left view, so that every point clicked is on screen.
  void select(int id) {
    window_->selectBuilding(id);
    window_->leftView()->fitToWindow();
  }

  // A building whose outline is `outline` with the roof interval 28..32 px, as the active polygon leaves it.
  int outlined(const core::Polygon& outline) {
    const int id = doc()->addBuilding(rectangle(outline.outer[0].x + 5, outline.outer[0].y + 5, 10, 10));
    doc()->setRoofInterval(id, project::DisparityInterval{28, 32});
    project::DelineationOutcome outcome;
    outcome.outline = outline;
    outcome.energy = -1.0;
    doc()->setDelineationResult(id, outcome);
    return id;
  }

  // A 640 x 480 noise pair with the disparity of roofDisparity().
  bool openPair() {
    const cv::Size size(640, 480);
    if (!guitest::openPairWithoutHeights(*window_, dir_, size)) return false;
    doc()->setDisparity(roofDisparity(size));
    return true;
  }

  void activate() {
    window_->activateWindow();
    QVERIFY(QTest::qWaitForWindowActive(window_.get()));
    window_->leftView()->setFocus();
  }

  void drag(QPoint from, QPoint to) {
    widgets::ImageView* view = window_->leftView();
    QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, from);
    QTest::mouseMove(view, from + (to - from) / 2);
    QTest::mouseMove(view, to);
    QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, to);
  }

  // True when a pixel of the view's picture near the segment from `a` to `b` has the colour of
  // the line being drawn (the noise image is grey, the outlines cyan or orange, the selected
  // building's region of interest a darker yellow).
  bool lineShown(QPoint a, QPoint b) {
    const QImage shot = window_->leftView()->grab().toImage();
    for (int k = 0; k <= 20; ++k) {
      const QPoint p = a + (b - a) * k / 20;
      for (int dx = -1; dx <= 1; ++dx) {
        const QColor c = shot.pixelColor(p + QPoint(dx, 0));
        if (c.red() > 230 && c.green() > 210 && c.blue() < 60) return true;
      }
    }
    return false;
  }

 private slots:
  void initTestCase() {
    guitest::isolateSettings(QStringLiteral("DelineoSplitMergeTest"), false);
    QVERIFY(dir_.isValid());
    window_ = guitest::showMainWindow();
    QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
    QVERIFY(openPair());
    wide_ = outlined(rectangle(100, 100, 200, 100));
    // One building: nothing to merge it with, but it can be split.
    select(wide_);
    QVERIFY(act("actionSplit")->isEnabled());
    QVERIFY(!act("actionMergeWith")->isEnabled());
    left_ = outlined(rectangle(100, 300, 100, 80));
    right_ = outlined(rectangle(200, 300, 100, 80));
    far_ = outlined(rectangle(450, 50, 60, 60));
    QCOMPARE(count(), 4);
    baseIndex_ = doc()->undoStack()->index();
  }

  // Each test starts from the buildings as made, none selected, the left view in Navigate.
  void init() {
    doc()->undoStack()->setIndex(baseIndex_);
    window_->selectBuilding(-1);
    window_->leftView()->setInteractionMode(InteractionMode::Navigate);
    window_->statusBar()->clearMessage();
  }

  void actionsNeedASelection() {
    for (const char* name : {"actionSplit", "actionMergeWith", "actionMergeSelected"}) {
      QVERIFY2(!act(name)->isEnabled(), name);
    }
    select(left_);
    QVERIFY(act("actionSplit")->isEnabled());
    QVERIFY(act("actionMergeWith")->isEnabled());
    QVERIFY(!act("actionMergeSelected")->isEnabled());  // one row of the list
    // The tool of a building that goes away gives the view back to Navigate.
    act("actionSplit")->trigger();
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::PickLine);
    window_->selectBuilding(-1);
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::Navigate);
  }

  void aDragAcrossSplitsTheBuildingInOneStep() {
    activate();
    select(wide_);
    const core::Polygon before = building(wide_)->outline;
    QTest::keyClick(window_->leftView(), Qt::Key_S);
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::PickLine);
    QVERIFY(act("actionSplit")->isChecked());
    // The dashed line shows while it is dragged.
    widgets::ImageView* view = window_->leftView();
    QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, at(200, 60));
    QTest::mouseMove(view, at(200, 150));
    QTest::mouseMove(view, at(200, 240));
    QVERIFY(lineShown(at(200, 62), at(200, 95)));
    QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, at(200, 240));
    QCOMPARE(count(), 5);
    QCOMPARE(doc()->undoStack()->index(), baseIndex_ + 1);
    QCOMPARE(doc()->undoStack()->undoText(), QStringLiteral("Split building %1").arg(wide_));
    QVERIFY(!lineShown(at(200, 62), at(200, 95)));
    // The first piece keeps the id and is selected; both are corrected halves of the outline.
    QCOMPARE(window_->selectedBuilding(), wide_);
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::Navigate);
    const int piece = doc()->project().buildings.back().id;
    QVERIFY(piece > far_);
    for (int id : {wide_, piece}) {
      QCOMPARE(st(building(id)->status), st(BuildingStatus::Corrected));
      QVERIFY(std::abs(core::area(building(id)->outline) - 10000.0) < 400.0);
    }
    QVERIFY2(message().contains(QStringLiteral("split into 2")), qPrintable(message()));
    // Like an edited outline, each piece is scored in the background.
    QTRY_VERIFY_WITH_TIMEOUT(std::isfinite(building(wide_)->energy) && std::isfinite(building(piece)->energy), 60000);
    act("actionUndo")->trigger();
    QCOMPARE(count(), 4);
    QVERIFY(building(piece) == nullptr);
    QVERIFY(samePolygon(building(wide_)->outline, before));
    QCOMPARE(st(building(wide_)->status), st(BuildingStatus::Automatic));
    act("actionRedo")->trigger();
    QCOMPARE(count(), 5);
    QVERIFY(building(piece) != nullptr);
  }

  void twoClicksSplitToo() {
    activate();
    select(wide_);
    act("actionSplit")->trigger();
    widgets::ImageView* view = window_->leftView();
    QTest::mouseClick(view, Qt::LeftButton, Qt::NoModifier, at(80, 150));
    QTest::mouseMove(view, at(200, 150));
    QVERIFY(lineShown(at(82, 150), at(98, 150)));  // the line follows the cursor from the first click
    QTest::mouseClick(view, Qt::LeftButton, Qt::NoModifier, at(320, 150));
    QCOMPARE(count(), 5);
    QVERIFY(std::abs(core::area(building(wide_)->outline) - 10000.0) < 400.0);
  }

  void aLineThatDoesNotCrossIsRefused() {
    activate();
    select(wide_);
    act("actionSplit")->trigger();
    drag(at(150, 150), at(250, 150));  // inside the building from end to end
    QCOMPARE(count(), 4);
    QCOMPARE(doc()->undoStack()->index(), baseIndex_);
    QVERIFY2(message().startsWith(QStringLiteral("Building %1 was not split: ").arg(wide_)), qPrintable(message()));
    // The tool stays for another try; Esc drops a line begun with a click.
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::PickLine);
    QTest::mouseClick(window_->leftView(), Qt::LeftButton, Qt::NoModifier, at(200, 60));
    QTest::keyClick(window_->leftView(), Qt::Key_Escape);
    QTest::mouseClick(window_->leftView(), Qt::LeftButton, Qt::NoModifier, at(200, 240));
    QCOMPARE(count(), 4);  // the second click began a new line
  }

  void mergeWithMergesTheNextBuildingClicked() {
    activate();
    select(left_);
    const core::Polygon leftBefore = building(left_)->outline;
    const core::Polygon rightBefore = building(right_)->outline;
    QTest::keyClick(window_->leftView(), Qt::Key_M);
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::PickOutline);
    QVERIFY2(message().startsWith(QStringLiteral("Click the building")), qPrintable(message()));
    // A click beside any building, or on the selected one, merges nothing.
    QTest::mouseClick(window_->leftView(), Qt::LeftButton, Qt::NoModifier, at(400, 400));
    QTest::mouseClick(window_->leftView(), Qt::LeftButton, Qt::NoModifier, at(150, 340));
    QCOMPARE(count(), 4);
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::PickOutline);
    QCOMPARE(window_->selectedBuilding(), left_);
    QTest::mouseClick(window_->leftView(), Qt::LeftButton, Qt::NoModifier, at(250, 340));
    QCOMPARE(count(), 3);
    QVERIFY(building(right_) == nullptr);
    QCOMPARE(st(building(left_)->status), st(BuildingStatus::Corrected));
    QTRY_VERIFY_WITH_TIMEOUT(std::isfinite(building(left_)->energy), 60000);  // scored like an edit
    QCOMPARE(window_->selectedBuilding(), left_);
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::Navigate);
    QVERIFY(std::abs(core::area(building(left_)->outline) - 16000.0) < 50.0);
    QCOMPARE(doc()->undoStack()->undoText(), QStringLiteral("Merge buildings %1 and %2").arg(left_).arg(right_));
    act("actionUndo")->trigger();
    QCOMPARE(count(), 4);
    QVERIFY(samePolygon(building(left_)->outline, leftBefore));
    QVERIFY(samePolygon(building(right_)->outline, rightBefore));
    QCOMPARE(st(building(right_)->status), st(BuildingStatus::Automatic));
    act("actionRedo")->trigger();
    QCOMPARE(count(), 3);
  }

  void escLeavesMergeWith() {
    activate();
    select(left_);
    act("actionMergeWith")->trigger();
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::PickOutline);
    QTest::keyClick(window_->leftView(), Qt::Key_Escape);
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::Navigate);
    QVERIFY(act("actionNavigate")->isChecked());
    QTest::mouseClick(window_->leftView(), Qt::LeftButton, Qt::NoModifier, at(250, 340));
    QCOMPARE(count(), 4);
    QCOMPARE(window_->selectedBuilding(), right_);  // a click in Navigate selects
  }

  void buildingsApartAreNotMerged() {
    activate();
    select(left_);
    act("actionMergeWith")->trigger();
    QTest::mouseClick(window_->leftView(), Qt::LeftButton, Qt::NoModifier, at(480, 80));
    QCOMPARE(count(), 4);
    QCOMPARE(doc()->undoStack()->index(), baseIndex_);
    QCOMPARE(message(), QStringLiteral("Buildings %1 and %2 were not merged: they are more than 3 px apart")
                            .arg(left_)
                            .arg(far_));
    QCOMPARE(window_->leftView()->interactionMode(), InteractionMode::Navigate);  // one click per Merge with…
  }

  void mergeBuildingsMergesTheSecondRowIntoTheFirst() {
    window_->showDock(QStringLiteral("buildingsDock"));
    QTableView* table = window_->buildingsTable();
    select(right_);
    const QRect row = table->visualRect(window_->buildingsModel()->index(window_->buildingsModel()->rowOf(left_), 0));
    QTest::mouseClick(table->viewport(), Qt::LeftButton, Qt::ControlModifier, row.center());
    QCOMPARE(table->selectionModel()->selectedRows().size(), 2);
    QCOMPARE(window_->selectedBuilding(), right_);  // the first one stays the selected building
    QVERIFY(act("actionMergeSelected")->isEnabled());
    QVERIFY(table->actions().contains(act("actionMergeSelected")));  // its context menu
    act("actionMergeSelected")->trigger();
    QCOMPARE(count(), 3);
    QVERIFY(building(left_) == nullptr);
    QCOMPARE(window_->selectedBuilding(), right_);
    QCOMPARE(table->selectionModel()->selectedRows().size(), 1);
    QVERIFY(!act("actionMergeSelected")->isEnabled());
    act("actionUndo")->trigger();
    QCOMPARE(count(), 4);
    // A plain click selects one row again.
    QTest::mouseClick(table->viewport(), Qt::LeftButton, Qt::NoModifier, row.center());
    QCOMPARE(window_->selectedBuilding(), left_);
    QCOMPARE(table->selectionModel()->selectedRows().size(), 1);
  }

  void frenchStrings() {
    QTranslator translator;
    QVERIFY(translator.load(QStringLiteral(":/i18n/delineo_fr.qm")));
    const char* context = "delineo::gui::MainWindow";
    QCOMPARE(translator.translate(context, "&Split building"), QStringLiteral("S&cinder le bâtiment"));
    QCOMPARE(translator.translate(context, "Merge &with…"), QStringLiteral("&Fusionner avec…"));
    QCOMPARE(translator.translate(context, "Building %1 split into %n buildings.", nullptr, 2),
             QStringLiteral("Bâtiment %1 scindé en %n bâtiments."));
    QCOMPARE(translator.translate("delineo::gui::Document", "Merge buildings %1 and %2"),
             QStringLiteral("Fusionner les bâtiments %1 et %2"));
    // The refusals too, which the library gives as a reason, not as text.
    QCOMPARE(translator.translate(context, "they are more than %1 px apart"),
             QStringLiteral("ils sont à plus de %1 px l’un de l’autre"));
  }

  void cleanupTestCase() { window_.reset(); }
};

QTEST_MAIN(SplitMergeTest)
#include "test_split_merge.moc"
