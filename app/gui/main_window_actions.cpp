// MainWindow's actions, menus and toolbar, and which actions are enabled.
#include <QAction>
#include <QActionGroup>
#include <QDockWidget>
#include <QFileDialog>
#include <QFileInfo>
#include <QMenu>
#include <QMenuBar>
#include <QSettings>
#include <QTableView>
#include <QToolBar>
#include <QToolButton>
#include <QUndoStack>
#include <map>
#include <utility>
#include <vector>

#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "main_window.hpp"

namespace delineo::gui {

using project::Building;
using project::BuildingStatus;
using widgets::ImageView;
using widgets::InteractionMode;

namespace {

// A named action of `window`: its shortcut works wherever the focus is in the window.
QAction* makeAction(QWidget* window, const QString& name, const QString& text, const QKeySequence& key = {}) {
  auto* a = new QAction(text, window);
  a->setObjectName(name);
  if (!key.isEmpty()) a->setShortcut(key);
  window->addAction(a);
  return a;
}

}  // namespace

// Every action is a child of the window named "action…" (action() finds it), with its shortcut
// active whatever widget has the focus; the menus and the toolbar only show them.
void MainWindow::createActions() {
  createFileActions();
  createToolActions();
  createBuildingActions();
  createReviewActions();
  createEditActions();
  createViewActions();
  createSceneActions();
}

void MainWindow::createFileActions() {
  connect(makeAction(this, QStringLiteral("actionOpen"), tr("&Open project…"), QKeySequence::Open),
          &QAction::triggered, this, [this] {
            if (!maybeSave()) return;
            const QString start =
                document_ ? document_->dialogFolder()
                          : QSettings().value(QStringLiteral("lastProjectFolder")).toString();
            const QString path = QFileDialog::getOpenFileName(this, tr("Open project"), start,
                                                              tr("Delineo projects (*.json)"));
            if (!path.isEmpty()) openProject(path);
          });
  connect(makeAction(this, QStringLiteral("actionNewFromPair"),
                     tr("&New project from a stereo pair…"), QKeySequence::New),
          &QAction::triggered, this, [this] {
            if (!maybeSave()) return;
            const QString filter = tr("Images (*.tif *.tiff *.png *.jpg)");
            const QString left = QFileDialog::getOpenFileName(
                this, tr("Left image (reference)"),
                QSettings().value(QStringLiteral("lastImageFolder")).toString(), filter);
            if (left.isEmpty()) return;
            const QString right = QFileDialog::getOpenFileName(this, tr("Right image"),
                                                               QFileInfo(left).path(), filter);
            QSettings().setValue(QStringLiteral("lastImageFolder"), QFileInfo(left).absolutePath());
            if (!right.isEmpty()) openPair(left, right);
          });
  connect(makeAction(this, QStringLiteral("actionOpenSample"), tr("Open the &sample project")),
          &QAction::triggered, this, [this] {
            if (maybeSave()) openSample();
          });
  connect(makeAction(this, QStringLiteral("actionSave"), tr("&Save"), QKeySequence::Save),
          &QAction::triggered, this, &MainWindow::save);
  connect(makeAction(this, QStringLiteral("actionSaveAs"), tr("Save &as…"), QKeySequence::SaveAs),
          &QAction::triggered, this, [this] {
            const QString path = QFileDialog::getSaveFileName(
                this, tr("Save project"), document_ ? document_->dialogFolder() : QString(),
                tr("Delineo projects (*.json)"));
            if (!path.isEmpty()) saveAs(path);
          });
  connect(makeAction(this, QStringLiteral("actionProjectSettings"), tr("Project se&ttings…")),
          &QAction::triggered, this, &MainWindow::openProjectSettings);
  connect(makeAction(this, QStringLiteral("actionExport"), tr("&Export accepted buildings…"),
                     QKeySequence(tr("Ctrl+E"))),
          &QAction::triggered, this, [this] {
            QString start = document_ ? document_->outputDirectory() : QString();
            if (start.isEmpty() && document_) start = document_->dialogFolder();
            const QString path = QFileDialog::getSaveFileName(
                this, tr("Export accepted buildings"), start + QStringLiteral("/buildings.geojson"),
                tr("GeoJSON (*.geojson);;GeoPackage (*.gpkg);;CityJSON 3D blocks (*.city.json *.cityjson)"));
            if (!path.isEmpty()) exportAccepted(path);
          });
  QAction* importOutlines = makeAction(this, QStringLiteral("actionImportOutlines"), tr("&Import outlines…"));
  importOutlines->setStatusTip(tr("Add the polygons of a vector file (a cadastre, OpenStreetMap, an export) as pending "
                                  "buildings, to outline with Building → Outline the pending buildings"));
  connect(importOutlines, &QAction::triggered, this, &MainWindow::chooseOutlineFile);
  connect(makeAction(this, QStringLiteral("actionExportRasters"), tr("Export e&levation rasters…")),
          &QAction::triggered, this, &MainWindow::chooseRasterFolder);
  connect(makeAction(this, QStringLiteral("actionQuit"), tr("&Quit"), QKeySequence::Quit),
          &QAction::triggered, this, &QWidget::close);
}

// A tool: a checkable action of the tool group that sets the left view's interaction mode.
QAction* MainWindow::addTool(const QString& name, const QString& text, const QString& key, InteractionMode mode,
                             const QString& tip) {
  QAction* a = makeAction(this, name, text, QKeySequence(key));
  a->setCheckable(true);
  a->setToolTip(tip);
  a->setStatusTip(tip);
  toolGroup_->addAction(a);
  connect(a, &QAction::triggered, this, [this, mode] { leftView_->setInteractionMode(mode); });
  return a;
}

// The left view's interaction modes, one checked at a time.
void MainWindow::createToolActions() {
  toolGroup_ = new QActionGroup(this);
  // V, as the selection tool of drawing programs: N goes to the next building to review.
  addTool(QStringLiteral("actionNavigate"), tr("&Navigate"), QStringLiteral("V"), InteractionMode::Navigate,
          tr("Pan with the mouse, zoom with the wheel, click a building to select it"))->setChecked(true);
  addTool(QStringLiteral("actionPickRectangle"), tr("Pick with a &rectangle"), QStringLiteral("B"),
          InteractionMode::PickRectangle, tr("Drag a rectangle around a building"));
  addTool(QStringLiteral("actionPickPolygon"), tr("Pick with a &polygon"), QStringLiteral("P"),
          InteractionMode::PickPolygon, tr("Click the corners of a rough polygon; double-click to close"));
  addTool(QStringLiteral("actionPickObject"), tr("Pick an above-ground &object"), QStringLiteral("O"),
          InteractionMode::PickPoint, tr("Click a building: its above-ground region becomes the initial polygon"));
  addTool(QStringLiteral("actionEdit"), tr("&Edit outline"), QStringLiteral("E"), InteractionMode::EditPolygon,
          tr("Drag a vertex or an edge of the selected building, Ctrl+drag to select vertices, "
             "right-click for more; every change can be undone"));
  createSplitMergeTools();
  connect(leftView_, &ImageView::interactionModeChanged, this, [this](InteractionMode mode) {
    static const std::map<InteractionMode, QString> names = {
        {InteractionMode::Navigate, QStringLiteral("actionNavigate")},
        {InteractionMode::PickRectangle, QStringLiteral("actionPickRectangle")},
        {InteractionMode::PickPolygon, QStringLiteral("actionPickPolygon")},
        {InteractionMode::PickPoint, QStringLiteral("actionPickObject")},
        {InteractionMode::EditPolygon, QStringLiteral("actionEdit")},
        {InteractionMode::PickLine, QStringLiteral("actionSplit")},
        {InteractionMode::PickOutline, QStringLiteral("actionMergeWith")}};
    if (QAction* a = action(names.at(mode))) a->setChecked(true);
  });
}

// Split building (S) and Merge with… (M), tools of the left view; Merge buildings, of the
// Buildings list. What they do is in main_window_split_merge.cpp.
void MainWindow::createSplitMergeTools() {
  addTool(QStringLiteral("actionSplit"), tr("&Split building"), QStringLiteral("S"), InteractionMode::PickLine,
          tr("Drag a line across the selected building (or click its two ends) to cut it in two"));
  QAction* merge = addTool(QStringLiteral("actionMergeWith"), tr("Merge &with…"), QStringLiteral("M"),
                           InteractionMode::PickOutline,
                           tr("Click another building to merge it into the selected one; Esc cancels"));
  connect(merge, &QAction::triggered, this, &MainWindow::beginMergeWith);
  connect(leftView_, &ImageView::linePicked, this, &MainWindow::onSplitLine);
  connect(leftView_, &ImageView::outlinePicked, this, &MainWindow::onMergeClick);
  QAction* mergeRows = makeAction(this, QStringLiteral("actionMergeSelected"), tr("Merge b&uildings"));
  mergeRows->setStatusTip(tr("Merge the second of the two buildings selected in the Buildings list into the first"));
  connect(mergeRows, &QAction::triggered, this, &MainWindow::mergeSelectedRows);
  buildingsTable_->setContextMenuPolicy(Qt::ActionsContextMenu);
  buildingsTable_->addAction(mergeRows);
}

// Processing and the selected building's commands.
void MainWindow::createBuildingActions() {
  connect(makeAction(this, QStringLiteral("actionMatch"), tr("Compute &disparity"),
                     QKeySequence(tr("Ctrl+M"))),
          &QAction::triggered, this, &MainWindow::startMatching);
  connect(makeAction(this, QStringLiteral("actionDelineate"), tr("Run the active &polygon"),
                     QKeySequence(tr("Ctrl+R"))),
          &QAction::triggered, this, [this] { startDelineation(selectedId_); });
  connect(makeAction(this, QStringLiteral("actionRegularize"), tr("Re&gularize outline")),
          &QAction::triggered, this, [this] { startRegularization(selectedId_); });
  action(QStringLiteral("actionRegularize"))
      ->setStatusTip(tr(
          "Square the selected outline: right angles, few vertices, within the tolerance of it"));
  QAction* outlinePending = makeAction(this, QStringLiteral("actionOutlinePending"), tr("&Outline the pending buildings"));
  outlinePending->setStatusTip(tr("Outline every pending building in turn with its method; a cancel keeps those done"));
  connect(outlinePending, &QAction::triggered, this, &MainWindow::outlinePendingBuildings);
  QAction* boxFit = makeAction(this, QStringLiteral("actionBoxFit"), tr("Bo&x-fitting"));
  boxFit->setStatusTip(tr("Fit boxes to the selected building from its DEM and the left image's edges, and show "
                          "their outline beside the building's outline"));
  connect(boxFit, &QAction::triggered, this, [this] { startBoxFitting(selectedId_); });
  QAction* keepBoxFit = makeAction(this, QStringLiteral("actionKeepBoxFit"), tr("Keep the bo&x-fitting outline"));
  keepBoxFit->setStatusTip(tr("The box-fitting outline becomes the selected building's outline (one undoable step)"));
  connect(keepBoxFit, &QAction::triggered, this, &MainWindow::keepBoxFitOutline);
  QAction* keepCurrent = makeAction(this, QStringLiteral("actionDiscardBoxFit"), tr("Keep the current outline"));
  keepCurrent->setStatusTip(tr("Drop the box-fitting outline and keep the building's outline as it is"));
  connect(keepCurrent, &QAction::triggered, this, &MainWindow::discardBoxFitProposal);
  findChild<QToolButton*>(QStringLiteral("keepBoxFit"))->setDefaultAction(keepBoxFit);
  findChild<QToolButton*>(QStringLiteral("keepCurrentOutline"))->setDefaultAction(keepCurrent);
  auto* onPick =
      makeAction(this, QStringLiteral("actionDelineateOnPick"), tr("Delineate on &pick"));
  onPick->setCheckable(true);
  onPick->setChecked(QSettings().value(QStringLiteral("delineateOnPick"), true).toBool());
  onPick->setStatusTip(
      tr("Run the active polygon as soon as a building is picked, and again when its roof interval "
         "changes"));
  connect(onPick, &QAction::toggled, this,
          [](bool on) { QSettings().setValue(QStringLiteral("delineateOnPick"), on); });
  connect(makeAction(this, QStringLiteral("actionAccept"), tr("&Accept building"),
                     QKeySequence(QStringLiteral("A"))),
          &QAction::triggered, this, &MainWindow::acceptSelected);
  connect(makeAction(this, QStringLiteral("actionReject"), tr("Re&ject building"),
                     QKeySequence(QStringLiteral("X"))),
          &QAction::triggered, this, &MainWindow::rejectSelected);
  connect(makeAction(this, QStringLiteral("actionReopen"), tr("Re&open building")),
          &QAction::triggered, this, &MainWindow::reopenSelected);
  connect(makeAction(this, QStringLiteral("actionRemove"), tr("Re&move building"),
                     QKeySequence::Delete),
          &QAction::triggered, this, &MainWindow::removeSelected);
  connect(makeAction(this, QStringLiteral("actionCancelJobs"), tr("&Cancel running jobs"),
                     QKeySequence(Qt::Key_Escape)),
          &QAction::triggered, jobs_, &widgets::JobRunner::cancelAll);
}

// Going through the buildings to review (main_window_review.cpp), and whether a decision on one
// goes on to the next.
void MainWindow::createReviewActions() {
  QAction* next = makeAction(this, QStringLiteral("actionNextToReview"), tr("Ne&xt building to review"),
                             QKeySequence(QStringLiteral("N")));
  next->setStatusTip(tr("Select the next building whose outline awaits a decision (automatic or corrected), "
                        "else the next pending one"));
  connect(next, &QAction::triggered, this, [this] { selectNextToReview(1); });
  QAction* previous = makeAction(this, QStringLiteral("actionPreviousToReview"), tr("Pre&vious building to review"),
                                 QKeySequence(QStringLiteral("Shift+N")));
  previous->setStatusTip(tr("Select the previous building whose outline awaits a decision (automatic or "
                            "corrected), else the previous pending one"));
  connect(previous, &QAction::triggered, this, [this] { selectNextToReview(-1); });
  QAction* onDecision = makeAction(this, QStringLiteral("actionNextAfterDecision"), tr("Next a&fter accepting or rejecting"));
  onDecision->setCheckable(true);
  onDecision->setChecked(QSettings().value(QStringLiteral("review/nextAfterDecision"), true).toBool());
  onDecision->setStatusTip(tr("After Accept or Reject, select the next building to review"));
  connect(onDecision, &QAction::toggled, this,
          [](bool on) { QSettings().setValue(QStringLiteral("review/nextAfterDecision"), on); });
}

// Undo, redo and the snapping of edited outlines.
void MainWindow::createEditActions() {
  auto* undo = makeAction(this, QStringLiteral("actionUndo"), tr("&Undo"));
  undo->setShortcuts({QKeySequence::Undo});
  auto* redo = makeAction(this, QStringLiteral("actionRedo"), tr("&Redo"));
  redo->setShortcuts({QKeySequence(tr("Ctrl+Y")), QKeySequence(tr("Ctrl+Shift+Z"))});
  connect(undo, &QAction::triggered, this, [this] {
    if (document_) document_->undoStack()->undo();
  });
  connect(redo, &QAction::triggered, this, [this] {
    if (document_) document_->undoStack()->redo();
  });

  // Snapping while editing outlines: right angles to the neighbouring edges, and the image's
  // own edges (an edge map of the left image computed when a project opens).
  auto* snapAngles =
      makeAction(this, QStringLiteral("actionSnapRightAngles"), tr("Snap to right &angles"));
  snapAngles->setCheckable(true);
  snapAngles->setChecked(QSettings().value(QStringLiteral("edit/snapRightAngles"), true).toBool());
  snapAngles->setStatusTip(tr("While dragging, corners within 6° of a right angle become square"));
  leftView_->polygons().setSnapToRightAngles(snapAngles->isChecked());
  connect(snapAngles, &QAction::toggled, this, [this](bool on) {
    leftView_->polygons().setSnapToRightAngles(on);
    QSettings().setValue(QStringLiteral("edit/snapRightAngles"), on);
  });
  auto* snapEdges = makeAction(this, QStringLiteral("actionSnapEdges"), tr("Snap to image &edges"));
  snapEdges->setCheckable(true);
  snapEdges->setChecked(QSettings().value(QStringLiteral("edit/snapEdges"), true).toBool());
  snapEdges->setStatusTip(
      tr("While dragging, a vertex within 3 px of an edge of the left image lands on it"));
  leftView_->polygons().setSnapToEdges(snapEdges->isChecked());
  leftView_->polygons().setEdgeSnapRadius(3.0);
  connect(snapEdges, &QAction::toggled, this, [this](bool on) {
    leftView_->polygons().setSnapToEdges(on);
    QSettings().setValue(QStringLiteral("edit/snapEdges"), on);
  });
}

void MainWindow::createViewActions() {
  // A label raster is reference material (ground truth of a simulated scene, a classification):
  // an operator's project usually has none, and when it has one the outlines should be judged on
  // the image first. So the overlay is off until asked for, and the choice is remembered.
  auto* labels = makeAction(this, QStringLiteral("actionShowLabels"), tr("Show &labels"),
                            QKeySequence(QStringLiteral("L")));
  labels->setCheckable(true);
  labels->setChecked(QSettings().value(QStringLiteral("view/showLabels"), false).toBool());
  labels->setEnabled(false);
  labels->setStatusTip(tr("Overlay the project's label raster (only when the project has one)"));
  connect(labels, &QAction::toggled, this, [this](bool on) {
    refreshLabelOverlay();
    QSettings().setValue(QStringLiteral("view/showLabels"), on);
  });
  // The project's exclusion mask (images.exclude, e.g. vegetation: never roof) hatched over the
  // left image and whatever overlay it has: checking the mask where it matters, on the roofs.
  auto* mask = makeAction(this, QStringLiteral("actionShowExclusionMask"), tr("E&xclusion mask"));
  mask->setCheckable(true);
  mask->setChecked(QSettings().value(QStringLiteral("view/showExclusionMask"), false).toBool());
  mask->setEnabled(false);
  mask->setStatusTip(tr("Hatch the pixels the project's exclusion mask keeps out of every outline (only when the "
                        "project has one)"));
  connect(mask, &QAction::toggled, this, [this](bool on) {
    refreshLabelOverlay();
    QSettings().setValue(QStringLiteral("view/showExclusionMask"), on);
  });
  // The DEM sharpened with the current outlines (walls vertical, roofs median-filtered), in the
  // DEM view and the 3D view; off shows the DEM as computed.
  QAction* enhanced = makeAction(this, QStringLiteral("actionEnhancedDem"), tr("En&hanced DEM"));
  enhanced->setCheckable(true);
  enhanced->setStatusTip(tr("Show the DEM sharpened with the buildings' outlines: vertical walls, filtered roofs"));
  connect(enhanced, &QAction::toggled, this, &MainWindow::onEnhancedDemToggled);
  findChild<QToolButton*>(QStringLiteral("enhancedDemButton"))->setDefaultAction(enhanced);
}

void MainWindow::createMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  file->addAction(action(QStringLiteral("actionNewFromPair")));
  file->addAction(action(QStringLiteral("actionOpen")));
  file->addAction(action(QStringLiteral("actionOpenSample")));
  recentMenu_ = file->addMenu(tr("Open &recent"));
  recentMenu_->setObjectName(QStringLiteral("recentMenu"));
  file->addSeparator();
  file->addAction(action(QStringLiteral("actionSave")));
  file->addAction(action(QStringLiteral("actionSaveAs")));
  file->addAction(action(QStringLiteral("actionImportOutlines")));
  file->addAction(action(QStringLiteral("actionExport")));
  file->addAction(action(QStringLiteral("actionExportRasters")));
  file->setToolTipsVisible(true);  // why Export elevation rasters is disabled
  file->addAction(action(QStringLiteral("actionProjectSettings")));
  file->addSeparator();
  file->addAction(action(QStringLiteral("actionQuit")));

