#pragma once
// A scripted walk through the main states of the workstation on the sample project, saving a
// PNG of the window at each step (hidden option --screenshot-dir, scripts/screenshots.sh).
#include <QString>

namespace delineo::gui {

class MainWindow;

// Returns false when a step failed (the message is printed on stderr).
bool runScreenshotTour(MainWindow& window, const QString& directory);

// The same on an operator's own pair (--left, --right): the window right after opening it,
// then a building picked at the image centre, delineated, and a rubber band selecting vertices
// of its outline in Edit outline mode (during the drag and after it).
bool runPairScreenshotTour(MainWindow& window, const QString& directory, const QString& left,
                           const QString& right);

}  // namespace delineo::gui
