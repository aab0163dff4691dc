// The project's own settings in the main window: the disparity range the Matching tab edits and
// every computation uses, where outputs go, the height model and the roof heights it gives, the
// warning when a roof reaches the matched range's end, and the energy of an edited outline.
#include <QAbstractSpinBox>
#include <QAction>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QLabel>
#include <QLineEdit>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTabWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QUndoStack>
#include <filesystem>

#include <opencv2/imgproc.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/disparity_histogram.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/job_runner.hpp"
#include "delineo/widgets/parameter_form.hpp"
#include "document.hpp"
#include "main_window.hpp"
#include "project_settings_dialog.hpp"
#include "sample_window.hpp"

using namespace delineo;
using gui::MainWindow;

namespace fs = std::filesystem;

class ProjectSettingsTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir dir_;
  QString projectPath_;
  std::unique_ptr<MainWindow> window_;

  // A synthetic disparity: ground at 8 px, a 60x40 roof at 30 px from (100, 90).
  static cv::Mat roofDisparity(cv::Size size) {
    cv::Mat d(size, CV_32F, cv::Scalar(8.0f));
    d(cv::Rect(100, 90, 60, 40)).setTo(30.0f);
    return d;
  }

  int addRoofBuilding() {
    core::Polygon pick;
    pick.outer = {{92, 82}, {168, 82}, {168, 138}, {92, 138}};
    return window_->document()->addBuilding(pick);
  }

 private slots:
  void initTestCase() {
    // A pick starts the active polygon here, as it does for the operator.
    guitest::isolateSettings(QStringLiteral("DelineoSettingsTest"), true);
    QVERIFY(dir_.isValid());
    projectPath_ = guitest::makeSampleProject(dir_);
    window_ = guitest::showMainWindow();
    QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
  }

  void theMatchingTabEditsTheProjectsOneRange() {
    QVERIFY(window_->openProject(projectPath_));
    gui::Document* doc = window_->document();
    const auto range = doc->project().disparityRange;
    QVERIFY(range.has_value());
    QCOMPARE(window_->rangeMinBox()->value(), range->low);
    QCOMPARE(window_->rangeMaxBox()->value(), range->high);
    // The matcher's form has no range of its own any more (it was a second, unused one).
    QVERIFY(window_->matchingForm()->findChild<QWidget*>(QStringLiteral("dmax")) == nullptr);
    window_->rangeMaxBox()->setValue(range->high + 36);
    QCOMPARE(doc->project().disparityRange->high, range->high + 36);
    QCOMPARE(doc->undoStack()->undoText(),
             QStringLiteral("Disparity range %1..%2 px").arg(range->low).arg(range->high + 36));
    doc->undoStack()->undo();
    QCOMPARE(doc->project().disparityRange->high, range->high);
    QCOMPARE(window_->rangeMaxBox()->value(), range->high);
    // An inverted range is refused with a message and the boxes come back.
    window_->rangeMinBox()->setValue(range->high + 5);
    QCOMPARE(doc->project().disparityRange->low, range->low);
    QCOMPARE(window_->rangeMinBox()->value(), range->low);
  }

  void aRoofBeyondTheMatchedRangeIsWarnedAbout() {
    gui::Document* doc = window_->document();
    doc->setDisparity(roofDisparity(doc->leftGrey().size()));
    doc->setDisparityRange(project::DisparityInterval{0, 64}, QStringLiteral("range"));
    const int id = addRoofBuilding();
    window_->selectBuilding(id);
    QVERIFY(!window_->intervalLabel()->text().contains(QStringLiteral("end of the matched range")));
    // Matched with a range that ends at the roof: the values pile up at its end.
    doc->setDisparityRange(project::DisparityInterval{0, 30}, QStringLiteral("range"));
    QVERIFY2(window_->intervalLabel()->text().contains(QStringLiteral("end of the matched range")),
             qPrintable(window_->intervalLabel()->text()));
    doc->setDisparityRange(project::DisparityInterval{0, 64}, QStringLiteral("range"));
    QVERIFY(!window_->intervalLabel()->text().contains(QStringLiteral("end of the matched range")));
  }

  void theHistogramsGroundLineIsTheStreetNotANeighbouringRoof() {
    gui::Document* doc = window_->document();
    // A neighbour's roof at 59.5 px wrapped around three sides of the building: the thin ring
    // around the pick used to land on it.
    cv::Mat map = roofDisparity(doc->leftGrey().size());
    map(cv::Rect(40, 30, 180, 54)).setTo(59.5f);
    map(cv::Rect(40, 84, 52, 60)).setTo(59.5f);
    map(cv::Rect(168, 84, 52, 60)).setTo(59.5f);
    doc->setDisparity(map);
    const int id = addRoofBuilding();
    window_->selectBuilding(id);
    QVERIFY(window_->histogram()->groundLevel().has_value());
    QVERIFY2(std::abs(*window_->histogram()->groundLevel() - 8.0) < 1.0,
             qPrintable(QString::number(*window_->histogram()->groundLevel())));
    doc->setDisparity(roofDisparity(doc->leftGrey().size()));
  }

  void theHeightModelIsSetInTheWindowAndRoofHeightsFollow() {
    gui::Document* doc = window_->document();
    core::Polygon outline;
    outline.outer = {{100, 90}, {160, 90}, {160, 130}, {100, 130}};
    const int id = addRoofBuilding();
    project::DelineationOutcome result;
    result.outline = outline;
    doc->setDelineationResult(id, result);
    const double before = doc->project().find(id)->roofHeight;
    // B = 100 m, H = 1000 m, f = 10000 px: k = H² / (B f) = 1 m/px, GSD = H / f = 0.1 m.
    QCOMPARE(gui::metresPerPixelFromCamera(100, 1000, 10000), 1.0);
    QCOMPARE(gui::metresPerPixelFromCamera(0, 1000, 10000), 0.0);
    window_->setProjectSettingsHandler([](gui::ProjectSettingsDialog& dialog) {
      dialog.findChild<QDoubleSpinBox*>(QStringLiteral("groundDisparity"))->setValue(8.0);
      dialog.findChild<QDoubleSpinBox*>(QStringLiteral("groundElevation"))->setValue(146.5);
      dialog.setCamera(100, 1000, 10000);
      return true;
    });
    const int entries = doc->undoStack()->count();
    window_->openProjectSettings();
    QCOMPARE(doc->undoStack()->count(), entries + 1);
    QCOMPARE(doc->project().height.metresPerPixel, 1.0);
    QCOMPARE(doc->project().height.gsd, 0.1);
    QCOMPARE(doc->project().height.groundElevation, 146.5);
    QCOMPARE(doc->project().find(id)->roofHeight, 22.0);
    QVERIFY(before != 22.0);
    doc->undoStack()->undo();
    QCOMPARE(doc->project().find(id)->roofHeight, before);
    doc->undoStack()->redo();
    QCOMPARE(doc->project().find(id)->roofHeight, 22.0);
  }

  void withoutAHeightModelTheDemViewSaysHowToGetOne() {
    // A new project on the sample's pair: no DEM file and no height model.
    const project::Project sample = project::loadProject(projectPath_.toStdString());
    QVERIFY(window_->openPair(QString::fromStdString(sample.left),
                              QString::fromStdString(sample.right)));
    QVERIFY(!window_->heightModelNotice()->isHidden());
    gui::Document* doc = window_->document();
    doc->setDisparity(roofDisparity(doc->leftGrey().size()));
    QVERIFY(doc->dem().empty());
    project::HeightModel model;
    model.groundDisparity = 8;
    model.metresPerPixel = 0.25;
    doc->setHeightModel(model);
    QVERIFY(window_->heightModelNotice()->isHidden());
    QVERIFY(!doc->dem().empty());
    QCOMPARE(doc->dem().at<float>(100, 120), 22.0f * 0.25f);
  }

  void outputsFollowTheProjectFileNotTheImages() {
    gui::Document* doc = window_->document();  // the unsaved project on the sample's pair
    const fs::path imagesDir = fs::path(doc->project().left).parent_path();
    QVERIFY(doc->outputDirectory().isEmpty());  // nowhere to write before the first save
    const QString elsewhere = dir_.filePath(QStringLiteral("work/site.delineo.json"));
    QVERIFY(window_->saveAs(elsewhere));
    QVERIFY(fs::exists(dir_.filePath(QStringLiteral("work/output/disparity.tif")).toStdString()));
    QVERIFY(!fs::exists(imagesDir / "output" / "disparity.tif"));
    QCOMPARE(doc->outputDirectory(), dir_.filePath(QStringLiteral("work/output")));
    QCOMPARE(QString::fromStdString(project::loadProject(elsewhere.toStdString()).outputDir),
             QStringLiteral("output"));
    // The operator's own output folder, relative to the project file.
    window_->setProjectSettingsHandler([](gui::ProjectSettingsDialog& dialog) {
      dialog.findChild<QLineEdit*>(QStringLiteral("outputDir"))->setText(QStringLiteral("results"));
      return true;
    });
    window_->openProjectSettings();
    QCOMPARE(doc->outputDirectory(), dir_.filePath(QStringLiteral("work/results")));
    QCOMPARE(doc->dialogFolder(), dir_.filePath(QStringLiteral("work")));
  }

  void anEditedOutlineGetsItsEnergyBack() {
    QVERIFY(window_->openProject(projectPath_));
    gui::Document* doc = window_->document();
    const int id = addRoofBuilding();
    doc->setRoofInterval(id, project::DisparityInterval{28, 32});
    doc->setDisparity(roofDisparity(doc->leftGrey().size()));
    project::DelineationOutcome result;
    result.outline.outer = {{100, 90}, {160, 90}, {160, 130}, {100, 130}};
    result.energy = -1.0;
    doc->setDelineationResult(id, result);
    QSignalSpy updated(window_.get(), &MainWindow::energyUpdated);
    const core::Ring moved = {{104, 90}, {160, 90}, {160, 130}, {100, 130}};
    doc->editRing(id, 0, moved, QStringLiteral("Move vertex"));
    QVERIFY(std::isnan(doc->project().find(id)->energy));
    QTRY_COMPARE_WITH_TIMEOUT(updated.count(), 1, 60000);
    const project::Building* b = doc->project().find(id);
    QVERIFY(std::isfinite(b->energy));
    QVERIFY(b->energyTerms.has_value());
    double sum = 0;
    for (double t : *b->energyTerms) sum += t;
    QVERIFY(std::abs(sum - b->energy) < 1e-6 * std::abs(b->energy) + 1e-6);
    const double edited = b->energy;
    // Undo brings the old outline's energy back without a new job.
    doc->undoStack()->undo();
    QCOMPARE(doc->project().find(id)->energy, -1.0);
    // Redo brings the edit back without its energy: it is scored again.
    doc->undoStack()->redo();
    QTRY_COMPARE_WITH_TIMEOUT(updated.count(), 2, 60000);
    QVERIFY(std::isfinite(doc->project().find(id)->energy));
    QCOMPARE(doc->project().find(id)->energy, edited);
  }

  void aPickStartsTheActivePolygonOnceTheDisparityIsThere() {
    QVERIFY(window_->openProject(projectPath_));  // no disparity yet, automatic matching off
    QVERIFY(window_->action(QStringLiteral("actionDelineateOnPick"))->isChecked());
    gui::Document* doc = window_->document();
    QSignalSpy finished(window_.get(), &MainWindow::delineationFinished);
    QSignalSpy started(window_->jobs(), &widgets::JobRunner::started);
    // Picked while there is no disparity: it waits for the matching.
    emit window_->leftView()->rectanglePicked(QRectF(92, 82, 76, 56));
    const int id = window_->selectedBuilding();
    QVERIFY(id > 0);
    QCOMPARE(started.count(), 0);
    window_->startMatching();
    QTRY_COMPARE_WITH_TIMEOUT(finished.count(), 1, 120000);
    QCOMPARE(finished.takeFirst().at(0).toInt(), id);
    QVERIFY(doc->project().find(id)->status == project::BuildingStatus::Automatic);
    // With the disparity there, the next pick runs at once.
    emit window_->leftView()->rectanglePicked(QRectF(300, 200, 60, 50));
    const int second = window_->selectedBuilding();
    QVERIFY(second != id);
    QTRY_COMPARE_WITH_TIMEOUT(finished.count(), 1, 120000);
    QCOMPARE(finished.takeFirst().at(0).toInt(), second);
  }

  void aPickIsOutlinedWithTheProjectsMethod() {
    QVERIFY(window_->openProject(projectPath_));
    gui::Document* doc = window_->document();
    QSignalSpy matched(window_.get(), &MainWindow::matchingFinished);
    window_->startMatching();
    QTRY_COMPARE_WITH_TIMEOUT(matched.count(), 1, 120000);
    QVERIFY2(!doc->dem().empty(), "the sample has a height model");
    // The method is a project setting, one undoable step.
    QComboBox* method = window_->methodChoice();
    QCOMPARE(method->currentData().toString(), QStringLiteral("active-polygon"));
    const int entries = doc->undoStack()->count();
    method->setCurrentIndex(method->findData(QStringLiteral("box-fitting")));
    QCOMPARE(doc->project().method, std::string(project::kBoxFitting));
    QCOMPARE(doc->undoStack()->count(), entries + 1);
    QCOMPARE(doc->undoStack()->undoText(), QStringLiteral("Outline with box-fitting"));
    // A pick is outlined by box-fitting at once: no proposal to choose from, the building has it.
    QSignalSpy fitted(window_.get(), &MainWindow::boxFittingFinished);
    QSignalSpy delineated(window_.get(), &MainWindow::delineationFinished);
    cv::Mat stats, centroids, components;
    const cv::Mat roofs = doc->labels() == 1;
    const int n = cv::connectedComponentsWithStats(roofs, components, stats, centroids);
    int largest = 1;
    for (int i = 2; i < n; ++i) {
      if (stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(largest, cv::CC_STAT_AREA)) largest = i;
    }
    const cv::Rect roof(stats.at<int>(largest, cv::CC_STAT_LEFT), stats.at<int>(largest, cv::CC_STAT_TOP),
                        stats.at<int>(largest, cv::CC_STAT_WIDTH), stats.at<int>(largest, cv::CC_STAT_HEIGHT));
    emit window_->leftView()->rectanglePicked(QRectF(roof.x - 8, roof.y - 8, roof.width + 16, roof.height + 16));
    const int id = window_->selectedBuilding();
    QTRY_COMPARE_WITH_TIMEOUT(fitted.count(), 1, 120000);
    QCOMPARE(delineated.count(), 0);
    const project::Building* b = doc->project().find(id);
    QVERIFY(b->hasOutline());
    QCOMPARE(b->method, std::string(project::kBoxFitting));
    QVERIFY(b->status == project::BuildingStatus::Automatic);
    QVERIFY(!window_->hasBoxFitProposal(id));
    const double inter = cv::countNonZero(core::rasterize(b->outline, roofs.size())(roof) & roofs(roof));
    const double iou = inter / (core::area(b->outline) + cv::countNonZero(roofs(roof)) - inter);
    qInfo("picked roof outlined by box-fitting: IoU %.3f", iou);
    QVERIFY2(iou > 0.7, qPrintable(QString::number(iou)));
    // Back to the active polygon: the method choice follows undo.
    doc->undoStack()->undo();  // the outline
    doc->undoStack()->undo();  // the pick
    doc->undoStack()->undo();  // the method
    QCOMPARE(doc->project().method, std::string(project::kActivePolygon));
    QCOMPARE(method->currentData().toString(), QStringLiteral("active-polygon"));
  }

  void boxFittingEnhancementAndPickHaveTheirForms() {
    if (!window_->document()) QVERIFY(window_->openProject(projectPath_));
    gui::Document* doc = window_->document();
    const std::vector<std::pair<std::string, std::string>> groups = {
        {"boxfit", "min-height"}, {"enhance", "wall-band"}, {"pick", "height-margin"}};
    for (const auto& [group, key] : groups) {
      widgets::ParameterForm* form = window_->parameterForm(group);
      QVERIFY2(form != nullptr, group.c_str());
      auto* spin = form->findChild<QAbstractSpinBox*>(QString::fromStdString(key));
      QVERIFY2(spin != nullptr, key.c_str());
      const auto stored = [&, group = group, key = key] {
        const nlohmann::json& all = doc->project().parameters;
        return all.contains(group) ? all.at(group).value(key, nlohmann::json()) : nlohmann::json();
      };
      const nlohmann::json before = stored();
      const int step = doc->undoStack()->index();
      spin->stepBy(1);
      QCOMPARE(doc->undoStack()->index(), step + 1);
      QVERIFY2(stored().is_number() && stored() != before, key.c_str());
      doc->undoStack()->undo();
      QCOMPARE(stored().dump(), before.dump());
      if (const QString dir = qEnvironmentVariable("DELINEO_SCREENSHOT_DIR"); !dir.isEmpty()) {
        auto* tabs = window_->findChild<QTabWidget*>(QStringLiteral("parameterTabs"));
        for (int i = 0; i < tabs->count(); ++i) {
          if (tabs->widget(i)->isAncestorOf(form)) tabs->setCurrentIndex(i);
        }
        QTest::qWait(100);
        window_->grab().save(dir + QStringLiteral("/%1-tab.png").arg(QString::fromStdString(group)));
      }
    }
  }

  void cleanupTestCase() { window_.reset(); }
};

QTEST_MAIN(ProjectSettingsTest)
#include "test_project_settings.moc"
