// File → Export elevation rasters, File → Export accepted buildings and View → Exclusion mask in
// the real main window, on a georeferenced copy of the generated sample project with a vegetation
// mask: the files written (values and geotransform read back against the window's layers), nothing
// written when canceled or when the operator keeps the existing files, the action disabled without
// elevation data; the CityJSON export in the background with the terrain, the same file as
// `delineo-cli export --terrain` writes; the mask hatched over the left view (pixels of the
// grabbed view) and disabled without a mask. With DELINEO_SCREENSHOT_DIR set, it saves the mask
// overlay, the folder dialog, the question before replacing files and the status messages there.
#include <QAction>
#include <QApplication>
#include <QDir>
#include <QElapsedTimer>
#include <QFileInfo>
#include <QHelpEvent>
#include <QMenu>
#include <QMenuBar>
#include <QScreen>
#include <QFileDialog>
#include <QMessageBox>
#include <QPushButton>
#include <QSettings>
#include <QSignalSpy>
#include <QStatusBar>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/nan_mask.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/project.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/image_view.hpp"
#include "document.hpp"
#include "main_window.hpp"
#include "sample_window.hpp"

using namespace delineo;
using gui::MainWindow;

namespace {

io::GeoReference lambert93Like() {
  io::GeoReference geo;
  geo.geoTransform = {574000.0, 0.5, 0.0, 6280000.0, 0.0, -0.5};
  geo.hasTransform = true;
  return geo;
}

// Equal sizes and values, NaN where NaN.
bool sameValues(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.channels() != b.channels()) return false;
  cv::Mat fa, fb;
  a.convertTo(fa, CV_32F);
  b.convertTo(fb, CV_32F);
  const cv::Mat nanA = core::nanMask(fa), nanB = core::nanMask(fb);
  if (cv::countNonZero(nanA != nanB) != 0) return false;
  cv::Mat diff;
  cv::absdiff(fa, fb, diff);
  diff.setTo(0.0f, nanA);
  double worst = 0.0;
  cv::minMaxLoc(diff, nullptr, &worst);
  return worst == 0.0;
}

QStringList namesIn(const QString& dir) {
  return QDir(dir).entryList(QDir::Files | QDir::Hidden, QDir::Name);
}

