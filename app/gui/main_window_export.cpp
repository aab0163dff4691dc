// MainWindow's File → Export accepted buildings: the outlines (GeoJSON, GeoPackage) written at
// once, the CityJSON blocks in a background job that analyses the scene first when there is no
// analysis (its DTM is the terrain) and writes the file only when it was not canceled.
#include <QFileInfo>
#include <QPointer>
#include <QStatusBar>
#include <optional>
#include <string>
#include <utility>

#include "delineo/core/error.hpp"
#include "delineo/io/cityjson.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/project/pipeline.hpp"
#include "document.hpp"
#include "error_text.hpp"
#include "main_window.hpp"

namespace delineo::gui {

namespace {

// What the CityJSON job gives back: the summary of the file written, the analysis made on the way.
struct CityModelExport {
  project::ExportSummary summary;
  std::optional<project::SceneAnalysisOutcome> analysis;
};

// Thrown inside the temporary file's writing when the job is canceled: the target stays as it was.
struct ExportCanceled {};

// The accepted buildings as CityJSON into `path`, through a temporary file renamed over it only
// when `progress` is not canceled by then. Returns nullopt when canceled.
std::optional<project::ExportSummary> writeUnlessCanceled(const project::Project& project, const std::string& path,
                                                          const project::CityModelInputs& model,
                                                          core::Progress& progress) {
  project::ExportSummary summary;
  try {
    io::writeAtomically(path, [&](const std::string& temporary) {
      summary = project::exportBuildings(project, temporary, {project::BuildingStatus::Accepted}, model, &progress);
      if (summary.status == core::RunStatus::Canceled || progress.canceled()) throw ExportCanceled{};
    });
  } catch (const ExportCanceled&) {
    return std::nullopt;
  }
  return summary;
}

}  // namespace

void MainWindow::exportAccepted(const QString& path) {
  if (io::isCityJsonPath(path.toStdString())) exportCityModel(path);
  else exportOutlines(path);
}

int MainWindow::exportOutlines(const QString& path) {
  if (!document_) return -1;
  try {
    const project::ExportSummary exported = document_->exportAccepted(path);
    showExportSummary(path, exported, {});
    return exported.written;
  } catch (const core::Error& e) {
    showMessage(tr("Cannot export"), errorMessage(e));
    return -1;
  }
}

widgets::JobId MainWindow::exportCityModel(const QString& path) {
  if (!document_) return 0;
  const project::Project& current = document_->project();
  const std::string out = path.toStdString();
  try {
    io::checkOutputs({{out, io::OutputFormat::CityJson}}, project::inputFiles(current));
  } catch (const core::Error& e) {
    showMessage(tr("Cannot export"), errorMessage(e));
    return 0;
  }
  const project::Project projectCopy = current;
  const cv::Mat heights = document_->dem();  // the 3D view's ground next to each building
  const cv::Mat disparity = document_->disparity();
  const cv::Mat dtm = scene_ ? scene_->dtm : cv::Mat();
  const bool analyse = !scene_ && sceneInputsMissing().isEmpty();
  const QString noTerrain = heights.empty()                      ? tr("no terrain: no heights")
                            : !(projectCopy.height.gsd > 0.0) ? tr("no terrain: no ground sample distance")
                                                              : tr("no terrain");
  const SceneInputs sceneInputs{heights.data, disparity.data, projectCopy.height.gsd};
  const std::string writing = tr("Writing the CityJSON file").toStdString();
  QPointer<Document> doc(document_.get());
  return jobs_->run<CityModelExport>(
      tr("Export accepted buildings"),
      [projectCopy, heights, disparity, dtm, out, analyse, writing](core::Progress& p) {
        CityModelExport result;
        project::CityModelInputs model{heights, dtm, {}};
        double analysed = 0.0;
        if (analyse) {
          core::Progress::Range range(&p, 0.0, 0.7);
          result.analysis = project::analyseScene(projectCopy, heights, io::readImage8(projectCopy.left), disparity, &range);
          if (p.canceled()) return result;  // dropped by the runner
          model.dtm = result.analysis->dtm;
          analysed = 0.7;
        }
        core::Progress::Range range(&p, analysed, 1.0);
        range.setStage(writing);
        if (auto summary = writeUnlessCanceled(projectCopy, out, model, range)) result.summary = std::move(*summary);
        return result;
      },
      [this, doc, path, sceneInputs, noTerrain](CityModelExport result) {
        if (!doc || doc != document_.get()) return;
        if (result.analysis) adoptSceneAnalysis(std::move(*result.analysis), sceneInputs);
        const project::ExportSummary& written = result.summary;
        showExportSummary(path, written,
                          written.terrainTriangles > 0 ? tr("terrain: %1 vertices, %2 triangles")
                                                             .arg(written.terrainVertices)
                                                             .arg(written.terrainTriangles)
                                                       : noTerrain);
        emit cityModelExported(path, result.summary.written);
      },
      QStringLiteral("export-city"));
}

// The status bar says what was written: the buildings, their roof parts and the terrain
// (CityJSON), then what was left out and where the blocks stand when it is not their own ground.
void MainWindow::showExportSummary(const QString& path, const project::ExportSummary& exported,
                                   const QString& terrain) {
  QString text = (exported.written == 1 ? tr("%1 building exported to %2")
                                         : tr("%1 buildings exported to %2"))
                     .arg(exported.written)
                     .arg(QFileInfo(path).fileName());  // the status bar's room: the name, not the folder
  if (exported.parts > 0) {
    text += QStringLiteral("; ") + (exported.parts == 1 ? tr("1 roof part") : tr("%1 roof parts").arg(exported.parts));
  }
  if (!terrain.isEmpty()) text += QStringLiteral("; ") + terrain;
  text += QLatin1Char('.');
  if (!exported.leftOut.empty()) {
    text += QStringLiteral(" ") + tr("%n left out: no roof height above the ground.", nullptr,
                                     static_cast<int>(exported.leftOut.size()));
  }
  if (!exported.notes.empty()) {
    text += QStringLiteral(" ") + (exported.onLocalGround
                                       ? tr("%n on the ground level: no ground next to them.", nullptr,
                                            static_cast<int>(exported.notes.size()))
                                       : tr("The blocks stand on the ground level: no heights."));
  }
  lastMessage_ = text;
  statusBar()->showMessage(text, 15000);
}

}  // namespace delineo::gui
