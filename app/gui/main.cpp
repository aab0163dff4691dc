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

namespace {
// Loads the application's and Qt's own translations for the chosen language ("" = system).
void installTranslations(QCoreApplication& app) {
  const QString code = QSettings().value(QStringLiteral("language")).toString();
  const QLocale locale = code.isEmpty() ? QLocale::system() : QLocale(code);
  QLocale::setDefault(locale);
  auto* appTranslator = new QTranslator(&app);
  if (appTranslator->load(locale, QStringLiteral("delineo"), QStringLiteral("_"), QStringLiteral(":/i18n"))) {
    QCoreApplication::installTranslator(appTranslator);
  }
  auto* qtTranslator = new QTranslator(&app);
  if (qtTranslator->load(locale, QStringLiteral("qtbase"), QStringLiteral("_"),
                         QLibraryInfo::path(QLibraryInfo::TranslationsPath))) {
    QCoreApplication::installTranslator(qtTranslator);
  }
}

void setApplicationNames() {
  QCoreApplication::setOrganizationName(QStringLiteral("Delineo"));
  QCoreApplication::setApplicationName(QStringLiteral("delineo"));
  QCoreApplication::setApplicationVersion(QStringLiteral("0.1.0"));
}

// The command line, the same whether a display is needed or not.
struct CommandLine {
  QCommandLineParser parser;
  QCommandLineOption left{QStringLiteral("left"), QCoreApplication::translate("main", "Left (reference) image"),
                          QStringLiteral("file")};
  QCommandLineOption right{QStringLiteral("right"), QCoreApplication::translate("main", "Right image"),
                           QStringLiteral("file")};

  CommandLine() {
    parser.setApplicationDescription(QCoreApplication::translate("main", "Building delineation on stereo pairs"));
    parser.addHelpOption();
    parser.addVersionOption();
    parser.addPositionalArgument(QStringLiteral("project"), QCoreApplication::translate("main", "Project file to open"));
    parser.addOption(left);
    parser.addOption(right);
  }
};

// --help and --version print and exit: they must work without a display (over ssh, in scripts).
bool onlyPrints(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const QByteArray arg(argv[i]);
    if (arg == "-h" || arg == "--help" || arg == "--help-all" || arg == "-?" || arg == "-v" || arg == "--version") {
      return true;
    }
  }
  return false;
}
}  // namespace

int main(int argc, char** argv) {
  delineo::core::tuneAllocatorForLargeImages();  // before any image is allocated
  if (onlyPrints(argc, argv)) {
    QCoreApplication app(argc, argv);
    setApplicationNames();
    installTranslations(app);
    CommandLine commandLine;
    commandLine.parser.process(app);  // prints and exits
    return 0;
  }
  // The 3D view (VTK) needs this format before the application exists (docs/qt6-vtk-facts.md).
  QSurfaceFormat format;
  format.setVersion(3, 2);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setDepthBufferSize(24);
  format.setStencilBufferSize(8);
  QSurfaceFormat::setDefaultFormat(format);

  QApplication app(argc, argv);
  setApplicationNames();
  installTranslations(app);
  CommandLine commandLine;
  QCommandLineParser& parser = commandLine.parser;
  parser.process(app);

  delineo::gui::MainWindow window;
  window.showActivated();
  if (parser.isSet(commandLine.left) || parser.isSet(commandLine.right)) {
    if (!parser.isSet(commandLine.left) || !parser.isSet(commandLine.right)) {
      parser.showHelp(2);
    }
    window.openPair(parser.value(commandLine.left), parser.value(commandLine.right));
  } else if (!parser.positionalArguments().isEmpty()) {
    window.openProject(parser.positionalArguments().first());
  } else {
    window.openSample();
  }
  return app.exec();
}