  QMenu* edit = menuBar()->addMenu(tr("&Edit"));
  edit->addAction(action(QStringLiteral("actionUndo")));
  edit->addAction(action(QStringLiteral("actionRedo")));
  edit->addSeparator();
  edit->addAction(action(QStringLiteral("actionSnapRightAngles")));
  edit->addAction(action(QStringLiteral("actionSnapEdges")));

  QMenu* building = menuBar()->addMenu(tr("&Building"));
  for (const char* name : {"actionNavigate", "actionPickRectangle", "actionPickPolygon", "actionPickObject", "actionEdit",
                           "actionSplit", "actionMergeWith", "actionMergeSelected"}) {
    building->addAction(action(QString::fromLatin1(name)));
  }
  building->addSeparator();
  building->addAction(action(QStringLiteral("actionDelineate")));
  building->addAction(action(QStringLiteral("actionDelineateOnPick")));
  building->addAction(action(QStringLiteral("actionRegularize")));
  building->addAction(action(QStringLiteral("actionBoxFit")));
  building->addAction(action(QStringLiteral("actionKeepBoxFit")));
  building->addAction(action(QStringLiteral("actionDiscardBoxFit")));
  building->addAction(action(QStringLiteral("actionAccept")));
  building->addAction(action(QStringLiteral("actionReject")));
  building->addAction(action(QStringLiteral("actionReopen")));
  building->addAction(action(QStringLiteral("actionRemove")));
  building->addSeparator();
  building->addAction(action(QStringLiteral("actionNextToReview")));
  building->addAction(action(QStringLiteral("actionPreviousToReview")));
  building->addAction(action(QStringLiteral("actionNextAfterDecision")));
  building->addSeparator();
  building->addAction(action(QStringLiteral("actionDetectBuildings")));
  building->addAction(action(QStringLiteral("actionOutlinePending")));

