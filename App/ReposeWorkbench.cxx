// ReposeWorkbench: the host application. Discovers modules, shows the main window, and offers
// headless modes for scripts and tests (--list-modules, --screenshot).
#include "qReposeMainWindow.h"
#include "qReposeModuleDiscovery.h"

#include <QApplication>
#include <QCommandLineParser>
#include <QPixmap>
#include <QSurfaceFormat>
#include <QTextStream>
#include <QTimer>

#include <cstring>
#include <memory>

namespace {

int listModules(const qReposeModuleDiscovery& discovery) {
  QTextStream out(stdout), err(stderr);
  for (const auto& m : discovery.modules())
    out << m.description.name << '\t' << m.description.version << '\t' << m.description.category
        << '\t' << m.description.title << '\t' << m.description.jsonPath << '\n';
  for (const QString& error : discovery.errors()) err << "error: " << error << '\n';
  if (discovery.modules().isEmpty())
    err << "error: no modules found in " << discovery.searchPaths().join(", ") << '\n';
  return discovery.errors().isEmpty() && !discovery.modules().isEmpty() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  // Listing and help need no display, so they run on a core application (no platform plugin).
  bool headless = false;
  for (int i = 1; i < argc; ++i)
    for (const char* option : {"--list-modules", "--help", "-h", "--version", "-v"})
      headless = headless || std::strcmp(argv[i], option) == 0;
  // Modules' 3D views (VTK) need an OpenGL 3.2 core context; it must be the default before the
  // application exists.
  if (!headless) {
    QSurfaceFormat format;
    format.setRenderableType(QSurfaceFormat::OpenGL);
    format.setVersion(3, 2);
    format.setProfile(QSurfaceFormat::CoreProfile);
    format.setSwapBehavior(QSurfaceFormat::DoubleBuffer);
    format.setRedBufferSize(8);
    format.setGreenBufferSize(8);
    format.setBlueBufferSize(8);
    format.setDepthBufferSize(8);
    format.setAlphaBufferSize(8);
    format.setStencilBufferSize(0);
    QSurfaceFormat::setDefaultFormat(format);
  }
  std::unique_ptr<QCoreApplication> app(headless ? new QCoreApplication(argc, argv)
                                                 : new QApplication(argc, argv));
  QCoreApplication::setApplicationName("ReposeWorkbench");
  QCoreApplication::setApplicationVersion(REPOSE_VERSION);

  QCommandLineParser parser;
  parser.setApplicationDescription("Repose workbench: re-pose segmented whole-body label maps.");
  parser.addHelpOption();
  parser.addVersionOption();
  const QCommandLineOption listOption("list-modules", "Print the discovered modules and exit.");
  const QCommandLineOption pathOption(
      "module-path", "Also look for modules in <dir> (before REPOSE_MODULE_PATH and the default).",
      "dir");
  const QCommandLineOption moduleOption("module", "Show module <name> first.", "name");
  const QCommandLineOption openOption("open", "Open <file> with the current module.", "file");
  const QCommandLineOption sceneOption(
      "scene", "Open the scene folder <dir> (scene.json and its files) with the current module.",
      "dir");
  const QCommandLineOption screenshotOption(
      "screenshot",
      "Render the window to <png> and exit (after the module's background work; the 3D view "
      "needs a display, e.g. xvfb-run).",
      "png");
  parser.addOptions(
      {listOption, pathOption, moduleOption, openOption, sceneOption, screenshotOption});
  parser.process(*app);

  qReposeModuleDiscovery discovery;
  discovery.setSearchPaths(qReposeModuleDiscovery::defaultSearchPaths(parser.values(pathOption)));
  discovery.discover();
  if (parser.isSet(listOption)) return listModules(discovery);

  qReposeMainWindow window(&discovery);
  QTextStream err(stderr);
  if (parser.isSet(moduleOption) && !window.selectModule(parser.value(moduleOption))) {
    err << "error: no module named " << parser.value(moduleOption) << '\n';
    return 1;
  }
  bool opened = true;
  if (parser.isSet(openOption)) opened = window.openFile(parser.value(openOption));
  if (parser.isSet(sceneOption)) opened = window.openFile(parser.value(sceneOption)) && opened;
  window.show();
  if (parser.isSet(screenshotOption)) {
    // The scene's background work (live posing) finishes before the picture is taken.
    if (!window.waitWhileBusy(300)) {
      err << "error: the module was still busy after 300 s\n";
      return 1;
    }
    QCoreApplication::processEvents();
    const QString path = parser.value(screenshotOption);
    if (!window.grab().save(path)) {
      err << "error: cannot write screenshot " << path << '\n';
      return 1;
    }
    return opened ? 0 : 1;
  }
  return app->exec();
}
