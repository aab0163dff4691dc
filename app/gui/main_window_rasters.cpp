// MainWindow's File → Export elevation rasters: the layers the window has (the disparity, the DEM,
// the enhanced DEM while it is shown, the scene analysis's), the folder, the question before
// replacing files, and the background job that analyses the scene when it is missing and writes
// every file through project::writeElevationRasters (all of them or none).
#include <QAction>
#include <QFileDialog>
#include <QFileInfo>
#include <QPointer>
#include <QStatusBar>
#include <iterator>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "delineo/core/error.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/io/raster.hpp"
#include "document.hpp"
#include "error_text.hpp"
#include "main_window.hpp"

namespace delineo::gui {

namespace {

// What the export job gives back: the files written, and the scene analysis made on the way.
struct RasterExport {
  project::ElevationRastersWritten written;
  std::optional<project::SceneAnalysisOutcome> analysis;
};

}  // namespace

void MainWindow::refreshRasterExportAction() {
  QAction* exportRasters = action(QStringLiteral("actionExportRasters"));
  const bool elevation = document_ && (!document_->disparity().empty() || !document_->dem().empty());
  exportRasters->setEnabled(elevation);
  const QString tip = elevation ? tr("Write the disparity, the DEM and the scene analysis's DTM, nDSM, labels and "
                                     "objects into a folder, georeferenced like the left image")
                                : tr("Nothing to export yet: compute the disparity (Processing → Compute disparity) "
                                     "or give the project a DEM");
  exportRasters->setToolTip(tip);
  exportRasters->setStatusTip(tip);
}

void MainWindow::chooseRasterFolder() {
  if (!document_) return;
  QString start = document_->outputDirectory();
  if (start.isEmpty() || !QFileInfo(start).isDir()) start = document_->dialogFolder();
  const QString dir = QFileDialog::getExistingDirectory(this, tr("Export elevation rasters into"), start);
  if (!dir.isEmpty()) exportElevationRasters(dir);
}

// The layers as the window has them now; the scene analysis's when it is computed.
project::ElevationLayers MainWindow::shownElevationLayers() const {
  project::ElevationLayers layers;
  layers.disparity = document_->disparity();
  layers.dem = document_->dem();
  if (action(QStringLiteral("actionEnhancedDem"))->isChecked() && !enhancedDem_.empty()) {
    layers.enhancedDem = enhancedDem_;
  }
  if (scene_) layers.setSceneAnalysis(*scene_);
  return layers;
}

// True when none of `files` exists, or the operator agrees to replace those that do.
bool MainWindow::agreeToReplace(const QString& dir, const std::vector<io::OutputFile>& files) {
  QStringList existing;
  for (const io::OutputFile& file : files) {
    const QFileInfo info(QString::fromStdString(file.path));
    if (info.exists()) existing << info.fileName();
  }
  if (existing.isEmpty()) return true;
  if (!interactive_) return replaceFiles_;
  return askYesNo(tr("Replace files"),
                  tr("%1 already holds %2. Replace them?").arg(dir, existing.join(QStringLiteral(", "))), false);
}

widgets::JobId MainWindow::exportElevationRasters(const QString& dir) {
  if (!document_) return 0;
  if (document_->disparity().empty() && document_->dem().empty()) {
    showMessage(tr("Export elevation rasters"), action(QStringLiteral("actionExportRasters"))->toolTip());
    return 0;
  }
  const project::Project& current = document_->project();
  const std::string folder = dir.toStdString();
  project::ElevationLayers layers = shownElevationLayers();
  QStringList leftOut;  // the project's own disparity or DEM file, already in the folder
  for (const std::string& name : project::leaveOutProjectSources(current, folder, layers)) {
    leftOut << QString::fromStdString(name);
  }
  const bool analyse = !scene_ && sceneInputsMissing().isEmpty();
  std::vector<project::ElevationLayer> planned = layers.present();
  if (analyse) {
    planned.insert(planned.end(), std::begin(project::kSceneAnalysisLayers), std::end(project::kSceneAnalysisLayers));
  }
  const std::vector<io::OutputFile> files = project::elevationFiles(folder, planned);
  const std::vector<std::string> inputs = project::inputFiles(current);
  try {
    io::checkOutputs(files, inputs);
  } catch (const core::Error& e) {
    showMessage(tr("Cannot export"), errorMessage(e));
    return 0;
  }
  if (!agreeToReplace(dir, files)) {
    lastMessage_ = tr("Nothing exported: the files in %1 are kept.").arg(dir);
    statusBar()->showMessage(lastMessage_, 8000);
    return 0;
  }
  const project::Project projectCopy = current;
  const cv::Mat heights = document_->dem();
  const cv::Mat disparity = document_->disparity();
  const io::GeoReference geo = document_->pair().geo;
  const SceneInputs sceneInputs{heights.data, disparity.data, projectCopy.height.gsd};
  const std::string writing = tr("Writing the files").toStdString();
  QPointer<Document> doc(document_.get());
  return jobs_->run<RasterExport>(
      tr("Export elevation rasters"),
      [projectCopy, heights, disparity, geo, folder, inputs, analyse, writing, layers](core::Progress& p) mutable {
        RasterExport result;
        double analysed = 0.0;
        if (analyse) {
          core::Progress::Range range(&p, 0.0, 0.8);
          result.analysis = project::analyseScene(projectCopy, heights, io::readImage8(projectCopy.left), disparity, &range);
          if (result.analysis->status == core::RunStatus::Canceled) {
            result.written.status = core::RunStatus::Canceled;
            return result;
          }
          layers.setSceneAnalysis(*result.analysis);
          analysed = 0.8;
        }
        core::Progress::Range range(&p, analysed, 1.0);
        range.setStage(writing);
        result.written = project::writeElevationRasters(folder, geo, layers, &range, inputs);
        return result;
      },
      [this, doc, dir, leftOut, sceneInputs](RasterExport result) {
        if (!doc || doc != document_.get() || result.written.status != core::RunStatus::Completed) return;
        if (result.analysis) adoptSceneAnalysis(std::move(*result.analysis), sceneInputs);
        onElevationRastersWritten(dir, result.written, leftOut);
      },
      QStringLiteral("rasters"));
}

// The status bar says what was written, what was left as it was, and why the scene analysis's
// layers are missing when they are.
void MainWindow::onElevationRastersWritten(const QString& dir, const project::ElevationRastersWritten& written,
                                           const QStringList& leftOut) {
  const bool one = written.rasters == 1;
  QString text = written.objects ? (one ? tr("%1 raster and the objects written to %2")
                                        : tr("%1 rasters and the objects written to %2"))
                                 : (one ? tr("%1 raster written to %2") : tr("%1 rasters written to %2"));
  text = text.arg(written.rasters).arg(dir);
  if (!leftOut.isEmpty()) {
    text += QLatin1Char(' ') + (leftOut.size() == 1 ? tr("%1 is the project's own file: left as it is.")
                                                    : tr("%1 are the project's own files: left as they are."))
                                   .arg(leftOut.join(QStringLiteral(", ")));
  }
  if (!written.objects) text += QLatin1Char(' ') + sceneInputsMissing();
  lastMessage_ = text.trimmed();
  statusBar()->showMessage(lastMessage_, 15000);
  QStringList files;
  for (const std::string& file : written.files) files << QString::fromStdString(file);
  emit elevationRastersExported(files);
}

}  // namespace delineo::gui
