#pragma once
// Set-up shared by the GUI tests that drive the real main window on the generated sample
// project: settings of their own, the sample project, the window shown, a pair without heights.
#include <QCoreApplication>
#include <QSettings>
#include <QStandardPaths>
#include <QString>
#include <QTemporaryDir>
#include <memory>
#include <string>
#include <thread>

#include <opencv2/core.hpp>

#include "delineo/io/raster.hpp"
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

// Opens in `window` a pair without heights (no disparity, no DEM, no height model) written into
// `dir`: two copies of one noise image of `size`.
inline bool openPairWithoutHeights(gui::MainWindow& window, const QTemporaryDir& dir, cv::Size size = {160, 120}) {
  cv::Mat left(size, CV_8U);
  cv::randu(left, 0, 255);
  const QString l = dir.filePath(QStringLiteral("bare_left.tif"));
  const QString r = dir.filePath(QStringLiteral("bare_right.tif"));
  io::writeGeoTiff(l.toStdString(), left);
  io::writeGeoTiff(r.toStdString(), left);
  return window.openPair(l, r);
}

}  // namespace delineo::guitest