  QMenu* process = menuBar()->addMenu(tr("&Processing"));
  process->addAction(action(QStringLiteral("actionMatch")));
  process->addAction(action(QStringLiteral("actionDelineate")));
  process->addAction(action(QStringLiteral("actionBoxFit")));
  process->addSeparator();
  process->addAction(action(QStringLiteral("actionAnalyseScene")));
  process->addAction(action(QStringLiteral("actionDetectBuildings")));
  process->addAction(action(QStringLiteral("actionOutlinePending")));
  process->addSeparator();
  process->addAction(action(QStringLiteral("actionCancelJobs")));

  QMenu* view = menuBar()->addMenu(tr("&View"));
  view->addAction(action(QStringLiteral("actionShowLabels")));
  view->addAction(action(QStringLiteral("actionShowClasses")));
  view->addAction(action(QStringLiteral("actionShowObjects")));
  view->addAction(action(QStringLiteral("actionShowExclusionMask")));
  view->addAction(action(QStringLiteral("actionEnhancedDem")));
  QMenu* demLayers = view->addMenu(tr("DEM &view shows"));
  for (const char* name : {"actionDemLayerDem", "actionDemLayerDtm", "actionDemLayerNdsm"}) {
    demLayers->addAction(action(QString::fromLatin1(name)));
  }
  view->addSeparator();
  for (QDockWidget* d : findChildren<QDockWidget*>()) view->addAction(d->toggleViewAction());

