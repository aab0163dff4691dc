// MainWindow's scene analysis (project::analyseScene): the ground, the DTM, the nDSM, the classes
// building / vegetation and the above-ground objects of the current heights, computed in the
// background and kept until the heights or the analysis's parameters change; its layers (the
// classes over the left image, the objects' outlines, the DTM or nDSM in the DEM view) with their
// legend, and the project's exclusion mask hatched over the left image; and Detect buildings,
// which adds the building proposals as pending buildings.
#include <QAction>
#include <QActionGroup>
#include <QComboBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QMessageBox>
#include <QPainter>
#include <QPixmap>
#include <QPointer>
#include <QSignalBlocker>
#include <QStatusBar>
#include <string>
#include <utility>
#include <vector>

#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "main_window.hpp"

namespace delineo::gui {

namespace {

// The classes' colours (project::SceneAnalysisOutcome::classes, and the same labels of a
// ground-truth raster): building blue and vegetation green, apart from the outlines' status
// colours (pending yellow, accepted green, edited orange) and from red tile roofs.
const QColor kBuildingColour(40, 110, 255);
const QColor kVegetationColour(40, 210, 60);
const QColor kWallColour(200, 80, 220);  // label 3 of a simulated ground truth
// The objects' outlines: lighter than the fills so they read over them.
const QColor kBuildingObjectColour(120, 170, 255);
const QColor kVegetationObjectColour(140, 255, 110);
// The exclusion mask (images.exclude): cyan stripes, apart from the classes and the outlines, over
// the labels or classes shown. The overlay is a little more opaque with it, for the stripes to read.
const QColor kMaskColour(0, 230, 230);
constexpr int kMaskedBit = 0x100;  // above every 8-bit label
constexpr double kMaskOverlayOpacity = 0.55;

QColor classColour(int label) {
  switch (label) {
    case 1: return kBuildingColour;
    case 2: return kVegetationColour;
    case 3: return kWallColour;
    default: return QColor(0, 0, 0, 0);
  }
}

// A legend entry: its swatch and its name.
QWidget* legendEntryOf(const QPixmap& swatch, const QString& text) {
  auto* entry = new QWidget;
  auto* layout = new QHBoxLayout(entry);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->setSpacing(3);
  auto* swatchLabel = new QLabel;
  swatchLabel->setPixmap(swatch);
  layout->addWidget(swatchLabel);
  layout->addWidget(new QLabel(text));
  return entry;
}

// A legend entry: a filled square (a class) or a short line (an outline) and its name.
QWidget* legendEntry(const QColor& colour, bool line, Qt::PenStyle style, const QString& text) {
  QPixmap pixmap(line ? 22 : 12, 12);
  pixmap.fill(Qt::transparent);
  QPainter painter(&pixmap);
  if (line) {
    painter.setPen(QPen(QColor(0, 0, 0, 160), 4.0));
    painter.drawLine(1, 6, 21, 6);
    painter.setPen(QPen(colour, 2.5, style));
    painter.drawLine(1, 6, 21, 6);
  } else {
    painter.fillRect(0, 0, 12, 12, colour);
    painter.setPen(QColor(0, 0, 0, 160));
    painter.drawRect(0, 0, 11, 11);
  }
  painter.end();
  return legendEntryOf(pixmap, text);
}

// The legend entry of a hatched layer: a square with the layer's stripes.
QWidget* hatchedLegendEntry(const QColor& colour, const QString& text) {
  QPixmap pixmap(12, 12);
  pixmap.fill(Qt::transparent);
  QPainter painter(&pixmap);
  painter.fillRect(0, 0, 12, 12, QBrush(colour, Qt::BDiagPattern));
  painter.setPen(QColor(0, 0, 0, 160));
  painter.drawRect(0, 0, 11, 11);
  painter.end();
  return legendEntryOf(pixmap, text);
}

// The overlay with the exclusion mask: `labels` (CV_8U, may be empty: none shown) as 16-bit labels,
// kMaskedBit added where the mask is non-zero (drawn hatched over the label's colour).
cv::Mat withMaskHatched(const cv::Mat& labels, const cv::Mat& mask) {
  cv::Mat overlay(mask.size(), CV_16U, cv::Scalar(0));
  if (!labels.empty()) labels.convertTo(overlay, CV_16U);
  cv::bitwise_or(overlay, cv::Scalar(kMaskedBit), overlay, mask);
  return overlay;
}

bool isBuildingObject(const core::Feature& object) {
  const auto it = object.attributes.find("class");
  return it != object.attributes.end() && std::holds_alternative<std::string>(it->second) &&
         std::get<std::string>(it->second) == "building";
}

}  // namespace

// ------------------------------------------------------------------------------------------
// actions and legend

void MainWindow::createSceneActions() {
  auto make = [this](const QString& name, const QString& text, const QString& tip) {
    auto* a = new QAction(text, this);
    a->setObjectName(name);
    a->setStatusTip(tip);
    addAction(a);
    return a;
  };
  connect(make(QStringLiteral("actionAnalyseScene"), tr("Analyse the &scene"),
               tr("Ground, DTM, height above ground, buildings and vegetation of the whole image, from its heights")),
          &QAction::triggered, this, &MainWindow::startSceneAnalysis);
  connect(make(QStringLiteral("actionDetectBuildings"), tr("De&tect buildings"),
               tr("Add the buildings the scene analysis finds as pending buildings, to review and delineate")),
          &QAction::triggered, this, &MainWindow::detectBuildings);
  QAction* classes = make(QStringLiteral("actionShowClasses"), tr("&Classes"),
                          tr("Colour the left image by class: buildings blue, vegetation green"));
  QAction* objects = make(QStringLiteral("actionShowObjects"), tr("O&bjects"),
                          tr("Outline the above-ground objects on the left image: buildings blue, vegetation green"));
  for (QAction* a : {classes, objects}) {
    a->setCheckable(true);
    connect(a, &QAction::toggled, this, [this, a](bool on) { onSceneLayerToggled(a, on); });
  }
  // The labels raster and the classes share the left view's overlay: one at a time.
  auto* overlays = new QActionGroup(this);
  overlays->setExclusionPolicy(QActionGroup::ExclusionPolicy::ExclusiveOptional);
  overlays->addAction(action(QStringLiteral("actionShowLabels")));
  overlays->addAction(classes);
  // What the DEM view shows, also chosen on the DEM dock.
  auto* layers = new QActionGroup(this);
  const QStringList names = {QStringLiteral("actionDemLayerDem"), QStringLiteral("actionDemLayerDtm"),
                             QStringLiteral("actionDemLayerNdsm")};
  const QStringList texts = {tr("&DEM"), tr("D&TM (ground)"), tr("&nDSM (height above ground)")};
  for (int i = 0; i < 3; ++i) {
    QAction* a = make(names[i], texts[i], tr("What the DEM view shows"));
    a->setCheckable(true);
    a->setChecked(i == 0);
    layers->addAction(a);
    connect(a, &QAction::triggered, this, [this, i] {
      demLayer_->setCurrentIndex(i);
      showDock(QStringLiteral("demDock"));
    });
  }
  connect(demLayer_, &QComboBox::currentIndexChanged, this, &MainWindow::onDemLayerChosen);
  connect(jobs_, &widgets::JobRunner::ended, this, &MainWindow::onSceneJobEnded);
}

// In the status bar: the colours of the overlay and of the objects' outlines, each part shown
// while its layer is.
QWidget* MainWindow::createLayerLegend() {
  layerLegend_ = new QWidget;
  layerLegend_->setObjectName(QStringLiteral("layerLegend"));
  auto* layout = new QHBoxLayout(layerLegend_);
  layout->setContentsMargins(0, 0, 6, 0);
  layout->setSpacing(8);
  classesLegend_ = new QWidget;
  classesLegend_->setObjectName(QStringLiteral("classesLegend"));
  auto* classes = new QHBoxLayout(classesLegend_);
  classes->setContentsMargins(0, 0, 0, 0);
  classesLegendTitle_ = new QLabel;
  classes->addWidget(classesLegendTitle_);
  classes->addWidget(legendEntry(kBuildingColour, false, Qt::SolidLine, tr("building")));
  classes->addWidget(legendEntry(kVegetationColour, false, Qt::SolidLine, tr("vegetation")));
  wallLegend_ = legendEntry(kWallColour, false, Qt::SolidLine, tr("wall"));
  classes->addWidget(wallLegend_);
  objectsLegend_ = new QWidget;
  objectsLegend_->setObjectName(QStringLiteral("objectsLegend"));
  auto* objects = new QHBoxLayout(objectsLegend_);
  objects->setContentsMargins(0, 0, 0, 0);
  objects->addWidget(new QLabel(tr("Objects:")));
  objects->addWidget(legendEntry(kBuildingObjectColour, true, Qt::SolidLine, tr("building")));
  objects->addWidget(legendEntry(kVegetationObjectColour, true, Qt::DashLine, tr("vegetation")));
  maskLegend_ = new QWidget;
  maskLegend_->setObjectName(QStringLiteral("maskLegend"));
  auto* mask = new QHBoxLayout(maskLegend_);
  mask->setContentsMargins(0, 0, 0, 0);
  mask->addWidget(new QLabel(tr("Exclusion mask:")));
  mask->addWidget(hatchedLegendEntry(kMaskColour, tr("not roof")));
  layout->addWidget(classesLegend_);
  layout->addWidget(objectsLegend_);
  layout->addWidget(maskLegend_);
  classesLegend_->hide();
  objectsLegend_->hide();
  maskLegend_->hide();
  layerLegend_->hide();
  return layerLegend_;
}

// ------------------------------------------------------------------------------------------
// the analysis

// Why the analysis cannot run on the open document; empty when it can.
QString MainWindow::sceneInputsMissing() const {
  if (!document_) return tr("Open a project first.");
  if (document_->dem().empty()) {
    return document_->disparity().empty()
               ? tr("The scene analysis needs heights: compute the disparity (Processing → Compute disparity) "
                    "and set the height model (File → Project settings), or give the project a DEM.")
               : tr("The scene analysis needs heights: set the height model of the pair (File → Project "
                    "settings).");
  }
  if (!(document_->project().height.gsd > 0.0)) {
    return tr("The scene analysis needs the ground sample distance: set it with the height model (File → "
              "Project settings).");
  }
  return {};
}

widgets::JobId MainWindow::startSceneAnalysis() {
  const QString missing = sceneInputsMissing();
  if (!missing.isEmpty()) {
    showMessage(tr("Scene analysis"), missing);
    return 0;
  }
  const project::Project projectCopy = document_->project();
  const cv::Mat heights = document_->dem();
  const cv::Mat disparity = document_->disparity();
  const SceneInputs inputs{heights.data, disparity.data, projectCopy.height.gsd};
  QPointer<Document> doc(document_.get());
  sceneJob_ = jobs_->run<project::SceneAnalysisOutcome>(
      tr("Scene analysis"),
      [projectCopy, heights, disparity](core::Progress& p) {
        // The left image as the command line reads it (8-bit grey or BGR), for the same classes.
        const cv::Mat image = io::readImage8(projectCopy.left);
        return project::analyseScene(projectCopy, heights, image, disparity, &p);
      },
      [this, doc, inputs](project::SceneAnalysisOutcome outcome) {
        if (!doc || doc != document_.get() || outcome.status != core::RunStatus::Completed) return;
        scene_ = std::move(outcome);
        sceneInputs_ = inputs;
        refreshRasters();
        refreshLabelOverlay();
        refreshGuides();
        statusBar()->showMessage(tr("Scene analysed: %n object(s).", nullptr, static_cast<int>(scene_->objects.size())),
                                 8000);
        emit sceneAnalysed();
        if (std::exchange(detectAfterAnalysis_, false)) addDetectedBuildings();
      },
      QStringLiteral("scene"));
  return sceneJob_;
}

// The analysis a layer needs: true when it is there or on its way (started here when missing);
// false, with the message saying why, when it cannot be computed.
bool MainWindow::ensureSceneAnalysis() {
  if (scene_ || (sceneJob_ != 0 && jobs_->isActive(sceneJob_))) return true;
  return startSceneAnalysis() != 0;
}

// A canceled or failed analysis leaves the document as it was; the layers waiting for it are
// turned off, and Detect buildings does not follow.
void MainWindow::onSceneJobEnded(widgets::JobId id, widgets::JobOutcome outcome) {
  if (id != sceneJob_) return;
  sceneJob_ = 0;
  if (outcome == widgets::JobOutcome::Finished) return;
  detectAfterAnalysis_ = false;
  if (scene_) return;
  for (const char* name : {"actionShowClasses", "actionShowObjects"}) {
    const QSignalBlocker block(action(QString::fromLatin1(name)));
    action(QString::fromLatin1(name))->setChecked(false);
  }
  setDemLayer(DemLayer::Dem);
  refreshLabelOverlay();
  refreshGuides();
}

// The analysis made for an export is the window's too while the heights are the same.
void MainWindow::adoptSceneAnalysis(project::SceneAnalysisOutcome analysis, const SceneInputs& inputs) {
  const SceneInputs now{document_->dem().data, document_->disparity().data, document_->project().height.gsd};
  if (scene_ || now != inputs) return;
  scene_ = std::move(analysis);
  sceneInputs_ = inputs;
  refreshRasters();
  refreshLabelOverlay();
  refreshGuides();
  emit sceneAnalysed();
}

// The heights, the disparity or the analysis's parameters changed: the analysis is of other
// data. It is computed again when one of its layers is shown.
void MainWindow::invalidateSceneAnalysis() {
  if (!scene_ && sceneJob_ == 0) return;
  scene_.reset();
  if (sceneJob_ != 0) jobs_->cancel(sceneJob_);
  const bool shown = detectAfterAnalysis_ || action(QStringLiteral("actionShowClasses"))->isChecked() ||
                     action(QStringLiteral("actionShowObjects"))->isChecked() || demLayer() != DemLayer::Dem;
  if (shown && sceneInputsMissing().isEmpty()) startSceneAnalysis();
  refreshRasters();
  refreshLabelOverlay();
  refreshGuides();
}

// ------------------------------------------------------------------------------------------
// detecting buildings

widgets::JobId MainWindow::detectBuildings() {
  if (scene_) {
    addDetectedBuildings();
    return 0;
  }
  if (sceneJob_ != 0 && jobs_->isActive(sceneJob_)) {
    detectAfterAnalysis_ = true;
    return sceneJob_;
  }
  const widgets::JobId job = startSceneAnalysis();
  detectAfterAnalysis_ = job != 0;
  return job;
}

void MainWindow::addDetectedBuildings() {
  if (!document_ || !scene_) return;
  const int proposed = static_cast<int>(scene_->proposals.size());
  std::vector<std::string> problems;
  const int added = static_cast<int>(document_->addProposedBuildings(scene_->proposals, &problems).size());
  showDock(QStringLiteral("buildingsDock"));
  QString text = (added == 1 ? tr("%1 building proposed (%2 already present).")
                              : tr("%1 buildings proposed (%2 already present)."))
                     .arg(added)
                     .arg(proposed - added);
  if (added > 0) text += QLatin1Char(' ') + tr("Review them in the buildings list and delineate them.");
  QStringList unread;
  for (const std::string& problem : problems) unread << QString::fromStdString(problem);
  if (!unread.isEmpty()) {
    text += QLatin1Char(' ') + tr("Some roof intervals could not be read: set them on the histogram (%1).")
                                   .arg(unread.join(QStringLiteral("; ")));
  }
  showInformation(tr("Detect buildings"), text);
  emit buildingsDetected(added, proposed - added);
}

void MainWindow::showInformation(const QString& title, const QString& text) {
  lastMessage_ = text;
  statusBar()->showMessage(text, 15000);
  emit messageShown(text);
  if (interactive_) QMessageBox::information(this, title, text);
}

// ------------------------------------------------------------------------------------------
// layers

void MainWindow::onSceneLayerToggled(QAction* toggle, bool on) {
  if (on && !ensureSceneAnalysis()) {
    const QSignalBlocker block(toggle);
    toggle->setChecked(false);
  }
  refreshLabelOverlay();
  refreshGuides();
}

void MainWindow::setDemLayer(DemLayer layer) { demLayer_->setCurrentIndex(static_cast<int>(layer)); }

MainWindow::DemLayer MainWindow::demLayer() const { return static_cast<DemLayer>(demLayer_->currentIndex()); }

void MainWindow::onDemLayerChosen(int index) {
  if (index != 0 && !ensureSceneAnalysis()) {
    const QSignalBlocker block(demLayer_);
    demLayer_->setCurrentIndex(0);
    index = 0;
  }
  static const char* const names[] = {"actionDemLayerDem", "actionDemLayerDtm", "actionDemLayerNdsm"};
  action(QString::fromLatin1(names[index]))->setChecked(true);
  refreshRasters();
}

// What the DEM view shows: the DEM (enhanced when asked for), or the analysis's DTM or nDSM
// (empty while it is being computed).
const cv::Mat& MainWindow::demViewRaster() const {
  static const cv::Mat none;
  switch (demLayer()) {
    case DemLayer::Dem: return shownDem();
    case DemLayer::Dtm: return scene_ ? scene_->dtm : none;
    case DemLayer::Ndsm: return scene_ ? scene_->ndsm : none;
  }
  return none;
}

// The left view's overlay: the analysis's classes or the project's label raster (one at a time),
// in the classes' colours, and the exclusion mask hatched over them, with the legend. Without the
// mask a hidden label raster stays in the view (turned on without making its tiles again).
void MainWindow::refreshLabelOverlay() {
  const bool classes = action(QStringLiteral("actionShowClasses"))->isChecked() && scene_;
  const bool labels = !classes && document_ && !document_->labels().empty();
  const bool labelsShown = classes || (labels && action(QStringLiteral("actionShowLabels"))->isChecked());
  const cv::Mat& mask = document_ ? document_->pair().exclude : cv::Mat();
  const bool maskShown = !mask.empty() && action(QStringLiteral("actionShowExclusionMask"))->isChecked();
  const cv::Mat base = classes ? scene_->classes : labels ? document_->labels() : cv::Mat();
  const OverlaySources wanted{maskShown && !labelsShown ? nullptr : base.data, maskShown ? mask.data : nullptr};
  if (!(wanted == overlayShows_)) {  // a new overlay raster: its tiles are made again
    if (maskShown) {
      leftView_->setOverlay(withMaskHatched(labelsShown ? base : cv::Mat(), mask), kMaskOverlayOpacity, classColour,
                            {kMaskedBit, kMaskColour});
    } else if (base.empty()) {
      leftView_->clearOverlay();
    } else {
      leftView_->setOverlay(base, classes ? 0.45 : 0.3, classColour);
    }
    overlayShows_ = wanted;
  }
  leftView_->setOverlayVisible(labelsShown || maskShown);
  classesLegendTitle_->setText(classes ? tr("Classes:") : tr("Labels:"));
  wallLegend_->setVisible(!classes);
  classesLegend_->setVisible(labelsShown);
  maskLegend_->setVisible(maskShown);
  refreshLayerLegend();
}

void MainWindow::refreshLayerLegend() {
  objectsLegend_->setVisible(action(QStringLiteral("actionShowObjects"))->isChecked() && scene_);
  layerLegend_->setVisible(classesLegend_->isVisibleTo(layerLegend_) || objectsLegend_->isVisibleTo(layerLegend_) ||
                           maskLegend_->isVisibleTo(layerLegend_));
}

// The analysis's objects, outlined in their class's colour (vegetation dashed).
std::vector<widgets::OverlayGuide> MainWindow::sceneObjectGuides() const {
  std::vector<widgets::OverlayGuide> guides;
  if (!scene_ || !action(QStringLiteral("actionShowObjects"))->isChecked()) return guides;
  for (const core::Feature& object : scene_->objects) {
    const bool building = isBuildingObject(object);
    guides.push_back({object.polygon, building ? kBuildingObjectColour : kVegetationObjectColour, 1.5,
                      building ? Qt::SolidLine : Qt::DashLine});
  }
  return guides;
}

// Reference shapes over the left view and the DEM view: the objects, then the box-fitting
// proposals (on top: the operator is choosing between them).
void MainWindow::refreshGuides() {
  std::vector<widgets::OverlayGuide> guides = sceneObjectGuides();
  for (widgets::OverlayGuide& g : boxFitGuides()) guides.push_back(std::move(g));
  for (widgets::ImageView* v : {leftView_, demView_}) v->polygons().setGuides(guides);
  refreshLayerLegend();
}

}  // namespace delineo::gui
