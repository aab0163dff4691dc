#pragma once
// A scripted walk through the main states of the workstation on the sample project, saving a
// PNG of the window at each step (hidden option --screenshot-dir, scripts/screenshots.sh).
#include <QString>

namespace delineo::gui {

class MainWindow;

// Returns false when a step failed (the message is printed on stderr).
bool runScreenshotTour(MainWindow& window, const QString& directory);

}  // namespace delineo::gui
