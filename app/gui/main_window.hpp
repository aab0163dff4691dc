#pragma once
// The operator's delineation workstation: the left image in the centre, the right image,
// disparity, DEM and 3D view in docks, the buildings list, the parameters dock (roof disparity
// interval on the ROI histogram + parameter forms), background jobs with progress and cancel,
// undo/redo of every change, projects with autosave and recovery.
#include <QMainWindow>
#include <QPointer>
#include <QTimer>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/project/pipeline.hpp"
#include "delineo/project/project.hpp"
#include "delineo/widgets/job_runner.hpp"
#include "building_blocks.hpp"

class QAction;
class QActionGroup;
class QDockWidget;
class QLabel;
class QMenu;
class QTableView;
class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QStackedWidget;
class QTabWidget;
class QSpinBox;
class QTableWidget;

namespace delineo::widgets {
class ImageView;
class DisparityHistogramWidget;
class ParameterForm;
class ColourLegend;
class Terrain3DView;
struct OverlayGuide;
enum class InteractionMode;
}  // namespace delineo::widgets

namespace delineo::gui {

class Document;
class BuildingsModel;
class ProjectSettingsDialog;

class MainWindow : public QMainWindow {
  Q_OBJECT
 public:
  explicit MainWindow(QWidget* parent = nullptr);
  ~MainWindow() override;
  // Shows the window and asks for the keyboard focus: without it (a window started from a
  // terminal, some window managers) no menu shortcut works until the operator clicks into it.
  void showActivated();

  // ---- documents ----
  // Each returns false (with a message shown, the current document unchanged) on failure.
  bool openProject(const QString& path);
  bool openPair(const QString& left, const QString& right);
  // Creates the sample scene on first use (background job), then opens it; documentOpened()
  // follows. Returns false when the sample cannot be made (no simulator in this build).
  bool openSample();
  bool save();
  bool saveAs(const QString& path);
  // File → Export accepted buildings to `path`, by its extension: the outlines (GeoJSON,
  // GeoPackage) at once, the CityJSON blocks in the background (exportCityModel).
  void exportAccepted(const QString& path);
  // The accepted outlines as GeoJSON or GeoPackage; returns the number written or -1 on failure.
  int exportOutlines(const QString& path);
  // The accepted buildings as CityJSON blocks with the terrain (key "export-city", main_window_export.cpp):
  // the scene analysis runs first when missing and the heights allow it (kept for the window as
  // Analyse the scene keeps it), then project::exportBuildings writes the blocks, roof parts and
  // the analysis's DTM as terrain, as `delineo-cli export --terrain` does. A cancel writes nothing.
  // Returns the job id, or 0 with a message saying why nothing started.
  widgets::JobId exportCityModel(const QString& path);
  Document* document() const { return document_.get(); }
  static QString sampleDirectory();

  // ---- actions on the selected building / the pair (also bound to menus) ----
  int selectedBuilding() const { return selectedId_; }
  void selectBuilding(int id);
  // Starts dense matching (key "matching"), after estimating the disparity range when the
  // project has none; returns the job id or 0.
  widgets::JobId startMatching();
  // Estimates the pair's disparity range from feature matches (key "range") and stores it;
  // `thenMatch` starts the matching with it.
  widgets::JobId startRangeEstimate(bool thenMatch);
  // Starts the active polygon on the building (key "delineate-<id>": a new run on the same
  // building cancels the previous one); returns the job id or 0.
  widgets::JobId startDelineation(int id);
  // Outlines a building with its method (Project::methodOf): the active polygon or box-fitting.
  widgets::JobId outlineBuilding(int id);
  // Building → Outline the pending buildings (key "outline-pending"): every pending building in
  // turn with its method, as `delineo-cli run` does; each result is applied as it comes (one
  // undoable step per building), so a cancel keeps those done. Returns the job id, or 0 with a
  // message saying why nothing started.
  widgets::JobId outlinePendingBuildings();
  // Accept (A) and Reject (X) the selected building; with Building → Next after accepting or
  // rejecting on, the next building to review is selected then (selectNextToReview).
  void acceptSelected();
  void rejectSelected();
  void autosaveNow();
  // The project settings dialog (output folder, height model); applied as one undoable step.
  void openProjectSettings();
  // Scores the building's current outline (after a manual edit) in the background; returns the
  // job id or 0 when there is nothing to score.
  widgets::JobId startEnergyUpdate(int id);
  // Squares the building's outline in the background (the delineation's last stage, energy gate
  // included) and applies it as one undoable edit, or says why it was kept; returns the job id.
  widgets::JobId startRegularization(int id);

