// File → Import outlines in the real main window: the polygons of a GeoJSON file become pending
// buildings in one undoable step, with the chosen attribute as their source id (shown in the
// buildings list); what lies outside the left image or is already a building is left out and
// said; map coordinates are read on a georeferenced pair, pixels on another; a file of which
// nothing lies on the image asks about its coordinates; an unreadable file is named in the message.
#include <QAction>
#include <QFile>
#include <QSignalSpy>
#include <QTableView>
#include <QTemporaryDir>
#include <QTest>
#include <QTranslator>
#include <QUndoStack>

#include <cmath>

#include <opencv2/core.hpp>

#include "buildings_model.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "main_window.hpp"
#include "sample_window.hpp"

using namespace delineo;
using gui::MainWindow;

namespace {

// A square of `side` px at (x, y) of the left image, with an osm_id and a name.
core::Feature square(double x, double y, double side, long long osmId) {
  core::Feature f;
  f.polygon.outer = {{x, y}, {x + side, y}, {x + side, y + side}, {x, y + side}};
  f.attributes["osm_id"] = osmId;
  f.attributes["name"] = std::string("house ") + std::to_string(osmId);
  return f;
}

}  // namespace

class ImportOutlinesTest : public QObject {
  Q_OBJECT
 private:
  QTemporaryDir dir_;
  QString projectPath_;
  std::unique_ptr<MainWindow> window_;
  QStringList namesAsked_;
  QString preselected_;

  gui::Document* doc() const { return window_->document(); }
  QAction* act(const char* name) const { return window_->action(QString::fromLatin1(name)); }

  // `features` (left-image pixels) written as GeoJSON in the left image's map coordinates.
  QString writeOutlines(const QString& name, const std::vector<core::Feature>& features) {
    const QString path = dir_.filePath(name);
    io::writeFeatures(path.toStdString(), features, doc()->pair().geo);
    return path;
  }

  // Answers the id field question with `answer`, or the preselected attribute when null.
  void answerIdField(const std::optional<QString>& answer) {
    window_->setIdFieldHandler([this, answer](const QStringList& names, const QString& preselected) {
      namesAsked_ = names;
      preselected_ = preselected;
      return answer ? answer : std::optional<QString>(preselected);
    });
  }

 private slots:
  void initTestCase() {
    guitest::isolateSettings(QStringLiteral("DelineoImportTest"), false);
    QVERIFY(dir_.isValid());
    projectPath_ = guitest::makeSampleProject(dir_);
    window_ = guitest::showMainWindow();
    QVERIFY(QTest::qWaitForWindowExposed(window_.get()));
    QVERIFY(!act("actionImportOutlines")->isEnabled());
  }

