#include "commands.hpp"

#include "document.hpp"

namespace delineo::gui {

BuildingCommand::BuildingCommand(Document* document, int id, std::optional<project::Building> before,
                                 std::optional<project::Building> after, const QString& text, int mergeKey)
    : QUndoCommand(text),
      document_(document),
      buildingId_(id),
      before_(std::move(before)),
      after_(std::move(after)),
      mergeKey_(mergeKey) {}

void BuildingCommand::undo() { document_->restoreBuilding(buildingId_, before_); }
void BuildingCommand::redo() { document_->restoreBuilding(buildingId_, after_); }

bool BuildingCommand::mergeWith(const QUndoCommand* other) {
  const auto* o = dynamic_cast<const BuildingCommand*>(other);
  if (o == nullptr || o->buildingId_ != buildingId_ || mergeKey_ < 0) return false;
  after_ = o->after_;
  return true;
}

BuildingsCommand::BuildingsCommand(Document* document, States before, States after, const QString& text)
    : QUndoCommand(text), document_(document), before_(std::move(before)), after_(std::move(after)) {}

void BuildingsCommand::undo() { document_->restoreBuildings(before_); }
void BuildingsCommand::redo() { document_->restoreBuildings(after_); }

ParametersCommand::ParametersCommand(Document* document, std::string group, nlohmann::json before,
                                     nlohmann::json after, const QString& text)
    : QUndoCommand(text),
      document_(document),
      group_(std::move(group)),
      before_(std::move(before)),
      after_(std::move(after)) {}

void ParametersCommand::undo() { document_->restoreParameters(group_, before_); }
void ParametersCommand::redo() { document_->restoreParameters(group_, after_); }

bool ParametersCommand::mergeWith(const QUndoCommand* other) {
  const auto* o = dynamic_cast<const ParametersCommand*>(other);
  if (o == nullptr || o->group_ != group_) return false;
  after_ = o->after_;
  return true;
}

DisparityCommand::DisparityCommand(Document* document, cv::Mat before, std::string beforePath,
                                   cv::Mat after, const QString& text)
    : QUndoCommand(text),
      document_(document),
      before_(std::move(before)),
      after_(std::move(after)),
      beforePath_(std::move(beforePath)) {}

void DisparityCommand::undo() { document_->restoreDisparity(before_, beforePath_); }
void DisparityCommand::redo() { document_->restoreDisparity(after_, {}); }

SettingsCommand::SettingsCommand(Document* document, Document::Settings before, Document::Settings after,
                                 const QString& text)
    : QUndoCommand(text), document_(document), before_(std::move(before)), after_(std::move(after)) {}

void SettingsCommand::undo() { document_->restoreSettings(before_); }
void SettingsCommand::redo() { document_->restoreSettings(after_); }

}  // namespace delineo::gui
