#pragma once
// Set-up shared by the GUI tests that drive the real main window on the generated sample
// project: settings of their own, the sample project, the window shown.
#include <QCoreApplication>
#include <QSettings>
#include <QStandardPaths>
#include <QString>
#include <QTemporaryDir>
#include <memory>
#include <string>
#include <thread>

#include "delineo/project/pipeline.hpp"
#include "main_window.hpp"

namespace delineo::guitest {

// Settings kept apart from the user's and from the other test programs' (`organisation`), cleared,
// with no matching on opening; `delineateOnPick` false leaves every step of a pick to the test.
inline void isolateSettings(const QString& organisation, bool delineateOnPick) {
  QStandardPaths::setTestModeEnabled(true);
  QCoreApplication::setOrganizationName(organisation);
  QSettings().clear();
  QSettings().setValue(QStringLiteral("autoMatch"), false);
  QSettings().setValue(QStringLiteral("delineateOnPick"), delineateOnPick);
}

// The sample project made in `dir`/sample on a worker thread, as the application's job runner
// makes it; its project file's path.
inline QString makeSampleProject(const QTemporaryDir& dir) {
  const std::string sampleDir = dir.filePath(QStringLiteral("sample")).toStdString();
  std::string made;
  std::thread maker([&] { made = project::ensureSampleProject(sampleDir); });
  maker.join();
  return QString::fromStdString(made);
}

// The main window without modal dialogs, shown at the size the tests' view positions assume.
// The caller waits for it to be exposed.
inline std::unique_ptr<gui::MainWindow> showMainWindow() {
  auto window = std::make_unique<gui::MainWindow>();
  window->setInteractive(false);
  window->resize(1300, 850);
  window->show();
  return window;
}

}  // namespace delineo::guitest