  void outlinesBecomePendingBuildingsInOneUndoStep() {
    QVERIFY(window_->openProject(projectPath_));
    QVERIFY(act("actionImportOutlines")->isEnabled());
    QVERIFY(doc()->project().buildings.empty());
    const cv::Size size = doc()->pair().left.size();
    const QString path = writeOutlines(QStringLiteral("outlines.geojson"),
                                       {square(20, 20, 30, 101), square(size.width - 60.0, 60, 30, 102),
                                        square(size.width + 200.0, 20, 30, 103)});
    answerIdField(std::nullopt);
    QSignalSpy imported(window_.get(), &MainWindow::outlinesImported);
    QCOMPARE(window_->importOutlines(path), 2);
    QCOMPARE(namesAsked_, (QStringList{QStringLiteral("name"), QStringLiteral("osm_id")}));
    QCOMPARE(preselected_, QStringLiteral("osm_id"));
    QCOMPARE(imported.count(), 1);
    QCOMPARE(imported.at(0).at(0).toInt(), 2);
    QCOMPARE(imported.at(0).at(1).toInt(), 3);
    QVERIFY2(window_->lastMessage().startsWith(QStringLiteral(
                 "2 of 3 outlines of outlines.geojson imported as pending buildings; 1 outside the left image. "
                 "Outline them with Building → Outline the pending buildings.")),
             qPrintable(window_->lastMessage()));
    const auto& buildings = doc()->project().buildings;
    QCOMPARE(buildings.size(), size_t(2));
    QCOMPARE(buildings[0].sourceId, std::string("101"));
    QCOMPARE(buildings[1].sourceId, std::string("102"));
    for (const project::Building& b : buildings) {
      QVERIFY(b.status == project::BuildingStatus::Pending);
      QCOMPARE(b.history.back().action, std::string("imported"));
      QVERIFY(b.history.back().detail.find("outlines.geojson") != std::string::npos);
    }
    QCOMPARE(window_->selectedBuilding(), buildings[0].id);
    QCOMPARE(window_->leftView()->polygons().polygons().size(), size_t(2));
    QVERIFY(act("actionOutlinePending")->isEnabled());
    // The buildings list shows the source ids.
    QTableView* table = window_->buildingsTable();
    QVERIFY(!table->isColumnHidden(gui::BuildingsModel::SourceId));
    QCOMPARE(table->model()->data(table->model()->index(1, gui::BuildingsModel::SourceId)).toString(),
             QStringLiteral("102"));
    QCOMPARE(table->model()->data(table->model()->index(1, gui::BuildingsModel::Status), Qt::ToolTipRole).toString(),
             QStringLiteral("Source id: 102"));
    // One undo removes both, one redo brings them back.
    QCOMPARE(doc()->undoStack()->undoText(), QStringLiteral("Import 2 outline(s)"));
    act("actionUndo")->trigger();
    QVERIFY(doc()->project().buildings.empty());
    QCOMPARE(table->model()->rowCount(), 0);
    QVERIFY(table->isColumnHidden(gui::BuildingsModel::SourceId));
    act("actionRedo")->trigger();
    QCOMPARE(doc()->project().buildings.size(), size_t(2));
    QCOMPARE(doc()->project().buildings[1].sourceId, std::string("102"));
    // The same file again: nothing new, and no undo step.
    const int steps = doc()->undoStack()->count();
    QCOMPARE(window_->importOutlines(path), 0);
    QCOMPARE(doc()->undoStack()->count(), steps);
    QVERIFY2(window_->lastMessage().contains(QStringLiteral("0 of 3 outlines")) &&
                 window_->lastMessage().contains(QStringLiteral("2 already in the project")),
             qPrintable(window_->lastMessage()));
  }

  void noIdFieldAndOutlinesCutAtTheBorder() {
    QVERIFY(window_->openProject(projectPath_));
    const QString path = writeOutlines(QStringLiteral("border.geojson"), {square(-10, 30, 40, 7)});
    answerIdField(QString());  // (none)
    QCOMPARE(window_->importOutlines(path), 1);
    const project::Building& b = doc()->project().buildings.front();
    QVERIFY(b.sourceId.empty());
    QCOMPARE(core::boundingBox(b.initial.outer).x, 0.0);
    QVERIFY2(window_->lastMessage().startsWith(
                 QStringLiteral("1 of 1 outline of border.geojson imported as a pending building (1 cut at the image border).")),
             qPrintable(window_->lastMessage()));
    QVERIFY(window_->buildingsTable()->isColumnHidden(gui::BuildingsModel::SourceId));
  }

  // Without georeferencing the file's coordinates are pixels; a file of which nothing lies on
  // the image asks whether they are. A file without attributes asks nothing.
  void nothingOnTheImageAsksAboutTheCoordinates() {
    QVERIFY(guitest::openPairWithoutHeights(*window_, dir_));
    QVERIFY(!doc()->pair().geo.valid());
    core::Feature far;
    far.polygon.outer = {{5000, 5000}, {5100, 5000}, {5100, 5100}, {5000, 5100}};
    const QString path = writeOutlines(QStringLiteral("far.geojson"), {far});
    namesAsked_.clear();
    answerIdField(QStringLiteral("never asked"));
    QCOMPARE(window_->importOutlines(path), 0);
    QVERIFY(namesAsked_.isEmpty());
    QVERIFY(doc()->project().buildings.empty());
    QVERIFY(!doc()->undoStack()->canUndo());
    QVERIFY2(window_->lastMessage().contains(QStringLiteral("1 outside the left image")) &&
                 window_->lastMessage().contains(QStringLiteral("it has no georeferencing, so the file's coordinates "
                                                                "are read as its pixels. Are they?")),
             qPrintable(window_->lastMessage()));
  }

