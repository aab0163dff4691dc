#pragma once
// core::Error codes as translated sentences for message boxes; the developer detail follows.
#include <QString>

#include "delineo/core/error.hpp"

namespace delineo::gui {

QString errorSentence(core::ErrorCode code, const QString& path = {});
// Sentence + the detail, for a message box's text.
QString errorMessage(const core::Error& error);

}  // namespace delineo::gui