  // Box-fitting on the building from its initial polygon and the DEM (key "boxfit-<id>"). Its
  // outline and boxes are shown beside the building's outline as a proposal, with both outlines'
  // attributes in the Buildings dock; nothing changes until the operator keeps one. Returns the
  // job id or 0 (with a message saying why).
  widgets::JobId startBoxFitting(int id);
  // The box-fitting proposal of the selected building becomes its outline (one undoable step,
  // method "box-fitting"); false when there is none.
  bool keepBoxFitOutline();
  // Keeps the selected building's outline as it is and drops its box-fitting proposal.
  void discardBoxFitProposal();
  bool hasBoxFitProposal(int id) const { return boxFitProposals_.count(id) > 0; }
  // The DEM the DEM view and the 3D view show: the enhanced one while View > Enhanced DEM is on
  // and computed, else the project's.
  const cv::Mat& shownDem() const;
  // DEM enhancement with the current outlines (key "enhance"); returns the job id or 0.
  widgets::JobId startDemEnhancement();

  // ---- scene analysis (main_window_scene.cpp) ----
  // Processing → Analyse the scene (key "scene"): ground, DTM, nDSM, classes and objects of the
  // current heights, kept until the heights or the analysis's parameters change. Returns the job
  // id, or 0 with a message saying what is missing.
  widgets::JobId startSceneAnalysis();
  // Building → Detect buildings: the analysis's building proposals become pending buildings in
  // one undoable step, after running the analysis when there is none. Returns the analysis's job
  // id, or 0 when the proposals were added at once or nothing could be done (message shown).
  widgets::JobId detectBuildings();
  // The scene analysis of the current heights; null until computed and while stale.
  const project::SceneAnalysisOutcome* sceneAnalysis() const { return scene_ ? &*scene_ : nullptr; }
  // What the DEM view shows: the DEM, the DTM or the nDSM of the scene analysis.
  enum class DemLayer { Dem = 0, Dtm = 1, Ndsm = 2 };
  void setDemLayer(DemLayer layer);
  DemLayer demLayer() const;
  // The legend of the coloured layers over the left image (classes, labels, objects, exclusion mask).
  QWidget* layerLegend() const { return layerLegend_; }

  // ---- elevation rasters (main_window_rasters.cpp) ----
  // File → Export elevation rasters into `dir` (key "rasters"): the disparity, the DEM, the
  // enhanced DEM while it is shown and the scene analysis's DTM, nDSM, labels and objects
  // (analysed first when missing and computable), georeferenced like the left image, all written
  // or none (project::writeElevationRasters). Existing files are replaced only when the operator
  // agrees. Returns the job id, or 0 with a message saying why nothing started.
  widgets::JobId exportElevationRasters(const QString& dir);

  // ---- outlines from elsewhere (main_window_import.cpp) ----
  // File → Import outlines of `path` (GeoJSON, GeoPackage, Shapefile, read by io::readFeatures
  // with the left image's georeferencing: in the CRS the file declares, else the image's, or its
  // pixels when it has no georeferencing): the operator chooses the attribute kept as each
  // building's source id, then the outlines on the left image that are not buildings yet become
  // pending buildings in one undoable step, and a message says how many and why the others were
  // left out. Returns the number added; -1 when the file cannot be read or the operator cancels
  // (a message says why).
  int importOutlines(const QString& path);

