#pragma once
// The open project as the GUI sees it: the Qt-free project::Project, the rasters it names
// (loaded once), and the undo stack through which every change goes. Views and models observe
// the signals; they never modify the project directly.
#include <QObject>
#include <QString>
#include <QUndoStack>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/io/raster.hpp"
#include "delineo/project/building_edits.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/project.hpp"

namespace delineo::gui {

class Document : public QObject {
  Q_OBJECT
 public:
  // Loads the project and its rasters. Throws core::Error (missing project, corrupt file,
  // unreadable or mismatched images); nothing is half-loaded on failure.
  static std::unique_ptr<Document> open(const QString& projectPath);
  // Opens an already-parsed project (e.g. after relocating a missing image or restoring an
  // autosave). `path` is where it will be saved.
  static std::unique_ptr<Document> fromProject(project::Project project, const QString& path);
  // A new, unsaved project on a stereo pair.
  static std::unique_ptr<Document> fromPair(const QString& left, const QString& right);

  const project::Project& project() const { return project_; }
  QString path() const { return path_; }
  QString displayName() const;
  QUndoStack* undoStack() { return &undo_; }
  bool isModified() const { return !undo_.isClean() || extraDirty_; }

  const project::StereoPair& pair() const { return pair_; }
  const cv::Mat& leftGrey() const { return leftGrey_; }    // CV_8U for display and read-out
  const cv::Mat& rightGrey() const { return rightGrey_; }
  // What the image views show: CV_8UC3 (BGR) when the file is a colour image, else the grey
  // image. Matching, the read-out and the edge map use the grey images.
  const cv::Mat& leftDisplay() const { return leftColour_.empty() ? leftGrey_ : leftColour_; }
  const cv::Mat& rightDisplay() const { return rightColour_.empty() ? rightGrey_ : rightColour_; }
  const cv::Mat& disparity() const { return disparity_; }  // CV_32F, empty when not computed
  const cv::Mat& dem() const { return dem_; }              // CV_32F metres, file or derived
  const cv::Mat& labels() const { return labels_; }        // CV_8U, may be empty
  bool demIsDerived() const { return demDerived_; }

  // ---- changes, each one an undoable command ----
  int addBuilding(const core::Polygon& initial);
  void removeBuilding(int id);
  // Replaces ring `ringIndex` (0 outer, k hole k-1) of the building's current polygon.
  void editRing(int id, int ringIndex, const core::Ring& ring, const QString& description);
  // Replaces the building's current polygon (e.g. a hole removed, vertices of several rings
  // deleted at once).
  void setPolygon(int id, const core::Polygon& polygon, const QString& description);
  // An active polygon result (status Automatic).
  void setDelineationResult(int id, const project::DelineationOutcome& outcome);
  // A box-fitting result the operator keeps (status Automatic, method "box-fitting"), with the
  // active polygon's energy of its outline when it was scored.
  void setBoxFitResult(int id, const project::BoxFitOutcome& outcome,
                       const std::optional<project::EnergyOutcome>& energy);
  // A pending building as project::outlinePendingBuilding() outlined it, applied only while the
  // building is still pending with the initial polygon it was outlined from (the operator may
  // have changed it meanwhile); returns whether it was applied.
  bool setOutlinedPending(const project::Building& after);
  // The scene analysis's building proposals that are not buildings yet, added as Pending
  // buildings (project::addProposedBuildings) in one undoable step. Returns the new ids; a proposal's
  // malformed roof interval is left out and said in `problems` when given.
  std::vector<int> addProposedBuildings(const std::vector<core::Feature>& proposals,
                                        std::vector<std::string>* problems = nullptr);
  // Outlines of another source (left-image pixels, as io::readFeatures gives them) added as
  // Pending buildings (project::importOutlines, origin "delineo") in one undoable step; none when
  // no outline is added. Throws like project::importOutlines.
  project::ImportSummary importOutlines(const std::vector<core::Feature>& features,
                                        const project::ImportOptions& options);
  // Building `id` cut along the segment from `from` to `to` (left-image pixels) by
  // project::splitBuilding with the disparity map, in one undoable step; a refusal changes nothing.
  project::BuildingEdit splitBuilding(int id, cv::Point2d from, cv::Point2d to);
  // Building `other` merged into building `id` by project::mergeBuildings with the disparity map,
  // in one undoable step; a refusal changes nothing.
  project::BuildingEdit mergeBuildings(int id, int other);
  void setStatus(int id, project::BuildingStatus status);
  void setRoofInterval(int id, project::DisparityInterval interval);
  void setParameters(const std::string& group, const nlohmann::json& values);
  void setDisparity(const cv::Mat& disparity);
  // Project-wide settings. A new height model recomputes every building's roof height in the
  // same step.
  void setOutputDir(const std::string& dir);
  void setDisparityRange(const std::optional<project::DisparityInterval>& range, const QString& description);
  void setHeightModel(const project::HeightModel& model);
  // The method buildings that name none are outlined with (project::kActivePolygon, kBoxFitting).
  void setMethod(const std::string& method);
  // A derived value, not an edit (no undo step): the energy of a building's outline, recorded
  // only while the building's outline is still `outline`.
  void setOutlineEnergy(int id, const core::Polygon& outline, double energy,
                        const std::optional<project::EnergyTerms>& terms);