std::string contents(const QString& path) {
  std::ifstream in(path.toStdString(), std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Shares of the mask's pixels changed towards the hatching's cyan, and of the pixels away from
// the mask changed at all, between two grabs of the left view.
struct OverlayChange {
  double maskHatched = 0.0;
  double elsewhereChanged = 0.0;
};
OverlayChange compareGrabs(const QImage& before, const QImage& after, const widgets::ImageView& view,
                           const cv::Mat& mask) {
  cv::Mat inside, outside;
  cv::erode(mask, inside, cv::Mat(), {-1, -1}, 2);
  cv::dilate(mask, outside, cv::Mat(), {-1, -1}, 3);
  int maskSeen = 0, hatched = 0, elsewhereSeen = 0, changed = 0;
  for (int y = 0; y < mask.rows; y += 2) {
    for (int x = 0; x < mask.cols; x += 2) {
      const QPoint w = view.imageToWidget(QPointF(x + 0.5, y + 0.5)).toPoint();
      if (!before.rect().contains(w)) continue;
      const QColor b(before.pixel(w)), a(after.pixel(w));
      const int delta = std::abs(a.red() - b.red()) + std::abs(a.green() - b.green()) + std::abs(a.blue() - b.blue());
      if (inside.at<uchar>(y, x) != 0) {
        ++maskSeen;
        // Cyan over the image: blue and green up, red down.
        if (delta > 30 && a.blue() > b.blue() && a.green() >= b.green() && a.red() <= b.red()) ++hatched;
      } else if (outside.at<uchar>(y, x) == 0) {
        ++elsewhereSeen;
        if (delta > 6) ++changed;
      }
    }
  }
  return {maskSeen ? static_cast<double>(hatched) / maskSeen : 0.0,
          elsewhereSeen ? static_cast<double>(changed) / elsewhereSeen : 1.0};
}

// The project at `samplePath` with each building of its ground-truth labels accepted: its outline
// the labels' contour, its roof height the median of the DEM inside it. Saved as `path`.
void saveWithAcceptedBuildings(const QString& samplePath, const QString& path) {
  project::Project p = project::loadProject(samplePath.toStdString());
  const cv::Mat dem = io::readRaster(p.dem).data;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(io::readRaster(p.labels).data == 1, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  for (const auto& contour : contours) {
    std::vector<cv::Point> simple;
    cv::approxPolyDP(contour, simple, 1.0, true);
    if (cv::contourArea(simple) < 100.0) continue;
    project::Building b;
    b.id = p.nextBuildingId();
    for (const cv::Point& v : simple) b.initial.outer.emplace_back(v.x, v.y);
    b.outline = b.initial;
    b.status = project::BuildingStatus::Accepted;
    std::vector<float> inside;
    const cv::Mat mask = core::rasterize(b.outline, dem.size());
    for (int y = 0; y < dem.rows; ++y) {
      for (int x = 0; x < dem.cols; ++x) {
        if (mask.at<uchar>(y, x) != 0 && std::isfinite(dem.at<float>(y, x))) inside.push_back(dem.at<float>(y, x));
      }
    }
    std::nth_element(inside.begin(), inside.begin() + inside.size() / 2, inside.end());
    b.roofHeight = inside[inside.size() / 2];
    p.buildings.push_back(b);
  }
  project::saveProject(p, path.toStdString());
}

}  // namespace

class ElevationRastersTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir dir_;
  QString projectPath_;  // the georeferenced sample with its vegetation mask
  QString cityPath_;     // the same with its buildings accepted, never matched nor saved by the window
  cv::Mat mask_;         // its mask as the project reads it (255 = not roof)
  std::unique_ptr<MainWindow> window_;

  gui::Document* doc() const { return window_->document(); }
  QAction* act(const char* name) const { return window_->action(QString::fromLatin1(name)); }
  QString screenshotDir() const { return qEnvironmentVariable("DELINEO_SCREENSHOT_DIR"); }

  void shot(QWidget* widget, const QString& name) {
    if (screenshotDir().isEmpty()) return;
    QTest::qWait(300);
    QDir().mkpath(screenshotDir());
    QVERIFY(widget->grab().save(QDir(screenshotDir()).filePath(name)));
  }

  // The sample project with its images georeferenced and the vegetation of its ground truth as
  // the exclusion mask, beside the sample.
  QString makeGeoreferencedProject(const QString& samplePath) {
    project::Project p = project::loadProject(samplePath.toStdString());
    const QString geoDir = dir_.filePath(QStringLiteral("geo"));
    QDir().mkpath(geoDir);
    for (std::string* image : {&p.left, &p.right}) {
      const std::string copy = QDir(geoDir).filePath(QFileInfo(QString::fromStdString(*image)).fileName()).toStdString();
      io::writeGeoTiff(copy, io::readRaster(*image).data, lambert93Like());
      *image = copy;
    }
    const cv::Mat vegetation = io::readRaster(p.labels).data == 2;
    p.exclude = QDir(geoDir).filePath(QStringLiteral("vegetation.tif")).toStdString();
    io::writeGeoTiff(p.exclude, vegetation, lambert93Like());
    mask_ = io::readMask(p.exclude, vegetation.size());
    const QString path = QDir(geoDir).filePath(QStringLiteral("geo.delineo.json"));
    project::saveProject(p, path.toStdString());
    return path;
  }

  // The left view at 3:1 on the widest part of the mask, saved as `name`; the view is left there.
  void shotMaskCloseUp(const QString& name) {
    if (screenshotDir().isEmpty()) return;
    cv::Mat distance;
    cv::distanceTransform(mask_, distance, cv::DIST_L2, 3);
    cv::Point widest;
    cv::minMaxLoc(distance, nullptr, nullptr, nullptr, &widest);
    window_->leftView()->setView(QPointF(widest.x, widest.y), 3.0);
    shot(window_->leftView(), name);
  }

  // The File menu open on the disabled Export elevation rasters with its tooltip (the whole
  // screen: the tooltip is a window of its own).
  void shotDisabledEntry() {
    if (screenshotDir().isEmpty()) return;
    QDir().mkpath(screenshotDir());
    QMenu* file = window_->menuBar()->actions().first()->menu();
    file->popup(window_->mapToGlobal(QPoint(0, window_->menuBar()->height())));
    QTest::qWait(300);
    const QRect entry = file->actionGeometry(act("actionExportRasters"));
    QHelpEvent hover(QEvent::ToolTip, entry.center(), file->mapToGlobal(entry.center()));
    QApplication::sendEvent(file, &hover);
    QTest::qWait(500);
    QVERIFY(window_->screen()->grabWindow(0).save(QDir(screenshotDir()).filePath(QStringLiteral("rasters-disabled.png"))));
    file->close();
  }

  QString freshFolder(const QString& name) {
    const QString path = dir_.filePath(name);
    QDir().mkpath(path);
    return path;
  }

  // Answers the next modal dialog after saving its picture (`name`), with `answer`.
  void answerNextDialog(const QString& name, QMessageBox::StandardButton answer) {
    QTimer::singleShot(600, this, [this, name, answer] {
      QWidget* modal = QApplication::activeModalWidget();
      if (modal == nullptr) return;
      if (!screenshotDir().isEmpty()) modal->grab().save(QDir(screenshotDir()).filePath(name));
      if (auto* box = qobject_cast<QMessageBox*>(modal)) box->button(answer)->click();
      else if (auto* dialog = qobject_cast<QDialog*>(modal)) dialog->reject();
    });
  }

 private slots:
  void initTestCase() {
    guitest::isolateSettings(QStringLiteral("DelineoRastersTest"), false);
    QVERIFY(dir_.isValid());
    projectPath_ = makeGeoreferencedProject(guitest::makeSampleProject(dir_));
    cityPath_ = dir_.filePath(QStringLiteral("geo/city.delineo.json"));
    saveWithAcceptedBuildings(projectPath_, cityPath_);
    QVERIFY(cv::countNonZero(mask_) > 500);
    window_ = guitest::showMainWindow();
    QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
  }

  void nothingToExportWithoutElevationData() {
    QVERIFY(guitest::openPairWithoutHeights(*window_, dir_));
    QVERIFY(!act("actionExportRasters")->isEnabled());
    QVERIFY2(act("actionExportRasters")->toolTip().contains(QStringLiteral("Nothing to export")),
             qPrintable(act("actionExportRasters")->toolTip()));
    shotDisabledEntry();
    const QString out = freshFolder(QStringLiteral("bare"));
    QCOMPARE(window_->exportElevationRasters(out), widgets::JobId(0));
    QVERIFY(window_->jobs()->waitForIdle(5000));
    QVERIFY(namesIn(out).isEmpty());
    // No mask in this project: the entry is disabled and nothing is drawn even when it is checked.
    QVERIFY(!act("actionShowExclusionMask")->isEnabled());
    act("actionShowExclusionMask")->setChecked(true);
    QVERIFY(!window_->leftView()->overlayVisible());
    QVERIFY(!window_->findChild<QWidget*>(QStringLiteral("maskLegend"))->isVisibleTo(window_.get()));
    act("actionShowExclusionMask")->setChecked(false);
  }

  void exportWritesTheLayersGeoreferenced() {
    QVERIFY(window_->openProject(projectPath_));
    QVERIFY(doc()->pair().geo.valid());
    QVERIFY(act("actionExportRasters")->isEnabled());  // the DEM alone is enough
    QSignalSpy matched(window_.get(), &MainWindow::matchingFinished);
    QVERIFY(window_->startMatching() != 0);
    QVERIFY(matched.wait(60000));
    QVERIFY(window_->sceneAnalysis() == nullptr);

    const QString out = freshFolder(QStringLiteral("rasters"));
    QSignalSpy exported(window_.get(), &MainWindow::elevationRastersExported);
    QVERIFY(window_->exportElevationRasters(out) != 0);
    QVERIFY(exported.wait(60000));
    QCOMPARE(namesIn(out), (QStringList{"dem.tif", "disparity.tif", "dtm.tif", "labels.tif", "ndsm.tif",
                                        "objects.geojson"}));
    QVERIFY2(window_->statusBar()->currentMessage().startsWith(QStringLiteral("5 rasters and the objects written to ")),
             qPrintable(window_->statusBar()->currentMessage()));
    // The analysis made for the files is the window's: its layers show without computing it again.
    const project::SceneAnalysisOutcome* scene = window_->sceneAnalysis();
    QVERIFY(scene != nullptr);

    const io::GeoReference left = doc()->pair().geo;
    const std::pair<const char*, cv::Mat> expected[] = {{"disparity.tif", doc()->disparity()},
                                                         {"dem.tif", doc()->dem()},
                                                         {"dtm.tif", scene->dtm},
                                                         {"ndsm.tif", scene->ndsm},
                                                         {"labels.tif", scene->classes}};
    for (const auto& [name, layer] : expected) {
      const io::Raster back = io::readRaster(QDir(out).filePath(QString::fromLatin1(name)).toStdString());
      QVERIFY2(sameValues(back.data, layer), name);
      QVERIFY2(back.geo.valid(), name);
      for (size_t i = 0; i < 6; ++i) QCOMPARE(back.geo.geoTransform[i], left.geoTransform[i]);
    }
    QCOMPARE(io::readRaster(QDir(out).filePath(QStringLiteral("labels.tif")).toStdString()).data.type(), CV_8U);
    const auto objects = io::readFeatures(QDir(out).filePath(QStringLiteral("objects.geojson")).toStdString(), left);
    QCOMPARE(objects.size(), scene->objects.size());
    shot(window_.get(), QStringLiteral("rasters-exported.png"));
  }

  void keptFilesAreNotReplaced() {
    const QString out = dir_.filePath(QStringLiteral("rasters"));
    const std::string before = contents(QDir(out).filePath(QStringLiteral("dem.tif")));
    window_->setReplaceFilesPolicy(false);
    QCOMPARE(window_->exportElevationRasters(out), widgets::JobId(0));
    window_->setReplaceFilesPolicy(true);
    QVERIFY(window_->lastMessage().startsWith(QStringLiteral("Nothing exported")));
    QCOMPARE(contents(QDir(out).filePath(QStringLiteral("dem.tif"))), before);
    QCOMPARE(namesIn(out).size(), 6);
    if (!screenshotDir().isEmpty()) {  // the folder dialog and the question, as the operator sees them
      window_->setInteractive(true);
      answerNextDialog(QStringLiteral("rasters-folder-dialog.png"), QMessageBox::Cancel);
      window_->action(QStringLiteral("actionExportRasters"))->trigger();
      answerNextDialog(QStringLiteral("rasters-replace-question.png"), QMessageBox::No);
      window_->exportElevationRasters(out);
      window_->setInteractive(false);
      QCOMPARE(contents(QDir(out).filePath(QStringLiteral("dem.tif"))), before);
    }
  }

  void theProjectsOwnDisparityIsLeftAsItIs() {
    QVERIFY(window_->save());  // writes the computed disparity into the output folder
    const QString out = doc()->outputDirectory();
    const QString disparityFile = QDir(out).filePath(QStringLiteral("disparity.tif"));
    QCOMPARE(QString::fromStdString(doc()->project().disparity), disparityFile);
    const std::string before = contents(disparityFile);
    QSignalSpy exported(window_.get(), &MainWindow::elevationRastersExported);
    QVERIFY(window_->exportElevationRasters(out) != 0);
    QVERIFY(exported.wait(60000));
    QVERIFY2(window_->lastMessage().startsWith(QStringLiteral("4 rasters and the objects written to ")) &&
                 window_->lastMessage().endsWith(QStringLiteral("disparity.tif is the project's own file: left as it is.")),
             qPrintable(window_->lastMessage()));
    QCOMPARE(contents(disparityFile), before);
    QVERIFY(QFileInfo::exists(QDir(out).filePath(QStringLiteral("dem.tif"))));
  }

  void canceledExportWritesNothing() {
    QVERIFY(window_->openProject(projectPath_));  // no analysis yet: the export starts with it
    QVERIFY(window_->sceneAnalysis() == nullptr);
    const QString out = freshFolder(QStringLiteral("canceled"));
    {
      std::ofstream(QDir(out).filePath(QStringLiteral("dem.tif")).toStdString()) << "previous";
    }
    QSignalSpy exported(window_.get(), &MainWindow::elevationRastersExported);
    const widgets::JobId job = window_->exportElevationRasters(out);
    QVERIFY(job != 0);
    window_->jobs()->cancel(job);
    QVERIFY(window_->jobs()->waitForIdle(60000));
    QTest::qWait(100);
    QCOMPARE(exported.count(), 0);
    QCOMPARE(namesIn(out), QStringList{QStringLiteral("dem.tif")});  // no temporary left either
    QCOMPARE(contents(QDir(out).filePath(QStringLiteral("dem.tif"))), std::string("previous"));
    QVERIFY(window_->sceneAnalysis() == nullptr);
  }

  // The CityJSON export starts a job and returns at once; without a prior analysis it runs one
  // and the file holds its terrain, byte for byte what `delineo-cli export --terrain` writes.
  void cityModelExportRunsInTheBackgroundWithTheTerrain() {
    QVERIFY(window_->openProject(cityPath_));
    QVERIFY(window_->sceneAnalysis() == nullptr);
    const int accepted = static_cast<int>(doc()->project().buildings.size());
    QVERIFY(accepted >= 5);
    const QString out = QDir(freshFolder(QStringLiteral("city"))).filePath(QStringLiteral("buildings.city.json"));
    QSignalSpy exported(window_.get(), &MainWindow::cityModelExported);
    int ticks = 0;  // the window's event loop turning while the job works
    QTimer ticker;
    connect(&ticker, &QTimer::timeout, [&ticks] { ++ticks; });
    ticker.start(5);
    QElapsedTimer clock;
    clock.start();
    window_->exportAccepted(out);
    const qint64 returnedAfter = clock.elapsed();
    QVERIFY(!QFileInfo::exists(out));
    QVERIFY(window_->jobs()->activeCount() >= 1);
    QVERIFY(exported.wait(120000));
    qInfo("CityJSON export: the action returned after %lld ms, the file came after %lld ms (%d ticks between)",
          returnedAfter, clock.elapsed(), ticks);
    QVERIFY(ticks > 0);
    QVERIFY(QFileInfo::exists(out));
    QCOMPARE(namesIn(QFileInfo(out).absolutePath()), QStringList{QStringLiteral("buildings.city.json")});
    QCOMPARE(exported.first().at(1).toInt(), accepted);
    QVERIFY(window_->sceneAnalysis() != nullptr);  // the analysis made on the way is the window's
    const QString message = window_->statusBar()->currentMessage();
    QVERIFY2(message.startsWith(QStringLiteral("%1 buildings exported to buildings.city.json; ").arg(accepted)) &&
                 message.contains(QStringLiteral("; terrain: ")) && message.contains(QStringLiteral(" triangles.")),
             qPrintable(message));
    const std::string written = contents(out);
    QVERIFY(written.find("\"TINRelief\"") != std::string::npos);

    // What the command line writes for the same saved project: its heights, the analysis's DTM.
    const project::Project saved = project::loadProject(cityPath_.toStdString());
    const cv::Mat image = io::readImage8(saved.left);
    const cv::Mat disparity = project::readDisparity(saved, image.size());
    project::CityModelInputs model;
    model.heights = project::projectHeights(saved, disparity);
    model.dtm = project::analyseScene(saved, model.heights, image, disparity, nullptr).dtm;
    const QString reference = dir_.filePath(QStringLiteral("city-reference.city.json"));
    project::exportBuildings(saved, reference.toStdString(), {project::BuildingStatus::Accepted}, model);
    QVERIFY(written == contents(reference));
    shot(window_.get(), QStringLiteral("city-export.png"));
    shot(window_->statusBar(), QStringLiteral("city-export-status.png"));
  }

  // A cancel during the analysis, or once the analysis is there during the writing, leaves no
  // file and no temporary, and the document as it was.
  void canceledCityModelExportWritesNothing() {
    const QString out = QDir(freshFolder(QStringLiteral("city-canceled"))).filePath(QStringLiteral("b.city.json"));
    for (const bool analysed : {false, true}) {
      if (!analysed) QVERIFY(window_->openProject(cityPath_));
      QCOMPARE(window_->sceneAnalysis() != nullptr, analysed);
      QSignalSpy exported(window_.get(), &MainWindow::cityModelExported);
      const widgets::JobId job = window_->exportCityModel(out);
      QVERIFY(job != 0);
      window_->jobs()->cancel(job);
      QVERIFY(window_->jobs()->waitForIdle(120000));
      QTest::qWait(100);
      QCOMPARE(exported.count(), 0);
      QVERIFY2(namesIn(QFileInfo(out).absolutePath()).isEmpty(), qPrintable(namesIn(QFileInfo(out).absolutePath()).join(' ')));
      QVERIFY(!doc()->isModified());
      if (analysed) continue;
      QVERIFY(window_->sceneAnalysis() == nullptr);
      QSignalSpy analysedSpy(window_.get(), &MainWindow::sceneAnalysed);
      QVERIFY(window_->startSceneAnalysis() != 0);
      QVERIFY(analysedSpy.wait(120000));
    }
  }

  // The outlines are still written at once.
  void geoJsonExportIsWrittenAtOnce() {
    QVERIFY(window_->openProject(cityPath_));
    const QString out = QDir(freshFolder(QStringLiteral("outlines"))).filePath(QStringLiteral("b.geojson"));
    window_->exportAccepted(out);
    QVERIFY(QFileInfo::exists(out));
    const auto features = io::readFeatures(out.toStdString(), doc()->pair().geo);
    QCOMPARE(features.size(), doc()->project().buildings.size());
    QVERIFY2(window_->statusBar()->currentMessage().startsWith(
                 QStringLiteral("%1 buildings exported to ").arg(features.size())),
             qPrintable(window_->statusBar()->currentMessage()));
  }

  void maskIsHatchedOverTheLeftView() {
    QVERIFY(window_->openProject(projectPath_));
    QVERIFY(act("actionShowExclusionMask")->isEnabled());
    act("actionShowLabels")->setChecked(false);
    act("actionShowExclusionMask")->setChecked(false);
    widgets::ImageView* view = window_->leftView();
    view->fitToWindow();
    QTest::qWait(100);
    const QImage plain = view->grab().toImage().convertToFormat(QImage::Format_RGB32);
    act("actionShowExclusionMask")->setChecked(true);
    QVERIFY(view->overlayVisible());
    QVERIFY(window_->findChild<QWidget*>(QStringLiteral("maskLegend"))->isVisible());
    QVERIFY(QSettings().value(QStringLiteral("view/showExclusionMask")).toBool());  // remembered
    const QImage hatched = view->grab().toImage().convertToFormat(QImage::Format_RGB32);
    const OverlayChange change = compareGrabs(plain, hatched, *view, mask_);
    qInfo("mask shown: %.0f %% of the mask's pixels hatched, %.1f %% of the others changed", 100 * change.maskHatched,
          100 * change.elsewhereChanged);
    // Stripes 3 pixels in 8 of the level drawn: about 3/8 of the mask's pixels.
    QVERIFY2(change.maskHatched > 0.2 && change.maskHatched < 0.6, qPrintable(QString::number(change.maskHatched)));
    QVERIFY2(change.elsewhereChanged < 0.01, qPrintable(QString::number(change.elsewhereChanged)));
    shot(window_.get(), QStringLiteral("exclusion-mask.png"));
    shotMaskCloseUp(QStringLiteral("exclusion-mask-zoom.png"));

    // With the labels: both drawn, the labels' colours between the stripes.
    act("actionShowLabels")->setChecked(true);
    view->fitToWindow();
    const QImage both = view->grab().toImage().convertToFormat(QImage::Format_RGB32);
    shotMaskCloseUp(QStringLiteral("exclusion-mask-labels-zoom.png"));
    view->fitToWindow();
    QVERIFY(compareGrabs(plain, both, *view, mask_).elsewhereChanged > 0.05);  // the buildings' labels
    QVERIFY(compareGrabs(plain, both, *view, mask_).maskHatched > 0.2);
    act("actionShowLabels")->setChecked(false);

    act("actionShowExclusionMask")->setChecked(false);
    QVERIFY(!view->overlayVisible());
    QVERIFY(!window_->findChild<QWidget*>(QStringLiteral("maskLegend"))->isVisible());
    const QImage off = view->grab().toImage().convertToFormat(QImage::Format_RGB32);
    QCOMPARE(compareGrabs(plain, off, *view, mask_).maskHatched, 0.0);
  }

  // Screenshots only: the mask over the real Toulouse 0051 image (a mask of its green pixels), when
  // DELINEO_SCREENSHOT_DIR is set and the real pairs are there (DELINEO_DATA_DIR, else ../shared/data).
  void realPairMaskScreenshots() {
    if (screenshotDir().isEmpty()) QSKIP("screenshots only (DELINEO_SCREENSHOT_DIR)");
    const QString data = qEnvironmentVariable("DELINEO_DATA_DIR", QStringLiteral(DELINEO_DEFAULT_DATA_DIR));
    const QString stem = data + QStringLiteral("/aerial-toulouse/31_15083_31_15084_0051_");
    if (!QFileInfo::exists(stem + QStringLiteral("left.png"))) QSKIP("the real pairs are not there");
    project::Project p;
    p.name = "Toulouse 0051";
    p.left = (stem + QStringLiteral("left.png")).toStdString();
    p.right = (stem + QStringLiteral("right.png")).toStdString();
    std::vector<cv::Mat> bgr;
    cv::split(io::readImage8(p.left), bgr);
    cv::Mat excessGreen;  // 2G - R - B, the usual vegetation index of RGB images
    cv::addWeighted(bgr[1], 2.0, bgr[2], -1.0, 0.0, excessGreen, CV_16S);
    excessGreen -= bgr[0];
    cv::Mat green = excessGreen > 24;
    cv::morphologyEx(green, green, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5}));
    p.exclude = dir_.filePath(QStringLiteral("toulouse_green.tif")).toStdString();
    io::writeGeoTiff(p.exclude, green);
    mask_ = io::readMask(p.exclude, green.size());
    qInfo("Toulouse 0051: %.1f %% of the image in the green mask", 100.0 * cv::countNonZero(mask_) / mask_.total());
    const QString path = dir_.filePath(QStringLiteral("toulouse.delineo.json"));
    project::saveProject(p, path.toStdString());
    window_->resize(1600, 1000);
    QVERIFY(window_->openProject(path));
    act("actionShowExclusionMask")->setChecked(true);
    window_->leftView()->fitToWindow();
    shot(window_.get(), QStringLiteral("toulouse-exclusion-mask.png"));
    shotMaskCloseUp(QStringLiteral("toulouse-exclusion-mask-zoom.png"));
  }

  void cleanupTestCase() { window_.reset(); }
};

QTEST_MAIN(ElevationRastersTest)
#include "test_elevation_rasters.moc"