  // ---- reviewing the outlines (main_window_review.cpp) ----
  // Building → Next / Previous building to review (N, Shift+N; step +1 or -1): from the selected
  // building, in the buildings list's order and wrapping, the next one whose outline awaits a
  // decision (automatic or corrected), else the next pending one. It is selected as a click in
  // the list selects it, and the left view zooms out to frame it when it does not fit at the
  // current zoom. Returns its id, or -1 with "review complete" in the status bar when none is left.
  int selectNextToReview(int step);
  // The status bar's count of the buildings to review, accepted and rejected.
  QLabel* reviewProgress() const { return reviewProgress_; }

  // ---- accessors for tests and the screenshot tour ----
  widgets::ImageView* leftView() const { return leftView_; }
  widgets::ImageView* rightView() const { return rightView_; }
  widgets::ImageView* disparityView() const { return disparityView_; }
  widgets::ImageView* demView() const { return demView_; }
  widgets::DisparityHistogramWidget* histogram() const { return histogram_; }
  widgets::Terrain3DView* view3D() const { return view3D_; }
  widgets::ParameterForm* delineationForm() const { return parameterForm("delineation"); }
  widgets::ParameterForm* matchingForm() const { return parameterForm("matching"); }
  // The form of a parameter group of the project file ("delineation", "matching", "boxfit",
  // "enhance", "pick"); null when this build has no such algorithm.
  widgets::ParameterForm* parameterForm(const std::string& group) const;
  QComboBox* methodChoice() const { return methodChoice_; }
  QTableView* buildingsTable() const { return buildingsTable_; }
  BuildingsModel* buildingsModel() const { return buildingsModel_; }
  widgets::JobRunner* jobs() const { return jobs_; }
  QLabel* readout() const { return readout_; }
  // Edge map of the left image used to snap dragged vertices (empty until computed).
  const cv::Mat& edgeMap() const { return edgeMap_; }
  // Horizontal offset (px) between the left view's centre and the right view's: the roof
  // disparity of the selected building, else the ground disparity (x_right = x_left - d).
  double rightViewShift() const { return rightShift_; }
  // The roof disparity a building's outline is shifted by in the right view; nullopt when the
  // building has neither a roof interval nor a disparity map to propose one from.
  std::optional<double> roofDisparity(int id) const;
  QDockWidget* dock(const QString& objectName) const;
  QAction* action(const QString& objectName) const;
  void showDock(const QString& objectName);

  // ---- non-interactive mode (tests, screenshot tour): no modal dialog ----
  void setInteractive(bool interactive) { interactive_ = interactive; }
  QString lastMessage() const { return lastMessage_; }
  // Answers "restore the newer autosave?" when not interactive (default: no).
  void setRestoreAutosavePolicy(bool restore) { restoreAutosave_ = restore; }
  // Asked for a replacement path of a missing image; empty = give up. Defaults to a file dialog.
  void setRelocateHandler(std::function<QString(const QString& missing)> handler) {
    relocate_ = std::move(handler);
  }
  // Answers "replace the existing files?" of an export when not interactive (default: yes).
  void setReplaceFilesPolicy(bool replace) { replaceFiles_ = replace; }
  // Answers "which attribute is the source id?" of Import outlines when not interactive: given the
  // attribute names and the preselected one (empty: none), returns the chosen name (empty: none),
  // or nullopt to cancel. Default: the preselected one.
  void setIdFieldHandler(std::function<std::optional<QString>(const QStringList& names, const QString& preselected)> handler) {
    idFieldHandler_ = std::move(handler);
  }
  // Fills and answers the project settings dialog when not interactive (true = OK).
  void setProjectSettingsHandler(std::function<bool(ProjectSettingsDialog&)> handler) {
    projectSettingsHandler_ = std::move(handler);
  }
  QSpinBox* rangeMinBox() const { return rangeMin_; }
  QSpinBox* rangeMaxBox() const { return rangeMax_; }
  QLabel* rangeNote() const { return rangeNote_; }
  QLabel* intervalLabel() const { return intervalLabel_; }
  QWidget* heightModelNotice() const { return heightModelNotice_; }
  QWidget* boxFitPanel() const { return boxFitPanel_; }
  QTableWidget* boxFitTable() const { return boxFitTable_; }