  // On a georeferenced pair the file's coordinates are map coordinates: a square written in
  // them lands on its pixels, and the same square written in pixels lies far outside.
  void georeferencedPairReadsMapCoordinates() {
    cv::Mat left(120, 160, CV_8U);
    cv::randu(left, 0, 255);
    io::GeoReference geo;
    geo.geoTransform = {500000.0, 0.5, 0.0, 4800000.0, 0.0, -0.5};
    geo.hasTransform = true;
    const QString l = dir_.filePath(QStringLiteral("geo_left.tif"));
    const QString r = dir_.filePath(QStringLiteral("geo_right.tif"));
    io::writeGeoTiff(l.toStdString(), left, geo);
    io::writeGeoTiff(r.toStdString(), left, geo);
    QVERIFY(window_->openPair(l, r));
    QVERIFY(doc()->pair().geo.valid());
    answerIdField(std::nullopt);
    QCOMPARE(window_->importOutlines(writeOutlines(QStringLiteral("map.geojson"), {square(40, 30, 20, 5)})), 1);
    const cv::Rect2d box = core::boundingBox(doc()->project().buildings.front().initial.outer);
    QVERIFY2(std::abs(box.x - 40.0) < 1e-6 && std::abs(box.y - 30.0) < 1e-6 && std::abs(box.width - 20.0) < 1e-6,
             qPrintable(QStringLiteral("%1 %2 %3").arg(box.x).arg(box.y).arg(box.width)));
    const QString pixels = dir_.filePath(QStringLiteral("pixels.geojson"));
    io::writeFeatures(pixels.toStdString(), {square(40, 30, 20, 6)});
    QCOMPARE(window_->importOutlines(pixels), 0);
    QVERIFY2(window_->lastMessage().contains(QStringLiteral(
                 "No outline lies on the left image: are the file's coordinates in the coordinate reference "
                 "system it declares, or in the left image's when it declares none?")),
             qPrintable(window_->lastMessage()));
  }

  void unreadableFileIsNamed() {
    QVERIFY(guitest::openPairWithoutHeights(*window_, dir_));
    const QString path = dir_.filePath(QStringLiteral("broken.geojson"));
    QFile file(path);
    QVERIFY(file.open(QIODevice::WriteOnly));
    file.write("{\"type\": \"FeatureCollection\", \"features\": [");
    file.close();
    QCOMPARE(window_->importOutlines(path), -1);
    QVERIFY2(window_->lastMessage().contains(QStringLiteral("broken.geojson")), qPrintable(window_->lastMessage()));
    QVERIFY(doc()->project().buildings.empty());
  }

  void frenchStrings() {
    QTranslator translator;
    QVERIFY(translator.load(QStringLiteral(":/i18n/delineo_fr.qm")));
    QCOMPARE(translator.translate("delineo::gui::MainWindow", "&Import outlines…"),
             QStringLiteral("&Importer des contours…"));
    QCOMPARE(translator.translate("delineo::gui::Document", "Import %n outline(s)", nullptr, 2),
             QStringLiteral("Importer %n contours"));  // the plural form; tr() puts the number in
    QCOMPARE(translator.translate("delineo::gui::BuildingsModel", "Source id"), QStringLiteral("Id. source"));
  }

  void cleanupTestCase() { window_.reset(); }
};

QTEST_MAIN(ImportOutlinesTest)
#include "test_import_outlines.moc"