  // The absolute folder outputs are written to; empty while a relative folder has no project
  // file to be relative to (an unsaved project writes nothing).
  QString outputDirectory() const;
  // The folder file dialogs start in: the project's folder, else the last folder used.
  QString dialogFolder() const;

  // What setOutputDir/setDisparityRange/setHeightModel change, for their undo command.
  struct Settings {
    std::string outputDir;
    std::optional<project::DisparityInterval> disparityRange;
    project::HeightModel height;
    std::string method;  // the project's outline method (Project::method)
    std::map<int, double> roofHeights;
  };
  Settings settings() const;

  // ---- used by the undo commands only ----
  void restoreBuilding(int id, const std::optional<project::Building>& state);
  void restoreBuildings(const std::map<int, std::optional<project::Building>>& states);
  void restoreParameters(const std::string& group, const nlohmann::json& values);
  void restoreDisparity(const cv::Mat& disparity, const std::string& path);
  void restoreSettings(const Settings& settings);

  // Atomic save (writes a freshly computed disparity next to the outputs first). Throws
  // core::Error(WriteFailed). Marks the document clean and removes the autosave.
  void save(const QString& path);
  // Writes the autosave companion file when modified; no-op otherwise.
  void autosave();
  // Exports the accepted buildings (outlines, or LoD1 blocks for a CityJSON name, on the ground
  // next to each in dem(), with `dtm` as terrain when not empty); returns how many were written
  // and which were left out.
  project::ExportSummary exportAccepted(const QString& path, const cv::Mat& dtm = {}) const;

 signals:
  void buildingChanged(int id);  // added, modified or removed
  void buildingsReset();
  void parametersChanged(const QString& group);
  void disparityChanged();
  void settingsChanged();  // output folder, disparity range or height model
  void modifiedChanged(bool modified);

 private:
  Document() = default;
  void loadRasters();
  void placeBuilding(int id, const std::optional<project::Building>& state);
  void deriveDem();
  void setExtraDirty(bool dirty);
  void pushSettings(const Settings& after, const QString& description);
  // The buildings `ids` as they are in `after` (a changed copy of the project; absent there:
  // removed) as one undo step.
  void pushBuildings(const project::Project& after, const std::vector<int>& ids, const QString& text);

  project::Project project_;
  QString path_;
  QUndoStack undo_;
  bool extraDirty_ = false;
  bool disparityOnDisk_ = true;
  project::StereoPair pair_;
  cv::Mat leftGrey_, rightGrey_, disparity_, dem_, labels_;
  cv::Mat leftColour_, rightColour_;  // empty for grey sources
  bool demDerived_ = false;
};

}  // namespace delineo::gui