 signals:
  void documentOpened();
  void messageShown(const QString& text);
  void selectedBuildingChanged(int id);
  void delineationFinished(int id);
  void matchingFinished();
  void energyUpdated(int id);
  void rangeEstimated();
  void regularizationFinished(int id);
  void boxFittingFinished(int id);  // a proposal is shown, or a message says why there is none
  void demEnhanced();
  void sceneAnalysed();                         // a new scene analysis is shown
  void buildingsDetected(int added, int present);  // Detect buildings has added its proposals
  void pendingOutlined(int outlined, int skipped);  // Outline the pending buildings has ended
  void elevationRastersExported(const QStringList& files);  // written into the folder, all of them
  void cityModelExported(const QString& path, int written);  // the CityJSON file is written
  void outlinesImported(int added, int read);  // Import outlines has added `added` of the `read` polygons

 protected:
  void closeEvent(QCloseEvent* event) override;

 private:
  // The range could not be read from the images: says so and shows where to enter it.
  void onRangeEstimateFailed(const QString& message);
  // The private functions, grouped by the file that defines them.
  // main_window.cpp: the window's settings, messages and title, the 3D view's content, the pick
  // of an above-ground object.
  void restoreSettings();
  void showMessage(const QString& title, const QString& text);
  bool askYesNo(const QString& title, const QString& text, bool defaultAnswer);
  void refreshTitle();
  void refresh3D();
  void onObjectPicked(QPointF imagePos);

  // main_window_views.cpp: the image views, what they show, the cursor readout.
  void createViews();
  void refreshRasters();
  void refreshOverlays();
  void syncRightView();
  void updateReadout(QPointF imagePos, bool leftGeometry, const cv::Mat& ownGrey);

  // main_window_docks.cpp: the docks around the left view.
  void createDocks();
  QDockWidget* createDisparityDock();
  QDockWidget* createDemDock();
  QDockWidget* create3DDock();
  void createBuildingsDock();
  QDockWidget* addDock(const QString& objectName, const QString& title, QWidget* content,
                       Qt::DockWidgetArea area);
  void ensure3DView();
  void frame3D();
  void refreshHeightModelNotice();

  // main_window_parameters.cpp: the roof interval histogram, the range editor, the forms.
  void createParametersDock();
  QTabWidget* createParameterTabs();
  void refreshHistogram();
  // The warning shown when the selected building's disparities reach the matched range's end.
  QString rangeEndWarning(const cv::Mat& roiDisparities) const;
  QWidget* createRangeEditor();
  void loadRangeFromDocument();
  template <class Params>
  void addParameterGroup(QTabWidget* tabs, const std::string& group, const QString& title,
                         const QString& description);
  QWidget* createMethodChoice();
  void writeFormIntoDocument(const std::string& group);
  void loadFormsFromDocument();

  // main_window_actions.cpp: actions, menus, toolbar.
  void createActions();
  void createFileActions();
  void createToolActions();
  QAction* addTool(const QString& name, const QString& text, const QString& key, widgets::InteractionMode mode,
                   const QString& tip);
  void createSplitMergeTools();
  void createBuildingActions();
  void createReviewActions();
  void createEditActions();
  void createViewActions();
  void createMenus();
  void createLanguageMenu();
  void createToolBar();
  void updateActions();
  void setLanguage(const QString& code);

  // main_window_project.cpp: opening, saving, exporting, recent projects.
  bool relocateMissingImages(project::Project& loaded, const QString& path);
  void installDocument(std::unique_ptr<Document> document);
  void connectDocument(Document* doc);
  bool maybeSave();
  void addRecent(const QString& path);
  void rebuildRecentMenu();
  void rememberFolder(const QString& path);

  // main_window_buildings.cpp: selection, picks, outline edits, status changes.
  void onSelectionFromOverlay(int id);
  void onSelectionFromTable();
  void onPicked(const core::Polygon& polygon);
  void onEditRequested(int id, int ringIndex, const QPolygonF& ring, const QString& description);
  void reopenSelected();
  void removeSelected();
  // The Buildings list shows `row` alone selected (none for -1); its selected rows' buildings.
  void selectListRow(int row);
  void restoreListSelection();
  std::vector<int> selectedRowIds() const;

