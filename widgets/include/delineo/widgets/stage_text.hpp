#pragma once
// The GUI's wording of an algorithm's progress stage, in the user's language.
#include <QString>

#include "delineo/core/progress.hpp"

namespace delineo::widgets {

// Translated text of `stage` (context "Stages"); free-text stages are shown as they are.
QString stageText(const core::Stage& stage);

}  // namespace delineo::widgets
