// MainWindow's project files: opening a project (with autosave recovery and missing images
// relocated), a stereo pair or the sample, installing the document in the views, saving,
// autosaving, the project settings and the recent projects.
#include <QAction>
#include <QFileDialog>
#include <QFileInfo>
#include <QMenu>
#include <QMessageBox>
#include <QSettings>
#include <QSignalBlocker>
#include <QStandardPaths>
#include <QStatusBar>
#include <QUndoStack>
#include <utility>

#include "buildings_model.hpp"
#include "delineo/core/error.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/roof_parts.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "error_text.hpp"
#include "main_window.hpp"
#include "project_settings_dialog.hpp"

namespace delineo::gui {

namespace {

constexpr int kMaxRecent = 8;

}  // namespace

bool MainWindow::openProject(const QString& path) {
  const std::string projectPath = path.toStdString();
  project::Project loaded;
  try {
    bool useAutosave = false;
    if (project::hasNewerAutosave(projectPath)) {
      useAutosave = interactive_
                        ? askYesNo(tr("Recover unsaved changes"),
                                   tr("An automatic backup of %1 is newer than the project file "
                                      "(Delineo may have stopped unexpectedly). Restore it?")
                                       .arg(QFileInfo(path).fileName()),
                                   true)
                        : restoreAutosave_;
    }
    loaded = project::loadProject(useAutosave ? project::autosavePath(projectPath) : projectPath);
    if (!relocateMissingImages(loaded, path)) return false;
    auto doc = Document::fromProject(std::move(loaded), path);
    installDocument(std::move(doc));
    rememberFolder(path);
  } catch (const core::Error& e) {
    showMessage(tr("Cannot open the project"), errorMessage(e));
    return false;
  }
  addRecent(path);
  return true;
}

// Missing images: asks for their new place, one by one; giving up (false, with a message) leaves
// everything as it was.
bool MainWindow::relocateMissingImages(project::Project& loaded, const QString& path) {
  for (const std::string& missing : loaded.missingFiles()) {
    const QString missingPath = QString::fromStdString(missing);
    QString replacement;
    if (relocate_) {
      replacement = relocate_(missingPath);
    } else if (interactive_) {
      if (askYesNo(tr("Image not found"),
                   tr("The project refers to %1, which does not exist. Locate it?").arg(missingPath), true)) {
        replacement = QFileDialog::getOpenFileName(this, tr("Locate %1").arg(QFileInfo(missingPath).fileName()),
                                                   QFileInfo(path).path());
      }
    }
    if (replacement.isEmpty()) {
      showMessage(tr("Image not found"),
                  tr("The project was not opened because %1 does not exist. Move the file back "
                     "or locate it when opening the project.").arg(missingPath));
      return false;
    }
    for (std::string* p : {&loaded.left, &loaded.right, &loaded.disparity, &loaded.dem, &loaded.labels,
                           &loaded.exclude}) {
      if (*p == missing) *p = replacement.toStdString();
    }
  }
  return true;
}

bool MainWindow::openPair(const QString& left, const QString& right) {
  try {
    installDocument(Document::fromPair(left, right));
  } catch (const core::Error& e) {
    showMessage(tr("Cannot open the stereo pair"), errorMessage(e));
    return false;
  }
  return true;
}

QString MainWindow::sampleDirectory() {
  return QStandardPaths::writableLocation(QStandardPaths::AppLocalDataLocation) + QStringLiteral("/sample");
}

bool MainWindow::openSample() {
  const QString dir = sampleDirectory();
  statusBar()->showMessage(tr("Preparing the sample project…"));
  jobs_->run<std::string>(
      tr("Sample project"),
      [dir](core::Progress& p) { return project::ensureSampleProject(dir.toStdString(), &p); },
      [this](std::string path) {
        if (openProject(QString::fromStdString(path))) {
          statusBar()->showMessage(tr("Sample project opened: pick a building on the left image."), 10000);
        }
      },
      QStringLiteral("sample"));
  return true;
}

void MainWindow::installDocument(std::unique_ptr<Document> document) {
  jobs_->cancelAll();
  selectedId_ = -1;
  awaitingDisparity_ = -1;
  // The model lets go of the old document while it still exists.
  buildingsModel_->setDocument(document.get());
  document_ = std::move(document);
  Document* doc = document_.get();
  connectDocument(doc);
  leftView_->setImage(doc->leftDisplay());
  rightView_->setImage(doc->rightDisplay());
  action(QStringLiteral("actionShowLabels"))->setEnabled(!doc->labels().empty());
  action(QStringLiteral("actionShowExclusionMask"))->setEnabled(!doc->pair().exclude.empty());
  // The scene analysis was of the previous document's heights.
  scene_.reset();
  sceneJob_ = 0;
  detectAfterAnalysis_ = false;
  overlayShows_ = {};
  leftView_->clearOverlay();
  for (const char* name : {"actionShowClasses", "actionShowObjects"}) {
    const QSignalBlocker block(action(QString::fromLatin1(name)));
    action(QString::fromLatin1(name))->setChecked(false);
  }
  setDemLayer(DemLayer::Dem);
  refreshLabelOverlay();
  edgeMap_ = cv::Mat();
  leftView_->polygons().setEdgeMap(cv::Mat(), 128.0);
  rightShift_ = document_->project().height.groundDisparity;
  leftView_->fitToWindow();
  syncRightView();
  leftView_->polygons().clearEvolvingContour();
  leftView_->polygons().setRoi({});
  energyAsked_.clear();
  rangeSource_.clear();
  boxFitProposals_.clear();
  enhanceTimer_.stop();
  enhancedDem_ = cv::Mat();
  enhancedFrom_.clear();
  {
    const QSignalBlocker block(action(QStringLiteral("actionEnhancedDem")));
    action(QStringLiteral("actionEnhancedDem"))->setChecked(false);
  }
  refreshBoxFitProposals();
  loadFormsFromDocument();
  loadRangeFromDocument();
  refreshHeightModelNotice();
  refreshRasters();
  refreshOverlays();
  refreshHistogram();
  refresh3D();
  refreshTitle();
  refreshReviewProgress();
  updateActions();
  emit documentOpened();
  startEdgeMap();
  if (doc->disparity().empty() && QSettings().value(QStringLiteral("autoMatch"), true).toBool()) {
    statusBar()->showMessage(tr("No disparity yet: computing it in the background."), 8000);
    startMatching();
  }
}

// What the views do when the document changes.
void MainWindow::connectDocument(Document* doc) {
  connect(doc, &Document::buildingChanged, this, &MainWindow::refreshReviewProgress);
  connect(doc, &Document::buildingsReset, this, &MainWindow::refreshReviewProgress);
  connect(doc, &Document::buildingChanged, this, [this](int id) {
    if (document_->project().find(id) == nullptr) boxFitProposals_.erase(id);
    refreshOverlays();
    refreshBoxFitProposals();
    scheduleDemEnhancement();
    if (id == selectedId_) {
      if (document_->project().find(id) == nullptr) {
        selectBuilding(-1);
      } else {
        refreshHistogram();
        rightShift_ = roofDisparity(id).value_or(document_->project().height.groundDisparity);
        syncRightView();
      }
    }
    refresh3D();
    updateActions();
  });
  // A new DEM (disparity, height model) makes the enhanced one stale: computed again if shown.
  const auto demChanged = [this] {
    enhancedDem_ = cv::Mat();
    enhancedFrom_.clear();
    scheduleDemEnhancement();
  };
  connect(doc, &Document::disparityChanged, this, demChanged);
  connect(doc, &Document::settingsChanged, this, demChanged);
  connect(doc, &Document::disparityChanged, this, [this] {
    refreshHeightModelNotice();
    refreshRasters();
    refreshOverlays();
    refreshHistogram();
    refresh3D();
    updateActions();
  });
  connect(doc, &Document::parametersChanged, this, [this, demChanged](const QString& group) {
    loadFormsFromDocument();
    if (group == QLatin1String("enhance")) demChanged();  // the enhanced DEM is made with them
    if (group == QLatin1String(project::kRoofLevelsGroup)) refresh3D();  // the blocks' parts
  });
  connect(doc, &Document::settingsChanged, this, [this] {
    loadFormsFromDocument();  // the method choice
    loadRangeFromDocument();
    refreshRasters();
    refreshHeightModelNotice();
    refreshHistogram();
    refresh3D();
  });
  connect(doc, &Document::buildingsReset, this, [this] {
    // Several buildings at once (detected ones, or their undo): the selection and the box-fitting
    // proposals follow like for one.
    std::erase_if(boxFitProposals_, [this](const auto& entry) { return document_->project().find(entry.first) == nullptr; });
    scheduleDemEnhancement();
    refreshOverlays();
    refreshBoxFitProposals();
    if (selectedId_ > 0 && document_->project().find(selectedId_) == nullptr) selectBuilding(-1);
    refresh3D();
    updateActions();
  });
  // The scene analysis is of the heights, the disparity and its parameters.
  connect(doc, &Document::disparityChanged, this, &MainWindow::invalidateSceneAnalysis);
  connect(doc, &Document::settingsChanged, this, [this] {
    const SceneInputs now{document_->dem().data, document_->disparity().data, document_->project().height.gsd};
    if (!(now == sceneInputs_)) invalidateSceneAnalysis();
  });
  connect(doc, &Document::parametersChanged, this, [this](const QString& group) {
    for (const char* g : {project::kSegmentGroup, project::kClassifyGroup, project::kObjectsGroup, project::kDetectGroup}) {
      if (group == QLatin1String(g)) invalidateSceneAnalysis();
    }
  });
  // A manual edit leaves the outline's energy unknown: it is scored again in the background.
  connect(doc, &Document::buildingChanged, this, [this](int id) { startEnergyUpdate(id); });
  connect(doc, &Document::modifiedChanged, this, [this] { refreshTitle(); });
  connect(doc->undoStack(), &QUndoStack::indexChanged, this, [this] {
    refreshTitle();
    updateActions();
  });
}

bool MainWindow::maybeSave() {
  if (!document_ || !document_->isModified()) return true;
  if (!interactive_) return true;
  const auto answer = QMessageBox::question(
      this, tr("Unsaved changes"), tr("Save the changes to %1?").arg(document_->displayName()),
      QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, QMessageBox::Save);
  if (answer == QMessageBox::Cancel) return false;
  if (answer == QMessageBox::Save) return save();
  return true;
}

bool MainWindow::save() {
  if (!document_) return false;
  if (document_->path().isEmpty()) {
    if (!interactive_) return false;
    const QString path = QFileDialog::getSaveFileName(this, tr("Save project"), document_->dialogFolder(),
                                                      tr("Delineo projects (*.json)"));
    return !path.isEmpty() && saveAs(path);
  }
  return saveAs(document_->path());
}

bool MainWindow::saveAs(const QString& path) {
  if (!document_) return false;
  try {
    document_->save(path);
  } catch (const core::Error& e) {
    showMessage(tr("Cannot save the project"), errorMessage(e));
    return false;
  }
  addRecent(path);
  rememberFolder(path);
  refreshTitle();
  statusBar()->showMessage(tr("Saved %1").arg(path), 5000);
  return true;
}

void MainWindow::autosaveNow() {
  if (!document_) return;
  try {
    document_->autosave();
  } catch (const core::Error& e) {
    statusBar()->showMessage(tr("Autosave failed: %1").arg(QString::fromStdString(e.detail())), 8000);
  }
}

void MainWindow::openProjectSettings() {
  if (!document_) return;
  ProjectSettingsDialog dialog(document_->project(), document_->path().isEmpty() ? QString() : document_->dialogFolder(),
                               project::suggestSceneGroundLevel(document_->disparity()), this);
  bool accepted = false;
  if (projectSettingsHandler_) accepted = projectSettingsHandler_(dialog);
  else if (interactive_) accepted = dialog.exec() == QDialog::Accepted;
  if (!accepted) return;
  QUndoStack* stack = document_->undoStack();
  stack->beginMacro(tr("Project settings"));
  document_->setOutputDir(dialog.outputDir());
  document_->setHeightModel(dialog.heightModel());
  stack->endMacro();
}

void MainWindow::addRecent(const QString& path) {
  QSettings settings;
  QStringList recent = settings.value(QStringLiteral("recentProjects")).toStringList();
  const QString absolute = QFileInfo(path).absoluteFilePath();
  recent.removeAll(absolute);
  recent.prepend(absolute);
  while (recent.size() > kMaxRecent) recent.removeLast();
  settings.setValue(QStringLiteral("recentProjects"), recent);
  rebuildRecentMenu();
}

void MainWindow::rebuildRecentMenu() {
  recentMenu_->clear();
  const QStringList recent = QSettings().value(QStringLiteral("recentProjects")).toStringList();
  for (const QString& path : recent) {
    QAction* a = recentMenu_->addAction(QFileInfo(path).fileName());
    a->setToolTip(path);
    connect(a, &QAction::triggered, this, [this, path] {
      if (maybeSave()) openProject(path);
    });
  }
  recentMenu_->setEnabled(!recent.isEmpty());
}

void MainWindow::rememberFolder(const QString& path) {
  QSettings().setValue(QStringLiteral("lastProjectFolder"), QFileInfo(path).absolutePath());
}

}  // namespace delineo::gui