  // main_window_split_merge.cpp: Split building, Merge with…, Merge buildings of the list.
  void onSplitLine(QPointF from, QPointF to);
  void beginMergeWith();
  void onMergeClick(int other);
  void mergeSelectedRows();
  void mergeInto(int id, int other);
  void showEditedBuildings(const std::vector<int>& ids);
  void updateSplitMergeActions(bool hasSelection);

  // main_window_review.cpp: the next building to review, the review's progress.
  int nextToReview(int step) const;
  void frameInLeftView(int id);
  void advanceAfterDecision();
  QString reviewProgressText() const;
  void refreshReviewProgress();

  // main_window_jobs.cpp: the background jobs (the others are public).
  void startEdgeMap();

  // main_window_dem_methods.cpp: box-fitting beside the active polygon, the enhanced DEM.
  QWidget* createBoxFitPanel();
  void refreshBoxFitProposals();
  void onEnhancedDemToggled(bool on);
  void scheduleDemEnhancement();
  std::vector<widgets::OverlayGuide> boxFitGuides() const;

  // main_window_scene.cpp: the scene analysis, its layers and the detection of buildings.
  void createSceneActions();
  QWidget* createLayerLegend();
  QString sceneInputsMissing() const;
  bool ensureSceneAnalysis();
  void onSceneJobEnded(widgets::JobId id, widgets::JobOutcome outcome);
  struct SceneInputs;
  // An analysis made by an export of `inputs` becomes the window's when it has none and the heights are still those.
  void adoptSceneAnalysis(project::SceneAnalysisOutcome analysis, const SceneInputs& inputs);
  void addDetectedBuildings();
  void invalidateSceneAnalysis();
  void onSceneLayerToggled(QAction* toggle, bool on);
  void onDemLayerChosen(int index);
  const cv::Mat& demViewRaster() const;
  void refreshLabelOverlay();
  void refreshLayerLegend();
  void refreshGuides();
  std::vector<widgets::OverlayGuide> sceneObjectGuides() const;
  void showInformation(const QString& title, const QString& text);

  // main_window_export.cpp: File → Export accepted buildings.
  void showExportSummary(const QString& path, const project::ExportSummary& exported, const QString& terrain);

  // main_window_import.cpp: File → Import outlines.
  void chooseOutlineFile();
  std::optional<QString> chooseIdField(const std::vector<core::Feature>& features);
  QString importSummaryText(const QString& file, const project::ImportSummary& summary) const;
  void showImportSummary(const QString& path, const project::ImportSummary& summary);

  // main_window_rasters.cpp: File → Export elevation rasters.
  void chooseRasterFolder();
  project::ElevationLayers shownElevationLayers() const;
  bool agreeToReplace(const QString& dir, const std::vector<io::OutputFile>& files);
  void onElevationRastersWritten(const QString& dir, const project::ElevationRastersWritten& written,
                                 const QStringList& leftOut);
  void refreshRasterExportAction();