  createLanguageMenu();
  createToolBar();
  rebuildRecentMenu();
}

// Settings > Language: the choice applies at the next start.
void MainWindow::createLanguageMenu() {
  QMenu* settingsMenu = menuBar()->addMenu(tr("&Settings"));
  QMenu* language = settingsMenu->addMenu(tr("&Language"));
  auto* languages = new QActionGroup(this);
  const QString current = QSettings().value(QStringLiteral("language")).toString();
  for (const auto& [code, name] : std::vector<std::pair<QString, QString>>{
           {QString(), tr("System default")}, {QStringLiteral("en"), QStringLiteral("English")},
           {QStringLiteral("fr"), QStringLiteral("Français")}}) {
    QAction* a = language->addAction(name);
    a->setObjectName(QStringLiteral("actionLanguage_") + (code.isEmpty() ? QStringLiteral("system") : code));
    a->setCheckable(true);
    a->setChecked(code == current);
    languages->addAction(a);
    connect(a, &QAction::triggered, this, [this, code = code] { setLanguage(code); });
  }
}

void MainWindow::createToolBar() {
  auto* toolbar = addToolBar(tr("Tools"));
  toolbar->setObjectName(QStringLiteral("toolsToolbar"));
  for (const char* name : {"actionOpen", "actionSave", "actionUndo", "actionRedo", "actionNavigate",
                           "actionPickRectangle", "actionPickPolygon", "actionPickObject", "actionEdit",
                           "actionMatch", "actionDelineate", "actionAccept", "actionReject"}) {
    toolbar->addAction(action(QString::fromLatin1(name)));
  }
}

