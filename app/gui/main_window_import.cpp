// MainWindow's File → Import outlines: the polygons of a vector file (a cadastre, OpenStreetMap,
// another project's or tool's export) read with the left image's georeferencing, the attribute
// kept as each building's source id, and the pending buildings added in one undoable step
// (Document::importOutlines), with a message saying what was left out and why.
#include <QFileDialog>
#include <QFileInfo>
#include <QInputDialog>
#include <QStringList>
#include <set>
#include <string>
#include <vector>

#include "delineo/core/error.hpp"
#include "delineo/io/vector.hpp"
#include "document.hpp"
#include "error_text.hpp"
#include "main_window.hpp"

namespace delineo::gui {

namespace {

// How many of the import's problems the message lists; the others are counted.
constexpr int kProblemsListed = 8;

// The attribute names of the features, each once, in alphabetical order.
QStringList attributeNames(const std::vector<core::Feature>& features) {
  std::set<std::string> names;
  for (const core::Feature& f : features) {
    for (const auto& [name, value] : f.attributes) names.insert(name);
  }
  QStringList list;
  for (const std::string& name : names) list << QString::fromStdString(name);
  return list;
}

// The attribute that most likely identifies an outline in its source: a usual id name
// (case-insensitive), else a name ending in "id"; empty when none.
QString preferredIdField(const QStringList& names) {
  for (const char* usual : {"id", "osm_id", "fid", "ref", "source_id", "gml_id", "objectid"}) {
    for (const QString& name : names) {
      if (name.compare(QLatin1String(usual), Qt::CaseInsensitive) == 0) return name;
    }
  }
  for (const QString& name : names) {
    if (name.endsWith(QLatin1String("id"), Qt::CaseInsensitive)) return name;
  }
  return {};
}

// The features of `path` in left-image pixels; an error without a file is given the file's name.
std::vector<core::Feature> readOutlines(const QString& path, const io::GeoReference& geo) {
  try {
    return io::readFeatures(path.toStdString(), geo);
  } catch (const core::Error& e) {
    if (!e.path().empty()) throw;
    throw core::Error(e.code(), e.detail(), path.toStdString());
  }
}

}  // namespace

void MainWindow::chooseOutlineFile() {
  if (!document_) return;
  const QString path = QFileDialog::getOpenFileName(
      this, tr("Import outlines"), document_->dialogFolder(),
      tr("Vector files (*.geojson *.json *.gpkg *.shp);;GeoJSON (*.geojson *.json);;GeoPackage (*.gpkg);;"
         "Shapefile (*.shp);;All files (*)"));
  if (!path.isEmpty()) importOutlines(path);
}

int MainWindow::importOutlines(const QString& path) {
  if (!document_) return -1;
  try {
    const std::vector<core::Feature> features = readOutlines(path, document_->pair().geo);
    const std::optional<QString> idField = chooseIdField(features);
    if (!idField) return -1;
    project::ImportOptions options;
    options.idField = idField->toStdString();
    options.source = QFileInfo(path).fileName().toStdString();
    const project::ImportSummary summary = document_->importOutlines(features, options);
    showImportSummary(path, summary);
    return static_cast<int>(summary.added.size());
  } catch (const core::Error& e) {
    showMessage(tr("Cannot import outlines"), errorMessage(e));
    return -1;
  }
}

// The attribute kept as the source id: empty for none (also when the features have no
// attribute: nothing is asked), nullopt when the operator cancels.
std::optional<QString> MainWindow::chooseIdField(const std::vector<core::Feature>& features) {
  const QStringList names = attributeNames(features);
  if (names.isEmpty()) return QString();
  const QString preselected = preferredIdField(names);
  if (!interactive_) return idFieldHandler_ ? idFieldHandler_(names, preselected) : preselected;
  const QStringList items = QStringList{tr("(none)")} + names;
  bool ok = false;
  const QString chosen = QInputDialog::getItem(
      this, tr("Import outlines"), tr("Attribute kept as each building's source id (exported as source_id):"), items,
      static_cast<int>(names.indexOf(preselected)) + 1, false, &ok);
  if (!ok) return std::nullopt;
  return chosen == items.front() ? QString() : chosen;
}

// What was added and what was left out, then the problems; when every polygon lay outside the
// image, a question about the file's coordinates.
QString MainWindow::importSummaryText(const QString& file, const project::ImportSummary& summary) const {
  const int added = static_cast<int>(summary.added.size());
  QString text = summary.read == 1 ? tr("%1 of 1 outline of %2 imported as a pending building").arg(added).arg(file)
                                   : tr("%1 of %2 outlines of %3 imported as pending buildings")
                                         .arg(added)
                                         .arg(summary.read)
                                         .arg(file);
  if (summary.clipped > 0) text += QLatin1Char(' ') + tr("(%1 cut at the image border)").arg(summary.clipped);
  if (summary.alreadyThere > 0) text += QStringLiteral("; ") + tr("%1 already in the project").arg(summary.alreadyThere);
  if (summary.outsideImage > 0) text += QStringLiteral("; ") + tr("%1 outside the left image").arg(summary.outsideImage);
  text += QLatin1Char('.');
  if (added > 0) text += QLatin1Char(' ') + tr("Outline them with Building → Outline the pending buildings.");
  if (summary.outsideImage == summary.read) {
    text += QLatin1Char(' ') + (document_->pair().geo.valid()
                                    ? tr("No outline lies on the left image: are the file's coordinates in the "
                                         "coordinate reference system it declares, or in the left image's when it "
                                         "declares none?")
                                    : tr("No outline lies on the left image: it has no georeferencing, so the "
                                         "file's coordinates are read as its pixels. Are they?"));
  }
  QStringList problems;
  for (const std::string& problem : summary.problems) {
    if (problems.size() < kProblemsListed) problems << QString::fromStdString(problem);
  }
  const int more = static_cast<int>(summary.problems.size()) - static_cast<int>(problems.size());
  if (more > 0) problems << tr("and %1 more").arg(more);
  if (!problems.isEmpty()) text += QLatin1Char('\n') + tr("Problems: %1.").arg(problems.join(QStringLiteral("; ")));
  return text;
}

// The new buildings are listed with the first one selected; a file of which nothing could be
// placed on the image is a warning.
void MainWindow::showImportSummary(const QString& path, const project::ImportSummary& summary) {
  const QString file = QFileInfo(path).fileName();
  const int added = static_cast<int>(summary.added.size());
  if (summary.read == 0) {
    showMessage(tr("Import outlines"), tr("%1 holds no polygon.").arg(file));
  } else if (summary.outsideImage == summary.read) {
    showMessage(tr("Import outlines"), importSummaryText(file, summary));
  } else {
    showDock(QStringLiteral("buildingsDock"));
    if (added > 0) selectBuilding(summary.added.front());
    showInformation(tr("Import outlines"), importSummaryText(file, summary));
  }
  emit outlinesImported(added, summary.read);
}

}  // namespace delineo::gui
