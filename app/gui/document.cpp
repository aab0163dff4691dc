#include "document.hpp"

#include <QCoreApplication>
#include <QDir>
#include <QFileInfo>
#include <QSettings>
#include <cmath>
#include <filesystem>

#include <opencv2/imgproc.hpp>

#include "commands.hpp"
#include "delineo/core/error.hpp"

namespace delineo::gui {

namespace fs = std::filesystem;
using project::Building;
using project::BuildingStatus;

namespace {
// The grey image as 8-bit for display (io::stretchTo8Bit: 8-bit values as they are).
cv::Mat toDisplayGrey(const cv::Mat& grey) { return io::stretchTo8Bit(grey); }

// A BGR 8-bit copy of a colour raster (io::readImage8: the first three bands as R, G, B, deeper
// values stretched) for display; empty for a grey one.
cv::Mat toDisplayColour(const std::string& path) {
  cv::Mat image = io::readImage8(path);
  return image.channels() == 3 ? image : cv::Mat();
}
}  // namespace

std::unique_ptr<Document> Document::open(const QString& projectPath) {
  project::Project p = project::loadProject(projectPath.toStdString());
  return fromProject(std::move(p), projectPath);
}

std::unique_ptr<Document> Document::fromProject(project::Project project, const QString& path) {
  std::unique_ptr<Document> doc(new Document);
  doc->project_ = std::move(project);
  doc->path_ = path;
  doc->loadRasters();
  doc->undo_.setClean();
  connect(&doc->undo_, &QUndoStack::cleanChanged, doc.get(),
          [d = doc.get()] { emit d->modifiedChanged(d->isModified()); });
  return doc;
}

std::unique_ptr<Document> Document::fromPair(const QString& left, const QString& right) {
  project::Project p;
  p.name = QFileInfo(left).completeBaseName().toStdString();
  p.left = fs::absolute(left.toStdString()).lexically_normal().string();
  p.right = fs::absolute(right.toStdString()).lexically_normal().string();
  // Outputs go to "output" beside the project file once it is saved, never beside the images.
  auto doc = fromProject(std::move(p), QString());
  doc->extraDirty_ = true;  // never saved
  return doc;
}

void Document::loadRasters() {
  pair_ = project::readStereoPair(project_);
  leftGrey_ = toDisplayGrey(pair_.left);
  rightGrey_ = toDisplayGrey(pair_.right);
  leftColour_ = toDisplayColour(project_.left);
  rightColour_ = toDisplayColour(project_.right);
  disparity_ = project::readDisparity(project_, pair_.left.size());
  pair_.disparity = disparity_;
  if (!project_.labels.empty()) {
    io::Raster labels = io::readRaster(project_.labels);
    if (labels.data.size() != pair_.left.size() || labels.data.channels() != 1) {
      throw core::Error(core::ErrorCode::MismatchedInputs,
                        "the label raster must have one band and the size of the left image",
                        project_.labels);
    }
    labels.data.convertTo(labels_, CV_8U);
  }
  if (!project_.dem.empty()) {
    io::ReadOptions options;
    options.type = io::PixelType::Float32;
    options.toGrey = true;
    dem_ = io::readRaster(project_.dem, options).data;
    if (dem_.size() != pair_.left.size()) {
      throw core::Error(core::ErrorCode::MismatchedInputs,
                        "the DEM must be in left-image geometry (same size as the left image)",
                        project_.dem);
    }
  } else {
    deriveDem();
  }
}

void Document::deriveDem() {
  // Without a DEM file, heights come from the disparity through the project's height model.
  if (project_.dem.empty()) {
    demDerived_ = true;
    dem_ = project::heightsFromDisparity(project_, disparity_);  // empty without a height model
  }
}

QString Document::displayName() const {
  if (!project_.name.empty()) return QString::fromStdString(project_.name);
  if (!path_.isEmpty()) return QFileInfo(path_).fileName();
  return tr("Untitled project");
}

int Document::addBuilding(const core::Polygon& initial) {
  Building b;
  b.id = project_.nextBuildingId();
  b.initial = initial;
  if (!disparity_.empty()) b.roofInterval = project::suggestRoofInterval(disparity_, initial);
  b.addHistory("picked", std::to_string(initial.outer.size()) + " vertices");
  undo_.push(new BuildingCommand(this, b.id, std::nullopt, b, tr("Pick building %1").arg(b.id)));
  return b.id;
}

std::vector<int> Document::addProposedBuildings(const std::vector<core::Feature>& proposals,
                                                std::vector<std::string>* problems) {
  project::Project after = project_;
  const std::vector<int> ids = project::addProposedBuildings(after, proposals, "delineo", problems);
  pushBuildings(after, ids, tr("Detect %n building(s)", nullptr, static_cast<int>(ids.size())));
  return ids;
}

void Document::pushBuildings(const project::Project& after, const std::vector<int>& ids, const QString& text) {
  if (ids.empty()) return;
  const auto state = [](const project::Project& p, int id) {
    const Building* b = p.find(id);
    return b != nullptr ? std::optional<Building>(*b) : std::nullopt;
  };
  BuildingsCommand::States before, changed;
  for (int id : ids) {
    before[id] = state(project_, id);
    changed[id] = state(after, id);
  }
  undo_.push(new BuildingsCommand(this, std::move(before), std::move(changed), text));
}

project::ImportSummary Document::importOutlines(const std::vector<core::Feature>& features,
                                                const project::ImportOptions& options) {
  project::Project after = project_;
  project::ImportOptions withOrigin = options;
  withOrigin.origin = "delineo";
  const project::ImportSummary summary = project::importOutlines(after, features, pair_.left.size(), withOrigin);
  pushBuildings(after, summary.added, tr("Import %n outline(s)", nullptr, static_cast<int>(summary.added.size())));
  return summary;
}

project::BuildingEdit Document::splitBuilding(int id, cv::Point2d from, cv::Point2d to) {
  project::Project after = project_;
  const project::BuildingEdit edit = project::splitBuilding(after, id, from, to, disparity_, "delineo");
  pushBuildings(after, edit.ids, tr("Split building %1").arg(id));
  return edit;
}

project::BuildingEdit Document::mergeBuildings(int id, int other) {
  project::Project after = project_;
  const project::BuildingEdit edit = project::mergeBuildings(after, id, other, disparity_, "delineo");
  if (edit.done()) pushBuildings(after, {id, other}, tr("Merge buildings %1 and %2").arg(id).arg(other));
  return edit;
}

void Document::removeBuilding(int id) {
  const Building* b = project_.find(id);
  if (b == nullptr) return;
  undo_.push(new BuildingCommand(this, id, *b, std::nullopt, tr("Remove building %1").arg(id)));
}

void Document::editRing(int id, int ringIndex, const core::Ring& ring, const QString& description) {
  const Building* current = project_.find(id);
  if (current == nullptr || ring.size() < 3) return;
  core::Polygon polygon = current->currentPolygon();
  if (ringIndex == 0) {
    polygon.outer = ring;
  } else if (ringIndex - 1 < static_cast<int>(polygon.holes.size())) {
    polygon.holes[static_cast<size_t>(ringIndex - 1)] = ring;
  } else {
    return;
  }
  setPolygon(id, polygon, description);
}

void Document::setPolygon(int id, const core::Polygon& polygon, const QString& description) {
  const Building* current = project_.find(id);
  if (current == nullptr || polygon.outer.size() < 3) return;
  Building after = *current;
  // A pending building's rough polygon is still the operator's input: edit it in place.
  (after.hasOutline() ? after.outline : after.initial) = polygon;
  if (after.status != BuildingStatus::Pending) after.status = BuildingStatus::Corrected;
  if (after.hasOutline()) after.roofHeight = project::roofHeight(project_, disparity_, after.outline);
  // The energy belongs to the old outline; the window scores the new one in the background.
  after.energy = std::nan("");
  after.energyTerms.reset();
  after.addHistory("edited", description.toStdString());
  undo_.push(new BuildingCommand(this, id, *current, after,
                                 description.isEmpty() ? tr("Edit building %1").arg(id) : description));
}

void Document::setDelineationResult(int id, const project::DelineationOutcome& outcome) {
  const Building* current = project_.find(id);
  if (current == nullptr) return;
  Building after = *current;
  after.outline = outcome.outline;
  after.energy = outcome.energy;
  after.energyTerms = outcome.terms;
  after.status = BuildingStatus::Automatic;
  after.method = project::kActivePolygon;
  after.roofHeight = project::roofHeight(project_, disparity_, after.outline);
  after.addHistory("delineated", std::to_string(outcome.outline.outer.size()) + " vertices, " +
                                     std::to_string(outcome.iterations) + " sweeps");
  undo_.push(new BuildingCommand(this, id, *current, after, tr("Delineate building %1").arg(id)));
}

bool Document::setOutlinedPending(const Building& after) {
  const Building* current = project_.find(after.id);
  if (current == nullptr || current->status != BuildingStatus::Pending) return false;
  if (!(current->initial.outer == after.initial.outer && current->initial.holes == after.initial.holes)) return false;
  if (current->roofInterval && current->roofInterval != after.roofInterval) return false;
  const QString text = after.method == project::kBoxFitting ? tr("Box-fitting outline for building %1").arg(after.id)
                                                            : tr("Delineate building %1").arg(after.id);
  undo_.push(new BuildingCommand(this, after.id, *current, after, text));
  return true;
}

void Document::setBoxFitResult(int id, const project::BoxFitOutcome& outcome,
                               const std::optional<project::EnergyOutcome>& energy) {
  const Building* current = project_.find(id);
  if (current == nullptr || !outcome.hasOutline()) return;
  Building after = project::withBoxFitOutline(project_, *current, outcome, disparity_);
  if (energy) {
    after.energy = energy->energy;
    after.energyTerms = energy->terms;
  }
  undo_.push(new BuildingCommand(this, id, *current, after, tr("Box-fitting outline for building %1").arg(id)));
}

void Document::setStatus(int id, BuildingStatus status) {
  const Building* current = project_.find(id);
  if (current == nullptr || current->status == status) return;
  Building after = *current;
  after.status = status;
  after.addHistory(project::toString(status));
  QString text;
  switch (status) {
    case BuildingStatus::Accepted: text = tr("Accept building %1").arg(id); break;
    case BuildingStatus::Rejected: text = tr("Reject building %1").arg(id); break;
    default: text = tr("Reopen building %1").arg(id); break;
  }
  undo_.push(new BuildingCommand(this, id, *current, after, text));
}

void Document::setRoofInterval(int id, project::DisparityInterval interval) {
  const Building* current = project_.find(id);
  if (current == nullptr || current->roofInterval == interval) return;
  Building after = *current;
  after.roofInterval = interval;
  undo_.push(new BuildingCommand(this, id, *current, after,
                                 tr("Roof interval of building %1: %2..%3 px")
                                     .arg(id)
                                     .arg(interval.low)
                                     .arg(interval.high),
                                 kMergeRoofInterval));
}

void Document::setParameters(const std::string& group, const nlohmann::json& values) {
  auto it = project_.parameters.find(group);
  const nlohmann::json before = it == project_.parameters.end() ? nlohmann::json() : *it;
  // Keys of the group the form does not know (a newer version's) stay in the project.
  nlohmann::json merged = values;
  if (before.is_object() && merged.is_object()) {
    for (auto key = before.begin(); key != before.end(); ++key) {
      if (!merged.contains(key.key())) merged[key.key()] = key.value();
    }
  }
  if (before == merged) return;
  undo_.push(new ParametersCommand(this, group, before, merged,
                                   tr("Change %1 parameters").arg(QString::fromStdString(group))));
}

void Document::setDisparity(const cv::Mat& disparity) {
  undo_.push(new DisparityCommand(this, disparity_, project_.disparity, disparity, tr("Compute disparity")));
}

Document::Settings Document::settings() const {
  Settings s{project_.outputDir, project_.disparityRange, project_.height, project_.method, {}};
  for (const Building& b : project_.buildings) s.roofHeights[b.id] = b.roofHeight;
  return s;
}

void Document::pushSettings(const Settings& after, const QString& description) {
  undo_.push(new SettingsCommand(this, settings(), after, description));
}

void Document::setOutputDir(const std::string& dir) {
  if (dir.empty() || dir == project_.outputDir) return;
  Settings after = settings();
  after.outputDir = dir;
  pushSettings(after, tr("Output folder: %1").arg(QString::fromStdString(dir)));
}

void Document::setDisparityRange(const std::optional<project::DisparityInterval>& range, const QString& description) {
  if (range == project_.disparityRange) return;
  Settings after = settings();
  after.disparityRange = range;
  pushSettings(after, description);
}

void Document::setHeightModel(const project::HeightModel& model) {
  if (model == project_.height) return;
  Settings after = settings();
  after.height = model;
  project::Project withModel = project_;
  withModel.height = model;
  for (const Building& b : project_.buildings) {
    after.roofHeights[b.id] =
        b.hasOutline() ? project::roofHeight(withModel, disparity_, b.outline) : std::nan("");
  }
  pushSettings(after, tr("Height model"));
}

void Document::setMethod(const std::string& method) {
  if (method == project_.method) return;
  Settings after = settings();
  after.method = method;
  pushSettings(after, method == project::kBoxFitting ? tr("Outline with box-fitting") : tr("Outline with the active polygon"));
}

void Document::restoreSettings(const Settings& settings) {
  const bool newModel = !(settings.height == project_.height);
  project_.outputDir = settings.outputDir;
  project_.method = settings.method;
  project_.disparityRange = settings.disparityRange;
  project_.height = settings.height;
  for (Building& b : project_.buildings) {
    auto it = settings.roofHeights.find(b.id);
    if (it != settings.roofHeights.end()) b.roofHeight = it->second;
  }
  if (newModel) deriveDem();
  emit settingsChanged();
  emit buildingsReset();
}

void Document::setOutlineEnergy(int id, const core::Polygon& outline, double energy,
                                const std::optional<project::EnergyTerms>& terms) {
  Building* b = project_.find(id);
  if (b == nullptr || !b->hasOutline() || !(b->outline.outer == outline.outer && b->outline.holes == outline.holes)) {
    return;
  }
  b->energy = energy;
  b->energyTerms = terms;
  emit buildingChanged(id);
}

QString Document::outputDirectory() const {
  try {
    return QString::fromStdString(project::outputDirectory(project_, path_.toStdString()));
  } catch (const core::Error&) {
    return {};
  }
}

QString Document::dialogFolder() const {
  if (!path_.isEmpty()) return QFileInfo(path_).absolutePath();
  const QString last = QSettings().value(QStringLiteral("lastProjectFolder")).toString();
  return !last.isEmpty() && QFileInfo(last).isDir() ? last : QDir::homePath();
}

void Document::placeBuilding(int id, const std::optional<Building>& state) {
  auto& list = project_.buildings;
  Building* existing = project_.find(id);
  if (state) {
    if (existing != nullptr) *existing = *state;
    else list.push_back(*state);
    std::sort(list.begin(), list.end(), [](const Building& a, const Building& b) { return a.id < b.id; });
  } else if (existing != nullptr) {
    list.erase(list.begin() + (existing - list.data()));
  }
}

void Document::restoreBuilding(int id, const std::optional<Building>& state) {
  placeBuilding(id, state);
  emit buildingChanged(id);
}

void Document::restoreBuildings(const std::map<int, std::optional<Building>>& states) {
  for (const auto& [id, state] : states) placeBuilding(id, state);
  emit buildingsReset();
}

void Document::restoreParameters(const std::string& group, const nlohmann::json& values) {
  if (values.is_null()) project_.parameters.erase(group);
  else project_.parameters[group] = values;
  emit parametersChanged(QString::fromStdString(group));
}

void Document::restoreDisparity(const cv::Mat& disparity, const std::string& path) {
  disparity_ = disparity;
  pair_.disparity = disparity;
  project_.disparity = path;
  disparityOnDisk_ = !path.empty() || disparity.empty();
  deriveDem();
  emit disparityChanged();
}

void Document::save(const QString& path) {
  project::Project toSave = project_;
  if (!disparityOnDisk_ && !disparity_.empty()) {
    // The output folder of the project at its new place (relative folders follow the file).
    const std::string dir = project::outputDirectory(project_, path.toStdString());
    const std::string out = (fs::path(dir) / "disparity.tif").string();
    std::error_code ec;
    fs::create_directories(dir, ec);
    io::writeFloatGeoTiff(out, disparity_, pair_.geo);
    project_.disparity = out;
    toSave.disparity = out;
    disparityOnDisk_ = true;
  }
  project::saveProject(toSave, path.toStdString());
  std::error_code ec;
  if (!path_.isEmpty()) fs::remove(project::autosavePath(path_.toStdString()), ec);
  path_ = path;
  fs::remove(project::autosavePath(path_.toStdString()), ec);
  undo_.setClean();
  setExtraDirty(false);
}

void Document::autosave() {
  if (!isModified() || path_.isEmpty()) return;
  project::saveProject(project_, project::autosavePath(path_.toStdString()));
}

project::ExportSummary Document::exportAccepted(const QString& path, const cv::Mat& dtm) const {
  project::CityModelInputs model;
  model.heights = dem_;  // the 3D view's ground next to each building
  model.dtm = dtm;
  return project::exportBuildings(project_, path.toStdString(), {project::BuildingStatus::Accepted}, model);
}

void Document::setExtraDirty(bool dirty) {
  if (extraDirty_ == dirty) return;
  extraDirty_ = dirty;
  emit modifiedChanged(isModified());
}

}  // namespace delineo::gui
