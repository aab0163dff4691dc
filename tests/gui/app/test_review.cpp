// The review of outlined buildings in the real main window: Next / Previous building to review
// (N, Shift+N) in the buildings list's order with wrap, outlines awaiting a decision before pending
// buildings, "review complete" when none is left, the left view zoomed out only for a building that
// does not fit; Next after accepting or rejecting (on and off, remembered); the status bar's count
// after accept, reject and undo; the French strings.
#include <QAction>
#include <QItemSelectionModel>
#include <QLabel>
#include <QSettings>
#include <QStatusBar>
#include <QTableView>
#include <QTemporaryDir>
#include <QTest>
#include <QTranslator>
#include <QUndoStack>

#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/image_view.hpp"
#include "document.hpp"
#include "main_window.hpp"
#include "sample_window.hpp"

using namespace delineo;
using gui::MainWindow;
using project::BuildingStatus;

namespace {

QString st(BuildingStatus status) { return QString::fromStdString(project::toString(status)); }

core::Polygon rectangle(double x, double y, double w, double h) {
  core::Polygon p;
  p.outer = {{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}};
  return p;
}

}  // namespace

class ReviewTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir dir_;
  std::unique_ptr<MainWindow> window_;
  // The buildings in the list's order: accepted, automatic, pending, corrected, rejected,
  // automatic (larger than the left view at zoom 4), pending.
  int accepted_ = -1, automatic_ = -1, pending_ = -1, corrected_ = -1, rejected_ = -1, large_ = -1, lastPending_ = -1;
  int baseIndex_ = 0;  // the undo stack's index once they are made

  gui::Document* doc() const { return window_->document(); }
  QAction* act(const char* name) const { return window_->action(QString::fromLatin1(name)); }
  // Statuses compared as their names, so a failure prints them.
  QString status(int id) const { return st(doc()->project().find(id)->status); }
  QString progress() const { return window_->reviewProgress()->text(); }

  // A building whose outline is `outline`, as the active polygon leaves it (automatic).
  int outlined(const core::Polygon& outline) {
    const int id = doc()->addBuilding(rectangle(outline.outer[0].x - 5, outline.outer[0].y - 5, 10, 10));
    project::DelineationOutcome outcome;
    outcome.outline = outline;
    doc()->setDelineationResult(id, outcome);
    return id;
  }

  void addBuildings() {
    accepted_ = outlined(rectangle(20, 20, 40, 40));
    doc()->setStatus(accepted_, BuildingStatus::Accepted);
    automatic_ = outlined(rectangle(100, 20, 40, 40));
    pending_ = doc()->addBuilding(rectangle(180, 20, 40, 40));
    corrected_ = outlined(rectangle(260, 20, 40, 40));
    doc()->setPolygon(corrected_, rectangle(262, 20, 38, 40), QStringLiteral("moved"));
    rejected_ = outlined(rectangle(340, 20, 40, 40));
    doc()->setStatus(rejected_, BuildingStatus::Rejected);
    large_ = outlined(rectangle(40, 150, 400, 260));
    lastPending_ = doc()->addBuilding(rectangle(500, 400, 50, 50));
  }

  void activate() {
    window_->activateWindow();
    QVERIFY(QTest::qWaitForWindowActive(window_.get()));
    window_->leftView()->setFocus();
  }

 private slots:
  void initTestCase() {
    guitest::isolateSettings(QStringLiteral("DelineoReviewTest"), false);
    QVERIFY(dir_.isValid());
    window_ = guitest::showMainWindow();
    QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
    QVERIFY(window_->reviewProgress()->text().isEmpty());
    QVERIFY(guitest::openPairWithoutHeights(*window_, dir_, {640, 480}));
    QVERIFY(progress().isEmpty());  // no building yet
    addBuildings();
    QCOMPARE(static_cast<int>(doc()->project().buildings.size()), 7);
    QCOMPARE(status(corrected_), st(BuildingStatus::Corrected));
    baseIndex_ = doc()->undoStack()->index();
    // On by default.
    QVERIFY(act("actionNextAfterDecision")->isChecked());
  }

  // Each test starts from the buildings as made, none selected, the option on.
  void cleanup() {
    doc()->undoStack()->setIndex(baseIndex_);
    window_->selectBuilding(-1);
    act("actionNextAfterDecision")->setChecked(true);
  }

  void statusLabelCountsEachStatus() {
    QCOMPARE(progress(), QStringLiteral("To review: 3 outlined, 2 pending · 1 accepted · 1 rejected"));
  }

  void nextAndPreviousFollowTheListAndWrap() {
    QAction* next = act("actionNextToReview");
    QAction* previous = act("actionPreviousToReview");
    QVERIFY(next->isEnabled() && previous->isEnabled());
    next->trigger();  // none selected: from the top
    QCOMPARE(window_->selectedBuilding(), automatic_);
    next->trigger();
    QCOMPARE(window_->selectedBuilding(), corrected_);
    next->trigger();
    QCOMPARE(window_->selectedBuilding(), large_);
    next->trigger();  // round to the top
    QCOMPARE(window_->selectedBuilding(), automatic_);
    previous->trigger();  // round to the bottom
    QCOMPARE(window_->selectedBuilding(), large_);
    previous->trigger();
    QCOMPARE(window_->selectedBuilding(), corrected_);
    // From a building that is not to review (the accepted one), the next one after it.
    window_->selectBuilding(accepted_);
    previous->trigger();
    QCOMPARE(window_->selectedBuilding(), large_);
    window_->selectBuilding(-1);
    previous->trigger();  // none selected: from the bottom
    QCOMPARE(window_->selectedBuilding(), large_);
    // The list shows the selection.
    QCOMPARE(window_->buildingsTable()->selectionModel()->selectedRows().size(), 1);
  }

  void keysNAndShiftNGoThroughTheBuildings() {
    activate();
    QTest::keyClick(window_->leftView(), Qt::Key_N);
    QCOMPARE(window_->selectedBuilding(), automatic_);
    QTest::keyClick(window_->leftView(), Qt::Key_N);
    QCOMPARE(window_->selectedBuilding(), corrected_);
    QTest::keyClick(window_->leftView(), Qt::Key_N, Qt::ShiftModifier);
    QCOMPARE(window_->selectedBuilding(), automatic_);
    // Navigate moved to V.
    window_->action(QStringLiteral("actionEdit"))->trigger();
    QTest::keyClick(window_->leftView(), Qt::Key_V);
    QCOMPARE(window_->leftView()->interactionMode(), widgets::InteractionMode::Navigate);
  }

  void zoomsOutOnlyForABuildingThatDoesNotFit() {
    widgets::ImageView* view = window_->leftView();
    window_->selectBuilding(accepted_);
    view->setView(view->viewCenter(), 4.0);
    act("actionNextToReview")->trigger();  // 40 px: 160 widget px at zoom 4, it fits
    QCOMPARE(window_->selectedBuilding(), automatic_);
    QCOMPARE(view->zoom(), 4.0);
    QVERIFY(view->visibleImageRect().contains(QRectF(100, 20, 40, 40)));
    window_->selectBuilding(corrected_);
    act("actionNextToReview")->trigger();  // 400 x 260 px: larger than the view at zoom 4
    QCOMPARE(window_->selectedBuilding(), large_);
    const QRectF large(40, 150, 400, 260);
    qInfo("left view %d x %d px: zoom 4 -> %.3f", view->width(), view->height(), view->zoom());
    QVERIFY(view->zoom() < 4.0);
    QVERIFY(view->visibleImageRect().contains(large.adjusted(-10, -10, 10, 10)));  // with a margin
    QVERIFY(view->visibleImageRect().width() < 2 * large.width() || view->visibleImageRect().height() < 2 * large.height());
    // The smaller zoom is kept for the next one, which fits at it.
    const double zoom = view->zoom();
    act("actionNextToReview")->trigger();
    QCOMPARE(window_->selectedBuilding(), automatic_);
    QCOMPARE(view->zoom(), zoom);
  }

  void pendingBuildingsComeAfterTheOutlines() {
    act("actionNextAfterDecision")->setChecked(false);
    for (int id : {automatic_, corrected_, large_}) {
      window_->selectBuilding(id);
      window_->acceptSelected();
      QCOMPARE(window_->selectedBuilding(), id);  // the option is off: the selection stays
    }
    QCOMPARE(progress(), QStringLiteral("To review: 2 pending · 4 accepted · 1 rejected"));
    act("actionNextToReview")->trigger();  // from the large one: the pending one after it
    QCOMPARE(window_->selectedBuilding(), lastPending_);
    act("actionNextToReview")->trigger();
    QCOMPARE(window_->selectedBuilding(), pending_);
    act("actionPreviousToReview")->trigger();
    QCOMPARE(window_->selectedBuilding(), lastPending_);
  }

  void saysTheReviewIsCompleteWhenNothingIsLeft() {
    act("actionNextAfterDecision")->setChecked(false);
    for (int id : {automatic_, corrected_, large_, pending_, lastPending_}) {
      window_->selectBuilding(id);
      window_->rejectSelected();
    }
    QCOMPARE(progress(), QStringLiteral("1 accepted · 6 rejected"));
    window_->statusBar()->clearMessage();
    act("actionNextToReview")->trigger();
    QCOMPARE(window_->selectedBuilding(), lastPending_);  // unchanged
    QVERIFY2(window_->statusBar()->currentMessage().startsWith(QStringLiteral("Review complete")),
             qPrintable(window_->statusBar()->currentMessage()));
  }

  void acceptOrRejectGoesOnToTheNextWithTheOption() {
    activate();
    window_->selectBuilding(automatic_);
    QTest::keyClick(window_->leftView(), Qt::Key_A);
    QCOMPARE(status(automatic_), st(BuildingStatus::Accepted));
    QCOMPARE(window_->selectedBuilding(), corrected_);
    QCOMPARE(progress(), QStringLiteral("To review: 2 outlined, 2 pending · 2 accepted · 1 rejected"));
    QTest::keyClick(window_->leftView(), Qt::Key_X);
    QCOMPARE(status(corrected_), st(BuildingStatus::Rejected));
    QCOMPARE(window_->selectedBuilding(), large_);
    QCOMPARE(progress(), QStringLiteral("To review: 1 outlined, 2 pending · 2 accepted · 2 rejected"));
    // The last outline decided: on to the pending ones.
    QTest::keyClick(window_->leftView(), Qt::Key_A);
    QCOMPARE(window_->selectedBuilding(), lastPending_);
    QCOMPARE(progress(), QStringLiteral("To review: 2 pending · 3 accepted · 2 rejected"));
    act("actionUndo")->trigger();
    QCOMPARE(status(large_), st(BuildingStatus::Automatic));
    QCOMPARE(progress(), QStringLiteral("To review: 1 outlined, 2 pending · 2 accepted · 2 rejected"));
    act("actionUndo")->trigger();
    QCOMPARE(progress(), QStringLiteral("To review: 2 outlined, 2 pending · 2 accepted · 1 rejected"));
    act("actionRedo")->trigger();
    QCOMPARE(progress(), QStringLiteral("To review: 1 outlined, 2 pending · 2 accepted · 2 rejected"));
  }

  void acceptOrRejectKeepsTheSelectionWithoutTheOption() {
    activate();
    act("actionNextAfterDecision")->trigger();
    QVERIFY(!act("actionNextAfterDecision")->isChecked());
    QCOMPARE(QSettings().value(QStringLiteral("review/nextAfterDecision")).toBool(), false);
    MainWindow restarted;  // the choice is remembered
    QVERIFY(!restarted.action(QStringLiteral("actionNextAfterDecision"))->isChecked());
    window_->selectBuilding(automatic_);
    QTest::keyClick(window_->leftView(), Qt::Key_A);
    QCOMPARE(status(automatic_), st(BuildingStatus::Accepted));
    QCOMPARE(window_->selectedBuilding(), automatic_);
    window_->selectBuilding(pending_);
    QTest::keyClick(window_->leftView(), Qt::Key_X);
    QCOMPARE(status(pending_), st(BuildingStatus::Rejected));
    QCOMPARE(window_->selectedBuilding(), pending_);
    QCOMPARE(progress(), QStringLiteral("To review: 2 outlined, 1 pending · 2 accepted · 2 rejected"));
    act("actionNextAfterDecision")->trigger();
    QCOMPARE(QSettings().value(QStringLiteral("review/nextAfterDecision")).toBool(), true);
  }

  void frenchStrings() {
    QTranslator translator;
    QVERIFY(translator.load(QStringLiteral(":/i18n/delineo_fr.qm")));
    const char* context = "delineo::gui::MainWindow";
    QCOMPARE(translator.translate(context, "Ne&xt building to review"), QStringLiteral("Bâtiment à &vérifier suivant"));
    QCOMPARE(translator.translate(context, "To review: %1"), QStringLiteral("À vérifier : %1"));
    QCOMPARE(translator.translate(context, "%n outlined", nullptr, 2), QStringLiteral("%n délimités"));
    QCOMPARE(translator.translate(context, "%n accepted", nullptr, 1), QStringLiteral("%n accepté"));
    QCOMPARE(translator.translate(context, "%n rejected", nullptr, 2), QStringLiteral("%n rejetés"));
  }

  void cleanupTestCase() { window_.reset(); }
};

QTEST_MAIN(ReviewTest)
#include "test_review.moc"
