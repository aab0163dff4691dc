#pragma once
// Undo commands: every change of a document is one of these, so Ctrl+Z / Ctrl+Y cover manual
// edits, status changes, parameter changes and algorithm results alike.
#include <QUndoCommand>
#include <map>
#include <optional>

#include <opencv2/core.hpp>

#include "delineo/project/project.hpp"
#include "document.hpp"

namespace delineo::gui {

// A building's full state before and after (nullopt = absent): add, remove, edit, result.
class BuildingCommand : public QUndoCommand {
 public:
  // Commands with the same non-negative merge key on the same building merge (interval drags).
  BuildingCommand(Document* document, int id, std::optional<project::Building> before,
                  std::optional<project::Building> after, const QString& text, int mergeKey = -1);
  void undo() override;
  void redo() override;
  int id() const override { return mergeKey_; }
  bool mergeWith(const QUndoCommand* other) override;

 private:
  Document* document_;
  int buildingId_;
  std::optional<project::Building> before_, after_;
  int mergeKey_;
};

// Several buildings' states before and after as one step (the buildings Detect buildings and
// Import outlines add).
class BuildingsCommand : public QUndoCommand {
 public:
  using States = std::map<int, std::optional<project::Building>>;
  BuildingsCommand(Document* document, States before, States after, const QString& text);
  void undo() override;
  void redo() override;

 private:
  Document* document_;
  States before_, after_;
};

class ParametersCommand : public QUndoCommand {
 public:
  ParametersCommand(Document* document, std::string group, nlohmann::json before,
                    nlohmann::json after, const QString& text);
  void undo() override;
  void redo() override;
  int id() const override { return 1000; }
  bool mergeWith(const QUndoCommand* other) override;

 private:
  Document* document_;
  std::string group_;
  nlohmann::json before_, after_;
};

class DisparityCommand : public QUndoCommand {
 public:
  DisparityCommand(Document* document, cv::Mat before, std::string beforePath, cv::Mat after,
                   const QString& text);
  void undo() override;
  void redo() override;

 private:
  Document* document_;
  cv::Mat before_, after_;
  std::string beforePath_;
};

// Project-wide settings (output folder, disparity range, height model with the roof heights
// it gives) before and after.
class SettingsCommand : public QUndoCommand {
 public:
  SettingsCommand(Document* document, Document::Settings before, Document::Settings after, const QString& text);
  void undo() override;
  void redo() override;

 private:
  Document* document_;
  Document::Settings before_, after_;
};

// Merge keys of BuildingCommand.
inline constexpr int kMergeRoofInterval = 2000;

}  // namespace delineo::gui
