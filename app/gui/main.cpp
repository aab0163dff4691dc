// delineo: the operator's delineation workstation.
//   delineo                      opens the bundled sample project (made on first start)
//   delineo PROJECT              opens a project file
//   delineo --left L --right R   starts a new project on a stereo pair
#include <QApplication>
#include <QCommandLineParser>
#include <QLibraryInfo>
#include <QLocale>
#include <QSettings>
#include <QSurfaceFormat>
#include <QTranslator>

#include "delineo/core/allocator.hpp"
#include "main_window.hpp"
#include "screenshot_tour.hpp"

namespace {
// Loads the application's and Qt's own translations for the chosen language ("" = system).
void installTranslations(QApplication& app) {
  const QString code = QSettings().value(QStringLiteral("language")).toString();
  const QLocale locale = code.isEmpty() ? QLocale::system() : QLocale(code);
  QLocale::setDefault(locale);
  auto* appTranslator = new QTranslator(&app);
  if (appTranslator->load(locale, QStringLiteral("delineo"), QStringLiteral("_"), QStringLiteral(":/i18n"))) {
    QApplication::installTranslator(appTranslator);
  }
  auto* qtTranslator = new QTranslator(&app);
  if (qtTranslator->load(locale, QStringLiteral("qtbase"), QStringLiteral("_"),
                         QLibraryInfo::path(QLibraryInfo::TranslationsPath))) {
    QApplication::installTranslator(qtTranslator);
  }
}
}  // namespace

int main(int argc, char** argv) {
  delineo::core::tuneAllocatorForLargeImages();  // before any image is allocated
  // The 3D view (VTK) needs this format before the application exists (docs/qt6-vtk-facts.md).
  QSurfaceFormat format;
  format.setVersion(3, 2);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setDepthBufferSize(24);
  format.setStencilBufferSize(8);
  QSurfaceFormat::setDefaultFormat(format);

  QApplication app(argc, argv);
  QApplication::setOrganizationName(QStringLiteral("Delineo"));
  QApplication::setApplicationName(QStringLiteral("delineo"));
  QApplication::setApplicationVersion(QStringLiteral("0.1.0"));
  installTranslations(app);

  QCommandLineParser parser;
  parser.setApplicationDescription(QApplication::translate("main", "Building delineation on stereo pairs"));
  parser.addHelpOption();
  parser.addVersionOption();
  parser.addPositionalArgument(QStringLiteral("project"), QApplication::translate("main", "Project file to open"));
  QCommandLineOption leftOption(QStringLiteral("left"), QApplication::translate("main", "Left (reference) image"),
                                QStringLiteral("file"));
  QCommandLineOption rightOption(QStringLiteral("right"), QApplication::translate("main", "Right image"),
                                 QStringLiteral("file"));
  // Hidden: scripted tour that saves a PNG of each main state (scripts/screenshots.sh); with
  // --left and --right, on that pair instead of the sample.
  QCommandLineOption screenshotOption(QStringLiteral("screenshot-dir"), QString(), QStringLiteral("dir"));
  screenshotOption.setFlags(QCommandLineOption::HiddenFromHelp);
  parser.addOption(leftOption);
  parser.addOption(rightOption);
  parser.addOption(screenshotOption);
  parser.process(app);

  delineo::gui::MainWindow window;
  if (parser.isSet(screenshotOption)) {
    window.setInteractive(false);
    window.showActivated();
    const QString dir = parser.value(screenshotOption);
    const bool onPair = parser.isSet(leftOption) && parser.isSet(rightOption);
    const bool done = onPair ? delineo::gui::runPairScreenshotTour(window, dir, parser.value(leftOption),
                                                                   parser.value(rightOption))
                             : delineo::gui::runScreenshotTour(window, dir);
    return done ? 0 : 1;
  }
  window.showActivated();
  if (parser.isSet(leftOption) || parser.isSet(rightOption)) {
    if (!parser.isSet(leftOption) || !parser.isSet(rightOption)) {
      parser.showHelp(2);
    }
    window.openPair(parser.value(leftOption), parser.value(rightOption));
  } else if (!parser.positionalArguments().isEmpty()) {
    window.openProject(parser.positionalArguments().first());
  } else {
    window.openSample();
  }
  return app.exec();
}
