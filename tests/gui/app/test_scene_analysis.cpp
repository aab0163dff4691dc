// The scene analysis in the real main window, on the generated sample project (its DEM and gsd,
// its ground-truth labels): Analyse the scene and its layers (classes against the truth, objects'
// outlines, DTM / nDSM in the DEM view), Detect buildings as one undoable step, Outline the
// pending buildings (one undo step each, a cancel keeping those done), a canceled analysis
// changing nothing, the message when heights are missing, the parameter tabs.
#include <QAction>
#include <QComboBox>
#include <QSignalSpy>
#include <QTableView>
#include <QTemporaryDir>
#include <QTest>
#include <QUndoStack>

#include <opencv2/core.hpp>

#include "delineo/io/raster.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/parameter_form.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "main_window.hpp"
#include "sample_window.hpp"

using namespace delineo;
using gui::MainWindow;

namespace {

// Share of the pixels of `truth` == label that `classes` gives that label too.
double recall(const cv::Mat& truth, const cv::Mat& classes, int label) {
  const int total = cv::countNonZero(truth == label);
  if (total == 0) return 0.0;
  const cv::Mat both = (truth == label) & (classes == label);
  return static_cast<double>(cv::countNonZero(both)) / total;
}

}  // namespace

class SceneAnalysisTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir dir_;
  QString projectPath_;
  std::unique_ptr<MainWindow> window_;

  gui::Document* doc() const { return window_->document(); }
  QAction* act(const char* name) const { return window_->action(QString::fromLatin1(name)); }

  bool analyse() {
    QSignalSpy analysed(window_.get(), &MainWindow::sceneAnalysed);
    if (window_->startSceneAnalysis() == 0) return false;
    return analysed.wait(60000);
  }

  // Computes the disparity, then Detect buildings; the number of buildings added, -1 on a timeout.
  int matchAndDetect() {
    QSignalSpy matched(window_.get(), &MainWindow::matchingFinished);
    QSignalSpy detected(window_.get(), &MainWindow::buildingsDetected);
    if (window_->startMatching() == 0 || !matched.wait(60000)) return -1;
    if (window_->detectBuildings() == 0 || !detected.wait(60000)) return -1;
    return detected.at(0).at(0).toInt();
  }

 private slots:
  void initTestCase() {
    guitest::isolateSettings(QStringLiteral("DelineoSceneTest"), false);
    QVERIFY(dir_.isValid());
    projectPath_ = guitest::makeSampleProject(dir_);
    window_ = guitest::showMainWindow();
    QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
  }

  void missingHeightsGiveAMessageAndNoLayer() {
    QVERIFY(guitest::openPairWithoutHeights(*window_, dir_));
    QVERIFY(doc()->dem().empty());
    QCOMPARE(window_->startSceneAnalysis(), widgets::JobId(0));
    QVERIFY2(window_->lastMessage().contains(QStringLiteral("needs heights")), qPrintable(window_->lastMessage()));
    QVERIFY(window_->lastMessage().contains(QStringLiteral("compute the disparity")));
    // A layer asked for without heights says so and stays off; so does Detect buildings.
    act("actionShowClasses")->trigger();
    QVERIFY(!act("actionShowClasses")->isChecked());
    QVERIFY(!window_->leftView()->overlayVisible());
    window_->setDemLayer(MainWindow::DemLayer::Ndsm);
    QCOMPARE(window_->demLayer(), MainWindow::DemLayer::Dem);
    const int undoCount = doc()->undoStack()->count();
    QCOMPARE(window_->detectBuildings(), widgets::JobId(0));
    QVERIFY(window_->lastMessage().contains(QStringLiteral("needs heights")));
    QCOMPARE(doc()->undoStack()->count(), undoCount);
    QVERIFY(doc()->project().buildings.empty());
  }

  void analysisGivesClassesObjectsAndTerrainLayers() {
    QVERIFY(window_->openProject(projectPath_));
    QVERIFY(!doc()->dem().empty());
    QVERIFY(window_->sceneAnalysis() == nullptr);
    const int undoCount = doc()->undoStack()->count();
    QVERIFY(analyse());
    const project::SceneAnalysisOutcome* scene = window_->sceneAnalysis();
    QVERIFY(scene != nullptr);
    QCOMPARE(doc()->undoStack()->count(), undoCount);  // a view of the data, not an edit
    // The classes where the simulated truth has them.
    const cv::Mat& truth = doc()->labels();
    QCOMPARE(scene->classes.size(), truth.size());
    const double buildings = recall(truth, scene->classes, 1);
    const double vegetation = recall(truth, scene->classes, 2);
    qInfo("sample: %.1f %% of the building pixels classified building, %.1f %% of the vegetation pixels vegetation",
          100 * buildings, 100 * vegetation);
    QVERIFY2(buildings > 0.8, qPrintable(QString::number(buildings)));
    QVERIFY2(vegetation > 0.5, qPrintable(QString::number(vegetation)));
    QVERIFY(cv::countNonZero((truth == 0) & (scene->classes == 1)) < 0.05 * cv::countNonZero(truth == 0));

    // Classes: the overlay over the left image, with its legend; the labels overlay goes off.
    act("actionShowLabels")->setChecked(true);
    act("actionShowClasses")->trigger();
    QVERIFY(act("actionShowClasses")->isChecked());
    QVERIFY(!act("actionShowLabels")->isChecked());
    QVERIFY(window_->leftView()->overlayVisible());
    QVERIFY(window_->layerLegend()->isVisible());
    QVERIFY(window_->findChild<QWidget*>(QStringLiteral("classesLegend"))->isVisible());
    act("actionShowClasses")->trigger();
    QVERIFY(!window_->leftView()->overlayVisible());

    // Objects: one outline per object over the left view, not editable (guides).
    QVERIFY(!scene->objects.empty());
    act("actionShowObjects")->trigger();
    QCOMPARE(window_->leftView()->polygons().guides().size(), scene->objects.size());
    QVERIFY(window_->findChild<QWidget*>(QStringLiteral("objectsLegend"))->isVisible());
    act("actionShowObjects")->trigger();
    QVERIFY(window_->leftView()->polygons().guides().empty());

    // The DEM view: the nDSM from 0 in height colours, the DTM, back to the DEM.
    window_->findChild<QComboBox*>(QStringLiteral("demMode"))->setCurrentIndex(1);
    act("actionDemLayerNdsm")->trigger();
    QCOMPARE(window_->demLayer(), MainWindow::DemLayer::Ndsm);
    QCOMPARE(window_->demView()->image().data, scene->ndsm.data);
    QCOMPARE(window_->demView()->displayRange().first, 0.0);
    act("actionDemLayerDtm")->trigger();
    QCOMPARE(window_->demView()->image().data, scene->dtm.data);
    act("actionDemLayerDem")->trigger();
    QCOMPARE(window_->demView()->image().data, doc()->dem().data);
  }

  void detectedBuildingsAreOneUndoStep() {
    QVERIFY(window_->openProject(projectPath_));
    QVERIFY(doc()->project().buildings.empty());
    // With the disparity, each proposal comes with its roof interval.
    QSignalSpy detected(window_.get(), &MainWindow::buildingsDetected);
    const int added = matchAndDetect();  // no analysis yet: Detect buildings runs it first
    QVERIFY(added >= 3);
    QCOMPARE(detected.at(0).at(1).toInt(), 0);
    QVERIFY2(window_->lastMessage().contains(QStringLiteral("%1 buildings proposed (0 already present)").arg(added)),
             qPrintable(window_->lastMessage()));
    const auto& buildings = doc()->project().buildings;
    QCOMPARE(static_cast<int>(buildings.size()), added);
    for (const project::Building& b : buildings) {
      QCOMPARE(QString::fromStdString(project::toString(b.status)), QStringLiteral("pending"));
      QVERIFY(b.roofInterval.has_value());
      QVERIFY(!b.hasOutline());
    }
    // The buildings list shows them, pending.
    QCOMPARE(window_->buildingsTable()->model()->rowCount(), added);
    QCOMPARE(window_->leftView()->polygons().polygons().size(), static_cast<size_t>(added));
    // One undo removes them all, one redo brings them back.
    QVERIFY(doc()->undoStack()->canUndo());
    act("actionUndo")->trigger();
    QVERIFY(doc()->project().buildings.empty());
    QCOMPARE(window_->buildingsTable()->model()->rowCount(), 0);
    act("actionRedo")->trigger();
    QCOMPARE(static_cast<int>(doc()->project().buildings.size()), added);
    // Asked again with the same analysis: nothing new, and no undo step.
    const int undoCount = doc()->undoStack()->count();
    QCOMPARE(window_->detectBuildings(), widgets::JobId(0));
    QCOMPARE(detected.count(), 2);
    QCOMPARE(detected.at(1).at(0).toInt(), 0);
    QCOMPARE(detected.at(1).at(1).toInt(), added);
    QCOMPARE(doc()->undoStack()->count(), undoCount);
    QVERIFY(window_->lastMessage().contains(QStringLiteral("already present")));
    // The active polygon takes a proposed building as it is.
    const int first = doc()->project().buildings.front().id;
    window_->selectBuilding(first);
    QSignalSpy delineated(window_.get(), &MainWindow::delineationFinished);
    QVERIFY(window_->startDelineation(first) != 0);
    QVERIFY(delineated.wait(120000));
    QVERIFY(doc()->project().find(first)->hasOutline());
  }

  // Building → Outline the pending buildings: every proposal outlined in turn, one undo step
  // each; a cancel keeps the buildings outlined before it and leaves the others pending.
  void pendingBuildingsAreOutlinedInTurn() {
    QVERIFY(window_->openProject(projectPath_));
    QVERIFY(!act("actionOutlinePending")->isEnabled());
    QCOMPARE(window_->outlinePendingBuildings(), widgets::JobId(0));  // nothing pending
    const int added = matchAndDetect();
    QVERIFY(added >= 3);
    QVERIFY(act("actionOutlinePending")->isEnabled());

    // Canceled once the first building is outlined: that one is kept, the others stay pending.
    const int undoBefore = doc()->undoStack()->count();
    QMetaObject::Connection cancelOnFirst =
        connect(doc(), &gui::Document::buildingChanged, window_->jobs(), &widgets::JobRunner::cancelAll);
    QVERIFY(window_->outlinePendingBuildings() != 0);
    QVERIFY(window_->jobs()->waitForIdle(120000));
    QTest::qWait(50);
    disconnect(cancelOnFirst);
    const int keptAfterCancel = added - static_cast<int>(doc()->project().pendingBuildings().size());
    QVERIFY2(keptAfterCancel >= 1 && keptAfterCancel < added, qPrintable(QString::number(keptAfterCancel)));
    QCOMPARE(doc()->undoStack()->count(), undoBefore + keptAfterCancel);

    // Run again: the rest are outlined, each by the active polygon, with a roof height, except the
    // last one, which the operator rejects while the job runs: it stays rejected.
    QSignalSpy outlined(window_.get(), &MainWindow::pendingOutlined);
    act("actionOutlinePending")->trigger();
    const int rejected = doc()->project().pendingBuildings().back();
    doc()->setStatus(rejected, project::BuildingStatus::Rejected);
    QVERIFY(outlined.wait(240000));
    QCOMPARE(outlined.at(0).at(0).toInt(), added - keptAfterCancel - 1);
    QCOMPARE(outlined.at(0).at(1).toInt(), 0);
    QVERIFY(doc()->project().pendingBuildings().empty());
    QVERIFY(!act("actionOutlinePending")->isEnabled());
    QVERIFY(doc()->project().find(rejected)->status == project::BuildingStatus::Rejected);
    QVERIFY(!doc()->project().find(rejected)->hasOutline());
    const cv::Mat& truth = doc()->labels();
    for (const project::Building& b : doc()->project().buildings) {
      if (b.id == rejected) continue;
      QVERIFY(b.status == project::BuildingStatus::Automatic);
      QCOMPARE(QString::fromStdString(b.method), QString::fromLatin1(project::kActivePolygon));
      QVERIFY(b.hasOutline());
      QVERIFY(std::isfinite(b.roofHeight) && b.roofHeight > 2.0);
      // Most of each outline is on the sample's buildings (label 1).
      const cv::Mat inside = core::rasterize(b.outline, truth.size());
      const double onBuildings = cv::countNonZero(inside & (truth == 1)) / double(cv::countNonZero(inside));
      QVERIFY2(onBuildings > 0.8, qPrintable(QStringLiteral("building %1: %2").arg(b.id).arg(onBuildings)));
    }
    QCOMPARE(doc()->undoStack()->count(), undoBefore + added);
    QVERIFY(window_->buildingsTable()->model()->rowCount() == added);
    // One undo puts the last one back to pending.
    act("actionUndo")->trigger();
    QCOMPARE(static_cast<int>(doc()->project().pendingBuildings().size()), 1);
    QVERIFY(act("actionOutlinePending")->isEnabled());
  }

  void canceledAnalysisChangesNothing() {
    QVERIFY(window_->openProject(projectPath_));
    const project::Project before = doc()->project();
    const int undoCount = doc()->undoStack()->count();
    QSignalSpy detected(window_.get(), &MainWindow::buildingsDetected);
    QSignalSpy analysed(window_.get(), &MainWindow::sceneAnalysed);
    act("actionShowObjects")->trigger();
    const widgets::JobId job = window_->detectBuildings();
    QVERIFY(job != 0);
    window_->jobs()->cancel(job);
    QVERIFY(window_->jobs()->waitForIdle(60000));
    QTest::qWait(50);
    QCOMPARE(analysed.count(), 0);
    QCOMPARE(detected.count(), 0);
    QVERIFY(window_->sceneAnalysis() == nullptr);
    QCOMPARE(doc()->undoStack()->count(), undoCount);
    QCOMPARE(doc()->project().buildings.size(), before.buildings.size());
    QVERIFY(!doc()->isModified());
    // The layer that waited for it is off again.
    QVERIFY(!act("actionShowObjects")->isChecked());
    QVERIFY(window_->leftView()->polygons().guides().empty());
  }

  void newHeightsOrParametersMakeTheAnalysisStale() {
    QVERIFY(window_->openProject(projectPath_));
    QVERIFY(analyse());
    // A parameter of the analysis: stale.
    widgets::ParameterForm* form = window_->parameterForm(project::kSegmentGroup);
    QVERIFY(form != nullptr);
    form->setValue("critical-height", widgets::ParameterForm::Value(3.0));
    QVERIFY(window_->sceneAnalysis() == nullptr);
    QVERIFY(analyse());
    // A new disparity: stale, and recomputed while a layer shows it.
    act("actionShowClasses")->trigger();
    QSignalSpy analysed(window_.get(), &MainWindow::sceneAnalysed);
    cv::Mat disparity(doc()->dem().size(), CV_32F, cv::Scalar(1.0f));
    doc()->setDisparity(disparity);
    QVERIFY(window_->sceneAnalysis() == nullptr);
    QVERIFY(analysed.wait(60000));
    QVERIFY(window_->sceneAnalysis() != nullptr);
    act("actionShowClasses")->trigger();
  }

  void parameterTabsWriteTheGroupsAsOneUndoStepEach() {
    QVERIFY(window_->openProject(projectPath_));
    const std::vector<std::pair<const char*, const char*>> fields = {{project::kSegmentGroup, "critical-height"},
                                                                     {project::kClassifyGroup, "window"},
                                                                     {project::kObjectsGroup, "min-area"},
                                                                     {project::kDetectGroup, "min-height"}};
    for (const auto& [group, key] : fields) {
      widgets::ParameterForm* form = window_->parameterForm(group);
      QVERIFY2(form != nullptr, group);
      const int undoIndex = doc()->undoStack()->index();
      const double value = std::get<double>(form->value(key)) + 1.0;
      form->setValue(key, widgets::ParameterForm::Value(value));
      QCOMPARE(doc()->undoStack()->index(), undoIndex + 1);
      QCOMPARE(doc()->project().parameters.at(group).at(key).get<double>(), value);
      doc()->undoStack()->undo();
      QVERIFY(!doc()->project().parameters.contains(group) || !doc()->project().parameters.at(group).contains(key) ||
              doc()->project().parameters.at(group).at(key).get<double>() != value);
    }
  }

  void cleanupTestCase() { window_.reset(); }
};

QTEST_MAIN(SceneAnalysisTest)
#include "test_scene_analysis.moc"
