// MainWindow's docks: the right image, disparity, DEM and 3D view on the right, the buildings
// list and the parameters (main_window_parameters.cpp) on the left.
#include <QComboBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QTableView>
#include <QToolButton>
#include <QVBoxLayout>
#include <algorithm>

#include "buildings_model.hpp"
#include "delineo/widgets/colour_maps.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/terrain3d_view.hpp"
#include "document.hpp"
#include "main_window.hpp"

namespace delineo::gui {

using project::Building;

// The right image, disparity, DEM and 3D view tabbed on the right (the right image in front);
// the buildings list and the parameters on the left.
void MainWindow::createDocks() {
  setDockOptions(QMainWindow::AnimatedDocks | QMainWindow::AllowTabbedDocks | QMainWindow::AllowNestedDocks);

  auto* rightDock = addDock(QStringLiteral("rightDock"), tr("Right image"), rightView_, Qt::RightDockWidgetArea);
  QDockWidget* disparityDock = createDisparityDock();
  QDockWidget* demDock = createDemDock();
  QDockWidget* view3DDock = create3DDock();
  tabifyDockWidget(rightDock, disparityDock);
  tabifyDockWidget(disparityDock, demDock);
  tabifyDockWidget(demDock, view3DDock);
  rightDock->raise();

  createBuildingsDock();
  createParametersDock();
}

QDockWidget* MainWindow::createDisparityDock() {
  auto* disparityPage = new QWidget;
  auto* disparityLayout = new QHBoxLayout(disparityPage);
  disparityLayout->setContentsMargins(0, 0, 0, 0);
  disparityLegend_ = new widgets::ColourLegend;
  disparityLegend_->setColourMap(widgets::ColourMap::Viridis);
  disparityLegend_->setTitle(tr("Disparity"));
  disparityLegend_->setUnit(tr("px"));
  disparityLayout->addWidget(disparityView_, 1);
  disparityLayout->addWidget(disparityLegend_);
  return addDock(QStringLiteral("disparityDock"), tr("Disparity"), disparityPage, Qt::RightDockWidgetArea);
}

// The DEM, as a hillshade or in height colours; a notice with a button stands above it while the
// pair has no height model.
QDockWidget* MainWindow::createDemDock() {
  auto* demPage = new QWidget;
  auto* demLayout = new QGridLayout(demPage);
  demLayout->setContentsMargins(0, 0, 0, 0);
  demLayer_ = new QComboBox;
  demLayer_->setObjectName(QStringLiteral("demLayer"));
  demLayer_->addItem(tr("DEM"));
  demLayer_->addItem(tr("DTM (ground)"));
  demLayer_->addItem(tr("nDSM (above ground)"));
  demLayer_->setToolTip(tr("The DEM, or the ground (DTM) and the height above it (nDSM) the scene analysis finds"));
  demMode_ = new QComboBox;
  demMode_->setObjectName(QStringLiteral("demMode"));
  demMode_->addItem(tr("Hillshade"));
  demMode_->addItem(tr("Height colours"));
  demLegend_ = new widgets::ColourLegend;
  demLegend_->setColourMap(widgets::ColourMap::Terrain);
  demLegend_->setTitle(tr("Height"));
  demLegend_->setUnit(tr("m"));
  heightModelNotice_ = new QWidget;
  heightModelNotice_->setObjectName(QStringLiteral("heightModelNotice"));
  auto* noticeLayout = new QHBoxLayout(heightModelNotice_);
  auto* noticeText = new QLabel(tr("Heights need the height model of the pair."));
  noticeText->setWordWrap(true);
  auto* noticeButton = new QPushButton(tr("Set the height model…"));
  noticeButton->setObjectName(QStringLiteral("setHeightModel"));
  connect(noticeButton, &QPushButton::clicked, this, &MainWindow::openProjectSettings);
  noticeLayout->addWidget(noticeText, 1);
  noticeLayout->addWidget(noticeButton);
  heightModelNotice_->hide();
  // View > Enhanced DEM, also here (its action is set with the actions: createViewActions).
  auto* enhanced = new QToolButton;
  enhanced->setObjectName(QStringLiteral("enhancedDemButton"));
  enhanced->setToolButtonStyle(Qt::ToolButtonTextOnly);
  auto* demControls = new QHBoxLayout;
  demControls->addWidget(demLayer_, 1);
  demControls->addWidget(demMode_, 1);
  demControls->addWidget(enhanced);
  demLayout->addLayout(demControls, 0, 0, 1, 2);
  demLayout->addWidget(heightModelNotice_, 1, 0, 1, 2);
  demLayout->addWidget(demView_, 2, 0);
  demLayout->addWidget(demLegend_, 2, 1);
  connect(demMode_, &QComboBox::currentIndexChanged, this, [this] { refreshRasters(); });
  return addDock(QStringLiteral("demDock"), tr("DEM"), demPage, Qt::RightDockWidgetArea);
}

// The 3D view's controls and, until a DEM and a display are there, a placeholder in its place
// (the VTK view itself is made by ensure3DView() when the dock is first shown).
QDockWidget* MainWindow::create3DDock() {
  view3DHost_ = new QWidget;
  auto* host3D = new QVBoxLayout(view3DHost_);
  host3D->setContentsMargins(0, 0, 0, 0);
  auto* controls3D = new QHBoxLayout;
  view3DColour_ = new QComboBox;
  view3DColour_->setObjectName(QStringLiteral("view3DColour"));
  view3DColour_->addItem(tr("Height colours"));
  view3DColour_->addItem(tr("Left image"));
  view3DColour_->setToolTip(tr("Colour the terrain by height, or drape the left image over it"));
  view3DExaggeration_ = new QDoubleSpinBox;
  view3DExaggeration_->setObjectName(QStringLiteral("view3DExaggeration"));
  view3DExaggeration_->setRange(0.5, 20.0);
  view3DExaggeration_->setSingleStep(0.5);
  view3DExaggeration_->setDecimals(1);
  view3DExaggeration_->setPrefix(QStringLiteral("× "));
  view3DExaggeration_->setValue(1.0);
  view3DExaggeration_->setToolTip(tr("Vertical exaggeration of the heights"));
  auto* frameButton = new QPushButton(tr("Frame"));
  frameButton->setObjectName(QStringLiteral("view3DFrame"));
  frameButton->setToolTip(tr("Look at the selected building, or at the whole DEM when none is selected"));
  controls3D->addWidget(view3DColour_);
  controls3D->addWidget(new QLabel(tr("Vertical")));
  controls3D->addWidget(view3DExaggeration_);
  controls3D->addWidget(frameButton);
  controls3D->addStretch(1);
  host3D->addLayout(controls3D);
  connect(view3DColour_, &QComboBox::currentIndexChanged, this, [this] { refresh3D(); });
  connect(view3DExaggeration_, &QDoubleSpinBox::valueChanged, this, [this](double factor) {
    if (view3D_ == nullptr) return;
    view3D_->setVerticalExaggeration(factor);
    frame3D();
  });
  connect(frameButton, &QPushButton::clicked, this, &MainWindow::frame3D);
  view3DPlaceholder_ = new QLabel(tr("The 3D view appears when a DEM is available: compute the disparity "
                                     "and set the height model (File → Project settings)."));
  view3DPlaceholder_->setAlignment(Qt::AlignCenter);
  view3DPlaceholder_->setWordWrap(true);
  host3D->addWidget(view3DPlaceholder_);
  auto* view3DDock = addDock(QStringLiteral("view3DDock"), tr("3D view"), view3DHost_, Qt::RightDockWidgetArea);
  connect(view3DDock, &QDockWidget::visibilityChanged, this, [this](bool visible) {
    if (visible) ensure3DView();
  });
  return view3DDock;
}

// The buildings list; its selection follows the selected building, also across model resets.
void MainWindow::createBuildingsDock() {
  buildingsModel_ = new BuildingsModel(this);
  buildingsTable_ = new QTableView;
  buildingsTable_->setObjectName(QStringLiteral("buildingsTable"));
  buildingsTable_->setModel(buildingsModel_);
  buildingsTable_->setSelectionBehavior(QAbstractItemView::SelectRows);
  // Two rows selected (Ctrl+click) can be merged (Merge buildings).
  buildingsTable_->setSelectionMode(QAbstractItemView::ExtendedSelection);
  buildingsTable_->verticalHeader()->hide();
  buildingsTable_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  buildingsTable_->horizontalHeader()->setStretchLastSection(true);
  connect(buildingsTable_->selectionModel(), &QItemSelectionModel::selectionChanged, this,
          &MainWindow::onSelectionFromTable);
  buildingsTable_->setColumnHidden(BuildingsModel::SourceId, true);
  connect(buildingsModel_, &QAbstractItemModel::modelReset, this, [this] {
    // The source ids of imported outlines, only when there are some.
    buildingsTable_->setColumnHidden(BuildingsModel::SourceId, !buildingsModel_->hasSourceIds());
    restoreListSelection();
  });
  auto* buildingsPage = new QWidget;
  auto* buildingsLayout = new QVBoxLayout(buildingsPage);
  buildingsLayout->setContentsMargins(0, 0, 0, 0);
  buildingsLayout->addWidget(buildingsTable_, 1);
  buildingsLayout->addWidget(createBoxFitPanel());
  addDock(QStringLiteral("buildingsDock"), tr("Buildings"), buildingsPage, Qt::LeftDockWidgetArea);
}

QDockWidget* MainWindow::addDock(const QString& objectName, const QString& title, QWidget* content,
                                  Qt::DockWidgetArea area) {
  auto* dock = new QDockWidget(title, this);
  dock->setObjectName(objectName);
  dock->setWidget(content);
  addDockWidget(area, dock);
  return dock;
}

void MainWindow::ensure3DView() {
  if (view3D_ != nullptr || !document_ || document_->dem().empty()) return;
  // VTK needs an X server in both of the view's backends (docs/qt6-vtk-facts.md).
  if (qEnvironmentVariableIsEmpty("DISPLAY")) {
    view3DPlaceholder_->setText(tr("The 3D view needs a display (X server)."));
    return;
  }
  view3D_ = new widgets::Terrain3DView;
  view3D_->setObjectName(QStringLiteral("view3D"));
  static_cast<QVBoxLayout*>(view3DHost_->layout())->addWidget(view3D_, 1);
  view3DPlaceholder_->hide();
  refresh3D();
  frame3D();
}

void MainWindow::frame3D() {
  if (view3D_ == nullptr || !document_) return;
  const Building* b = selectedId_ > 0 ? document_->project().find(selectedId_) : nullptr;
  if (b == nullptr) {
    view3D_->resetCamera();
    return;
  }
  // The building with as much again of its surroundings on each side.
  const cv::Rect2d box = core::boundingBox(b->currentPolygon().outer);
  const double margin = 0.5 * std::max(box.width, box.height);
  view3D_->frameRegion(cv::Rect2d(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin));
}

void MainWindow::refreshHeightModelNotice() {
  const bool missing = document_ && document_->dem().empty() && document_->project().dem.empty() &&
                       !document_->project().height.known();
  heightModelNotice_->setVisible(missing);
  view3DPlaceholder_->setText(missing ? tr("The 3D view needs heights: set the height model (File → Project settings).")
                                      : tr("The 3D view appears when a DEM is available."));
}

}  // namespace delineo::gui