  std::unique_ptr<Document> document_;
  widgets::JobRunner* jobs_ = nullptr;
  widgets::ImageView* leftView_ = nullptr;
  widgets::ImageView* rightView_ = nullptr;
  widgets::ImageView* disparityView_ = nullptr;
  widgets::ImageView* demView_ = nullptr;
  widgets::ColourLegend* disparityLegend_ = nullptr;
  widgets::ColourLegend* demLegend_ = nullptr;
  QComboBox* demMode_ = nullptr;
  QWidget* view3DHost_ = nullptr;
  QLabel* view3DPlaceholder_ = nullptr;
  widgets::Terrain3DView* view3D_ = nullptr;
  QComboBox* view3DColour_ = nullptr;
  QDoubleSpinBox* view3DExaggeration_ = nullptr;
  cv::Mat view3DDem_;  // the DEM the 3D view's exaggeration was chosen for
  BuildingBlocks buildingBlocks_;  // the 3D view's blocks, kept between refreshes
  widgets::DisparityHistogramWidget* histogram_ = nullptr;
  QLabel* intervalLabel_ = nullptr;
  // One form per parameter group of the project file, and how it reads and writes the group.
  struct ParameterGroup {
    std::string group;
    widgets::ParameterForm* form = nullptr;
    std::function<void(const project::Project&)> load;
    std::function<void(Document&)> write;
  };
  std::vector<ParameterGroup> parameterGroups_;
  QComboBox* methodChoice_ = nullptr;
  QTableView* buildingsTable_ = nullptr;
  BuildingsModel* buildingsModel_ = nullptr;
  QLabel* readout_ = nullptr;
  QLabel* reviewProgress_ = nullptr;
  QMenu* recentMenu_ = nullptr;
  QActionGroup* toolGroup_ = nullptr;
  QTimer autosaveTimer_;
  int selectedId_ = -1;
  std::vector<int> listSelection_;  // the rows selected in the Buildings list with the selected building's
  bool interactive_ = true;
  bool restoreAutosave_ = false;
  bool replaceFiles_ = true;
  bool updatingForms_ = false;
  bool updatingSelection_ = false;
  QString lastMessage_;
  std::function<QString(const QString&)> relocate_;
  std::function<bool(ProjectSettingsDialog&)> projectSettingsHandler_;
  std::function<std::optional<QString>(const QStringList&, const QString&)> idFieldHandler_;
  QSpinBox* rangeMin_ = nullptr;
  QSpinBox* rangeMax_ = nullptr;
  QLabel* rangeNote_ = nullptr;
  QString rangeSource_;  // how the current range was obtained, when estimated since the project was opened
  QWidget* heightModelNotice_ = nullptr;
  QLabel* view3DNotice_ = nullptr;
  // Outlines whose energy is being asked for or could not be scored, so that they are not asked
  // again; a scored one leaves it.
  std::map<int, core::Polygon> energyAsked_;
  int awaitingDisparity_ = -1;  // picked while matching ran: delineated when the disparity arrives
  widgets::JobId matchingJob_ = 0;
  widgets::JobId rangeJob_ = 0;
  cv::Mat edgeMap_;
  // Box-fitting results shown beside a building's outline until kept or dropped, by building.
  struct BoxFitProposal {
    project::BoxFitOutcome outcome;
    std::optional<project::EnergyOutcome> activeEnergy;  // F(C) of its outline, when computable
  };
  std::map<int, BoxFitProposal> boxFitProposals_;
  QWidget* boxFitPanel_ = nullptr;
  QTableWidget* boxFitTable_ = nullptr;
  cv::Mat enhancedDem_;  // the enhanced DEM, empty until computed (or while stale)
  std::vector<core::Polygon> enhancedFrom_;  // the outlines it was made from
  QTimer enhanceTimer_;  // outlines changed while the enhanced DEM is shown: compute it again
  // The scene analysis of the current heights and what it was computed from.
  std::optional<project::SceneAnalysisOutcome> scene_;
  struct SceneInputs {
    const uchar* heights = nullptr;
    const uchar* disparity = nullptr;
    double gsd = 0.0;
    bool operator==(const SceneInputs&) const = default;
  };
  SceneInputs sceneInputs_;
  widgets::JobId sceneJob_ = 0;
  bool detectAfterAnalysis_ = false;  // Detect buildings waits for the running analysis
  QComboBox* demLayer_ = nullptr;
  QWidget* layerLegend_ = nullptr;
  QWidget* classesLegend_ = nullptr;
  QLabel* classesLegendTitle_ = nullptr;
  QWidget* wallLegend_ = nullptr;
  QWidget* objectsLegend_ = nullptr;
  QWidget* maskLegend_ = nullptr;
  // What the left view's overlay was made of: the labels or classes raster, the exclusion mask
  // hatched over them (null when not shown).
  struct OverlaySources {
    const uchar* labels = nullptr;
    const uchar* mask = nullptr;
    bool operator==(const OverlaySources&) const = default;
  };
  OverlaySources overlayShows_;
  double rightShift_ = 0.0;
  bool linkingRight_ = false;
};

}  // namespace delineo::gui