void MainWindow::updateActions() {
  const bool hasDoc = document_ != nullptr;
  const Building* b = hasDoc && selectedId_ > 0 ? document_->project().find(selectedId_) : nullptr;
  action(QStringLiteral("actionSave"))->setEnabled(hasDoc);
  action(QStringLiteral("actionSaveAs"))->setEnabled(hasDoc);
  action(QStringLiteral("actionExport"))->setEnabled(hasDoc);
  action(QStringLiteral("actionImportOutlines"))->setEnabled(hasDoc);
  refreshRasterExportAction();
  action(QStringLiteral("actionMatch"))->setEnabled(hasDoc);
  action(QStringLiteral("actionDelineate"))->setEnabled(b != nullptr);
  action(QStringLiteral("actionRegularize"))->setEnabled(b != nullptr && b->hasOutline());
  action(QStringLiteral("actionBoxFit"))->setEnabled(b != nullptr);
  action(QStringLiteral("actionOutlinePending"))->setEnabled(hasDoc && !document_->project().pendingBuildings().empty());
  const bool proposal = b != nullptr && hasBoxFitProposal(b->id);
  action(QStringLiteral("actionKeepBoxFit"))->setEnabled(proposal);
  action(QStringLiteral("actionDiscardBoxFit"))->setEnabled(proposal);
  action(QStringLiteral("actionEnhancedDem"))->setEnabled(hasDoc);
  for (const char* name : {"actionAnalyseScene", "actionDetectBuildings", "actionShowClasses", "actionShowObjects",
                           "actionDemLayerDtm", "actionDemLayerNdsm"}) {
    action(QString::fromLatin1(name))->setEnabled(hasDoc);
  }
  action(QStringLiteral("actionAccept"))->setEnabled(b != nullptr && b->hasOutline() && b->status != BuildingStatus::Accepted);
  action(QStringLiteral("actionReject"))->setEnabled(b != nullptr && b->status != BuildingStatus::Rejected);
  action(QStringLiteral("actionReopen"))->setEnabled(
      b != nullptr && (b->status == BuildingStatus::Accepted || b->status == BuildingStatus::Rejected));
  action(QStringLiteral("actionRemove"))->setEnabled(b != nullptr);
  updateSplitMergeActions(b != nullptr);
  action(QStringLiteral("actionNextToReview"))->setEnabled(hasDoc);
  action(QStringLiteral("actionPreviousToReview"))->setEnabled(hasDoc);
  action(QStringLiteral("actionCancelJobs"))->setEnabled(jobs_->activeCount() > 0);
  QUndoStack* stack = hasDoc ? document_->undoStack() : nullptr;
  QAction* undo = action(QStringLiteral("actionUndo"));
  QAction* redo = action(QStringLiteral("actionRedo"));
  undo->setEnabled(stack && stack->canUndo());
  redo->setEnabled(stack && stack->canRedo());
  undo->setText(stack && stack->canUndo() ? tr("&Undo %1").arg(stack->undoText()) : tr("&Undo"));
  redo->setText(stack && stack->canRedo() ? tr("&Redo %1").arg(stack->redoText()) : tr("&Redo"));
  // The toolbar keeps a short label (with the command's name the buttons after it moved into the
  // overflow menu); the tooltip and the Edit menu name the command.
  undo->setIconText(tr("Undo"));
  redo->setIconText(tr("Redo"));
  undo->setToolTip(QString(undo->text()).remove(QLatin1Char('&')));
  redo->setToolTip(QString(redo->text()).remove(QLatin1Char('&')));
}

void MainWindow::setLanguage(const QString& code) {
  QSettings().setValue(QStringLiteral("language"), code);
  showMessage(tr("Language"), tr("The language will change the next time Delineo starts."));
}

}  // namespace delineo::gui
